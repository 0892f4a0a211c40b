"""The verification section of the model report: tables, notices and sized figures of a time-domain verification."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from sysid.fit import Grade, Guidelines
from sysid.verify import OutputSummary, RecordVerification, Verification, mode_names

from .verify_figures import display_scale, verification_figures

__all__ = ["verification_context", "sized_svg"]


def sized_svg(svg: str, caption: str) -> tuple[str, str, float]:
    """SVG, caption and width (% of the 7.5 in column), so every figure's text prints at one size.

    Parameters
    ----------
    svg : str
        Inline SVG from :func:`reports.svg.figure_svg` (its viewBox is in points).
    caption : str
        The figure's caption.

    Returns
    -------
    tuple of (str, str, float)
        The SVG, the caption and the width to show it at, % of the report's column.

    Examples
    --------
    >>> sized_svg('<svg viewBox="0 0 270 144">', "half")[2]
    49.3
    """
    head = svg[: svg.index(">")]
    view = head.split('viewBox="', 1)[1].split('"', 1)[0].split() if 'viewBox="' in head else []
    width_in = float(view[2]) / 72.0 if len(view) == 4 else 7.5
    return svg, caption, round(min(100.0, 100.0 * width_in / 7.6), 1)


@dataclass(frozen=True, slots=True, kw_only=True)
class _OutputRow:
    name: str
    unit: str
    rmse: float
    tic: float
    grade: Grade
    prediction_rmse: float | None
    prediction_tic: float | None
    n_records: int
    doublets: str


def _output_rows(
    summaries: Sequence[OutputSummary],
    records: Sequence[RecordVerification],
    guidelines: Guidelines,
    *,
    judged: bool = True,
) -> list[_OutputRow]:
    rows = []
    for s in summaries:
        scale, unit = display_scale(s.unit)
        grade = guidelines.tic_grade(s.tic)
        excited = dict.fromkeys(
            r.excited or "all inputs"
            for r in records
            if any(o.name == s.name for o in (r.judged if judged else r.informative))
        )
        rows.append(
            _OutputRow(
                name=s.name,
                unit=unit,
                rmse=s.rmse * scale,
                tic=s.tic,
                grade=grade,
                prediction_rmse=None if s.prediction_rmse is None else s.prediction_rmse * scale,
                prediction_tic=s.prediction_tic,
                n_records=s.n_records,
                doublets=", ".join(excited),
            )
        )
    return rows


def _notices(records: Sequence[RecordVerification]) -> list[str]:
    """One notice for all the records an unstable model diverges over, and any other notice as it is."""
    unstable = [r for r in records if r.unstable]
    notices = [f"{r.label}: {r.notice}" for r in records if r.notice and not r.unstable]
    if unstable:
        growth = sorted({f"{r.growth:.0f}" for r in unstable}, key=float)
        spans = sorted({f"{r.time_s[-1] - r.time_s[0]:.1f}" for r in unstable}, key=float)
        names = mode_names([m for r in unstable for m in r.unstable_modes])
        notices.insert(
            0,
            f"The model is unstable open loop in its {names}, which the judged outputs depend on, "
            f"and grows "
            f"{'-'.join(dict.fromkeys([growth[0], growth[-1]]))}-fold over the "
            f"{'-'.join(dict.fromkeys([spans[0], spans[-1]]))} s of {len(unstable)} of the "
            f"{len(records)} records ({'; '.join(r.label for r in unstable)}): small input or "
            "initial-state errors diverge there, so judge them also by the one-step-ahead "
            "prediction error.",
        )
    return notices


def verification_context(verification: Verification | None, guidelines: Guidelines) -> dict[str, Any]:
    """What the report template needs of a verification (nothing but ``verification=None`` without one).

    Parameters
    ----------
    verification : Verification or None
        The verification on doublets, if any.
    guidelines : Guidelines
        The TIC limits that colour each output's row (those of the verdict).

    Returns
    -------
    dict
        Template variables: the verification, its on- and off-axis rows, wind rows, figures, notices, offsets.
    """
    if verification is None:
        return {"verification": None}
    return {
        "verification": verification,
        "output_rows": _output_rows(verification.summary, verification.records, guidelines),
        "off_axis_rows": _output_rows(verification.off_axis, verification.records, guidelines, judged=False),
        "wind_band_hz": next((c.band_hz for c in verification.wind_correction if math.isfinite(c.band_hz)), None),
        "wind_rows": [
            (
                c.name,
                display_scale(c.unit)[1],
                c.rmse_without * display_scale(c.unit)[0],
                c.rmse_with * display_scale(c.unit)[0],
                c.reduction_percent,
                c.reduction_in_band_percent,
            )
            for c in verification.wind_correction
        ],
        "verification_figures": [sized_svg(svg, caption) for svg, caption in verification_figures(verification)],
        "notices": [*verification.unverified, *_notices(verification.records)],
        "offsets": [
            (r.label, dict(r.reference_shifts), {o.name: o.bias * display_scale(o.unit)[0] for o in r.outputs})
            for r in verification.records
        ],
    }
