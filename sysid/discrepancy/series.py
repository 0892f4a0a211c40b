"""The flown part of a flight as the discrepancy search sees it: uniform samples, angular accelerations.

Equation-error models need the outputs the physics acts on: the specific
forces ``ax ay az`` (m/s²) as logged and the angular accelerations
``p_dot q_dot r_dot`` (rad/s², a Savitzky-Golay derivative of the rates).
Every record of a conditioned flight is resampled to one rate and kept
apart (lags never reach across a gap); only the samples where the vehicle
flies (thrust above a third of its 95th percentile and above 85 % of the
hover's, and off the ground where a height is logged) are used.

A flight whose specific forces were derived from its velocities (a
motion-capture table, :attr:`flightlogs.flightlog.Signal.derived`) is
compared like with like: the flights it is compared with have theirs derived
the same way (:func:`flightlogs.kinematics.specific_force`), and a model's
are smoothed as that derivative smooths (:func:`smoothed_as_derivative`).

The body velocities ``u v w`` are ground-relative here, whatever the
conditioning made of them: a simulation flown in a calm and a model of it
know nothing of the air, so drag on the wind is a discrepancy to find, not
something to hide in the states. The wind, where the log has one, is kept
apart in body axes (``wind_lon wind_lat``, m/s): the anemometer's when one
was given, else the autopilot's own estimate.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from flightlogs.conditioning.condition import ConditionedFlight
from flightlogs.errors import DataError
from flightlogs.frames import earth_to_body, wind_to_body_axes
from flightlogs.kinematics import SPECIFIC_FORCE_WINDOW_S, specific_force
from flightlogs.record import Record
from sysid._filters import butterworth_zero_phase, savgol_slope

__all__ = [
    "OUTPUTS",
    "COMMANDS",
    "FlightSeries",
    "flight_series",
    "flights_series",
    "smoothed_as_derivative",
    "smoothed_specific_forces",
]

#: Outputs the terms act on: specific forces (m/s²) and angular accelerations (rad/s²).
OUTPUTS: tuple[str, ...] = ("ax", "ay", "az", "p_dot", "q_dot", "r_dot")
#: Mixer inputs (as logged).
COMMANDS: tuple[str, ...] = ("delta_lat", "delta_lon", "delta_yaw", "delta_thr")
_NEEDED = ("p", "q", "r", "ax", "ay", "az", *COMMANDS)
_RATE_HZ = 50.0  # the search's sample rate
_SMOOTH_S = 0.1  # Savitzky-Golay window of the rate derivatives
_SLOWER = 1.2  # a record logged this many times faster than the flights it is compared with is sampled at their rate
_FINE_HZ = 100.0  # a record slower than this has its rates interpolated finer before they are differentiated
_THRUST_ON = 1.0 / 3.0  # flying: thrust above this fraction of its 95th percentile
_LIFT_OFF = 0.85  # and above this fraction of its median there (a take-off ramp on the ground is not flight)
_ON_GROUND_M = 0.05  # and, where a height is logged, above this
_WIND = ("wind_lon", "wind_lat")
_CALM_M_S = 0.5  # RMS wind below which a flight flew in a calm: its drag is below anything the search tells from noise
_FORCES = ("ax", "ay", "az")
_VELOCITIES = ("vn", "ve", "vd", "phi", "theta", "psi")  # what derived specific forces are made of
_VIBRATING = _FORCES  # signals low-passed before they are sampled at the search's rate
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
    specific_force_derived : bool, optional
        Whether ``ax ay az`` are derived from the velocities, not measured
        (:func:`flightlogs.kinematics.specific_force`).
    """

    name: str
    time_s: np.ndarray
    piece: np.ndarray
    signals: Mapping[str, np.ndarray]
    rate_hz: float
    specific_force_derived: bool = False

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
        return replace(self, signals=kept)

    def subset(self, rows: np.ndarray) -> FlightSeries:
        """The samples `rows` (sorted indices), pieces split where rows skip samples."""
        rows = np.asarray(rows)
        breaks = np.concatenate([[0], np.cumsum((np.diff(rows) != 1) | (np.diff(self.piece[rows]) != 0))])
        return replace(
            self, time_s=self.time_s[rows], piece=breaks, signals={k: v[rows] for k, v in self.signals.items()}
        )


def flights_series(
    flights: Sequence[ConditionedFlight], *, like: Sequence[ConditionedFlight] = ()
) -> list[FlightSeries]:
    """Each conditioned flight as the search sees it, sampled as the flights it is compared with are.

    Like is compared with like: when any flight of `flights` or `like` has specific forces derived from
    its velocities (:attr:`ConditionedFlight.derived`, a motion-capture table), every flight's are derived
    so; and every flight is first sampled at the slowest rate any of them was logged at (a 250 Hz log
    compared with a 50 Hz table is sampled at 50 Hz, as the table's logger sampled its flight).

    Parameters
    ----------
    flights : sequence of ConditionedFlight
        The flights.
    like : sequence of ConditionedFlight, optional
        The flights they are compared with (the simulation's for the real ones, and the other way round).

    Returns
    -------
    list of FlightSeries
        One per flight, in order.

    Raises
    ------
    DataError
        As :func:`flight_series`.
    """
    every = [*flights, *like]
    derived = any(set(_FORCES) & set(f.derived) for f in every)
    slowest = min((f.rate_hz for f in every), default=None)
    return [
        flight_series(f.source.name, f.records, specific_force_derived=derived, logged_rate_hz=slowest) for f in flights
    ]


def flight_series(
    name: str,
    records: Sequence[Record],
    rate_hz: float = _RATE_HZ,
    *,
    specific_force_derived: bool = False,
    logged_rate_hz: float | None = None,
) -> FlightSeries:
    """The flown samples of a flight's records, at `rate_hz`, with the angular accelerations.

    Parameters
    ----------
    name : str
        The log's name.
    records : sequence of Record
        A conditioned flight's records (trim is added back).
    rate_hz : float, optional
        Sample rate of the search, Hz.
    specific_force_derived : bool, optional
        Derive ``ax ay az`` from the velocities and the attitude
        (:func:`flightlogs.kinematics.specific_force`), whatever the records hold.
    logged_rate_hz : float, optional
        Sample a record logged faster than this at this rate first, as a slower logger would have
        (no filter: a logger samples; only the accelerometer's vibration is anti-aliased first); by
        default each record as it is.

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
    needed = _NEEDED if not specific_force_derived else (*_VELOCITIES, *(s for s in _NEEDED if s not in _FORCES))
    for k, record in enumerate(records):
        missing = [s for s in needed if s not in record.signals]
        if missing:
            hint = ""
            if set(missing) & set(COMMANDS) and any(s.startswith("motor_") for s in record.signals):
                hint = " (a table derives the mixer inputs from its motors given a [rotors] layout in its map)"
            raise DataError(f"{name}: {', '.join(missing)} not logged; the discrepancy search needs them{hint}")
        t = record.time_s
        if t[-1] - t[0] < 2.0:
            continue
        grid = np.arange(t[0], t[-1], 1.0 / rate_hz)
        absolute = {s: record.absolute(s) for s in record.signals}
        logged_hz = record.rate_hz
        if logged_rate_hz is not None and logged_hz > _SLOWER * logged_rate_hz:
            # sampled as the slower logger samples; the accelerometer's vibration anti-aliased first
            slow = np.arange(t[0], t[-1], 1.0 / logged_rate_hz)
            for s in _VIBRATING:
                absolute[s] = _anti_aliased(absolute[s], logged_hz, logged_rate_hz)
            absolute = {s: np.interp(slow, t, x) for s, x in absolute.items()}
            t, logged_hz = slow, logged_rate_hz
        if specific_force_derived:
            velocity = np.column_stack([absolute[v] for v in ("vn", "ve", "vd")])
            force = specific_force(t, velocity, absolute["phi"], absolute["theta"], absolute["psi"])
            absolute.update({s: force[:, j] for j, s in enumerate(_FORCES)})
        else:
            for s in _VIBRATING:  # the accelerometer: where the rotors' vibration lives (the rates are smoothed below)
                absolute[s] = _anti_aliased(absolute[s], logged_hz, rate_hz)
        values = {s: np.interp(grid, t, x) for s, x in absolute.items()}
        for rate in ("p", "q", "r"):
            values[f"{rate}_dot"] = np.interp(grid, t, _angular_acceleration(t, absolute[rate], logged_hz))
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
    whole = FlightSeries(
        name=name,
        time_s=time_s,
        piece=piece,
        signals=signals,
        rate_hz=rate_hz,
        specific_force_derived=specific_force_derived,
    )
    series = whole.subset(np.flatnonzero(flown))
    if not all(np.all(np.isfinite(series[w])) for w in _WIND if w in series):
        return series.without(_WIND)  # a wind with holes is no regressor
    return series


def _angular_acceleration(t: np.ndarray, rate: np.ndarray, rate_hz: float) -> np.ndarray:
    """The slope of a quadratic over 0.1 s of a uniform record's rate, rad/s², shape (n,).

    A centred window holds an odd number of samples: at 100 Hz 11 span 0.1 s, at 50 Hz 5 span 0.08 s and
    7 span 0.12 s. A record slower than 100 Hz is interpolated onto a grid an integer times finer (at
    least 100 Hz) first, so that its window spans 0.1 s as a faster log's does; a 50 Hz table and a
    100 Hz log of one flight then differ by no smoothing of their own.
    """
    finer = max(1, int(np.ceil(_FINE_HZ / rate_hz - 1e-9)))
    fine_hz = rate_hz * finer
    fine_t = t[0] + np.arange((t.size - 1) * finer + 1) / fine_hz if finer > 1 else t
    fine = np.interp(fine_t, t, rate) if finer > 1 else rate
    slope = savgol_slope(fine, max(5, int(round(_SMOOTH_S * fine_hz)) | 1), 2, 1.0 / fine_hz)
    return np.interp(t, fine_t, slope) if finer > 1 else slope


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


def smoothed_as_derivative(series: FlightSeries, x: np.ndarray, window_s: float = _SMOOTH_S) -> np.ndarray:
    """An angular acceleration smoothed as :func:`flight_series` smooths the logged ones, shape (n,).

    The slope of a quadratic fitted over a window is the rate's change across it weighted by a
    parabola: the same as the acceleration averaged with a parabolic kernel over the window. An
    acceleration known sample by sample (a model's) is made comparable to the logged ones by it.

    Parameters
    ----------
    series : FlightSeries
        Its sample rate and pieces (no kernel reaches across a gap).
    x : ndarray, shape (n,)
        Angular acceleration at the series' samples, rad/s² (or a specific force, m/s²).
    window_s : float, optional
        The derivative's window, s: 0.1 s for the rates, :data:`~flightlogs.kinematics.SPECIFIC_FORCE_WINDOW_S`
        for a velocity.
    """
    half = window_s / 2.0
    reach = int(half * series.rate_hz)
    offsets = np.arange(-reach, reach + 1) / series.rate_hz
    kernel = half**2 - offsets**2
    kernel /= kernel.sum()
    out = np.empty_like(x, dtype=float)
    for rows in series.pieces():
        out[rows] = np.convolve(np.pad(x[rows], reach, mode="edge"), kernel, mode="valid")
    return out


def smoothed_specific_forces(series: FlightSeries, outputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """`outputs` with ``ax ay az`` smoothed as the series' own are when it derives them from its velocities.

    Parameters
    ----------
    series : FlightSeries
        The flight a model's outputs are compared with.
    outputs : Mapping[str, ndarray]
        A model's outputs along `series`, shape (n,) each.

    Returns
    -------
    dict of str to ndarray
        The same outputs; the specific forces smoothed over
        :data:`~flightlogs.kinematics.SPECIFIC_FORCE_WINDOW_S` if ``series.specific_force_derived``.
    """
    out = dict(outputs)
    if series.specific_force_derived:
        for name in _FORCES:
            if name in out:
                out[name] = smoothed_as_derivative(series, np.asarray(out[name]), SPECIFIC_FORCE_WINDOW_S)
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
