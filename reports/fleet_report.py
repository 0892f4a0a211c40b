"""HTML report of a fleet batch: drift flagged, every vehicle's parameter trends with ±2 CR bands, the failures."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sysid.batch import BatchResult, Drift, GroupFit, parameter_series
from sysid.batch.drift import DriftOptions

from .html import render_html, write_html
from .svg import figure_svg, new_figure

__all__ = ["trend_figure", "render_fleet_report", "write_fleet_report"]

_FLAG, _BAND, _POINT, _POOR = "#c0392b", "#d6e4f0", "#1f4e79", "#b0b0b0"


def trend_figure(
    groups: Sequence[GroupFit],
    vehicle: str,
    parameters: Sequence[str],
    drifts: Mapping[str, Drift],
    max_cost_average: float = DriftOptions().max_cost_average,
) -> str:
    """SVG: each parameter of `vehicle` over its groups by date, ±2 Cramér–Rao bounds as bars.

    Parameters
    ----------
    groups : sequence of GroupFit
        The batch's groups (the vehicle's fitted ones are drawn).
    vehicle : str
        The vehicle.
    parameters : sequence of str
        Parameters to draw, a panel each.
    drifts : Mapping[str, Drift]
        The vehicle's drifts by parameter: the baseline is shaded (±2 of its bound) and the
        flagged group and those after it drawn in red.
    max_cost_average : float, optional
        Fits with a larger J_ave (not trended) are drawn grey.

    Returns
    -------
    str
        Inline SVG ("" when nothing to draw).
    """
    series = {name: parameter_series(groups, vehicle, name) for name in parameters}
    series = {name: s for name, s in series.items() if s}
    if not series:
        return ""
    cols = min(4, len(series))
    rows = -(-len(series) // cols)
    figure, axes = new_figure(rows, cols, width_in=7.5, height_in=1.9 * rows + 0.3)
    grid = np.array(axes, dtype=object).reshape(-1)
    dates = sorted({g.date or "" for s in series.values() for g, _, _ in s})
    for ax, (name, points) in zip(grid, series.items()):
        x = np.array([dates.index(g.date or "") for g, _, _ in points])
        values = np.array([v for _, v, _ in points])
        bars = 2.0 * np.array([b for _, _, b in points])
        drift = drifts.get(name)
        flagged = np.zeros(x.size, dtype=bool)
        if drift is not None:
            start = next(k for k, (g, _, _) in enumerate(points) if g.key == drift.after)
            flagged[start:] = True
            ax.axhspan(
                drift.baseline - 2 * drift.baseline_bound, drift.baseline + 2 * drift.baseline_bound, color=_BAND, lw=0
            )
            ax.axhline(drift.baseline, color=_POINT, lw=0.6)
        poor = np.array([g.cost_average > max_cost_average for g, _, _ in points])
        for mask, color in ((~flagged & ~poor, _POINT), (flagged & ~poor, _FLAG), (poor, _POOR)):
            ax.errorbar(x[mask], values[mask], yerr=bars[mask], fmt="o", ms=2.5, lw=0.8, color=color, capsize=1.5)
        ax.set_title(name, fontsize=8, color=_FLAG if drift is not None else "black")
        ax.tick_params(labelsize=6)
        ax.set_xticks(range(len(dates)), [d[5:] for d in dates], rotation=90, fontsize=5)
    for ax in grid[len(series) :]:
        ax.set_visible(False)
    figure.tight_layout(pad=0.4, h_pad=0.6)
    return figure_svg(figure)


def render_fleet_report(
    result: BatchResult,
    *,
    path: str | Path,
    title: str = "Fleet batch",
    run: Mapping[str, Any] | None = None,
    drift: DriftOptions = DriftOptions(),
) -> str:
    """The fleet report's HTML text.

    Parameters
    ----------
    result : BatchResult
        The batch.
    path : str or Path
        Where the report will be written (links to the groups' files are relative to it).
    title : str, optional
        Page title.
    run : Mapping[str, Any], optional
        How the batch ran (workers, seconds, scheduler ...), shown in the summary.
    drift : DriftOptions, optional
        The drift rule used (stated in the report).
    """
    here = Path(path).resolve().parent
    by_vehicle: dict[str, list[GroupFit]] = {}
    for g in result.groups:
        by_vehicle.setdefault(g.vehicle, []).append(g)
    vehicles = []
    for vehicle, groups in by_vehicle.items():
        names = list(dict.fromkeys(p.name for g in groups for p in g.parameters if p.status == "estimated"))
        drifts = {d.parameter: d for d in result.drifts if d.vehicle == vehicle}
        vehicles.append(
            {
                "name": vehicle,
                "groups": len(groups),
                "drifts": [d.sentence for d in drifts.values()],
                "figure": trend_figure(result.groups, vehicle, names, drifts, drift.max_cost_average),
            }
        )
    vehicles.sort(key=lambda v: (not v["drifts"], v["name"]))
    rows = [
        {
            "fit": g,
            "report": None if not g.report_file else os.path.relpath(g.report_file, here),
            "verified": g.tic is not None,
        }
        for g in result.groups
    ]
    return render_html(
        "fleet.html",
        title=title,
        result=result,
        failures=result.failures,
        flagged=[d for d in result.drifts if d.confirmed],
        watch=[d for d in result.drifts if not d.confirmed],
        vehicles=vehicles,
        groups=rows,
        run=dict(run or {}),
        rule=drift,
        read=sum(s.error is None for s in result.surveys),
    )


def write_fleet_report(path: str | Path, result: BatchResult, **kwargs: Any) -> Path:
    """Render the fleet report and write it atomically.

    Parameters
    ----------
    path : str or Path
        Destination HTML file; its folder must exist.
    result : BatchResult
        The batch.
    **kwargs
        ``title``, ``run`` and ``drift``, as for :func:`render_fleet_report`.

    Returns
    -------
    Path
    """
    return write_html(path, render_fleet_report(result, path=path, **kwargs))
