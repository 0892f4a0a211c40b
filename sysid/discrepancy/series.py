"""The flown part of a flight as the discrepancy search sees it: uniform samples, angular accelerations.

Equation-error models need the outputs the physics acts on: the specific
forces ``ax ay az`` (m/s²) as logged and the angular accelerations
``p_dot q_dot r_dot`` (rad/s², a Savitzky-Golay derivative of the rates).
Every record of a conditioned flight is resampled to one rate and kept
apart (lags never reach across a gap); only the samples where the vehicle
flies (thrust above a third of its 95th percentile, and off the ground
where a height is logged) are used.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.signal import savgol_filter

from flightlogs.errors import DataError
from flightlogs.record import Record

__all__ = ["OUTPUTS", "COMMANDS", "FlightSeries", "flight_series"]

#: Outputs the terms act on: specific forces (m/s²) and angular accelerations (rad/s²).
OUTPUTS: tuple[str, ...] = ("ax", "ay", "az", "p_dot", "q_dot", "r_dot")
#: Mixer inputs (as logged).
COMMANDS: tuple[str, ...] = ("delta_lat", "delta_lon", "delta_yaw", "delta_thr")
_NEEDED = ("p", "q", "r", "ax", "ay", "az", *COMMANDS)
_RATE_HZ = 50.0  # the search's sample rate
_SMOOTH_S = 0.1  # Savitzky-Golay window of the rate derivatives
_THRUST_ON = 1.0 / 3.0  # flying: thrust above this fraction of its 95th percentile
_ON_GROUND_M = 0.05  # and, where a height is logged, above this


@dataclass(frozen=True, slots=True, kw_only=True)
class FlightSeries:
    """Uniform samples of the flown part of one flight.

    Parameters
    ----------
    name : str
        The log's name, for messages.
    time_s : ndarray, shape (n,)
        Sample times on the log clock, s.
    piece : ndarray of int, shape (n,)
        Index of the contiguous piece each sample belongs to.
    signals : Mapping[str, ndarray]
        Each shape (n,): the canonical signals, ``p_dot q_dot r_dot`` (rad/s²) and a flight clock ``t_flight``
        (s since the first flown sample).
    rate_hz : float
        Sample rate, Hz.
    """

    name: str
    time_s: np.ndarray
    piece: np.ndarray
    signals: Mapping[str, np.ndarray]
    rate_hz: float

    def __getitem__(self, name: str) -> np.ndarray:
        return self.signals[name]

    def __contains__(self, name: object) -> bool:
        return name in self.signals

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.time_s.size)

    def pieces(self) -> list[np.ndarray]:
        """Sample indices of each contiguous piece, in order."""
        edges = np.flatnonzero(np.diff(self.piece)) + 1
        return np.split(np.arange(self.n), edges)

    def subset(self, rows: np.ndarray) -> FlightSeries:
        """The samples `rows` (sorted indices), pieces split where rows skip samples."""
        rows = np.asarray(rows)
        breaks = np.concatenate([[0], np.cumsum((np.diff(rows) != 1) | (np.diff(self.piece[rows]) != 0))])
        return FlightSeries(
            name=self.name,
            time_s=self.time_s[rows],
            piece=breaks,
            signals={k: v[rows] for k, v in self.signals.items()},
            rate_hz=self.rate_hz,
        )


def flight_series(name: str, records: Sequence[Record], rate_hz: float = _RATE_HZ) -> FlightSeries:
    """The flown samples of a flight's records, at `rate_hz`, with the angular accelerations.

    Parameters
    ----------
    name : str
        The log's name.
    records : sequence of Record
        A conditioned flight's records (trim is added back).
    rate_hz : float, optional
        Sample rate of the search, Hz.

    Returns
    -------
    FlightSeries

    Raises
    ------
    DataError
        If a record lacks a signal the search needs, or nothing is flown.
    """
    times: list[np.ndarray] = []
    pieces: list[np.ndarray] = []
    columns: dict[str, list[np.ndarray]] = {}
    for k, record in enumerate(records):
        missing = [s for s in _NEEDED if s not in record.signals]
        if missing:
            raise DataError(f"{name}: {', '.join(missing)} not logged; the discrepancy search needs them")
        t = record.time_s
        if t[-1] - t[0] < 2.0:
            continue
        grid = np.arange(t[0], t[-1], 1.0 / rate_hz)
        window = max(5, int(round(_SMOOTH_S * record.rate_hz)) | 1)
        values = {s: np.interp(grid, t, record.absolute(s)) for s in record.signals}
        for rate in ("p", "q", "r"):
            derivative = savgol_filter(record.absolute(rate), window, 2, deriv=1, delta=1.0 / record.rate_hz)
            values[f"{rate}_dot"] = np.interp(grid, t, derivative)
        times.append(grid)
        pieces.append(np.full(grid.size, k))
        for s, v in values.items():
            columns.setdefault(s, []).append(v)
    if not times:
        raise DataError(f"{name}: no record of 2 s or more")
    n = sum(t.size for t in times)
    signals = {s: np.concatenate(v) for s, v in columns.items() if sum(x.size for x in v) == n}
    time_s, piece = np.concatenate(times), np.concatenate(pieces)
    flown = _flown(signals)
    if flown.sum() < 10 * rate_hz:
        raise DataError(f"{name}: less than 10 s of flight (thrust on, off the ground)")
    signals["t_flight"] = time_s - time_s[flown][0]
    whole = FlightSeries(name=name, time_s=time_s, piece=piece, signals=signals, rate_hz=rate_hz)
    return whole.subset(np.flatnonzero(flown))


def _flown(signals: Mapping[str, np.ndarray]) -> np.ndarray:
    thrust = signals["delta_thr"]
    on = thrust > _THRUST_ON * float(np.percentile(thrust, 95))
    if "height_agl" in signals:
        on &= signals["height_agl"] > _ON_GROUND_M
    return np.asarray(on & np.all([np.isfinite(signals[s]) for s in _NEEDED], axis=0))
