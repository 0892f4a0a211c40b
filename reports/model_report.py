"""The model report: one self-contained HTML page on an identified model and, when given, its verification.

Sections: a summary card with a verdict against Tischler's guidelines
(DESIGN.md), Bode and coherence of every response with the model overlaid,
parameters with CR% and I%, costs, correlations, modes and poles, the
verification on doublets (with and without the wind term), the structure
reduction log and provenance. Everything that comes from a log or a file
(vehicle names, labels, parameter names, notes, options) is escaped by the
template; figures are our own SVG.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from sysid.fit import IdentifiedModel
from sysid.freqresp import FrequencyResponse
from sysid.model.modes import Mode, modes
from sysid.verify import Verification

from .html import render_html, write_html
from .model_figures import correlation_figure, pole_map_figure, response_figures
from .svg import figure_svg
from .verify_section import TIC_ACCEPTABLE, TIC_GOOD, sized_svg, verification_context

__all__ = [
    "J_AVE_GOOD",
    "J_AVE_ACCEPTABLE",
    "J_RESPONSE_MAX",
    "CR_MAX_PERCENT",
    "INSENSITIVITY_MAX_PERCENT",
    "CORRELATION_FLAG",
    "TIC_GOOD",
    "TIC_ACCEPTABLE",
    "Check",
    "Verdict",
    "model_verdict",
    "model_report_html",
    "write_model_report",
]

#: J_ave of a good fit (eq. 3.9; Tischler & Remple).
J_AVE_GOOD = 100.0
#: J_ave of an acceptable fit.
J_AVE_ACCEPTABLE = 150.0
#: Guideline on the cost of any single response.
J_RESPONSE_MAX = 200.0
#: Cramér–Rao bound guideline, % of the value.
CR_MAX_PERCENT = 20.0
#: Insensitivity guideline, % of the value.
INSENSITIVITY_MAX_PERCENT = 10.0
#: |r| above which two parameters are reported as correlated.
CORRELATION_FLAG = 0.9

Grade = Literal["good", "acceptable", "poor"]
_ORDER: dict[str, int] = {"good": 0, "acceptable": 1, "poor": 2}


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
    """The report's verdict: the worst grade of its checks, said in one sentence.

    Parameters
    ----------
    grade : {"good", "acceptable", "poor"}
        Worst grade of `checks`.
    sentence : str
        One sentence for the summary card.
    checks : tuple of Check
        Cost, response costs, parameter accuracy and (when verified) prediction.
    """

    grade: Grade
    sentence: str
    checks: tuple[Check, ...]


def _worst(grades: Sequence[Grade]) -> Grade:
    return max(grades, key=lambda g: _ORDER[g], default="good")


def _misses(p: Any) -> bool:
    cr, ins = p.cr_percent, p.insensitivity_percent
    return p.status == "estimated" and (
        (math.isfinite(cr) and cr > CR_MAX_PERCENT) or (math.isfinite(ins) and ins > INSENSITIVITY_MAX_PERCENT)
    )


def _cost_checks(model: IdentifiedModel) -> list[Check]:
    j = model.cost.average
    grade: Grade = "good" if j <= J_AVE_GOOD else "acceptable" if j <= J_AVE_ACCEPTABLE else "poor"
    problem = (
        ""
        if grade == "good"
        else (
            f"J_ave = {j:.1f} is above {J_AVE_GOOD:g}"
            + (f" (acceptable up to {J_AVE_ACCEPTABLE:g})" if grade == "acceptable" else f" and {J_AVE_ACCEPTABLE:g}")
        )
    )
    checks = [
        Check(
            guideline="average cost J_ave",
            value=f"{j:.1f}",
            limit=f"≤ {J_AVE_GOOD:g} good, ≤ {J_AVE_ACCEPTABLE:g} acceptable",
            grade=grade,
            problem=problem,
        )
    ]
    over = {k: v for k, v in model.cost.responses.items() if not v <= J_RESPONSE_MAX}
    worst = max(model.cost.responses.values(), default=math.nan)
    problem = (
        ""
        if not over
        else (
            f"{len(over)} response cost{'s' if len(over) > 1 else ''} exceed "
            f"{J_RESPONSE_MAX:g} ({', '.join(f'{k} {v:.0f}' for k, v in over.items())})"
        )
    )
    checks.append(
        Check(
            guideline="cost of each response J",
            value=f"worst {worst:.1f}",
            limit=f"≤ {J_RESPONSE_MAX:g}",
            grade="acceptable" if over else "good",
            problem=problem,
        )
    )
    return checks


def _parameter_check(model: IdentifiedModel) -> Check:
    estimated = [p for p in model.parameters if p.status == "estimated"]
    failing = [p.name for p in estimated if _misses(p)]
    problem = (
        ""
        if not failing
        else (
            f"{len(failing)} of {len(estimated)} estimated parameters miss CR ≤ "
            f"{CR_MAX_PERCENT:g} % or I ≤ {INSENSITIVITY_MAX_PERCENT:g} % "
            f"({', '.join(failing)})"
        )
    )
    return Check(
        guideline="parameter accuracy",
        value=f"{len(estimated) - len(failing)} of {len(estimated)} within",
        limit=f"CR ≤ {CR_MAX_PERCENT:g} %, I ≤ {INSENSITIVITY_MAX_PERCENT:g} %",
        grade="acceptable" if failing else "good",
        problem=problem,
    )


def _verification_check(verification: Verification) -> Check | None:
    if not verification.summary:
        return None
    worst = max(verification.summary, key=lambda s: s.tic if math.isfinite(s.tic) else math.inf)
    tic = worst.tic
    grade: Grade = "good" if tic <= TIC_GOOD else "acceptable" if tic <= TIC_ACCEPTABLE else "poor"
    shown = f"{tic:.2f}" if round(tic, 2) not in (TIC_GOOD, TIC_ACCEPTABLE) else f"{tic:.3f}"
    problem = (
        ""
        if grade == "good"
        else (
            f"the worst doublet prediction has TIC {shown} ({worst.name}), above "
            f"{TIC_GOOD:g}" + ("" if grade == "acceptable" else f"-{TIC_ACCEPTABLE:g}")
        )
    )
    return Check(
        guideline="prediction of doublets, worst on-axis output TIC",
        value=f"{shown} ({worst.name})",
        limit=f"≤ {TIC_GOOD:g}-{TIC_ACCEPTABLE:g}",
        grade=grade,
        problem=problem,
    )


def model_verdict(model: IdentifiedModel, verification: Verification | None = None) -> Verdict:
    """Judge a model by the guidelines of DESIGN.md (Tischler & Remple).

    J_ave ≤ 100 is good and ≤ 150 acceptable; any single response cost
    above 200, or an estimated parameter with CR% > 20 or I% > 10, makes the
    model at best acceptable; when verified, the worst output's Theil
    inequality coefficient must be ≤ 0.25 (good) or ≤ 0.3 (acceptable); only
    the on-axis outputs of each doublet are judged (the off-axis ones are
    shown for information).

    Parameters
    ----------
    model : IdentifiedModel
        The model.
    verification : Verification, optional
        Its verification on doublets not used in the fit.

    Returns
    -------
    Verdict
    """
    checks = _cost_checks(model) + [_parameter_check(model)]
    verified = _verification_check(verification) if verification is not None else None
    if verified is not None:
        checks.append(verified)
    grade = _worst([c.grade for c in checks])
    n = sum(p.status == "estimated" for p in model.parameters)
    fit_ok = all(c.grade == "good" for c in checks if c is not verified)
    fit_text = (
        f"J_ave = {model.cost.average:.1f} ≤ {J_AVE_GOOD:g}, every response cost ≤ {J_RESPONSE_MAX:g}, "
        f"all {n} estimated parameters within CR ≤ {CR_MAX_PERCENT:g} % and I ≤ "
        f"{INSENSITIVITY_MAX_PERCENT:g} %"
    )
    if grade == "good":
        sentence = f"Good model by Tischler's guidelines: {fit_text}" + (
            f", and doublets predicted with TIC ≤ {TIC_GOOD:g} (worst {verified.value})."
            if verified is not None
            else "; not yet verified on doublets."
        )
    else:
        sentence = f"{grade.capitalize()} model: " + "; ".join(c.problem for c in checks if c.problem)
        if fit_ok:
            sentence += f", although the fit meets the guidelines ({fit_text})"
        sentence += "." if verified is not None else "; not yet verified on doublets."
    return Verdict(grade=grade, sentence=sentence, checks=tuple(checks))


def _wind_text(model: IdentifiedModel) -> str:
    north, east = model.trim.get("wind_n"), model.trim.get("wind_e")
    if north is None or east is None or not (math.isfinite(north) and math.isfinite(east)):
        text = "no anemometer data"
    else:
        origin = math.degrees(math.atan2(-east, -north)) % 360.0
        text = f"mean {math.hypot(north, east):.1f} m/s from {origin:03.0f}° (anemometer, at the vehicle)"
    if model.wind is not None:
        units = {r.output: r.output_unit for r in model.responses}
        change = ", ".join(
            f"{o} {b:.3g} → {a:.3g} {units.get(o, '')}".rstrip()
            for o, b, a in zip(model.wind.outputs, model.wind.rms_before, model.wind.rms_after)
        )
        text += f"; wind terms G_w fitted on the residual of eq. 3.14 (RMS {change})"
    elif any(p.stage == "wind" for p in model.parameters):
        text += "; the structure's wind terms were not fitted"
    return text


def _card(
    model: IdentifiedModel, verification: Verification | None, logs_summary: Mapping[str, str] | None
) -> list[tuple[str, str]]:
    structure = model.structure
    counts = {s: sum(p.status == s for p in model.parameters) for s in ("estimated", "fixed", "dropped")}
    facts: dict[str, str] = {
        "structure": (
            f"{model.structure_name}: {structure.description} ({len(structure.states)} states, "
            f"{len(structure.outputs)} outputs)"
        ),
        "data": ", ".join(Path(f).name for f in model.provenance.files) or "not recorded",
    }
    facts.update({str(k): str(v) for k, v in (logs_summary or {}).items()})
    facts.setdefault("wind", _wind_text(model))
    if model.responses:
        low = (
            min(r.fit_range[0] for r in model.responses if r.fit_range)
            if any(r.fit_range for r in model.responses)
            else math.nan
        )
        high = max((r.fit_range[1] for r in model.responses if r.fit_range), default=math.nan)
        facts.setdefault(
            "fit", f"{len(model.responses)} responses over {low:.2g}-{high:.3g} rad/s, J_ave = {model.cost.average:.1f}"
        )
    facts.setdefault(
        "parameters",
        f"{counts['estimated']} estimated, {counts['fixed']} fixed, {counts['dropped']} dropped by structure reduction",
    )
    if verification is not None:
        sources = ", ".join(dict.fromkeys(r.source.name for r in verification.records))
        facts.setdefault(
            "verification",
            f"{len(verification.records)} doublet records from {sources}, each judged "
            f"on the outputs of its axis: overall TIC {verification.tic:.2f}, "
            f"J_rms {verification.rmse:.3g}",
        )
    facts.setdefault("identified", model.provenance.created_utc or "unknown")
    return list(facts.items())


def _shown(figure: Any, caption: str) -> tuple[str, str, float]:
    """SVG, caption and width (% of the 7.5 in column), so every figure's text prints at one size."""
    return sized_svg(figure_svg(figure), caption)


@dataclass(frozen=True, slots=True, kw_only=True)
class _ParameterRow:
    name: str
    value: float
    unit: str
    cr: float
    ins: float
    status: str
    stage: str
    cr_flag: bool
    ins_flag: bool


@dataclass(frozen=True, slots=True, kw_only=True)
class _CostRow:
    pair: str
    cost: float
    flag: bool
    low: float
    high: float
    decades: float
    coherence: float
    conditioned: str


def _parameter_rows(model: IdentifiedModel) -> list[_ParameterRow]:
    rows = []
    for p in model.parameters:
        estimated = p.status == "estimated"
        rows.append(
            _ParameterRow(
                name=p.name,
                value=p.value,
                unit=p.unit,
                cr=p.cr_percent,
                ins=p.insensitivity_percent,
                status=p.status,
                stage=p.stage,
                cr_flag=estimated and p.cr_percent > CR_MAX_PERCENT,
                ins_flag=estimated and p.insensitivity_percent > INSENSITIVITY_MAX_PERCENT,
            )
        )
    return rows


def _cost_rows(model: IdentifiedModel) -> list[_CostRow]:
    responses: dict[str, FrequencyResponse] = {}
    for fitted in model.responses:
        responses.setdefault(fitted.pair, fitted)
    rows = []
    for pair, cost in model.cost.responses.items():
        r = responses.get(pair.partition("#")[0])
        low = high = decades = coherence = math.nan
        conditioned = ""
        if r is not None and r.fit_range is not None:
            low, high = r.fit_range
            decades = math.log10(high / low)
            inside = (r.omega >= low) & (r.omega <= high)
            coherence = float(np.mean(r.coherence[inside])) if inside.any() else math.nan
            conditioned = ", ".join(r.conditioned_on)
        rows.append(
            _CostRow(
                pair=pair,
                cost=cost,
                flag=not cost <= J_RESPONSE_MAX,
                low=low,
                high=high,
                decades=decades,
                coherence=coherence,
                conditioned=conditioned,
            )
        )
    return rows


def _mode_rows(found: Sequence[Mode]) -> list[dict[str, Any]]:
    return [
        {
            "mode": m.mode,
            "real": m.real,
            "imag": m.imag,
            "damping": m.damping,
            "omega_n": m.natural_frequency_rad_s,
            "stability": m.stability,
            "time": m.time_to_double_s if m.stability == "unstable" else m.time_to_half_s,
            "time_kind": "to double" if m.stability == "unstable" else "to half" if m.stability == "stable" else "",
        }
        for m in found
    ]


def _correlated(names: Sequence[str], matrix: Any) -> list[tuple[str, str, float]]:
    pairs = []
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            value = float(matrix[i, j])
            if math.isfinite(value) and abs(value) > CORRELATION_FLAG:
                pairs.append((names[i], names[j], value))
    return sorted(pairs, key=lambda item: -abs(item[2]))


def _flatten(options: Mapping[str, Any], prefix: str = "") -> list[tuple[str, str]]:
    rows: list[tuple[str, str]] = []
    for key, value in options.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping) and value:
            rows.extend(_flatten(value, name + "."))
        else:
            rows.append((name, value if isinstance(value, str) else json.dumps(value, default=str)))
    return rows


def model_report_html(
    model: IdentifiedModel,
    *,
    verification: Verification | None = None,
    title: str | None = None,
    logs_summary: Mapping[str, str] | None = None,
    verification_options: Mapping[str, Any] | None = None,
    generated_utc: str | None = None,
) -> str:
    """The model report as HTML text.

    Parameters
    ----------
    model : IdentifiedModel
        The identified model (from :func:`sysid.fit.identify_logs` or :func:`sysid.fit.read_model`).
    verification : Verification, optional
        Its verification on doublets not used in the fit; adds the
        verification section and enters the verdict.
    title : str, optional
        Page title; default ``"Identified model: <structure>"``.
    logs_summary : Mapping[str, str], optional
        Extra lines of the summary card, label to text (``{"vehicle": ...}``,
        e.g. from ``sysid ingest --json``); a label the report fills itself
        (``wind``, ``data``) is replaced.
    verification_options : Mapping[str, Any], optional
        Options the verification was run with, listed under provenance.
    generated_utc : str, optional
        Time stamp of the footer; default now (pass one for a reproducible file).

    Returns
    -------
    str
        One self-contained HTML document (inline CSS and SVG, no scripts, no fetches).
    """
    linear = model.linear_model(include_wind=False)
    found = modes(linear)
    min_coherence = model.provenance.options.get("min_coherence")
    estimated = [k for k, name in enumerate(model.correlation_names) if model.parameter(name).status == "estimated"]
    names = [model.correlation_names[k] for k in estimated]
    matrix = model.correlation[np.ix_(estimated, estimated)] if estimated else np.zeros((0, 0))
    stages = np.array([model.parameter(name).stage for name in names])
    matrix = np.where(stages[:, None] == stages[None, :], matrix, np.nan)  # the two steps are fitted apart
    context: dict[str, Any] = {
        "title": title or f"Identified model: {model.structure_name}",
        "model": model,
        "verdict": model_verdict(model, verification),
        "card": _card(model, verification, logs_summary),
        "bode": [
            _shown(f, caption)
            for f, caption in response_figures(
                model, min_coherence=float(min_coherence) if isinstance(min_coherence, (int, float)) else None
            )
        ],
        "parameters": _parameter_rows(model),
        "costs": _cost_rows(model),
        "correlation": _shown(correlation_figure(names, matrix), "") if len(names) >= 2 else None,
        "correlated": _correlated(names, matrix),
        "n_correlated": len(names),
        "modes": _mode_rows(found),
        "poles": _shown(pole_map_figure(found), "") if found else None,
        "limits": {
            "cr": CR_MAX_PERCENT,
            "ins": INSENSITIVITY_MAX_PERCENT,
            "j_good": J_AVE_GOOD,
            "j_ok": J_AVE_ACCEPTABLE,
            "j_one": J_RESPONSE_MAX,
            "r": CORRELATION_FLAG,
            "tic_good": TIC_GOOD,
            "tic_ok": TIC_ACCEPTABLE,
        },
        "options": _flatten(model.provenance.options),
        "verification_options": _flatten(verification_options or {}),
        "files": [(f, model.provenance.sha256.get(f, "")) for f in model.provenance.files],
        "model_versions": dict(model.provenance.versions),
        "constants": [(k, v) for k, v in model.constants.items()],
        "data_text": ", ".join(Path(f).name for f in model.provenance.files) or "flight data not recorded in the file",
    }
    context.update(verification_context(verification))
    if generated_utc is not None:
        context["generated_utc"] = generated_utc
    return render_html("model.html", **context)


def write_model_report(
    path: str | Path,
    model: IdentifiedModel,
    *,
    verification: Verification | None = None,
    title: str | None = None,
    logs_summary: Mapping[str, str] | None = None,
    verification_options: Mapping[str, Any] | None = None,
    generated_utc: str | None = None,
) -> Path:
    """Render the model report and write it atomically.

    Parameters
    ----------
    path : str or Path
        Destination HTML file; its folder must exist.
    model : IdentifiedModel
        The identified model.
    verification : Verification, optional
        Its verification on doublets.
    title : str, optional
        Page title.
    logs_summary : Mapping[str, str], optional
        Extra lines of the summary card (vehicle ...).
    verification_options : Mapping[str, Any], optional
        Options the verification was run with.
    generated_utc : str, optional
        Time stamp of the footer; default now.

    Returns
    -------
    Path
        The file written.
    """
    return write_html(
        path,
        model_report_html(
            model,
            verification=verification,
            title=title,
            logs_summary=logs_summary,
            verification_options=verification_options,
            generated_utc=generated_utc,
        ),
    )
