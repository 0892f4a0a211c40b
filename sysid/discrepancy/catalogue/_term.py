"""What one effect of the catalogue is: its shape on a flight, its parameters and its sentence.

A :class:`Term` is the whole of an effect (pysindy's feature library, with physical meaning): the
outputs it acts on, the flight variable that locates it, its coefficients with their reported names
and units, a ``make`` that builds its :class:`Candidate` on a flight (regressors whose coefficients are
fitted, or the model's prediction with its inputs changed), the parameters derived from the fitted
ones, and the sentence that says what the real vehicle does. The search knows no effect by name.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache, cached_property
from typing import Literal

import numpy as np

from flightlogs._moving import moving_mean
from sysid._filters import one_pole
from sysid.discrepancy.baseline import BaselineModel
from sysid.discrepancy.result import Finding, FittedParameter
from sysid.discrepancy.series import COMMANDS, OUTPUTS, FlightSeries

__all__ = [
    "Calibration",
    "Candidate",
    "Coefficient",
    "Derivation",
    "FASTER_SWEEPS",
    "FlightContext",
    "Regressors",
    "Prediction",
    "SIGN_SIGMAS",
    "THRUST_GAIN",
    "Term",
    "averaged",
    "delayed",
    "first_order",
    "input_transform",
    "linear",
    "parameter",
    "pm",
]

Regressors = Mapping[str, np.ndarray]  # output -> (n, k)
Prediction = Mapping[str, np.ndarray]  # output -> (n,)


@dataclass(frozen=True, slots=True, kw_only=True)
class Candidate:
    """One effect's term built on a flight, ready to be fitted.

    Parameters
    ----------
    effect : str
        The term's name.
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
        Keys of the fitted coefficients (linear), in column order over the outputs.
    regime : str or None
        The flight variable its shape depends on, whose range the finding reports; None: found from the data.
    """

    effect: str
    outputs: tuple[str, ...]
    kind: Literal["linear", "transform"]
    grid: tuple[float, ...]
    grid_parameter: str
    build: Callable[[float], Regressors | Prediction]
    coefficients: tuple[str, ...] = ()
    regime: str | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Calibration:
    """A sensor of the real flight measured against the kinematics of the others, and the flight corrected.

    Parameters
    ----------
    parameters : tuple of FittedParameter
        Each axis measured, with its standard deviation.
    outputs : tuple of str
        Outputs whose logged values the correction changes.
    corrected : FlightSeries
        The real flight with the sensor's signals (and those derived from them) corrected.
    """

    parameters: tuple[FittedParameter, ...]
    outputs: tuple[str, ...]
    corrected: FlightSeries


@dataclass(frozen=True, slots=True, kw_only=True)
class Coefficient:
    """A fitted coefficient: its key in the regressors, its reported name and its unit.

    Parameters
    ----------
    key : str
        Column key (unique within the term).
    name : str
        Reported name (``drag_x``, ``thrust_effectiveness_change``).
    unit : str
        SI unit (``1`` for a ratio).
    sign : {0, 1, -1}, optional
        The sign the physics gives it (0: either). A fit that puts it on the other side, beyond
        :data:`SIGN_SIGMAS` of its uncertainty, is another effect's shape (a thrust "lost" above a
        ceiling that grows instead is the thrust's curvature, no saturation).
    """

    key: str
    name: str
    unit: str
    sign: int = 0


@dataclass(frozen=True, slots=True, kw_only=True)
class Derivation:
    """What a term's derived parameters may use beyond its own fit.

    Parameters
    ----------
    thrust_scale : float
        Real over simulated thrust per input apart from this term's own gain change.
    rotor_radius_m : float or None
        Propeller radius, m, if known.
    """

    thrust_scale: float = 1.0
    rotor_radius_m: float | None = None


@dataclass(frozen=True, kw_only=True)
class FlightContext:
    """A flight as every term sees it: the samples, the simulation's model and its specific thrust.

    Parameters
    ----------
    series : FlightSeries
        The flight.
    baseline : BaselineModel
        The simulation's model (transforms re-predict through it).
    thrust : ndarray, shape (n,)
        The specific thrust the model expects, ``-az`` predicted (m/s², about g in hover).
    """

    series: FlightSeries
    baseline: BaselineModel
    thrust: np.ndarray

    @cached_property
    def command_parts(self) -> dict[str, dict[str, np.ndarray]]:
        """Per mixer input, the part of each output's prediction it makes (:meth:`BaselineModel.command_part`)."""
        return {c: self.baseline.command_part(self.series, c) for c in COMMANDS}


def _no_derivation(_parameters: list[FittedParameter], _context: Derivation) -> list[FittedParameter]:
    return _parameters


@dataclass(frozen=True, kw_only=True)
class Term:
    """One effect of the catalogue: everything the search and the report need of it.

    Parameters
    ----------
    effect : str
        Its name, as reported (``control_effectiveness``).
    summary : str
        What physics it stands for, one phrase (the report's catalogue table).
    outputs : tuple of str
        Outputs it may act on.
    regime : str or None
        The flight variable that locates it (``height_agl``, ``ground_speed``, ``airspeed``, ``climb_rate``,
        ``wind_speed``, ``delta_thr``, ``battery_v``, ``t_flight``); None: the narrowest found.
    coefficients : tuple of Coefficient
        Its fitted coefficients (linear terms).
    make : callable
        ``make(context)``: its :class:`Candidate` on a flight, or None where the flight cannot show it.
    what : callable
        ``what(finding)``: the sentence's first half, what the real vehicle does, with the numbers.
    derive : callable, optional
        ``derive(parameters, derivation)``: the parameters with those derived from the fitted ones.
    rivals : tuple of str
        Terms it competes with for one residual: once one is kept the others are not tried.
    separated_by : str
        The flight that shows it apart from the terms it may be confused with (for an ambiguous finding).
    shown_on : tuple of str
        Outputs on which the term must by itself remove a held-out share above its threshold (empty: any):
        a rotor's drag is a force first, and its hub moment alone (a flapping rotor) is not one; a thrust
        ceiling is thrust that stops growing, and a roll moment lost above a command alone is not one.
    calibrate : callable or None
        ``calibrate(sim, real)``: for a sensor's error, measured on the flights themselves before any model
        (a gyro against the attitude's kinematics), its :class:`Calibration`, or None where the real
        flight's sensor agrees with the simulated one's. Such a term builds no candidate (``make`` gives
        None): no model of the vehicle can tell a sensor's scale from the physics it measures.
    """

    effect: str
    summary: str
    outputs: tuple[str, ...]
    regime: str | None
    make: Callable[[FlightContext], Candidate | None]
    what: Callable[[Finding], str]
    coefficients: tuple[Coefficient, ...] = ()
    derive: Callable[[list[FittedParameter], Derivation], list[FittedParameter]] = field(default=_no_derivation)
    rivals: tuple[str, ...] = ()
    separated_by: str = ""
    shown_on: tuple[str, ...] = ()
    calibrate: Callable[[FlightSeries, FlightSeries], Calibration | None] | None = None

    def coefficient(self, key: str) -> Coefficient:
        """The coefficient of column `key` (a key the term does not list is reported as it is, unit 1)."""
        return next((c for c in self.coefficients if c.key == key), Coefficient(key=key, name=key, unit="1"))

    def against_physics(self, values: Sequence[tuple[str, float, float]]) -> bool:
        """Whether a fitted coefficient is on the side of zero its physics rules out.

        Parameters
        ----------
        values : sequence of (str, float, float)
            Its coefficients as (key, value, standard deviation) (:meth:`TermFit.coefficient_values`).
        """
        return any(self.coefficient(k).sign * v < -SIGN_SIGMAS * e for k, v, e in values)


#: Standard deviations beyond which a coefficient on the wrong side of zero rules its term out.
SIGN_SIGMAS = 2.0

#: The flight that tells a delay from a lag (both terms say it in these words, so an ambiguity says it once).
FASTER_SWEEPS = "sweeps to higher frequency (a delay's phase keeps falling, a lag's magnitude rolls off)"

#: The thrust gain beside a term's shape on az (the real thrust per input may differ by a constant factor).
THRUST_GAIN = Coefficient(key="gain", name="thrust_gain_change", unit="1")


def input_transform(
    context: FlightContext,
    effect: str,
    grid: tuple[float, ...],
    grid_parameter: str,
    change: Callable[[FlightSeries, np.ndarray, float], np.ndarray],
) -> Candidate:
    """A transform candidate: the simulation's model re-predicting every output from its inputs changed.

    Parameters
    ----------
    context : FlightContext
        The flight and the simulation's model.
    effect : str
        The term's name.
    grid : tuple of float
        Values of the change's parameter tried.
    grid_parameter : str
        Its name and unit (``delay_s``).
    change : callable
        ``change(series, command, value)``: one mixer input changed (delayed, lagged), shape (n,); linear and
        time-invariant within each piece, holding the piece's first value before it (see
        :meth:`~sysid.discrepancy.baseline.BaselineModel.changed`).
    """
    series = context.series
    predict = context.baseline.changed(series)  # the inputs' and states' parts once for the whole grid

    @cache
    def build(value: float) -> Prediction:
        return predict(lambda x: change(series, x, value))

    return Candidate(
        effect=effect, outputs=OUTPUTS, kind="transform", grid=grid, grid_parameter=grid_parameter, build=build
    )


def linear(
    term_effect: str, columns: Mapping[str, Sequence[np.ndarray]], keys: tuple[str, ...], regime: str | None
) -> Candidate:
    """A linear candidate without a grid: fixed regressors per output.

    Parameters
    ----------
    term_effect : str
        The term's name.
    columns : Mapping[str, sequence of ndarray]
        Per output, its regressors, each shape (n,).
    keys : tuple of str
        The coefficients' keys, in column order over the outputs.
    regime : str or None
        The flight variable that locates it.
    """
    regressors = {o: np.column_stack(list(c)) for o, c in columns.items()}
    return Candidate(
        effect=term_effect,
        outputs=tuple(columns),
        kind="linear",
        grid=(float("nan"),),
        grid_parameter="",
        build=lambda _value: regressors,
        coefficients=keys,
        regime=regime,
    )


def parameter(finding: Finding, name: str) -> FittedParameter | None:
    """The parameter `name` of a finding, or None.

    Parameters
    ----------
    finding : Finding
        A finding.
    name : str
        A parameter's name.
    """
    return next((p for p in finding.parameters if p.name == name), None)


def pm(value: float, sigma: float, scale: float = 1.0, sign: bool = False) -> str:
    """``value ± sigma`` (times `scale`), the value to the sigma's second significant digit.

    Parameters
    ----------
    value, sigma : float
        Estimate and its standard deviation.
    scale : float, optional
        Factor both are shown times (1e3: ms from s).
    sign : bool, optional
        Show the sign of a positive value.

    Examples
    --------
    >>> pm(0.0123456, 0.00042)
    '0.01235 ± 0.00042'
    >>> pm(-0.3, 0.05, 100.0, sign=True)
    '-30.0 ± 5.0'
    """
    v, s = value * scale, abs(sigma * scale)
    digits = max(0, min(6, 1 - int(np.floor(np.log10(s)))) if s > 0 and np.isfinite(s) else 1)
    return f"{v:{'+' if sign else ''}.{digits}f} ± {s:.{digits}f}"


def delayed(series: FlightSeries, x: np.ndarray, tau: float) -> np.ndarray:
    """`x` delayed by `tau` seconds within each piece of the flight (held at its first value), shape (n,).

    Parameters
    ----------
    series : FlightSeries
        Its pieces and sample rate.
    x : ndarray, shape (n,)
        A signal at the series' samples.
    tau : float
        Delay, s.
    """
    out = np.empty_like(x)
    for rows in series.spans():
        t = np.arange(rows.stop - rows.start) / series.rate_hz
        out[rows] = np.interp(t - tau, t, x[rows])
    return out


def averaged(series: FlightSeries, x: np.ndarray, width_s: float) -> np.ndarray:
    """`x` averaged over `width_s` around each sample, within each piece of the flight, shape (n,).

    Parameters
    ----------
    series : FlightSeries
        Its pieces and sample rate.
    x : ndarray, shape (n,)
        A signal at the series' samples.
    width_s : float
        Width of the average, s.
    """
    width = max(1, int(round(width_s * series.rate_hz)))
    out = np.empty_like(x)
    for rows in series.spans():
        out[rows] = moving_mean(x[rows], width)
    return out


def first_order(series: FlightSeries, x: np.ndarray, time_constant: float) -> np.ndarray:
    """`x` through ``1 / (time_constant s + 1)`` within each piece (started at rest), shape (n,).

    Parameters
    ----------
    series : FlightSeries
        Its pieces and sample rate.
    x : ndarray, shape (n,)
        A signal at the series' samples.
    time_constant : float
        The lag's time constant, s.
    """
    a = float(np.exp(-1.0 / (series.rate_hz * time_constant)))
    out = np.empty_like(x)
    for rows in series.spans():
        piece = x[rows]
        out[rows] = one_pole(a, (1.0 - a) * (piece - piece[0])) + piece[0]
    return out
