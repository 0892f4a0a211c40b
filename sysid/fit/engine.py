"""Fit the F and G_u parameters of a structure to gated frequency responses (eq. 3.9).

A bounded secant-type search on the weighted residual vector: scipy's
trust-region-reflective least squares (Gauss–Newton steps in a trust
region, bounds by reflection) with the analytic Jacobian of
:class:`~sysid.fit.cost.ResponseModel`. Control derivatives start at the
measured gain of their input's responses (sign included), so the same
structure file works whatever unit the mixer inputs were logged in; more
starts, randomly spread about that one, can be asked for. The structure is
then reduced (:mod:`sysid.fit.reduce`) until every parameter meets the
CR% / I% guidelines (:mod:`sysid.fit.guidelines`), each step taken only if
the costs stay within the guidelines' margins.

A free parameter that no fitted response informs (its Jacobian column is
zero, or no response of an input whose part of the model reads it was
fitted: :mod:`sysid.model.axes`) is ``unidentified``: it keeps its starting
value inside the search, where it changes nothing, and has no value (NaN) in
the result. Each control input's axis is ``identified`` only when its
responses informed every parameter of its part of the model
(:mod:`sysid.fit.axes`).
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Literal

import numpy as np
from scipy import optimize

from flightlogs.errors import FitError
from sysid.fit.accuracy import Accuracy, accuracy
from sysid.fit.axes import AxisStatus, axis_name
from sysid.fit.bias import RAISED_BOTTOMS, bounds_with_bias, raised
from sysid.fit.cost import CostSummary, CostWeights, FitPoints, ResponseModel, fit_points
from sysid.fit.guidelines import DEFAULT_GUIDELINES, Guidelines
from sysid.fit.reduce import ReductionStep, worst_parameter
from sysid.freqresp import FrequencyResponse
from sysid.model.assemble import Assembler
from sysid.model.axes import axis_parts
from sysid.model.structure import ModelStructure

__all__ = ["FitOptions", "FrequencyFit", "fit_frequency_responses"]

Status = Literal["estimated", "fixed", "dropped", "unidentified"]


@dataclass(frozen=True, slots=True, kw_only=True)
class FitOptions:
    """Choices of the frequency-response fit; defaults follow Tischler and the dissertation.

    Parameters
    ----------
    weights : CostWeights
        W_g, W_p, W_gamma gain and n_omega of eq. 3.9.
    starts : int
        Number of starting points (1: the structure's values, rescaled).
    seed : int
        Seed of the extra starting points.
    reduce : bool
        Run structure reduction after the first fit.
    guidelines : Guidelines
        The guidelines the fit applies and its model is judged by: the CR% and I% limits (% of ``|value|``)
        reduction removes parameters beyond, and the J margins a reduction step keeps within; default
        Tischler's (:data:`~sysid.fit.guidelines.DEFAULT_GUIDELINES`).
    max_correlation : float or None
        Also remove one of a pair correlated beyond this; None to ignore.
    max_steps : int
        Most parameters reduction may remove.
    reduction_cost_check : bool
        Take a reduction step only if the costs stay within the guidelines' margins;
        False removes every parameter that misses CR% or I%, whatever the cost.
    max_evaluations : int
        Most cost evaluations per fit.
    jacobian : {"analytic", "numeric"}
        Analytic Jacobian, or scipy's forward differences (for comparison).
    rescale_controls : bool
        Start control derivatives at the measured gain of their input.
    """

    weights: CostWeights = field(default_factory=CostWeights)
    starts: int = 1
    seed: int = 0
    reduce: bool = True
    guidelines: Guidelines = DEFAULT_GUIDELINES
    max_correlation: float | None = None
    max_steps: int = 30
    reduction_cost_check: bool = True
    max_evaluations: int = 300
    jacobian: Literal["analytic", "numeric"] = "analytic"
    rescale_controls: bool = True

    def __post_init__(self) -> None:
        if self.starts < 1:
            raise ValueError(f"starts={self.starts} must be at least 1")
        if self.jacobian not in ("analytic", "numeric"):
            raise ValueError(f"jacobian={self.jacobian!r} must be 'analytic' or 'numeric'")


@dataclass(frozen=True, slots=True, kw_only=True)
class FrequencyFit:
    """Result of :func:`fit_frequency_responses`.

    Parameters
    ----------
    structure : ModelStructure
        The structure fitted.
    values : Mapping[str, float]
        Every parameter's final value (estimates, fixed and dropped values;
        NaN for the unidentified).
    status : Mapping[str, str]
        ``estimated``, ``fixed``, ``dropped`` or ``unidentified`` for every
        parameter the fit concerned (wind-step parameters are absent).
    accuracy : Accuracy
        CR, I and correlations of the estimated parameters; each CR bound
        carries the residual's sandwich bound and the fit range's spread
        (:mod:`sysid.fit.bias`).
    cost : CostSummary
        J_ave and per-pair costs of the final fit.
    reduction : tuple of ReductionStep
        What structure reduction removed, in order.
    constants : Mapping[str, float]
        Trim constants used, SI.
    responses : tuple of FrequencyResponse
        The responses fitted.
    evaluations : int
        Cost evaluations spent, all fits together.
    axes : tuple of AxisStatus
        Each control input's axis, identified or not (with the reason).
    """

    structure: ModelStructure
    values: Mapping[str, float]
    status: Mapping[str, Status]
    accuracy: Accuracy
    cost: CostSummary
    reduction: tuple[ReductionStep, ...]
    constants: Mapping[str, float]
    responses: tuple[FrequencyResponse, ...]
    evaluations: int = 0
    axes: tuple[AxisStatus, ...] = ()

    @property
    def unidentified_axes(self) -> tuple[AxisStatus, ...]:
        """The axes not identified."""
        return tuple(a for a in self.axes if not a.identified)


def fit_frequency_responses(
    structure: ModelStructure,
    responses: Sequence[FrequencyResponse],
    *,
    constants: Mapping[str, float] | None = None,
    initial: Mapping[str, float] | None = None,
    options: FitOptions = FitOptions(),
) -> FrequencyFit:
    """Identify the F and G_u parameters of `structure` from gated frequency responses.

    Parameters
    ----------
    structure : ModelStructure
        The model structure (wind columns are ignored here).
    responses : sequence of FrequencyResponse
        Gated responses; those whose input is not a control input of the
        structure, or whose output it lacks, are left out.
    constants : Mapping[str, float], optional
        Trim constants (``g U0 W0 theta0`` ...), SI; default the structure's.
    initial : Mapping[str, float], optional
        Starting values overriding the structure's, by parameter name.
    options : FitOptions, optional
        Search and reduction choices.

    Returns
    -------
    FrequencyFit

    Raises
    ------
    FitError
        If no response can be fitted or the search fails.

    Notes
    -----
    Structure reduction judges the parameters by Tischler's Cramér–Rao
    bound; the bounds returned also carry the fit's systematic error
    (:mod:`sysid.fit.bias`: the residual's sandwich bound, the fit range's
    spread).
    """
    controls = {c.signal for c in structure.control_inputs}
    used = tuple(r for r in responses if r.input in controls and r.output in structure.outputs)
    if not used:
        pairs = ", ".join(r.pair for r in responses) or "none"
        raise FitError(
            f"no gated response has a control input and an output of model {structure.name} (responses: {pairs})"
        )
    consts = dict(structure.default_constants()) | dict(constants or {})
    values = structure.values(initial)
    wind = set(structure.wind_parameters)
    status: dict[str, Status] = {
        p.name: ("estimated" if p.free else "fixed") for p in structure.parameters if p.name not in wind
    }
    points = fit_points(used, weights=options.weights)
    search = _Search(structure, points, consts, options)
    parts = {signal: part.parameters for signal, part in axis_parts(structure, values).items()}
    fitted = {r.input for r in used}
    free = [n for n, s in status.items() if s == "estimated"]
    for name in search.uninformed(free, values, parts, fitted):
        status[name] = "unidentified"
    values, evaluations = search.first_fit(values, status)
    values, status, acc, cost, steps, spent = _reduce(search, values, status)
    acc, refits = _bounds_with_bias(search, used, values, status, acc)
    shown = {n: math.nan if status.get(n) == "unidentified" else v for n, v in values.items()}
    return FrequencyFit(
        structure=structure,
        values=MappingProxyType(shown),
        status=MappingProxyType(dict(status)),
        accuracy=acc,
        cost=cost,
        reduction=tuple(steps),
        constants=MappingProxyType(consts),
        responses=used,
        evaluations=evaluations + spent + refits,
        axes=_axes(parts, status, used),
    )


def _axes(
    parts: Mapping[str, Sequence[str]], status: Mapping[str, Status], used: Sequence[FrequencyResponse]
) -> tuple[AxisStatus, ...]:
    """Each control input's axis: identified when its responses informed every parameter of its part."""
    out = []
    for signal, names in parts.items():
        pairs = [r.pair for r in used if r.input == signal]
        missing = [n for n in names if status.get(n) == "unidentified"]
        if not pairs:
            reason = f"no gated response of {signal} was fitted"
        elif missing:
            reason = (
                f"{', '.join(missing)} {'is' if len(missing) == 1 else 'are'} informed by no fitted response "
                f"(fitted: {', '.join(pairs)})"
            )
        else:
            out.append(AxisStatus(axis=axis_name(signal), input=signal, status="identified"))
            continue
        out.append(AxisStatus(axis=axis_name(signal), input=signal, status="unidentified", reason=reason))
    return tuple(out)


def _bounds_with_bias(
    search: _Search,
    used: Sequence[FrequencyResponse],
    values: Mapping[str, float],
    status: Mapping[str, Status],
    acc: Accuracy,
) -> tuple[Accuracy, int]:
    """`acc` carrying the fit's systematic error (:mod:`sysid.fit.bias`); and the evaluations its refits spent."""
    estimated = [n for n, s in status.items() if s == "estimated"]
    if not estimated:
        return acc, 0
    theta = np.array([values[n] for n in estimated])
    model = search.model(estimated, values)
    estimates, spent = [theta], 0
    for factor in RAISED_BOTTOMS:
        moved = [raised(r, factor) for r in used]
        if not any(moved):
            continue
        points = fit_points([m or r for m, r in zip(moved, used)], weights=search.options.weights)
        fitted, evaluations = _Search(search.structure, points, search.constants, search.options).refit(
            dict(values), status
        )
        estimates.append(np.array([fitted[n] for n in estimated]))
        spent += evaluations
    return bounds_with_bias(acc, model.jacobian(theta), model.residuals(theta), search.points, estimates), spent


def _reduce(
    search: _Search, values: dict[str, float], status: dict[str, Status]
) -> tuple[dict[str, float], dict[str, Status], Accuracy, CostSummary, list[ReductionStep], int]:
    """Remove the worst parameter and refit until every one meets the guidelines (see :mod:`.reduce`).

    A removal whose refit raises J_ave or a response's J beyond the
    guidelines' margins (:meth:`Guidelines.reduction_cost_rise`) is undone:
    the parameter is kept, the step logged as ``kept`` with the cost that rose.
    """
    options = search.options
    guidelines = options.guidelines
    steps: list[ReductionStep] = []
    kept: set[str] = set()
    previous: tuple[dict[str, float], dict[str, Status]] | None = None
    evaluations = 0
    while True:
        estimated = [n for n, s in status.items() if s == "estimated"]
        model, theta = search.model(estimated, values), np.array([values[n] for n in estimated])
        acc = accuracy(model.jacobian(theta), theta, tuple(estimated))
        cost = model.cost(theta)
        if steps and math.isnan(steps[-1].cost_average_after):
            step = replace(steps[-1], cost_average_after=cost.average, cost_responses_after=cost.responses)
            before = CostSummary(average=step.cost_average, responses=step.cost_responses)
            rise = guidelines.reduction_cost_rise(before, cost) if options.reduction_cost_check else ""
            if rise and previous is not None:
                values, status = previous
                kept.add(step.parameter)
                steps[-1] = replace(
                    step, action="kept", value=step.estimate, reason=f"{step.reason}; removing it, {rise}, so it stays"
                )
                continue
            steps[-1] = step
        worst = (
            None
            if not options.reduce or len(steps) >= options.max_steps
            else worst_parameter(
                acc,
                guidelines=guidelines,
                max_correlation=options.max_correlation,
                exclude=frozenset(kept),
            )
        )
        if worst is None:
            return values, status, acc, cost, steps, evaluations
        previous = (dict(values), dict(status))
        steps.append(_remove(search.structure, worst, acc, values, status, cost, len(steps) + 1))
        values, spent = search.refit(values, status)
        evaluations += spent


def _remove(
    structure: ModelStructure,
    worst: tuple[str, str],
    acc: Accuracy,
    values: dict[str, float],
    status: dict[str, Status],
    cost: CostSummary,
    step: int,
) -> ReductionStep:
    name, reason = worst
    k = acc.names.index(name)
    parameter = structure.parameter(name)
    estimate = values[name]
    if parameter.reduce == "drop":
        values[name], status[name] = parameter.drop_value, "dropped"
    else:
        status[name] = "fixed"
    return ReductionStep(
        step=step,
        parameter=name,
        action="dropped" if parameter.reduce == "drop" else "fixed",
        value=values[name],
        estimate=estimate,
        cr_percent=float(acc.cramer_rao_percent[k]),
        insensitivity_percent=float(acc.insensitivity_percent[k]),
        reason=reason,
        cost_average=cost.average,
        cost_responses=cost.responses,
    )


class _Search:
    """Builds residual models for a set of free parameters and runs the bounded search."""

    def __init__(
        self, structure: ModelStructure, points: FitPoints, constants: Mapping[str, float], options: FitOptions
    ) -> None:
        self.structure, self.points, self.constants, self.options = structure, points, constants, options

    def model(self, free: Sequence[str], values: Mapping[str, float]) -> ResponseModel:
        assembler = Assembler(self.structure, free=free, fixed=values, constants=self.constants, include_wind=False)
        return ResponseModel(assembler, self.points, weights=self.options.weights)

    def uninformed(
        self,
        free: Sequence[str],
        values: Mapping[str, float],
        parts: Mapping[str, Sequence[str]],
        fitted: Collection[str],
    ) -> list[str]:
        """Parameters no fitted response informs.

        Those whose Jacobian column is zero, and those read only by the parts
        of inputs (`parts`, by signal) of which no response was fitted: such a
        parameter can reach the others' responses only through the trim terms
        that couple the axes weakly, which do not measure it.
        """
        if not free:
            return []
        model = self.model(free, values)
        jac = model.jacobian(np.array([values[n] for n in free]))
        out = []
        for name, column in zip(free, jac.T):
            owners = [signal for signal, names in parts.items() if name in names]
            if not np.any(column) or (owners and not any(signal in fitted for signal in owners)):
                out.append(name)
        return out

    def first_fit(self, values: dict[str, float], status: Mapping[str, Status]) -> tuple[dict[str, float], int]:
        free = [n for n, s in status.items() if s == "estimated"]
        rng = np.random.default_rng(self.options.seed)
        best: tuple[float, dict[str, float]] | None = None
        evaluations = 0
        for start in range(self.options.starts):
            trial = dict(values) if start == 0 else self._spread(values, free, rng)
            if self.options.rescale_controls:
                trial = self._rescaled(trial, free)
            fitted, cost, spent = self._solve(trial, free)
            evaluations += spent
            if best is None or cost < best[0]:
                best = (cost, fitted)
        assert best is not None
        return best[1], evaluations

    def refit(self, values: dict[str, float], status: Mapping[str, Status]) -> tuple[dict[str, float], int]:
        fitted, _, spent = self._solve(values, [n for n, s in status.items() if s == "estimated"])
        return fitted, spent

    def _spread(self, values: Mapping[str, float], free: Sequence[str], rng: np.random.Generator) -> dict[str, float]:
        trial = dict(values)
        for name in free:
            p = self.structure.parameter(name)
            value = values[name] * math.exp(rng.normal(scale=0.7))
            if name.startswith("tau") or value == 0.0:
                value = rng.uniform(max(p.lower, 0.0), min(p.upper, 0.1)) if math.isfinite(p.upper) else value
            trial[name] = float(np.clip(value, p.lower, p.upper))
        return trial

    def _rescaled(self, values: dict[str, float], free: Sequence[str]) -> dict[str, float]:
        """Scale each input's control derivatives jointly to match the measured gain (and sign)."""
        model = self.model(free, values)
        theta = np.array([values[n] for n in free])
        error = self.points.log_measured - model.log_response(theta)[0]
        out = dict(values)
        for channel in self.structure.control_inputs:
            names = [n for n in free if self.structure.parameter(n).input == channel.name]
            mask = np.array([self.points.inputs[r] == channel.signal for r in self.points.response])
            mask &= np.isfinite(error)
            if not names or not mask.any():
                continue
            weight = self.points.weight[mask]
            gain = math.exp(float(np.average(error[mask].real, weights=weight + 1e-12)))
            turn = np.angle(np.average(np.exp(1j * error[mask].imag), weights=weight + 1e-12))
            factor = gain * (-1.0 if abs(turn) > np.pi / 2 else 1.0)
            for name in names:
                p = self.structure.parameter(name)
                out[name] = float(np.clip(values[name] * factor, p.lower, p.upper))
        return out

    def _solve(self, values: Mapping[str, float], free: Sequence[str]) -> tuple[dict[str, float], float, int]:
        if not free:
            return dict(values), 0.0, 0
        model = self.model(free, values)
        lower = np.array([self.structure.parameter(n).lower for n in free])
        upper = np.array([self.structure.parameter(n).upper for n in free])
        theta0 = np.clip(np.array([values[n] for n in free]), lower, upper)
        jac = model.jacobian if self.options.jacobian == "analytic" else "2-point"
        try:
            result = optimize.least_squares(
                model.residuals,
                theta0,
                jac=jac,
                bounds=(lower, upper),
                method="trf",
                x_scale="jac",
                max_nfev=self.options.max_evaluations,
            )
        except (ValueError, np.linalg.LinAlgError) as err:
            raise FitError(f"the search on model {self.structure.name} failed: {err}") from None
        fitted = dict(values) | {n: float(v) for n, v in zip(free, result.x)}
        return fitted, float(2.0 * result.cost), int(result.nfev)
