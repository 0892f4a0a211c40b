"""The flown part of a flight as the discrepancy search sees it: uniform samples, angular accelerations.

Equation-error models need the outputs the physics acts on: the specific
forces ``ax ay az`` (m/s²) as logged and the angular accelerations
``p_dot q_dot r_dot`` (rad/s², a Savitzky-Golay derivative of the rates).
Every record of a conditioned flight is resampled to one rate and kept
apart (lags never reach across a gap); only the samples where the vehicle
flies (thrust above a third of its 95th percentile and above 85 % of the
hover's, and off the ground where a height is logged) are used.

The body velocities ``u v w`` are ground-relative here, whatever the
conditioning made of them: a simulation flown in a calm and a model of it
know nothing of the air, so drag on the wind is a discrepancy to find, not
something to hide in the states. The wind, where the log has one, is kept
apart in body axes (``wind_lon wind_lat``, m/s): the anemometer's when one
was given, else the autopilot's own estimate.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from flightlogs.errors import DataError
from flightlogs.frames import earth_to_body, wind_to_body_axes
from flightlogs.record import Record
from sysid.discrepancy._filters import butterworth_zero_phase, savgol_slope

__all__ = ["OUTPUTS", "COMMANDS", "FlightSeries", "flight_series", "smoothed_as_derivative"]

#: Outputs the terms act on: specific forces (m/s²) and angular accelerations (rad/s²).
OUTPUTS: tuple[str, ...] = ("ax", "ay", "az", "p_dot", "q_dot", "r_dot")
#: Mixer inputs (as logged).
COMMANDS: tuple[str, ...] = ("delta_lat", "delta_lon", "delta_yaw", "delta_thr")
_NEEDED = ("p", "q", "r", "ax", "ay", "az", *COMMANDS)
_RATE_HZ = 50.0  # the search's sample rate
_SMOOTH_S = 0.1  # Savitzky-Golay window of the rate derivatives
_THRUST_ON = 1.0 / 3.0  # flying: thrust above this fraction of its 95th percentile
_LIFT_OFF = 0.85  # and above this fraction of its median there (a take-off ramp on the ground is not flight)
_ON_GROUND_M = 0.05  # and, where a height is logged, above this
_WIND = ("wind_lon", "wind_lat")
_CALM_M_S = 0.5  # RMS wind below which a flight flew in a calm: its drag is below anything the search tells from noise
_VIBRATING = ("ax", "ay", "az")  # signals low-passed before they are sampled at the search's rate
_FILTER_PAD = 60  # samples the anti-alias filter pads each record's ends with


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

    @property
    def windy(self) -> bool:
        """Whether a wind is logged (``wind_lon``, ``wind_lat``, m/s) and is no calm: its RMS is 0.5 m/s or more."""
        if not all(w in self.signals for w in _WIND):
            return False
        return bool(np.sqrt(np.mean(self.signals[_WIND[0]] ** 2 + self.signals[_WIND[1]] ** 2)) >= _CALM_M_S)

    def pieces(self) -> list[np.ndarray]:
        """Sample indices of each contiguous piece, in order."""
        edges = np.flatnonzero(np.diff(self.piece)) + 1
        return np.split(np.arange(self.n), edges)

    def spans(self) -> list[slice]:
        """Each contiguous piece as a slice of the samples, in order (:meth:`pieces` without index arrays)."""
        edges = [0, *(np.flatnonzero(np.diff(self.piece)) + 1).tolist(), self.n]
        return [slice(a, b) for a, b in zip(edges[:-1], edges[1:])]

    def without(self, names: Sequence[str]) -> FlightSeries:
        """The same samples without the signals `names`."""
        kept = {k: v for k, v in self.signals.items() if k not in names}
        return FlightSeries(name=self.name, time_s=self.time_s, piece=self.piece, signals=kept, rate_hz=self.rate_hz)

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
        absolute = {s: record.absolute(s) for s in record.signals}
        for s in _VIBRATING:  # the accelerometer: where the rotors' vibration lives (the rates are smoothed below)
            absolute[s] = _anti_aliased(absolute[s], record.rate_hz, rate_hz)
        values = {s: np.interp(grid, t, x) for s, x in absolute.items()}
        for rate in ("p", "q", "r"):
            derivative = savgol_slope(absolute[rate], window, 2, 1.0 / record.rate_hz)
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
    _ground_relative(signals)
    whole = FlightSeries(name=name, time_s=time_s, piece=piece, signals=signals, rate_hz=rate_hz)
    series = whole.subset(np.flatnonzero(flown))
    if not all(np.all(np.isfinite(series[w])) for w in _WIND if w in series):
        return series.without(_WIND)  # a wind with holes is no regressor
    return series


def _anti_aliased(x: np.ndarray, from_hz: float, to_hz: float) -> np.ndarray:
    """`x` low-passed (zero-phase, 4th order) at 40 % of `to_hz` before it is sampled at `to_hz`, shape (n,).

    Applied to the accelerometer's signals; the rates' derivatives are smoothed over 0.1 s already.

    A real accelerometer's log holds the rotors' vibration (100-200 Hz, aliased by the log's own rate to
    tens of Hz, often m/s² in size); sampled again at the search's rate it would alias once more into the
    band the physics lives in. Records already slower than 2.5 times the search's rate are left as they are.
    """
    if from_hz < 2.5 * to_hz or x.size <= _FILTER_PAD:
        return x
    return butterworth_zero_phase(x, 0.4 * to_hz, from_hz, order=4, pad=min(_FILTER_PAD, x.size - 1))


def smoothed_as_derivative(series: FlightSeries, x: np.ndarray) -> np.ndarray:
    """An angular acceleration smoothed as :func:`flight_series` smooths the logged ones, shape (n,).

    The slope of a quadratic fitted over a window is the rate's change across it weighted by a
    parabola: the same as the acceleration averaged with a parabolic kernel over the window. An
    acceleration known sample by sample (a model's) is made comparable to the logged ones by it.

    Parameters
    ----------
    series : FlightSeries
        Its sample rate and pieces (no kernel reaches across a gap).
    x : ndarray, shape (n,)
        Angular acceleration at the series' samples, rad/s².
    """
    half = _SMOOTH_S / 2.0
    reach = int(half * series.rate_hz)
    offsets = np.arange(-reach, reach + 1) / series.rate_hz
    kernel = half**2 - offsets**2
    kernel /= kernel.sum()
    out = np.empty_like(x, dtype=float)
    for rows in series.pieces():
        out[rows] = np.convolve(np.pad(x[rows], reach, mode="edge"), kernel, mode="valid")
    return out


def _ground_relative(signals: dict[str, np.ndarray]) -> None:
    """Put ground-relative body velocities in ``u v w``; add the estimator's wind in body axes if none is given."""
    if {"vn", "ve", "vd", "phi", "theta", "psi"} <= signals.keys():
        ned = np.column_stack([signals["vn"], signals["ve"], signals["vd"]])
        uvw = earth_to_body(ned, signals["phi"], signals["theta"], signals["psi"])
        signals["u"], signals["v"], signals["w"] = uvw.T
    if "wind_lon" not in signals and {"est_wind_n", "est_wind_e", "psi"} <= signals.keys():
        wind_ne = np.column_stack([signals["est_wind_n"], signals["est_wind_e"]])
        signals["wind_lon"], signals["wind_lat"] = wind_to_body_axes(wind_ne, signals["psi"]).T


def _flown(signals: Mapping[str, np.ndarray]) -> np.ndarray:
    thrust = signals["delta_thr"]
    on = thrust > _THRUST_ON * float(np.percentile(thrust, 95))
    if np.any(on):  # on the ground the thrust ramps up to the hover's without lifting: not flight yet
        on &= thrust > _LIFT_OFF * float(np.median(thrust[on]))
    if "height_agl" in signals:
        on &= signals["height_agl"] > _ON_GROUND_M
    return np.asarray(on & np.all([np.isfinite(signals[s]) for s in _NEEDED], axis=0))
