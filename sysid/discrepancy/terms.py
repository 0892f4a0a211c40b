"""The library of physics a simulation may leave out: one candidate term per effect, with a known shape.

Each term says which outputs it acts on and how, from logged signals and
the simulation model's own prediction (pysindy's library, with physical
meaning): either regressors whose coefficients are fitted (``linear``), or
the model's prediction with its inputs delayed or lagged (``transform``).
Terms with a parameter inside the shape (a mass step's time, a delay) carry
a grid; the selection picks the grid value on the data that fit, never on
the data that judge.

``T`` below is the specific thrust the simulation model expects, ``-az``
predicted from the inputs (m/s², about g in hover); velocities are body
axes, ground-relative (the wind is a term of its own). The real vehicle's thrust may
differ from the simulated one by a constant factor (a trim, fitted before
any term and again with every term on az): those are judged by what they
explain beyond it.

========== ========= ===================================================
effect     outputs   shape
========== ========= ===================================================
ground_effect  az    ``az += -T (c / (h + d)² + a)``: thrust ratio ``1 + c / (h + d)²``, d the rotors' height over h
rotor_drag ax ay     ``ax += -d_x T u``, ``ay += -d_y T v``
wind       ax ay p_dot q_dot  drag and hub moment on the measured wind, ``∝ T wind``
time_delay all       inputs delayed by ``tau``
actuator_lag all     inputs through ``1 / (T_a s + 1)``
battery_sag az       ``az += -T (n (V - V̄) / V̄ + a)``: thrust ``∝ V^n``
mass_change az       ``az += T ((Δm/(m + Δm)) H(t - t0) - a)``: reported also as Δm/m
cg_offset  p_dot q_dot  ``+ k T``: a moment that follows the thrust
========== ========= ===================================================
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import cache
from typing import Literal

import numpy as np
from scipy.ndimage import uniform_filter1d
from scipy.signal import lfilter

from sysid.discrepancy.baseline import BaselineModel
from sysid.discrepancy.series import COMMANDS, OUTPUTS, FlightSeries

__all__ = ["EFFECTS", "Candidate", "candidate_terms"]

#: The effects the library can name, in the order they are tried.
EFFECTS: tuple[str, ...] = (
    "ground_effect",
    "rotor_drag",
    "wind",
    "time_delay",
    "actuator_lag",
    "battery_sag",
    "mass_change",
    "cg_offset",
)
_DELAYS_S = tuple(np.round(np.arange(0.0025, 0.1501, 0.0025), 4))
_LAGS_S = tuple(np.round(np.arange(0.0025, 0.1501, 0.0025), 4))
_CALM_M_S = 0.5  # RMS wind below which the wind term is not tried, m/s
# The anemometer's wind is averaged over this long before it is a regressor, s: the rotors feel the air over their
# discs, and a gust measured at a point metres upstream reaches them smeared; the faster part of its record is
# measurement noise for the drag, and noise in a regressor shrinks its coefficient (at 2.7 m/s, the wind's own moment
# then came out 30 % short, and the constant rest was named a CG offset on another generator's flights).
_WIND_AVERAGE_S = 1.0
_STEP_EDGE = 0.1  # a mass step lies within the middle 80 % of the flight
_STEP_GRID_S = 0.25  # times tried for it
_ROTOR_ABOVE_M = tuple(np.round(np.arange(0.0, 0.501, 0.05), 3))  # rotor plane above the logged height, m
_MIN_HEIGHT_M = 0.05

Regressors = Mapping[str, np.ndarray]  # output -> (n, k)
Prediction = Mapping[str, np.ndarray]  # output -> (n,)


@dataclass(frozen=True, slots=True, kw_only=True)
class Candidate:
    """One effect's term, ready to be fitted.

    Parameters
    ----------
    effect : str
        One of :data:`EFFECTS`.
    outputs : tuple of str
        Outputs it acts on.
    kind : {"linear", "transform"}
        Regressors added to the model, or the model's prediction changed.
    grid : tuple of float
        Values of the parameter inside the shape (NaN alone if none).
    grid_parameter : str
        Name and unit of that parameter (``""`` if none).
    build : callable
        ``build(value)``: the regressors per output (linear) or the new prediction per output (transform).
    coefficients : tuple of str
        Names of the fitted coefficients (linear), in column order.
    regime : str or None
        The flight variable its shape depends on (``height_agl``, ``battery_v``, ``ground_speed``, ``wind_speed``,
        ``delta_thr``, ``t_flight``), whose range the finding reports; None: found from the data.
    """

    effect: str
    outputs: tuple[str, ...]
    kind: Literal["linear", "transform"]
    grid: tuple[float, ...]
    grid_parameter: str
    build: Callable[[float], Regressors | Prediction]
    coefficients: tuple[str, ...] = ()
    regime: str | None = None


def candidate_terms(
    series: FlightSeries,
    baseline: BaselineModel,
    prediction: Prediction,
    *,
    exclude: tuple[str, ...] = (),
) -> list[Candidate]:
    """The terms that apply to `series` (those whose signals it logs), but the `exclude`d effects.

    Parameters
    ----------
    series : FlightSeries
        The real flight.
    baseline : BaselineModel
        The simulation's model (delays and lags re-predict through it).
    prediction : Mapping[str, ndarray]
        The current prediction of each output on `series`, shape (n,).
    exclude : tuple of str
        Effects already found.
    """
    thrust = -np.asarray(prediction["az"])
    found: list[Candidate] = []
    for effect in EFFECTS:
        if effect in exclude:
            continue
        made = _MAKERS[effect](series, baseline, thrust)
        if made is not None:
            found.append(made)
    return found


def _linear(
    effect: str, columns: Mapping[str, list[np.ndarray]], names: tuple[str, ...], regime: str | None
) -> Candidate:
    regressors = {o: np.column_stack(c) for o, c in columns.items()}
    return Candidate(
        effect=effect,
        outputs=tuple(columns),
        kind="linear",
        grid=(float("nan"),),
        grid_parameter="",
        build=lambda _value: regressors,
        coefficients=names,
        regime=regime,
    )


def _ground_effect(series: FlightSeries, _baseline: BaselineModel, thrust: np.ndarray) -> Candidate | None:
    if "height_agl" not in series:
        return None
    h = np.maximum(series["height_agl"], _MIN_HEIGHT_M)

    @cache
    def build(rotor_above_m: float) -> Regressors:
        return {"az": np.column_stack([-thrust / (h + rotor_above_m) ** 2, -thrust])}

    return Candidate(
        effect="ground_effect",
        outputs=("az",),
        kind="linear",
        grid=_ROTOR_ABOVE_M,
        grid_parameter="rotor_above_height_m",
        build=build,
        coefficients=("c_m2", "gain"),
        regime="height_agl",
    )


def _rotor_drag(series: FlightSeries, _baseline: BaselineModel, thrust: np.ndarray) -> Candidate | None:
    if "u" not in series or "v" not in series:
        return None
    u, v = series["u"], series["v"]  # ground-relative: drag on the wind is the wind term's
    return _linear("rotor_drag", {"ax": [-thrust * u], "ay": [-thrust * v]}, ("d_x_s_m", "d_y_s_m"), "ground_speed")


def _wind(series: FlightSeries, _baseline: BaselineModel, thrust: np.ndarray) -> Candidate | None:
    if "wind_lon" not in series or "wind_lat" not in series:
        return None
    if np.sqrt(np.mean(series["wind_lon"] ** 2 + series["wind_lat"] ** 2)) < _CALM_M_S:
        return None  # a calm: its drag is below anything the search can tell from noise
    along = thrust * _averaged(series, series["wind_lon"], _WIND_AVERAGE_S)
    across = thrust * _averaged(series, series["wind_lat"], _WIND_AVERAGE_S)
    columns = {"ax": [along], "ay": [across], "p_dot": [across], "q_dot": [along]}
    return _linear("wind", columns, ("d_x_s_m", "d_y_s_m", "l_wind_rad_m", "m_wind_rad_m"), "wind_speed")


def _time_delay(series: FlightSeries, baseline: BaselineModel, _thrust: np.ndarray) -> Candidate:
    @cache
    def build(tau: float) -> Prediction:
        return baseline.predict(series, {c: _delayed(series, series[c], tau) for c in COMMANDS})

    return Candidate(
        effect="time_delay", outputs=OUTPUTS, kind="transform", grid=_DELAYS_S, grid_parameter="delay_s", build=build
    )


def _actuator_lag(series: FlightSeries, baseline: BaselineModel, _thrust: np.ndarray) -> Candidate:
    @cache
    def build(time_constant: float) -> Prediction:
        return baseline.predict(series, {c: _first_order(series, series[c], time_constant) for c in COMMANDS})

    return Candidate(
        effect="actuator_lag",
        outputs=OUTPUTS,
        kind="transform",
        grid=_LAGS_S,
        grid_parameter="time_constant_s",
        build=build,
    )


def _battery_sag(series: FlightSeries, _baseline: BaselineModel, thrust: np.ndarray) -> Candidate | None:
    if "battery_v" not in series or np.ptp(series["battery_v"]) <= 0:
        return None
    volts = series["battery_v"]
    relative = (volts - volts.mean()) / volts.mean()
    return _linear("battery_sag", {"az": [-thrust * relative, -thrust]}, ("exponent", "gain"), "battery_v")


def _mass_change(series: FlightSeries, _baseline: BaselineModel, thrust: np.ndarray) -> Candidate:
    clock = series["t_flight"]
    span = clock[-1] - clock[0]
    times = np.arange(clock[0] + _STEP_EDGE * span, clock[-1] - _STEP_EDGE * span, _STEP_GRID_S)

    @cache
    def build(t0: float) -> Regressors:
        return {"az": np.column_stack([thrust * (clock >= t0), -thrust])}

    return Candidate(
        effect="mass_change",
        outputs=("az",),
        kind="linear",
        grid=tuple(float(t) for t in times),
        grid_parameter="time_s",
        build=build,
        coefficients=("mass_ratio", "gain"),
        regime="t_flight",
    )


def _cg_offset(series: FlightSeries, _baseline: BaselineModel, thrust: np.ndarray) -> Candidate:
    return _linear("cg_offset", {"p_dot": [thrust], "q_dot": [thrust]}, ("l_rad_m", "m_rad_m"), "delta_thr")


_MAKERS: Mapping[str, Callable[[FlightSeries, BaselineModel, np.ndarray], Candidate | None]] = {
    "ground_effect": _ground_effect,
    "rotor_drag": _rotor_drag,
    "wind": _wind,
    "time_delay": _time_delay,
    "actuator_lag": _actuator_lag,
    "battery_sag": _battery_sag,
    "mass_change": _mass_change,
    "cg_offset": _cg_offset,
}


def _delayed(series: FlightSeries, x: np.ndarray, tau: float) -> np.ndarray:
    out = np.empty_like(x)
    for rows in series.pieces():
        t = np.arange(rows.size) / series.rate_hz
        out[rows] = np.interp(t - tau, t, x[rows])
    return out


def _averaged(series: FlightSeries, x: np.ndarray, width_s: float) -> np.ndarray:
    """`x` averaged over `width_s` around each sample, within each piece of the flight."""
    width = max(1, int(round(width_s * series.rate_hz)))
    out = np.empty_like(x)
    for rows in series.pieces():
        out[rows] = uniform_filter1d(x[rows], width, mode="nearest")
    return out


def _first_order(series: FlightSeries, x: np.ndarray, time_constant: float) -> np.ndarray:
    a = float(np.exp(-1.0 / (series.rate_hz * time_constant)))
    out = np.empty_like(x)
    for rows in series.pieces():
        piece = x[rows]
        out[rows] = lfilter([1.0 - a], [1.0, -a], piece - piece[0]) + piece[0]
    return out
