"""HTML report of a discrepancy search: the summary first, then each finding's evidence and held-out proof."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sysid.discrepancy import FAR_FROM_FLOOR, DiscrepancyResult, Finding, ResponseComparison

from .bode import bode_figure
from .html import render_html, write_html
from .svg import figure_svg, new_figure

__all__ = ["finding_figure", "responses_figure", "render_discrepancy_report", "write_discrepancy_report"]

_BEFORE, _AFTER = "#c0392b", "#1f4e79"
_LABELS = {
    "height_agl": "height above ground, m",
    "ground_speed": "ground speed, m/s",
    "wind_speed": "wind speed at the vehicle, m/s",
    "delta_thr": "thrust input",
    "battery_v": "battery voltage, V",
    "time": "time in flight, s",
}


def finding_figure(finding: Finding) -> str:
    """SVG: each output's held-out residual against the regime variable and against time, before and after.

    Parameters
    ----------
    finding : Finding
        A finding with its traces.

    Returns
    -------
    str
        Inline SVG ("" without traces).
    """
    traces = finding.traces
    if traces is None:
        return ""
    outputs = list(finding.outputs)[:4]
    figure, axes = new_figure(len(outputs), 2, width_in=7.5, height_in=2.2 * len(outputs) + 0.4)
    grid = np.asarray(axes).reshape(len(outputs), 2)
    for row, output in zip(grid, outputs):
        for ax, x, label in (
            (row[0], traces.regime, _LABELS.get(finding.regime.variable, finding.regime.variable)),
            (row[1], traces.time_s, "time in flight, s"),
        ):
            ax.plot(x, traces.before[output], ".", ms=1.2, color=_BEFORE, alpha=0.5, label="simulation model")
            ax.plot(x, traces.after[output], ".", ms=1.2, color=_AFTER, alpha=0.5, label=f"with {finding.effect}")
            ax.set_xlabel(label)
            ax.set_ylabel(f"{output} residual")
        row[0].axvspan(finding.regime.low, finding.regime.high, color="0.85", lw=0)
    grid[0, 1].legend(loc="best", fontsize=7, markerscale=6)
    return figure_svg(figure)


def responses_figure(comparisons: Sequence[ResponseComparison]) -> str:
    """SVG: each compared pair's real response (solid) with the simulation's (dashed) on magnitude and phase.

    Parameters
    ----------
    comparisons : sequence of ResponseComparison
        From :func:`sysid.discrepancy.compare_responses`.

    Returns
    -------
    str
        Inline SVG ("" with nothing to compare).
    """
    if not comparisons:
        return ""
    figure = bode_figure(
        [c.real for c in comparisons],
        models={c.pair: c.sim_on_real_omega for c in comparisons},
        min_coherence=0.6,
        labels=("real flight", comparisons[0].sim_label),
    )
    return figure_svg(figure)


def render_discrepancy_report(
    result: DiscrepancyResult,
    comparisons: Sequence[ResponseComparison] = (),
    *,
    title: str = "Simulation against flight",
    model: str | None = None,
) -> str:
    """The report as one HTML document.

    Parameters
    ----------
    result : DiscrepancyResult
        The search's answer.
    comparisons : sequence of ResponseComparison, optional
        Real against simulated frequency responses of the sweeps both flew.
    title : str, optional
        Page title.
    model : str, optional
        The model file in the simulation's place, if it was one.
    """
    findings: list[dict[str, Any]] = [{"finding": f, "svg": finding_figure(f)} for f in result.findings]
    screened = [{"effect": t.effect, "score": t.score, "threshold": t.threshold} for t in result.screened]
    return render_html(
        "discrepancy.html",
        title=title,
        result=result,
        findings=findings,
        screened=screened,
        far=FAR_FROM_FLOOR,
        bode=responses_figure(comparisons),
        model=model,
    )


def write_discrepancy_report(
    path: str | Path,
    result: DiscrepancyResult,
    comparisons: Sequence[ResponseComparison] = (),
    *,
    model: str | None = None,
) -> Path:
    """Render and write the report atomically; returns the path.

    Parameters
    ----------
    path : str or Path
        Destination ``.html``.
    result : DiscrepancyResult
        The search's answer.
    comparisons : sequence of ResponseComparison, optional
        Real against simulated frequency responses.
    model : str, optional
        The model file in the simulation's place, if it was one.
    """
    return write_html(path, render_discrepancy_report(result, comparisons, model=model))
