"""Fit the F and G_u parameters of a structure to gated frequency responses (eq. 3.9).

A bounded secant-type search on the weighted residual vector: scipy's
trust-region-reflective least squares (Gauss–Newton steps in a trust
region, bounds by reflection) with the analytic Jacobian of
:class:`~sysid.fit.cost.ResponseModel`. Control derivatives start at the
measured gain of their input's responses (sign included), so the same
structure file works whatever unit the mixer inputs were logged in; more
starts, randomly spread about that one, can be asked for. The structure is
then reduced (:mod:`sysid.fit.reduce`) until every parameter meets the
CR% / I% guidelines.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Literal

import numpy as np
from scipy import optimize

from flightlogs.errors import FitError
from sysid.fit.accuracy import Accuracy, accuracy
from sysid.fit.cost import CostSummary, CostWeights, FitPoints, ResponseModel, fit_points
from sysid.fit.reduce import ReductionStep, worst_parameter
from sysid.freqresp import FrequencyResponse
from sysid.model.assemble import Assembler
from sysid.model.structure import ModelStructure

__all__ = ["FitOptions", "FrequencyFit", "fit_frequency_responses"]

Status = Literal["estimated", "fixed", "dropped"]


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
    max_cr_percent : float
        CR% guideline.
    max_insensitivity_percent : float
        I% guideline.
    max_correlation : float or None
        Also remove one of a pair correlated beyond this; None to ignore.
    max_steps : int
        Most parameters reduction may remove.
    max_cost_increase : float or None
        With a value, a removal raising J_ave by more than this fraction
        (and by more than 1) is undone and the parameter kept although it
        misses a guideline; None (default) applies the guidelines strictly,
        as the dissertation's procedure does.
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
    max_cr_percent: float = 20.0
    max_insensitivity_percent: float = 10.0
    max_correlation: float | None = None
    max_steps: int = 30
    max_cost_increase: float | None = None
    max_evaluations: int = 300
    jacobian: Literal["analytic", "numeric"] = "analytic"
    rescale_controls: bool = True

    def __post_init__(self) -> None:
        if self.starts < 1:
            raise ValueError(f"starts={self.starts} must be at least 1")
        if self.max_cr_percent <= 0 or self.max_insensitivity_percent <= 0:
            raise ValueError("the CR% and I% guidelines must be positive")
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
        Every parameter's final value (estimates, fixed and dropped values).
    status : Mapping[str, str]
        ``estimated``, ``fixed`` or ``dropped`` for every parameter the fit
        concerned (wind-step parameters are absent).
    accuracy : Accuracy
        CR, I and correlations of the estimated parameters.
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
    for name in search.uninformed([n for n, s in status.items() if s == "estimated"], values):
        status[name] = "fixed"
    values, evaluations = search.first_fit(values, status)
    values, status, acc, cost, steps, spent = _reduce(search, values, status)
    return FrequencyFit(
        structure=structure,
        values=MappingProxyType(dict(values)),
        status=MappingProxyType(dict(status)),
        accuracy=acc,
        cost=cost,
        reduction=tuple(steps),
        constants=MappingProxyType(consts),
        responses=used,
        evaluations=evaluations + spent,
    )


def _reduce(
    search: _Search, values: dict[str, float], status: dict[str, Status]
) -> tuple[dict[str, float], dict[str, Status], Accuracy, CostSummary, list[ReductionStep], int]:
    """Remove the worst parameter and refit until every one meets the guidelines (see :mod:`.reduce`)."""
    options = search.options
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
            steps[-1] = replace(steps[-1], cost_average_after=cost.average)
            if previous is not None and _too_costly(steps[-1], options.max_cost_increase):
                values, status = previous
                kept.add(steps[-1].parameter)
                steps[-1] = replace(
                    steps[-1],
                    action="kept",
                    value=steps[-1].estimate,
                    reason=steps[-1].reason + f"; removing it raised J_ave to "
                    f"{steps[-1].cost_average_after:.3g}, so it stays",
                )
                continue
        worst = (
            None
            if not options.reduce or len(steps) >= options.max_steps
            else worst_parameter(
                acc,
                max_cr_percent=options.max_cr_percent,
                max_insensitivity_percent=options.max_insensitivity_percent,
                max_correlation=options.max_correlation,
                exclude=frozenset(kept),
            )
        )
        if worst is None:
            return values, status, acc, cost, steps, evaluations
        previous = (dict(values), dict(status))
        steps.append(_remove(search.structure, worst, acc, values, status, cost.average, len(steps) + 1))
        values, spent = search.refit(values, status)
        evaluations += spent


def _too_costly(step: ReductionStep, tolerance: float | None) -> bool:
    """Whether removing the step's parameter raised J_ave beyond the tolerance (relative, and by more than 1)."""
    if tolerance is None:
        return False
    rise = step.cost_average_after - step.cost_average
    return rise > 1.0 and rise > tolerance * step.cost_average


def _remove(
    structure: ModelStructure,
    worst: tuple[str, str],
    acc: Accuracy,
    values: dict[str, float],
    status: dict[str, Status],
    cost_average: float,
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
        cost_average=cost_average,
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

    def uninformed(self, free: Sequence[str], values: Mapping[str, float]) -> list[str]:
        """Parameters no fitted response depends on (their Jacobian column is zero)."""
        if not free:
            return []
        model = self.model(free, values)
        jac = model.jacobian(np.array([values[n] for n in free]))
        return [n for n, column in zip(free, jac.T) if not np.any(column)]

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
