"""Tischler's identification guidelines, in one place, and the verdict on a model judged by them.

:class:`Guidelines` holds every limit the workbench judges an identification
by: the accuracy of each parameter (CR%, I%), the fit's costs (J_ave, J of
each response, eq. 3.9) and the prediction of doublets (TIC). Structure
reduction (:func:`~sysid.fit.reduce.worst_parameter`, the wind step) removes
parameters beyond the accuracy limits; :func:`model_verdict` grades a model
against all of them. The limits a fit was run with travel with its model:
``sysid fit`` records its options in the model's provenance and
:attr:`IdentifiedModel.guidelines <sysid.fit.result.IdentifiedModel.guidelines>`
reads them back (:meth:`Guidelines.from_options`), so a report judges the
model by the ``--max-cr`` it was fitted with.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields
from typing import Any, Literal, Protocol

from sysid.fit.cost import CostSummary

__all__ = ["Grade", "Guidelines", "DEFAULT_GUIDELINES", "MIN_ESTIMATED_FRACTION", "Check", "Verdict", "model_verdict"]

Grade = Literal["good", "acceptable", "poor"]
_ORDER: dict[str, int] = {"good": 0, "acceptable": 1, "poor": 2}
#: A fit that estimated fewer than this fraction of the structure's free parameters (the others dropped or
#: unidentified) says little about the structure, whatever its costs: it is not judged good.
MIN_ESTIMATED_FRACTION = 0.5
#: The limits a fit applied, as the options of a model written before ``FitOptions`` held a ``Guidelines`` record them.
_FIT_LIMITS = (
    "max_cr_percent",
    "max_insensitivity_percent",
    "reduction_j_average_rise_percent",
    "reduction_j_response_rise_percent",
    "reduction_j_rise_floor",
)


@dataclass(frozen=True, slots=True, kw_only=True)
class Guidelines:
    """Limits an identified model is judged by; the defaults are Tischler's.

    Parameters
    ----------
    max_cr_percent : float
        Largest Cramér–Rao bound of an estimated parameter, % of ``|value|``:
        20 (Tischler & Remple, ch. 11; dissertation section 3.4.2, with eq. 3.9).
        A parameter beyond it is removed by structure reduction.
    max_insensitivity_percent : float
        Largest insensitivity of an estimated parameter, % of ``|value|``: 10
        (Tischler & Remple, ch. 11; dissertation section 3.4.2).
    j_average_good : float
        J_ave (eq. 3.9, dimensionless) of a good fit: ≤ 100 (Tischler & Remple, ch. 11).
    j_average_acceptable : float
        J_ave of an acceptable fit: ≤ 150 (Tischler & Remple, ch. 11;
        dissertation section 3.4.2).
    j_response_max : float
        Cost J of any single response (eq. 3.9, dimensionless): ≤ 200; a few
        may exceed it, which makes the model acceptable, not good (Tischler &
        Remple, ch. 11).
    tic_good : float
        Theil inequality coefficient (dimensionless, 0-1) of a doublet
        predicted in the time domain by a good model: ≤ 0.25 (Tischler &
        Remple, section 15.3; Jategaonkar 2006, eq. 11.12).
    tic_acceptable : float
        Upper end of the 0.25-0.3 band of good predictive accuracy: 0.3.
    reduction_j_average_rise_percent : float
        Largest rise of J_ave (eq. 3.9), % of its value before, that a
        structure-reduction step may cause: 2 %. Tischler & Remple (2nd ed.,
        ch. 10, model structure determination) accept dropping or fixing a
        parameter only if the overall cost hardly changes, J_ave rising by no
        more than about 2 % (a few units); the dissertation (section 3.4.1)
        follows their reduction procedure without a number of its own.
    reduction_j_response_rise_percent : float
        Largest rise of the cost J of any single response, % of its value
        before, that a reduction step may cause: 20 %. Tischler & Remple
        (ch. 10) ask also that no individual response cost rise markedly, so
        a parameter that one response needs is not traded for a small change
        of the average.
    reduction_j_rise_floor : float
        Rise of J_ave or of a response's J (eq. 3.9, cost units) that counts
        as no rise whatever the percentages say: 2, the "few units" of
        Tischler & Remple (a cost of 2 is an error of about 0.3 dB or 2.4 deg
        at every fit point); below it a well-fitted response (J of a few)
        would otherwise refuse any change.

    Raises
    ------
    ValueError
        If a limit is not a positive number, or a "good" limit is above its
        "acceptable" one.

    Examples
    --------
    >>> DEFAULT_GUIDELINES.max_cr_percent, DEFAULT_GUIDELINES.cost_grade(120.0)
    (20.0, 'acceptable')
    >>> Guidelines(max_cr_percent=30.0).misses_cr(25.0)
    False
    """

    max_cr_percent: float = 20.0
    max_insensitivity_percent: float = 10.0
    j_average_good: float = 100.0
    j_average_acceptable: float = 150.0
    j_response_max: float = 200.0
    tic_good: float = 0.25
    tic_acceptable: float = 0.3
    reduction_j_average_rise_percent: float = 2.0
    reduction_j_response_rise_percent: float = 20.0
    reduction_j_rise_floor: float = 2.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
                raise ValueError(f"{f.name}={value!r} must be a positive number")
        if self.j_average_good > self.j_average_acceptable:
            raise ValueError(f"j_average_good={self.j_average_good:g} must be ≤ j_average_acceptable")
        if self.tic_good > self.tic_acceptable:
            raise ValueError(f"tic_good={self.tic_good:g} must be ≤ tic_acceptable")

    @classmethod
    def from_options(cls, options: Mapping[str, Any]) -> Guidelines:
        """The guidelines a fit was run with, from the options its model records.

        Parameters
        ----------
        options : Mapping[str, Any]
            Options of the identification as ``IdentifiedModel.provenance.options``
            holds them (``options["fit"]["guidelines"]``, every field; files written before
            ``FitOptions`` held a ``Guidelines`` give the limits in ``options["fit"]`` itself, as
            ``options["fit"]["max_cr_percent"]``, %); a limit they do not give is Tischler's.

        Returns
        -------
        Guidelines

        Raises
        ------
        ValueError
            If ``options["fit"]`` is not a mapping, or a limit it gives is not a positive number.

        Examples
        --------
        >>> Guidelines.from_options({"fit": {"guidelines": {"max_cr_percent": 30, "tic_good": 0.2}}}).tic_good
        0.2
        >>> Guidelines.from_options({"fit": {"max_cr_percent": 30}}).max_cr_percent  # an older file
        30.0
        >>> Guidelines.from_options({}) == DEFAULT_GUIDELINES
        True
        """
        fit = options.get("fit", {})
        if not isinstance(fit, Mapping):
            raise ValueError(f"options fit is {fit!r}, not a mapping")
        recorded, where = fit, "fit"
        names: tuple[str, ...] = _FIT_LIMITS
        if "guidelines" in fit:
            recorded, where, names = fit["guidelines"], "fit.guidelines", tuple(f.name for f in fields(cls))
            if not isinstance(recorded, Mapping):
                raise ValueError(f"options fit.guidelines is {recorded!r}, not a mapping")
        given: dict[str, float] = {}
        for name in names:
            value = recorded.get(name)
            if value is None:
                continue
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ValueError(f"options {where}.{name} is {value!r}, not a number")
            given[name] = float(value)
        return cls(**given)

    def misses_cr(self, cr_percent: float) -> bool:
        """Whether a parameter's CR% (% of ``|value|``) is beyond the limit: ``inf`` (unidentifiable) is, NaN is not."""
        return cr_percent > self.max_cr_percent

    def misses_insensitivity(self, insensitivity_percent: float) -> bool:
        """Whether a parameter's I% (% of ``|value|``) is beyond the limit; NaN (not estimated) is not."""
        return insensitivity_percent > self.max_insensitivity_percent

    def response_cost_exceeds(self, cost: float) -> bool:
        """Whether the cost J of one response (eq. 3.9) is beyond `j_response_max`; NaN is."""
        return not cost <= self.j_response_max

    def reduction_cost_rise(self, before: CostSummary, after: CostSummary) -> str:
        """Why removing a parameter raised the cost too much (eq. 3.9), in words; empty when the rise is acceptable.

        A structure-reduction step is acceptable when J_ave rises by at most
        `reduction_j_average_rise_percent` % and every response's J by at most
        `reduction_j_response_rise_percent` %, a rise up to
        `reduction_j_rise_floor` counting as none (Tischler & Remple, ch. 10).

        Parameters
        ----------
        before : CostSummary
            Costs of the fit with the parameter.
        after : CostSummary
            Costs of the refit without it (responses by the same pair names).

        Returns
        -------
        str
            The responses whose cost rose beyond the margin, worst first
            (``"r/delta_yaw from 2.8 to 83"``), or the rise of J_ave; "" if none did.

        Examples
        --------
        >>> g = DEFAULT_GUIDELINES
        >>> g.reduction_cost_rise(CostSummary(average=20.0, responses={"q/delta_lon": 20.0, "r/delta_yaw": 2.8}),
        ...                       CostSummary(average=51.0, responses={"q/delta_lon": 19.0, "r/delta_yaw": 83.0}))
        'the cost of r/delta_yaw rose from 2.8 to 83 (allowed: up to 4.8)'
        >>> g.reduction_cost_rise(CostSummary(average=20.0, responses={"q/delta_lon": 20.0}),
        ...                       CostSummary(average=21.5, responses={"q/delta_lon": 21.5}))
        ''
        """
        rises = []
        for pair, old in before.responses.items():
            new = after.responses.get(pair, math.nan)
            allowed = self._allowed_rise(old, self.reduction_j_response_rise_percent)
            if not new <= old + allowed:
                rises.append(
                    (
                        new - old,
                        f"the cost of {pair} rose from {old:.3g} to {new:.3g} (allowed: up to {old + allowed:.3g})",
                    )
                )
        if rises:
            return "; ".join(
                text for _, text in sorted(rises, key=lambda item: -item[0] if math.isfinite(item[0]) else -math.inf)
            )
        allowed = self._allowed_rise(before.average, self.reduction_j_average_rise_percent)
        if not after.average <= before.average + allowed:
            return f"J_ave rose from {before.average:.3g} to {after.average:.3g} (allowed: up to {before.average + allowed:.3g})"
        return ""

    def _allowed_rise(self, cost: float, percent: float) -> float:
        return max(self.reduction_j_rise_floor, percent / 100.0 * cost)

    def cost_grade(self, cost_average: float) -> Grade:
        """Grade of J_ave (eq. 3.9): good up to `j_average_good`, acceptable up to `j_average_acceptable`."""
        return _grade(cost_average, self.j_average_good, self.j_average_acceptable)

    def tic_grade(self, tic: float) -> Grade:
        """Grade of a prediction's Theil inequality coefficient: good up to `tic_good`, acceptable to `tic_acceptable`."""
        return _grade(tic, self.tic_good, self.tic_acceptable)


def _grade(value: float, good: float, acceptable: float) -> Grade:
    """Good up to `good`, acceptable up to `acceptable`, poor beyond (and for NaN): a limit met exactly is met."""
    if value <= good:
        return "good"
    return "acceptable" if value <= acceptable else "poor"


#: Tischler's guidelines, the defaults of ``sysid fit`` and of the verdict.
DEFAULT_GUIDELINES = Guidelines()


class _Estimate(Protocol):
    """What the verdict reads of a parameter (:class:`~sysid.fit.result.ParameterEstimate`)."""

    @property
    def name(self) -> str: ...
    @property
    def status(self) -> str: ...
    @property
    def cr_percent(self) -> float: ...
    @property
    def insensitivity_percent(self) -> float: ...


class _Axis(Protocol):
    """What the verdict reads of an axis (:class:`~sysid.fit.axes.AxisStatus`)."""

    @property
    def axis(self) -> str: ...
    @property
    def status(self) -> str: ...
    @property
    def reason(self) -> str: ...


class _Found(Protocol):
    """What the verdict reads of a model's provenance (:class:`~sysid.fit.result.Provenance`)."""

    @property
    def maneuvers(self) -> Sequence[str]: ...


class _Judged(Protocol):
    """What the verdict reads of a model (:class:`~sysid.fit.result.IdentifiedModel`)."""

    @property
    def provenance(self) -> _Found: ...

    @property
    def cost(self) -> CostSummary: ...
    @property
    def parameters(self) -> Sequence[_Estimate]: ...
    @property
    def guidelines(self) -> Guidelines: ...
    @property
    def axis_status(self) -> Sequence[_Axis]: ...


class _Scored(Protocol):
    """What the verdict reads of a verified output (:class:`~sysid.verify.OutputSummary`)."""

    @property
    def name(self) -> str: ...
    @property
    def tic(self) -> float: ...


class _Verified(Protocol):
    """What the verdict reads of a verification (:class:`~sysid.verify.Verification`)."""

    @property
    def summary(self) -> Sequence[_Scored]: ...
    @property
    def unverified(self) -> Sequence[str]: ...


@dataclass(frozen=True, slots=True, kw_only=True)
class Check:
    """One guideline and how the model meets it.

    Parameters
    ----------
    guideline : str
        What is checked, in words.
    value : str
        The model's figure, for display.
    limit : str
        The guideline's limit, for display.
    grade : {"good", "acceptable", "poor"}
        Met, nearly met (or missed where Tischler tolerates a few), missed.
    problem : str
        What misses the guideline, in words; empty when it is met.
    """

    guideline: str
    value: str
    limit: str
    grade: Grade
    problem: str = ""


@dataclass(frozen=True, slots=True, kw_only=True)
class Verdict:
    """The verdict on a model: the worst grade of its checks, said in one sentence.

    Parameters
    ----------
    grade : {"good", "acceptable", "poor"}
        Worst grade of `checks`.
    sentence : str
        One sentence for the report's summary card.
    checks : tuple of Check
        Cost, response costs, parameter accuracy and (when verified) prediction.
    guidelines : Guidelines
        The limits the model was judged by.
    """

    grade: Grade
    sentence: str
    checks: tuple[Check, ...]
    guidelines: Guidelines


def _worst(grades: Sequence[Grade]) -> Grade:
    return max(grades, key=lambda g: _ORDER[g], default="good")


def _cost_checks(cost: CostSummary, g: Guidelines) -> list[Check]:
    j = cost.average
    grade = g.cost_grade(j)
    above = (
        f" (acceptable up to {g.j_average_acceptable:g})"
        if grade == "acceptable"
        else f" and {g.j_average_acceptable:g}"
    )
    checks = [
        Check(
            guideline="average cost J_ave",
            value=f"{j:.1f}",
            limit=f"≤ {g.j_average_good:g} good, ≤ {g.j_average_acceptable:g} acceptable",
            grade=grade,
            problem="" if grade == "good" else f"J_ave = {j:.1f} is above {g.j_average_good:g}{above}",
        )
    ]
    over = {k: v for k, v in cost.responses.items() if g.response_cost_exceeds(v)}
    listed = ", ".join(f"{k} {v:.0f}" for k, v in over.items())
    # a few may pass the limit (Tischler & Remple), by as much as J_ave may pass its good one (x 1.5); beyond, poor
    tolerated = g.j_response_max * g.j_average_acceptable / g.j_average_good
    far = any(not v <= tolerated for v in over.values())
    checks.append(
        Check(
            guideline="cost of each response J",
            value=f"worst {max(cost.responses.values(), default=math.nan):.1f}",
            limit=f"≤ {g.j_response_max:g} (a few up to {tolerated:g})",
            grade="poor" if far else "acceptable" if over else "good",
            problem=f"{len(over)} response {'costs exceed' if len(over) > 1 else 'cost exceeds'} {g.j_response_max:g} ({listed})"
            if over
            else "",
        )
    )
    return checks


def _parameter_check(parameters: Sequence[_Estimate], g: Guidelines) -> Check:
    estimated = [p for p in parameters if p.status == "estimated"]
    failing = [
        p.name for p in estimated if g.misses_cr(p.cr_percent) or g.misses_insensitivity(p.insensitivity_percent)
    ]
    limits = f"CR ≤ {g.max_cr_percent:g} %, I ≤ {g.max_insensitivity_percent:g} %"
    return Check(
        guideline="parameter accuracy",
        value=f"{len(estimated) - len(failing)} of {len(estimated)} within",
        limit=limits,
        grade="acceptable" if failing else "good",
        problem=f"{len(failing)} of {len(estimated)} estimated parameters miss CR ≤ {g.max_cr_percent:g} % or "
        f"I ≤ {g.max_insensitivity_percent:g} % ({', '.join(failing)})"
        if failing
        else "",
    )


def _coverage_checks(model: _Judged) -> list[Check]:
    """Whether every axis was identified, and enough of the structure's free parameters estimated."""
    checks = []
    axes = list(model.axis_status)
    missing = [a for a in axes if a.status != "identified"]
    if axes:
        checks.append(
            Check(
                guideline="every axis identified",
                value=f"{len(axes) - len(missing)} of {len(axes)}",
                limit="all (half at least for an acceptable model)",
                grade="poor" if 2 * len(missing) > len(axes) else "acceptable" if missing else "good",
                problem="; ".join(f"{a.axis} unidentified ({a.reason})" for a in missing)
                + (
                    f": a model of {', '.join(a.axis for a in axes if a not in missing) or 'no axis'} only"
                    if missing
                    else ""
                ),
            )
        )
    free = [p for p in model.parameters if p.status in ("estimated", "dropped", "unidentified")]
    estimated = [p for p in free if p.status == "estimated"]
    few = bool(free) and len(estimated) < MIN_ESTIMATED_FRACTION * len(free)
    checks.append(
        Check(
            guideline="free parameters estimated",
            value=f"{len(estimated)} of {len(free)}",
            limit=f"at least {MIN_ESTIMATED_FRACTION:.0%}",
            grade="acceptable" if few else "good",
            problem=f"only {len(estimated)} of the structure's {len(free)} free parameters were estimated "
            f"({sum(p.status == 'dropped' for p in free)} dropped, {sum(p.status == 'unidentified' for p in free)} "
            "unidentified)"
            if few
            else "",
        )
    )
    return checks


def _maneuver_check(maneuvers: Sequence[str]) -> Check | None:
    """Whether the responses come from designed maneuvers: a pilot's broadband input found by detection in a
    flight is a look at the data, never a model on its own; given by the user, it is at best acceptable."""
    if not maneuvers:
        return None  # a model file written before the maneuvers were recorded
    found = [m.split() for m in maneuvers]
    broadband = [axis for kind, axis, _source in found if kind == "broadband"]
    detected = [axis for kind, axis, source in found if kind == "broadband" and source == "detected"]
    grade: Grade = "poor" if detected else "acceptable" if broadband else "good"
    return Check(
        guideline="maneuvers designed for identification",
        value=", ".join(maneuvers),
        limit="sweeps, multisines, doublets or 3211s",
        grade=grade,
        problem=f"the responses of {', '.join(detected)} come from a pilot's broadband input found in the flight "
        "(no frequency trend, no designed maneuver): a look at the data, not a model on its own"
        if detected
        else f"the responses of {', '.join(broadband)} come from a pilot's broadband input (no frequency trend), "
        "not a designed maneuver"
        if broadband
        else "",
    )


def _verification_check(summary: Sequence[_Scored], g: Guidelines) -> Check | None:
    if not summary:
        return None
    worst = max(summary, key=lambda s: s.tic if math.isfinite(s.tic) else math.inf)
    grade = g.tic_grade(worst.tic)
    shown = f"{worst.tic:.2f}" if round(worst.tic, 2) not in (g.tic_good, g.tic_acceptable) else f"{worst.tic:.3f}"
    return Check(
        guideline="prediction of doublets, worst on-axis output TIC",
        value=f"{shown} ({worst.name})",
        limit=f"≤ {g.tic_good:g}-{g.tic_acceptable:g}",
        grade=grade,
        problem=""
        if grade == "good"
        else f"the worst doublet prediction has TIC {shown} ({worst.name}), above {g.tic_good:g}"
        + ("" if grade == "acceptable" else f"-{g.tic_acceptable:g}"),
    )


def model_verdict(
    model: _Judged, verification: _Verified | None = None, *, guidelines: Guidelines | None = None
) -> Verdict:
    """Judge a model by Tischler's guidelines (DESIGN.md, "Numerics").

    J_ave ≤ `j_average_good` is good and ≤ `j_average_acceptable`
    acceptable; any single response cost above `j_response_max`, or an
    estimated parameter with CR% or I% beyond its limit, makes the model at
    best acceptable; when verified, the worst on-axis output's Theil
    inequality coefficient must be ≤ `tic_good` (good) or ≤ `tic_acceptable`
    (acceptable); the off-axis outputs are shown for information only. A
    limit met exactly is met. A model is never good when an axis of its
    structure is unidentified (the sentence names the missing axes first) or
    when fewer than half the structure's free parameters were estimated; never
    better than poor when its responses come from a pilot's broadband input
    found in the flight (no designed maneuver), never better than acceptable
    when that input was given.

    Parameters
    ----------
    model : IdentifiedModel
        The model (anything with its ``cost``, ``parameters``, ``guidelines`` and ``axis_status``).
    verification : Verification, optional
        Its verification on doublets not used in the fit (anything with a
        ``summary`` of outputs with a ``name`` and a ``tic``).
    guidelines : Guidelines, optional
        The limits; default ``model.guidelines``, those the model was fitted with.

    Returns
    -------
    Verdict

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> x_u = SimpleNamespace(name="X_u", status="estimated", cr_percent=25.0, insensitivity_percent=2.0)
    >>> model = SimpleNamespace(cost=CostSummary(average=50.0, responses={"q/delta_lon": 60.0}), parameters=(x_u,),
    ...                         guidelines=DEFAULT_GUIDELINES, axis_status=(),
    ...                         provenance=SimpleNamespace(maneuvers=("sweep lon detected",)))
    >>> model_verdict(model).grade, model_verdict(model, guidelines=Guidelines(max_cr_percent=30.0)).grade
    ('acceptable', 'good')
    """
    g = model.guidelines if guidelines is None else guidelines
    maneuvers = _maneuver_check(model.provenance.maneuvers)
    coverage = _coverage_checks(model) + ([maneuvers] if maneuvers is not None else [])
    checks = _cost_checks(model.cost, g) + [_parameter_check(model.parameters, g)] + coverage
    verified = _verification_check(verification.summary, g) if verification is not None else None
    if verified is not None:
        checks.append(verified)
    grade = _worst([c.grade for c in checks])
    n = sum(p.status == "estimated" for p in model.parameters)
    fit_ok = all(c.grade == "good" for c in checks if c is not verified)
    fit_text = (
        f"J_ave = {model.cost.average:.1f} ≤ {g.j_average_good:g}, every response cost ≤ {g.j_response_max:g}, "
        f"all {n} estimated parameters within CR ≤ {g.max_cr_percent:g} % and I ≤ {g.max_insensitivity_percent:g} %"
    )
    if grade == "good":
        sentence = f"Good model by Tischler's guidelines: {fit_text}" + (
            f", and doublets predicted with TIC ≤ {g.tic_good:g} (worst {verified.value})."
            if verified is not None
            else "; not yet verified on doublets."
        )
    else:
        problems = [c.problem for c in coverage if c.problem] + [
            c.problem for c in checks if c.problem and c not in coverage
        ]
        sentence = f"{grade.capitalize()} model: " + "; ".join(problems)
        if fit_ok:
            sentence += f", although the fit meets the guidelines ({fit_text})"
        sentence += "." if verified is not None else "; not yet verified on doublets."
    if verification is not None and verification.unverified:
        sentence += " Not verified: " + "; ".join(verification.unverified) + "."
    return Verdict(grade=grade, sentence=sentence, checks=tuple(checks), guidelines=g)
