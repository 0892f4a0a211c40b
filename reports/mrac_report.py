"""HTML report of the altitude-loop comparison: PID, MRAC (linear), MRAC (RBF) near the ground (chapter 2)."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

import numpy as np
from matplotlib.figure import Figure

from simulator.mrac import (
    CONTROLLERS,
    ControllerResult,
    MetricStatistics,
    MracComparison,
    Statistic,
    StepCase,
    flown_rise_time,
)

from .html import render_html, write_html
from .svg import figure_svg, new_figure

__all__ = ["height_figure", "theta_figure", "rise_time_figure", "render_mrac_report", "write_mrac_report"]

_COLOURS = {"pid": "#7f7f7f", "mrac_linear": "#1f4e79", "mrac_rbf": "#c0392b"}
_LABELS = {"pid": "PID", "mrac_linear": "MRAC, linear", "mrac_rbf": "MRAC, RBF"}
_REFERENCE = "#2e8b57"
_PHASES: tuple[Literal["takeoff", "landing"], ...] = ("takeoff", "landing")
_PHASE_LABELS = {"takeoff": "take-off", "landing": "landing"}
_INDICES = (
    ("rise_time_s", "rise time (s)", 1.0),
    ("steady_state_error_m", "SSE (mm)", 1e3),
    ("mse_m2", "MSE to reference (mm²)", 1e6),
    ("overshoot_percent", "overshoot (%)", 1.0),
    ("settling_time_s", "settling time (s)", 1.0),
)


def _every(n_samples: int, most: int = 600) -> slice:
    """A stride that keeps at most about `most` points of a trace (figures stay small)."""
    return slice(None, None, max(1, n_samples // most))


def _phase_axis(result: ControllerResult, phase: str) -> tuple[np.ndarray, slice, slice]:
    """Time from the step command (s), the rows of `phase` (two equal phases, take-off first), the plot stride."""
    n = result.run.time_s.size // 2
    every = _every(n)
    return result.run.time_s[:n][every], slice(0, n) if phase == "takeoff" else slice(n, 2 * n), every


def _title(case: StepCase) -> str:
    if case.in_ground_effect:
        return f"Z/R ≈ {case.height_ratio:g}: ground ↔ {100 * case.high_m:.2f} cm"
    return f"Z/R ≈ {case.height_ratio:g}: {100 * case.low_m:.1f} ↔ {100 * case.high_m:.1f} cm (out of ground effect)"


def height_figure(comparison: MracComparison, height_ratio: float) -> Figure:
    """Height against time for each controller (mean ± std over trials), the reference model and the command.

    Parameters
    ----------
    comparison : MracComparison
        The result.
    height_ratio : float
        Which case.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels: take-off and landing, time from the step command.
    """
    figure, raw = new_figure(1, 2, width_in=7.5, height_in=3.0)
    axes: Any = raw
    results = [comparison.result(height_ratio, name) for name in comparison.config.controllers]
    longest = max(results, key=lambda r: r.phase_s)
    for phase, ax in zip(_PHASES, axes):
        for result in results:
            t, rows, every = _phase_axis(result, phase)
            height = 100 * result.run.height_m[rows][every]
            mean, std = height.mean(axis=1), height.std(axis=1)
            colour = _COLOURS[result.controller]
            ax.fill_between(t, mean - std, mean + std, color=colour, alpha=0.2, linewidth=0)
            ax.plot(t, mean, color=colour, linewidth=1.3, label=_LABELS[result.controller])
        t, rows, every = _phase_axis(longest, phase)
        ax.plot(
            t,
            100 * longest.reference_m[rows][every],
            color=_REFERENCE,
            linestyle="--",
            linewidth=1.1,
            label="reference (2.20)",
        )
        ax.plot(
            t,
            100 * longest.run.command_m[rows, 0][every],
            color="#222222",
            linestyle=":",
            linewidth=1.0,
            label="command",
        )
        ax.set_title(_PHASE_LABELS[phase])
        ax.set_xlabel("time from the step (s)")
        ax.set_ylabel("height above ground (cm)")
    axes[0].legend(loc="lower right", fontsize=7.5)
    return figure


def theta_figure(comparison: MracComparison, height_ratio: float) -> Figure | None:
    """Adaptive parameters Theta_hat(t) of each MRAC (mean over trials), through take-off and landing.

    Parameters
    ----------
    comparison : MracComparison
        The result.
    height_ratio : float
        Which case.

    Returns
    -------
    matplotlib.figure.Figure or None
        One panel per MRAC; None if no MRAC was flown.
    """
    names = [n for n in comparison.config.controllers if n != "pid"]
    if not names:
        return None
    figure, raw = new_figure(1, len(names), width_in=7.5, height_in=2.8)
    axes: Any = raw
    for name, ax in zip(names, np.atleast_1d(axes)):
        result = comparison.result(height_ratio, name)
        assert result.adaptive is not None
        every = _every(result.run.time_s.size)
        theta = 1e3 * result.adaptive.theta[every].mean(axis=1)
        for k, label in enumerate(result.adaptive.labels):
            ax.plot(result.run.time_s[every], theta[:, k], linewidth=1.1, label=f"θ[{label}]")
        ax.axvline(result.phase_s, color="#222222", linestyle=":", linewidth=0.9)
        ax.set_title(_LABELS[name])
        ax.set_xlabel("time (s); dotted: landing command")
        ax.set_ylabel("Θ̂ (mN per unit basis)")
        ax.legend(fontsize=7, ncol=2)
    return figure


def rise_time_figure(comparison: MracComparison) -> Figure:
    """Rise time of each controller per case and phase (mean ± std over trials).

    Parameters
    ----------
    comparison : MracComparison
        The result.

    Returns
    -------
    matplotlib.figure.Figure
    """
    figure, raw = new_figure(width_in=7.0, height_in=2.8)
    ax: Any = raw
    groups = [(case, phase) for case in comparison.cases for phase in _PHASES]
    names = comparison.config.controllers
    width = 0.8 / len(names)
    for k, name in enumerate(names):
        stats = [comparison.statistics(name, height_ratio=c.height_ratio, phase=p).rise_time_s for c, p in groups]
        x = np.arange(len(groups)) + (k - (len(names) - 1) / 2) * width
        ax.bar(
            x,
            [s.mean for s in stats],
            width,
            yerr=[s.std for s in stats],
            color=_COLOURS[name],
            label=_LABELS[name],
            capsize=2,
        )
    ax.set_xticks(np.arange(len(groups)))
    ax.set_xticklabels([f"{c.height_ratio:g} {'up' if p == 'takeoff' else 'down'}" for c, p in groups], fontsize=8)
    ax.set_xlabel("Z/R and phase")
    ax.set_ylabel("rise time 10–90 % (s)")
    ax.legend(fontsize=8)
    return figure


def _cell(statistic: Statistic, scale: float) -> dict[str, Any]:
    return {"mean": statistic.mean * scale, "std": statistic.std * scale, "n": statistic.n, "total": statistic.total}


def _table(stats: dict[str, MetricStatistics]) -> list[dict[str, Any]]:
    return [
        {"label": _LABELS[name], "cells": [_cell(getattr(s, field), scale) for field, _, scale in _INDICES]}
        for name, s in stats.items()
    ]


def _checks(comparison: MracComparison) -> list[dict[str, Any]]:
    names = comparison.config.controllers
    rows = []
    for case in comparison.cases:
        for phase in _PHASES:
            stats = {n: comparison.statistics(n, height_ratio=case.height_ratio, phase=phase) for n in names}
            row: dict[str, Any] = {
                "case": f"{case.height_ratio:g}",
                "in_ground_effect": case.in_ground_effect,
                "phase": _PHASE_LABELS[phase],
            }
            pid = stats["pid"].rise_time_s.mean if "pid" in stats else float("nan")
            flown = flown_rise_time(case.height_ratio, phase)
            for n in ("mrac_linear", "mrac_rbf"):
                row[n] = stats[n].rise_time_s.mean / pid if n in stats else float("nan")
                cut = None if flown is None else flown.cut(n)
                row[f"flown_{n}"] = float("nan") if cut is None else cut
            both = "mrac_linear" in stats and "mrac_rbf" in stats
            row["mse"] = stats["mrac_rbf"].mse_m2.mean / stats["mrac_linear"].mse_m2.mean if both else float("nan")
            rows.append(row)
    return rows


def render_mrac_report(
    comparison: MracComparison, *, title: str = "Altitude loop near the ground: PID and MRAC"
) -> str:
    """The comparison as one self-contained HTML page.

    Parameters
    ----------
    comparison : MracComparison
        The result of :func:`simulator.mrac.compare_controllers`.
    title : str, optional
        Page title.

    Returns
    -------
    str
        HTML.
    """
    names = comparison.config.controllers
    cases = []
    for case, analysis in zip(comparison.cases, comparison.analyses):
        theta = theta_figure(comparison, case.height_ratio)
        cases.append(
            {
                "title": _title(case),
                "case": case,
                "analysis": analysis,
                "height_svg": figure_svg(height_figure(comparison, case.height_ratio)),
                "theta_svg": figure_svg(theta) if theta is not None else None,
                "phases": [
                    {
                        "name": _PHASE_LABELS[p],
                        "rows": _table(
                            {n: comparison.statistics(n, height_ratio=case.height_ratio, phase=p) for n in names}
                        ),
                    }
                    for p in _PHASES
                ],
            }
        )
    vehicle = comparison.vehicle
    return render_html(
        "mrac.html",
        title=title,
        comparison=comparison,
        config=comparison.config,
        vehicle=vehicle,
        indices=[label for _, label, _ in _INDICES],
        overall=_table({n: comparison.statistics(n) for n in names}),
        cases=cases,
        checks=_checks(comparison),
        rise_svg=figure_svg(rise_time_figure(comparison)),
        has_mrac=any(n != "pid" for n in names),
        labels=_LABELS,
        all_controllers=CONTROLLERS,
    )


def write_mrac_report(path: str | Path, comparison: MracComparison, **options: Any) -> Path:
    """Render and write the report atomically.

    Parameters
    ----------
    path : str or Path
        Destination HTML file.
    comparison : MracComparison
        The result.
    **options
        Passed to :func:`render_mrac_report`.

    Returns
    -------
    Path
    """
    return write_html(path, render_mrac_report(comparison, **options))
