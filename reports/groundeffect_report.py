"""HTML report of a ground-effect fit (F/F0 against Z/R) or of a rotor-spacing study."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from sysid.groundeffect import GroundEffectFit, HoverSteps, ModelFit, SpacingStudy

from .html import render_html, write_html
from .svg import figure_svg, new_figure

__all__ = [
    "fit_figure",
    "residual_figure",
    "steps_figure",
    "spacing_figure",
    "render_groundeffect_report",
    "write_groundeffect_report",
    "render_spacing_report",
    "write_spacing_report",
]

_COLOURS = {
    "cheeseman_bennett": "#7f7f7f",
    "corrected": "#c0392b",
    "exponential": "#2e8b57",
    "piecewise_linear": "#1f4e79",
}
_LABELS = {
    "cheeseman_bennett": "Cheeseman–Bennett (2.1)",
    "corrected": "corrected ρ (2.2)",
    "exponential": "exponential (2.3)",
    "piecewise_linear": "piecewise linear (2.5)",
}
_DATA = "#222222"
_CRITERIA = {"aicc": "AICc", "bic": "BIC"}


def _figure(n_rows: int = 1, n_cols: int = 1, **kwargs: Any) -> tuple[Figure, Any]:
    """:func:`reports.svg.new_figure` with its axes typed for use."""
    figure, axes = new_figure(n_rows, n_cols, **kwargs)
    return figure, axes


def _curve_x(fit: GroundEffectFit) -> np.ndarray:
    x = fit.data.height_ratio
    return np.linspace(float(x.min()), float(x.max()), 400)


def fit_figure(fit: GroundEffectFit, *, ax: Any = None, legend: bool = True) -> Figure:
    """Data points and every fitted curve, F/F0 against Z/R; the chosen model drawn bold.

    Parameters
    ----------
    fit : GroundEffectFit
        The fit.
    ax : matplotlib Axes, optional
        Draw into these axes instead of a new figure.
    legend : bool, optional
        Add a legend.

    Returns
    -------
    matplotlib.figure.Figure
        The figure the axes belong to.
    """
    figure, axes = _figure(width_in=6.5, height_in=3.6) if ax is None else (ax.figure, ax)
    x = _curve_x(fit)
    for model in fit.models:
        chosen = model.name == fit.best
        axes.plot(
            x,
            model.ratio(x),
            color=_COLOURS[model.name],
            lw=2.2 if chosen else 1.1,
            ls="-" if chosen else "--",
            label=_LABELS[model.name] + (" — chosen" if chosen else ""),
        )
    axes.plot(fit.data.height_ratio, fit.data.thrust_ratio, "o", ms=3.2, color=_DATA, alpha=0.7, label="data")
    axes.set_xlabel("Z/R")
    axes.set_ylabel("F/F0")
    if legend:
        axes.legend(fontsize=7.5, loc="upper right")
    return figure


def residual_figure(fit: GroundEffectFit) -> Figure:
    """Residuals (data minus model) of each family against Z/R, one row per family.

    Parameters
    ----------
    fit : GroundEffectFit
        The fit.

    Returns
    -------
    matplotlib.figure.Figure
    """
    n = len(fit.models)
    figure, axes = _figure(n, 1, width_in=6.5, height_in=1.25 * n + 0.6, sharex=True)
    for ax, model in zip(np.atleast_1d(axes), fit.models):
        ax.axhline(0.0, color="#999999", lw=0.8)
        ax.plot(fit.data.height_ratio, model.residuals, "o", ms=2.8, color=_COLOURS[model.name])
        ax.set_ylabel("residual", fontsize=8)
        ax.set_title(f"{_LABELS[model.name]}: RMSE {model.rmse:.3g}", fontsize=8.5, loc="left")
    np.atleast_1d(axes)[-1].set_xlabel("Z/R")
    figure.tight_layout()
    return figure


def steps_figure(steps: HoverSteps, rotor_radius_m: float) -> Figure:
    """Height trace of a flight log (block means) with the hover steps and their steady halves shaded.

    Parameters
    ----------
    steps : HoverSteps
        Steps found.
    rotor_radius_m : float
        Propeller radius R, m (right axis in Z/R).

    Returns
    -------
    matplotlib.figure.Figure
    """
    figure, ax = _figure(width_in=7.0, height_in=2.8)
    ax.plot(steps.time_s, steps.height_m, color=_DATA, lw=0.9, label="height (0.5 s means)")
    for i, step in enumerate(steps.steps):
        ax.axvspan(
            step.steady_start_s,
            step.end_s,
            color="#2e8b57",
            alpha=0.18,
            lw=0,
            label="steady half used" if i == 0 else None,
        )
        ax.plot(
            [step.steady_start_s, step.end_s],
            [step.height_m] * 2,
            color="#c0392b",
            lw=1.6,
            label="step mean" if i == 0 else None,
        )
    ax.set_xlabel("time (s)")
    ax.set_ylabel("height (m)")
    right = ax.secondary_yaxis("right", functions=(lambda h: h / rotor_radius_m, lambda r: r * rotor_radius_m))
    right.set_ylabel("Z/R")
    ax.legend(fontsize=7.5, loc="upper right")
    return figure


def spacing_figure(study: SpacingStudy) -> Figure:
    """R^2 and RMSE of the compared families against rotor spacing (mm); rho with its interval when compared.

    Parameters
    ----------
    study : SpacingStudy
        The study.

    Returns
    -------
    matplotlib.figure.Figure
    """
    show_rho = "corrected" in study.families
    n_panels = 3 if show_rho else 2
    figure, axes = _figure(1, n_panels, width_in=7.5, height_in=2.8)
    spacing_mm = study.spacings_m * 1e3
    for name in study.families:  # the others are in the table
        style = {"color": _COLOURS[name], "marker": "o", "ms": 4, "lw": 1.6, "label": _LABELS[name]}
        axes[0].plot(spacing_mm, study.r2(name), **style)
        axes[1].plot(spacing_mm, study.rmse(name), **style)
    axes[0].set_ylabel("R²")
    axes[1].set_ylabel("RMSE")
    if study.transition_m is not None:
        for ax in axes[:2]:
            ax.axvline(study.transition_m * 1e3, color="#9a6700", lw=1.0, ls="--")
    if show_rho:
        rho, low, high = study.parameter("corrected", "rho")
        axes[2].errorbar(
            spacing_mm,
            rho,
            yerr=[rho - low, high - rho],
            fmt="o-",
            color=_COLOURS["corrected"],
            capsize=3,
            ms=4,
            lw=1.2,
        )
        axes[2].set_ylabel("ρ (eq. 2.2)")
    for ax in axes:
        ax.set_xlabel("rotor spacing increment (mm)")
    axes[0].legend(fontsize=7, loc="lower right")
    figure.tight_layout()
    return figure


def _spacing_curves(study: SpacingStudy) -> Figure:
    """Small multiples: data and the compared families at each spacing."""
    n = len(study.fits)
    cols = min(3, n)
    rows = math.ceil(n / cols)
    figure, axes = _figure(rows, cols, width_in=7.5, height_in=2.3 * rows)
    flat = np.atleast_1d(axes).ravel()
    for ax, spacing, fit, chosen in zip(flat, study.spacings_m, study.fits, study.chosen):
        x = _curve_x(fit)
        ax.plot(fit.data.height_ratio, fit.data.thrust_ratio, "o", ms=2.2, color=_DATA, alpha=0.5)
        for name in study.families:
            ax.plot(
                x,
                fit.model(name).ratio(x),
                color=_COLOURS[name],
                lw=2.0 if name == chosen else 1.0,
                ls="-" if name == chosen else "--",
            )
        ax.set_title(f"{spacing * 1e3:g} mm: {_LABELS[chosen]}", fontsize=8, loc="left")
        ax.set_xlabel("Z/R", fontsize=8)
        ax.set_ylabel("F/F0", fontsize=8)
    for ax in flat[n:]:
        ax.set_visible(False)
    figure.tight_layout()
    return figure


def _model_rows(fit: GroundEffectFit) -> list[dict[str, Any]]:
    rows = []
    for model in fit.models:
        rows.append(
            {
                "name": model.name,
                "label": _LABELS[model.name],
                "params": _param_rows(model),
                "rmse": model.rmse,
                "r2": model.r2,
                "aicc": model.aicc,
                "bic": model.bic,
                "delta": fit.delta(model.name),
                "chosen": model.name == fit.best,
                "notes": list(model.notes),
                "n_free": model.n_free,
            }
        )
    return rows


def _param_rows(model: ModelFit) -> list[dict[str, Any]]:
    return [
        {"name": n, "value": v, "low": lo, "high": hi}
        for n, v, lo, hi in zip(model.param_names, model.values, model.ci_low, model.ci_high)
    ]


def render_groundeffect_report(fit: GroundEffectFit, *, title: str | None = None) -> str:
    """The fit report as one HTML document: data, curves, residuals, the model table.

    Parameters
    ----------
    fit : GroundEffectFit
        The fit.
    title : str, optional
        Page title; default names the data.

    Returns
    -------
    str
        Self-contained HTML.
    """
    data = fit.data
    steps = data.steps
    return render_html(
        "groundeffect.html",
        kind="fit",
        title=title or f"Ground effect: {data.source or 'data'}",
        fit_svg=figure_svg(fit_figure(fit)),
        residual_svg=figure_svg(residual_figure(fit)),
        steps_svg=figure_svg(steps_figure(steps, data.rotor_radius_m)) if steps is not None else None,
        steps=list(steps.steps) if steps is not None else [],
        dropped=list(steps.dropped) if steps else [],
        rows=_model_rows(fit),
        best=_LABELS[fit.best],
        criterion=_CRITERIA[fit.criterion],
        confidence=fit.confidence,
        source=data.source,
        f0_source=data.f0_source,
        n_points=data.n_points,
        rotor_radius_m=data.rotor_radius_m,
        x_range=(float(data.height_ratio.min()), float(data.height_ratio.max())),
    )


def write_groundeffect_report(fit: GroundEffectFit, path: str | Path, *, title: str | None = None) -> Path:
    """Write the fit report atomically.

    Parameters
    ----------
    fit : GroundEffectFit
        The fit.
    path : str or Path
        Destination HTML file; its folder must exist.
    title : str, optional
        Page title.

    Returns
    -------
    Path
        The path written.
    """
    return write_html(path, render_groundeffect_report(fit, title=title))


def render_spacing_report(study: SpacingStudy, *, title: str | None = None) -> str:
    """The rotor-spacing report: R^2 (and rho) against spacing, curves per spacing, the table.

    Parameters
    ----------
    study : SpacingStudy
        The study.
    title : str, optional
        Page title.

    Returns
    -------
    str
        Self-contained HTML.
    """
    names = [m.name for m in study.fits[0].models]
    rows = []
    for spacing, fit, chosen in zip(study.spacings_m, study.fits, study.chosen):
        rows.append(
            {
                "spacing_mm": spacing * 1e3,
                "source": fit.data.source,
                "n_points": fit.data.n_points,
                "models": [
                    {"name": n, "r2": fit.model(n).r2, "rmse": fit.model(n).rmse, "params": _param_rows(fit.model(n))}
                    for n in names
                ],
                "chosen": _LABELS[chosen],
                "best_overall": _LABELS[fit.best],
            }
        )
    return render_html(
        "groundeffect.html",
        kind="spacing",
        title=title or f"Rotor-spacing study, {study.rotors} rotors",
        spacing_svg=figure_svg(spacing_figure(study)),
        curves_svg=figure_svg(_spacing_curves(study)),
        rows=rows,
        names=[_LABELS[n] for n in names],
        families=[_LABELS[f] for f in study.families],
        transition_mm=None if study.transition_m is None else study.transition_m * 1e3,
        criterion=_CRITERIA[study.fits[0].criterion],
        confidence=study.fits[0].confidence,
        rotors=study.rotors,
    )


def write_spacing_report(study: SpacingStudy, path: str | Path, *, title: str | None = None) -> Path:
    """Write the rotor-spacing report atomically.

    Parameters
    ----------
    study : SpacingStudy
        The study.
    path : str or Path
        Destination HTML file; its folder must exist.
    title : str, optional
        Page title.

    Returns
    -------
    Path
        The path written.
    """
    return write_html(path, render_spacing_report(study, title=title))
