"""The validation report: a model's predictions of flights it was not fitted to, as one HTML page."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from sysid.verify import OutputSummary, Verification

from .html import render_html, write_html
from .verify_figures import display_scale, verification_figures

__all__ = ["TIC_GOOD", "TIC_ACCEPTABLE", "render_validate_report", "write_validate_report"]

#: Theil inequality coefficient of a model with good predictive accuracy (Tischler & Remple; DESIGN.md).
TIC_GOOD = 0.25
#: Upper end of the acceptable range.
TIC_ACCEPTABLE = 0.3


@dataclass(frozen=True, slots=True)
class _Row:
    """One line of the summary table, in display units."""

    name: str
    unit: str
    rmse: float
    tic: float
    grade: str
    prediction_rmse: float | None
    prediction_tic: float | None
    n_records: int


def _grade(tic: float) -> str:
    if tic <= TIC_GOOD:
        return "good"
    return "warn" if tic <= TIC_ACCEPTABLE else "bad"


def _row(summary: OutputSummary) -> _Row:
    scale, unit = display_scale(summary.unit)
    prediction = None if summary.prediction_rmse is None else summary.prediction_rmse * scale
    return _Row(summary.name, unit, summary.rmse * scale, summary.tic, _grade(summary.tic), prediction,
                summary.prediction_tic, summary.n_records)


@dataclass(frozen=True, slots=True)
class _WindRow:
    """One line of the wind-correction table, in display units."""

    name: str
    unit: str
    rmse_without: float
    rmse_with: float
    reduction_percent: float


def render_validate_report(verification: Verification, *, model_name: str, logs: Sequence[str | Path] = (),
                           title: str = "Model validation") -> str:
    """The validation report as HTML text.

    Parameters
    ----------
    verification : Verification
        Result of :func:`sysid.verify.verify`.
    model_name : str
        What was validated (the model file's name).
    logs : sequence of str or Path, optional
        The logs the records came from.
    title : str, optional
        Page title.

    Returns
    -------
    str
        One self-contained HTML document (inline CSS and SVG).
    """
    worst = max((s.tic for s in verification.summary), default=float("nan"))
    notices = [f"{r.label}: {r.notice}" for r in verification.records if r.notice]
    shifts = [(r.label, {k: v for k, v in r.reference_shifts.items()},
               {o.name: o.bias * display_scale(o.unit)[0] for o in r.outputs}) for r in verification.records]
    return render_html(
        "validate.html", title=title, model_name=model_name, logs=[str(Path(p).name) for p in logs],
        verification=verification, rows=[_row(s) for s in verification.summary], worst_tic=worst,
        verdict=_grade(worst) if verification.summary else "bad", tic_good=TIC_GOOD, tic_acceptable=TIC_ACCEPTABLE,
        notices=notices, offsets=shifts, figures=verification_figures(verification),
        wind_rows=[_WindRow(c.name, display_scale(c.unit)[1], c.rmse_without * display_scale(c.unit)[0],
                            c.rmse_with * display_scale(c.unit)[0], c.reduction_percent)
                   for c in verification.wind_correction],
    )


def write_validate_report(path: str | Path, verification: Verification, *, model_name: str,
                          logs: Sequence[str | Path] = ()) -> Path:
    """Render the validation report and write it atomically.

    Parameters
    ----------
    path : str or Path
        Destination HTML file; its folder must exist.
    verification : Verification
        Result of :func:`sysid.verify.verify`.
    model_name : str
        What was validated.
    logs : sequence of str or Path, optional
        The logs the records came from.

    Returns
    -------
    Path
        The file written.
    """
    return write_html(path, render_validate_report(verification, model_name=model_name, logs=logs))
