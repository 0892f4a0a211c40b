"""The model report: one self-contained HTML page on an identified model and, when given, its verification.

Sections: a summary card with the verdict of :func:`sysid.fit.model_verdict`
against Tischler's guidelines (DESIGN.md) as the model was fitted with them,
Bode and coherence of every response with the model overlaid, parameters
with CR% and I%, costs, correlations, modes and poles, the
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
from typing import Any

import numpy as np

from sysid.fit import Guidelines, IdentifiedModel, Verdict, model_verdict
from sysid.fit.result import PARAMETER_STATUSES
from sysid.freqresp import FrequencyResponse
from sysid.model.modes import Mode, modes
from sysid.verify import Verification

from .html import render_html, write_html
from .model_figures import correlation_figure, pole_map_figure, response_figures
from .svg import figure_svg
from .verify_section import sized_svg, verification_context
from .wind_figures import clock_offset_figure, wind_trace_figure

__all__ = ["CORRELATION_FLAG", "model_report_html", "write_model_report"]

#: |r| above which two parameters are reported as correlated.
CORRELATION_FLAG = 0.9


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
        clock = model.wind.clock_offset
        if clock is not None and clock.measured:
            text += (
                f"; anemometer clock offset {clock.clock_offset_s:+.2f} ± {clock.sigma_s:.2f} s, measured from that "
                f"residual ({clock.used_clock_offset_s:+.2f} s before)"
            )
        elif clock is not None:
            text += f"; anemometer clock offset not measured: {clock.reason}"
    elif any(p.stage == "wind" for p in model.parameters):
        text += "; the structure's wind terms were not fitted"
    return text


def _clock_offset(model: IdentifiedModel) -> tuple[str, str, float] | None:
    clock = model.wind.clock_offset if model.wind is not None else None
    return _shown(clock_offset_figure(clock), "") if clock is not None else None


def _wind_trace(model: IdentifiedModel) -> tuple[str, str, float] | None:
    trace = model.wind.trace if model.wind is not None else None
    return _shown(wind_trace_figure(trace), "") if trace is not None else None


def _card(
    model: IdentifiedModel, verification: Verification | None, logs_summary: Mapping[str, str] | None
) -> list[tuple[str, str]]:
    structure = model.structure
    counts = {s: sum(p.status == s for p in model.parameters) for s in PARAMETER_STATUSES}
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
        f"{counts['estimated']} estimated, {counts['fixed']} fixed, {counts['dropped']} dropped by structure reduction"
        + (f", {counts['unidentified']} unidentified (no value)" if counts["unidentified"] else ""),
    )
    missing = model.unidentified_axes
    if missing:
        facts.setdefault(
            "axes",
            f"identified: {', '.join(a.axis for a in model.axis_status if a.identified) or 'none'}; "
            + "; ".join(f"unidentified, so not simulated: {a.axis} ({a.reason})" for a in missing),
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
    unidentified: bool


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


def _parameter_rows(model: IdentifiedModel, guidelines: Guidelines) -> list[_ParameterRow]:
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
                cr_flag=estimated and guidelines.misses_cr(p.cr_percent),
                ins_flag=estimated and guidelines.misses_insensitivity(p.insensitivity_percent),
                unidentified=p.unidentified,
            )
        )
    return rows


def _cost_rows(model: IdentifiedModel, guidelines: Guidelines) -> list[_CostRow]:
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
                flag=guidelines.response_cost_exceeds(cost),
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
    verdict: Verdict | None = None,
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
    verdict : Verdict, optional
        The verdict to show, whose guidelines also flag the tables; default
        :func:`sysid.fit.model_verdict` of `model` and `verification`.

    Returns
    -------
    str
        One self-contained HTML document (inline CSS and SVG, no scripts, no fetches).
    """
    verdict = model_verdict(model, verification) if verdict is None else verdict
    linear = model.linear_model(include_wind=False)
    found = modes(linear)
    gating = model.gating
    estimated = [k for k, name in enumerate(model.correlation_names) if model.parameter(name).status == "estimated"]
    names = [model.correlation_names[k] for k in estimated]
    matrix = model.correlation[np.ix_(estimated, estimated)] if estimated else np.zeros((0, 0))
    stages = np.array([model.parameter(name).stage for name in names])
    matrix = np.where(stages[:, None] == stages[None, :], matrix, np.nan)  # the two steps are fitted apart
    context: dict[str, Any] = {
        "title": title or f"Identified model: {model.structure_name}",
        "model": model,
        "verdict": verdict,
        "card": _card(model, verification, logs_summary),
        "bode": [
            _shown(f, caption)
            for f, caption in response_figures(
                model, min_coherence=gating.min_coherence if gating is not None else None
            )
        ],
        "parameters": _parameter_rows(model, verdict.guidelines),
        "costs": _cost_rows(model, verdict.guidelines),
        "correlation": _shown(correlation_figure(names, matrix), "") if len(names) >= 2 else None,
        "correlated": _correlated(names, matrix),
        "n_correlated": len(names),
        "modes": _mode_rows(found),
        "poles": _shown(pole_map_figure(found), "") if found else None,
        "clock_offset": _clock_offset(model),
        "wind_trace": _wind_trace(model),
        "guidelines": verdict.guidelines,
        "correlation_flag": CORRELATION_FLAG,
        "options": _flatten(model.provenance.options),
        "verification_options": _flatten(verification_options or {}),
        "files": [(f, model.provenance.sha256.get(f, "")) for f in model.provenance.files],
        "model_versions": dict(model.provenance.versions),
        "constants": [(k, v) for k, v in model.constants.items()],
        "data_text": ", ".join(Path(f).name for f in model.provenance.files) or "flight data not recorded in the file",
    }
    context.update(verification_context(verification, verdict.guidelines))
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
    verdict: Verdict | None = None,
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
    verdict : Verdict, optional
        The verdict to show; default :func:`sysid.fit.model_verdict` of `model` and `verification`.

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
            verdict=verdict,
        ),
    )
