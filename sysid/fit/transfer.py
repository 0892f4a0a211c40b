"""Transfer-function fits of one frequency response each (CIFER's NAVFIT, MATLAB's ``tfest``).

A :class:`~sysid.model.transfer.TransferStructure` (with an optional
transport delay ``exp(-tau s)``) is fitted to a gated response by the same
cost as the state-space fits (eq. 3.9: coherence-weighted magnitude and
phase errors, :class:`~sysid.fit.cost.LogResponseCost`), with Cramér–Rao
bounds and insensitivities from its Jacobian (:func:`~sysid.fit.accuracy.accuracy`),
the bounds carrying the fit's systematic error as the state-space fits' do
(:mod:`sysid.fit.bias`).

The start is found, not guessed: for each delay on a 2 ms grid the
coefficients come from the linear least-squares fit of ``N(s) - T(s) e^{tau s} D(s) = 0``
(Levy), reweighted by ``1 / |T D|`` of the previous pass (Sanathanan–Koerner),
which makes each equation a relative error like the cost's; the delay whose
start costs least is then refined with the coefficients by the nonlinear
search. No random restarts: the same data give the same answer.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np
from scipy.optimize import least_squares

from flightlogs.conditioning.condition import ConditionedFlight
from flightlogs.errors import FitError
from sysid.fit.accuracy import accuracy
from sysid.fit.bias import RAISED_BOTTOMS, bounds_with_bias, raised
from sysid.fit.cost import CostWeights, FitPoints, LogResponseCost, fit_points
from sysid.fit.guidelines import DEFAULT_GUIDELINES, Guidelines
from sysid.freqresp.gating import Gating, gate_responses
from sysid.freqresp.options import ResponseOptions
from sysid.freqresp.records import flight_responses
from sysid.freqresp.response import FrequencyResponse
from sysid.model.transfer import TransferStructure

__all__ = [
    "TransferOptions",
    "FittedCoefficient",
    "TransferFunctionFit",
    "fit_transfer_function",
    "fit_transfer_functions",
]

_SK_PASSES = 8  # Sanathanan–Koerner reweightings of the linear start (settles in 3-5 on the test responses)
_DELAY_STEP_S = 0.002
_DELAY_NAME = "tau"


@dataclass(frozen=True, slots=True, kw_only=True)
class TransferOptions:
    """How transfer functions are fitted.

    Parameters
    ----------
    delay : bool
        Fit a transport delay ``exp(-tau s)`` with the coefficients.
    band_rad_s : tuple of (float, float) or None
        Frequencies to fit, rad/s, within each response's gated fit range; None for that range.
    max_delay_s : float
        Longest delay searched, s.
    weights : CostWeights
        Eq. 3.9's weights and number of points.
    guidelines : Guidelines
        The limits the fit is judged by (CR 20 %, insensitivity 10 %, J 100).
    """

    delay: bool = False
    band_rad_s: tuple[float, float] | None = None
    max_delay_s: float = 0.25
    weights: CostWeights = field(default_factory=CostWeights)
    guidelines: Guidelines = DEFAULT_GUIDELINES

    def __post_init__(self) -> None:
        if self.band_rad_s is not None and not 0 < self.band_rad_s[0] < self.band_rad_s[1]:
            raise ValueError(f"band {self.band_rad_s} rad/s must be two increasing positive frequencies")
        if not self.max_delay_s > 0:
            raise ValueError(f"max_delay_s={self.max_delay_s} must be > 0")


@dataclass(frozen=True, slots=True, kw_only=True)
class FittedCoefficient:
    """One fitted parameter with its accuracy.

    Parameters
    ----------
    name : str
        Parameter name (``tau`` for the delay, s).
    value : float
        Estimate.
    cr_percent : float
        Cramér–Rao bound, % of ``|value|`` (inf when the data do not inform it).
    insensitivity_percent : float
        Insensitivity, % of ``|value|``.
    unit : str, optional
        Its unit (:meth:`~sysid.model.transfer.TransferStructure.parameter_units`; s for the delay).
    """

    name: str
    value: float
    cr_percent: float
    insensitivity_percent: float
    unit: str = ""


@dataclass(frozen=True, slots=True, kw_only=True)
class TransferFunctionFit:
    """A transfer function fitted to one response.

    Parameters
    ----------
    structure : TransferStructure
        What was fitted.
    coefficients : tuple of FittedCoefficient
        The structure's parameters, then ``tau`` when a delay was fitted.
    numerator, denominator : tuple of float
        Polynomial coefficients, highest power of s first.
    delay_s : float or None
        Transport delay, s (None when not fitted).
    cost : float
        J of eq. 3.9 (dimensionless; guideline ≤ 100).
    band_rad_s : tuple of (float, float)
        The frequencies fitted, rad/s.
    poles, zeros : tuple of complex
        Roots of the denominator and the numerator, rad/s.
    response : FrequencyResponse
        The measured response, with its fit range.
    notes : tuple of str
        What a reader must know: an unstable or non-minimum-phase fit, a
        parameter beyond the guidelines.
    guidelines : Guidelines
        The limits it was judged by.
    """

    structure: TransferStructure
    coefficients: tuple[FittedCoefficient, ...]
    numerator: tuple[float, ...]
    denominator: tuple[float, ...]
    delay_s: float | None
    cost: float
    band_rad_s: tuple[float, float]
    poles: tuple[complex, ...]
    zeros: tuple[complex, ...]
    response: FrequencyResponse
    notes: tuple[str, ...] = ()
    guidelines: Guidelines = DEFAULT_GUIDELINES

    @property
    def stable(self) -> bool:
        """Every pole in the open left half-plane."""
        return all(p.real < 0 for p in self.poles)

    @property
    def minimum_phase(self) -> bool:
        """No zero in the right half-plane."""
        return all(z.real <= 0 for z in self.zeros)

    def evaluate(self, omega: np.ndarray) -> np.ndarray:
        """The fitted transfer function at `omega`, rad/s.

        Parameters
        ----------
        omega : ndarray, shape (n_freq,)
            Frequencies, rad/s.

        Returns
        -------
        ndarray of complex, shape (n_freq,)
        """
        s = 1j * np.asarray(omega, dtype=float)
        shift = np.exp(-s * (self.delay_s or 0.0))
        return np.asarray(np.polyval(self.numerator, s) / np.polyval(self.denominator, s) * shift)

    def to_dict(self) -> dict[str, Any]:
        """The fit as JSON-ready data (``tf[]`` of ``sysid fit --json``)."""
        return {
            "pair": self.structure.pair,
            "expression": self.structure.text,
            "numerator": list(self.numerator),
            "denominator": list(self.denominator),
            "delay_s": self.delay_s,
            "parameters": {
                c.name: {
                    "value": c.value,
                    "cr_percent": c.cr_percent,
                    "insensitivity_percent": c.insensitivity_percent,
                    "unit": c.unit,
                }
                for c in self.coefficients
            },
            "J": self.cost,
            "band_rad_s": list(self.band_rad_s),
            "poles": [[p.real, p.imag] for p in self.poles],
            "zeros": [[z.real, z.imag] for z in self.zeros],
            "stable": self.stable,
            "minimum_phase": self.minimum_phase,
            "notes": list(self.notes),
        }


class _TransferCost(LogResponseCost):
    """Eq. 3.9 for ``N(s) / D(s) exp(-tau s)``; the polynomials' bases are evaluated once."""

    def __init__(self, structure: TransferStructure, points: FitPoints, *, delay: bool, weights: CostWeights) -> None:
        super().__init__(points, weights=weights)
        self.structure, self.delay = structure, delay
        self.s = 1j * points.omega
        self.n_fixed, self.d_fixed, self.n_basis, self.d_basis = structure.basis(self.s)

    def log_response(
        self, theta: np.ndarray, *, with_derivatives: bool = False
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """``ln T`` at each point and optionally ``d ln T / d theta`` (coefficients, then tau).

        Parameters
        ----------
        theta : ndarray, shape (n_parameters [+ 1],)
            The structure's parameters, then the delay, s, when fitted.
        with_derivatives : bool, optional
            Also return the derivatives, shape (n_points, n_free).
        """
        n = len(self.structure.parameters)
        numerator = self.n_fixed + self.n_basis @ theta[:n]
        denominator = self.d_fixed + self.d_basis @ theta[:n]
        tau = float(theta[n]) if self.delay else 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            log_t = np.log(numerator) - np.log(denominator) - self.s * tau
            if not with_derivatives:
                return log_t, None
            d = self.n_basis / numerator[:, None] - self.d_basis / denominator[:, None]
        if self.delay:
            d = np.column_stack([d, -self.s])
        return log_t, d


def fit_transfer_function(
    response: FrequencyResponse, structure: TransferStructure, options: TransferOptions = TransferOptions()
) -> TransferFunctionFit:
    """Fit `structure` to one gated response.

    Parameters
    ----------
    response : FrequencyResponse
        The measured response of ``structure.pair``, gated (``fit_range`` set).
    structure : TransferStructure
        The transfer function to fit.
    options : TransferOptions, optional
        Delay, band, weights and guidelines.

    Returns
    -------
    TransferFunctionFit

    Raises
    ------
    FitError
        If the response has no fit range inside the band, or has fewer points than parameters.
    """
    if response.fit_range is None:
        raise FitError(f"response {response.pair} has no fit range: gate the responses before fitting")
    band = response.fit_range
    if options.band_rad_s is not None:
        band = (max(band[0], options.band_rad_s[0]), min(band[1], options.band_rad_s[1]))
        if band[0] >= band[1]:
            raise FitError(
                f"{response.pair}: the band {options.band_rad_s[0]:g}-{options.band_rad_s[1]:g} rad/s misses the "
                f"coherent range {response.fit_range[0]:.3g}-{response.fit_range[1]:.3g} rad/s"
            )
    banded = dataclasses.replace(response, fit_range=band)
    points = fit_points([banded], weights=options.weights)
    n_free = len(structure.parameters) + int(options.delay)
    if 2 * points.omega.size <= n_free:
        raise FitError(f"{response.pair}: {points.omega.size} frequency points for {n_free} parameters")
    model = _TransferCost(structure, points, delay=options.delay, weights=options.weights)
    start = _start(model, options)
    upper = np.full(n_free, np.inf)
    lower = -upper.copy()
    if options.delay:
        lower[-1], upper[-1] = 0.0, options.max_delay_s
    fitted = _searched(model, start, lower, upper)
    names = (*structure.parameters, *((_DELAY_NAME,) if options.delay else ()))
    estimates = [fitted]
    for factor in RAISED_BOTTOMS:  # the fit range's spread (sysid.fit.bias)
        moved = raised(banded, factor)
        if moved is None:
            continue
        again = fit_points([moved], weights=options.weights)
        if 2 * again.omega.size <= n_free:
            continue
        other = _TransferCost(structure, again, delay=options.delay, weights=options.weights)
        estimates.append(_searched(other, fitted, lower, upper))
    jacobian = model.jacobian(fitted)
    spread = bounds_with_bias(accuracy(jacobian, fitted, names), jacobian, model.residuals(fitted), points, estimates)
    units = structure.parameter_units(response.output_unit, response.input_unit) | {_DELAY_NAME: "s"}
    coefficients = tuple(
        FittedCoefficient(
            name=name, value=float(v), cr_percent=float(cr), insensitivity_percent=float(i), unit=units[name]
        )
        for name, v, cr, i in zip(names, fitted, spread.cramer_rao_percent, spread.insensitivity_percent)
    )
    numerator, denominator = structure.coefficients(fitted[: len(structure.parameters)])
    poles = tuple(complex(p) for p in np.roots(denominator))
    zeros = tuple(complex(z) for z in np.roots(np.trim_zeros(numerator, "f")))
    cost = model.cost(fitted).average
    return TransferFunctionFit(
        structure=structure,
        coefficients=coefficients,
        numerator=tuple(float(c) for c in numerator),
        denominator=tuple(float(c) for c in denominator),
        delay_s=float(fitted[-1]) if options.delay else None,
        cost=cost,
        band_rad_s=band,
        poles=poles,
        zeros=zeros,
        response=banded,
        notes=_notes(structure.pair, coefficients, cost, poles, zeros, options.guidelines),
        guidelines=options.guidelines,
    )


def _searched(model: _TransferCost, start: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """The nonlinear search from `start` within the bounds: the coefficients (and delay) of least cost."""
    found = least_squares(
        model.residuals, start, jac=model.jacobian, bounds=(lower, upper), method="trf", x_scale="jac", xtol=1e-12
    )
    return cast(np.ndarray, found.x)


def _start(model: _TransferCost, options: TransferOptions) -> np.ndarray:
    """The linear (Levy / Sanathanan–Koerner) fit at each delay of the grid; the one of least cost."""
    delays = np.arange(0.0, options.max_delay_s + 1e-12, _DELAY_STEP_S) if options.delay else np.zeros(1)
    best, best_cost = np.zeros(0), np.inf
    for tau in delays:
        theta = _levy(model, float(tau))
        candidate = np.append(theta, tau) if options.delay else theta
        cost = float(np.sum(model.residuals(candidate) ** 2))
        if cost < best_cost:
            best, best_cost = candidate, cost
    return best


def _levy(model: _TransferCost, tau: float) -> np.ndarray:
    """Coefficients solving ``N - M D = 0`` in least squares, ``M = T e^{tau s}``, reweighted by ``1/|M D|``."""
    measured = np.exp(model.points.log_measured + model.s * tau)
    rows = model.n_basis - measured[:, None] * model.d_basis
    rhs = measured * model.d_fixed - model.n_fixed
    root = np.sqrt(model.points.weight) / np.abs(measured)
    scale = np.ones(model.s.size)
    theta = np.zeros(rows.shape[1])
    for _ in range(_SK_PASSES):
        w = root / scale
        a = np.concatenate([(rows * w[:, None]).real, (rows * w[:, None]).imag])
        b = np.concatenate([(rhs * w).real, (rhs * w).imag])
        theta = np.linalg.lstsq(a, b, rcond=None)[0]
        scale = np.maximum(np.abs(model.d_fixed + model.d_basis @ theta), 1e-300)
    return theta


def _notes(
    pair: str,
    coefficients: Sequence[FittedCoefficient],
    cost: float,
    poles: Sequence[complex],
    zeros: Sequence[complex],
    guidelines: Guidelines,
) -> tuple[str, ...]:
    notes = []
    unstable = [p for p in poles if p.real >= 0]
    if unstable:
        notes.append(f"{pair}: unstable fit, pole(s) at {', '.join(f'{p:.3g}' for p in unstable)} rad/s")
    nonminimum = [z for z in zeros if z.real > 0]
    if nonminimum:
        notes.append(f"{pair}: non-minimum phase, zero(s) at {', '.join(f'{z:.3g}' for z in nonminimum)} rad/s")
    if cost > guidelines.j_average_good:
        notes.append(f"{pair}: J = {cost:.0f} > {guidelines.j_average_good:g}, the fit misses the data")
    for c in coefficients:
        if c.cr_percent > guidelines.max_cr_percent or c.insensitivity_percent > guidelines.max_insensitivity_percent:
            notes.append(
                f"{pair}: {c.name} not identified to the guidelines (CR {c.cr_percent:.3g} % against "
                f"{guidelines.max_cr_percent:g}, insensitivity {c.insensitivity_percent:.3g} % against "
                f"{guidelines.max_insensitivity_percent:g})"
            )
    return tuple(notes)


def fit_transfer_functions(
    flights: Sequence[ConditionedFlight],
    structures: Sequence[TransferStructure],
    *,
    options: TransferOptions = TransferOptions(),
    responses: ResponseOptions = ResponseOptions(),
    kind: str = "sweep",
    gating: Gating = Gating(),
) -> tuple[TransferFunctionFit, ...]:
    """Compute and gate each structure's response on the flights' maneuvers, then fit it.

    Parameters
    ----------
    flights : sequence of ConditionedFlight
        Conditioned flights with maneuvers of the pairs' axes.
    structures : sequence of TransferStructure
        The transfer functions, one pair each (the input a mixer input ``delta_<axis>``).
    options : TransferOptions, optional
        Delay, band and weights.
    responses : ResponseOptions, optional
        How the responses are computed.
    kind : str, optional
        Maneuvers used (``sweep``).
    gating : Gating, optional
        The gating rule (eq. 3.8).

    Returns
    -------
    tuple of TransferFunctionFit
        In the order of `structures`.

    Raises
    ------
    FitError
        If a pair's response does not pass gating (the reason named).
    """
    pairs = list(dict.fromkeys((s.output, s.input) for s in structures))
    computed = flight_responses(flights, pairs, kind=kind, options=responses)
    gated = gate_responses(computed.responses, gating)
    kept = {r.pair: r for r in gated.kept}
    dropped = {f"{d.output}/{d.input}": d.reason for d in gated.dropped}
    fits = []
    for structure in structures:
        if structure.pair not in kept:
            raise FitError(
                f"{structure.pair}: the response cannot be fitted: {dropped.get(structure.pair, 'not computed')}"
            )
        fits.append(fit_transfer_function(kept[structure.pair], structure, options))
    return tuple(fits)
