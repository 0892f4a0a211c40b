"""Figures of a time-domain verification: measured against simulated, per record and output."""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

import numpy as np
from matplotlib.axes import Axes

from sysid.verify import RecordVerification, Verification, WindCorrection

from .svg import figure_svg, new_figure

__all__ = ["record_figure", "wind_correction_figure", "verification_figures", "display_scale"]

_MEASURED = {"color": "#8c959f", "linewidth": 2.2, "solid_capstyle": "round"}
_MODEL = {"color": "#0969da", "linewidth": 1.1}
_WITHOUT = {"color": "#d4760a", "linewidth": 1.1, "linestyle": "--"}


def display_scale(unit: str) -> tuple[float, str]:
    """Factor and unit to show a signal in: radians as degrees, everything else as it is.

    Parameters
    ----------
    unit : str
        The signal's unit inside the library (SI, radians).

    Returns
    -------
    factor : float
        Multiply the values by this for display.
    unit : str
        The unit shown.

    Examples
    --------
    >>> display_scale("rad/s")
    (57.29577951308232, 'deg/s')
    >>> display_scale("m/s^2")
    (1.0, 'm/s^2')
    """
    if unit.startswith("rad"):
        return float(np.degrees(1.0)), "deg" + unit[3:]
    return 1.0, unit


def record_figure(result: RecordVerification, *, without_wind: RecordVerification | None = None) -> str:
    """Measured and simulated time histories of every output of one record, stacked.

    Parameters
    ----------
    result : RecordVerification
        The model verified on the record (with G_w when `without_wind` is given).
    without_wind : RecordVerification, optional
        The model without G_w on the same record, drawn dashed.

    Returns
    -------
    str
        Inline SVG.
    """
    outputs = result.outputs
    figure, axes = new_figure(len(outputs), 1, height_in=0.5 + 1.3 * len(outputs), sharex=True)
    axes = np.atleast_1d(cast(np.ndarray, axes))
    for ax, output in zip(axes, outputs):
        scale, unit = display_scale(output.unit)
        ax.plot(result.time_s, output.measured * scale, label="measured", **_MEASURED)
        score = f"TIC {output.tic:.2f}"
        if without_wind is not None and any(o.name == output.name for o in without_wind.outputs):
            other = without_wind.output(output.name)
            ax.plot(result.time_s, other.simulated * scale, label="model without $G_w$", **_WITHOUT)
            score = f"TIC {output.tic:.2f} with $G_w$, {other.tic:.2f} without"
        ax.plot(result.time_s, output.simulated * scale,
                label="model with $G_w$" if without_wind is not None else "model", **_MODEL)
        ax.set_ylabel(f"{output.name} [{unit}]")
        ax.text(0.005, 0.97, score, transform=ax.transAxes, ha="left", va="top", fontsize=8, color="#5b6575",
                bbox={"facecolor": "white", "alpha": 0.75, "edgecolor": "none", "pad": 1.0})
        ax.margins(x=0)
        low, high = ax.get_ylim()
        ax.set_ylim(low, high + 0.3 * (high - low))  # room for the score above the traces
    axes[-1].set_xlabel("time [s]")
    axes[0].set_title(result.label, fontsize=9, loc="left")
    if result.unstable:
        axes[0].set_title(f"unstable open loop: grows {result.growth:.0f}-fold", fontsize=8, loc="right",
                          color="#9a6700")
    axes[-1].legend(loc="upper center", bbox_to_anchor=(0.5, -0.45), ncol=3, frameon=False, fontsize=8)
    figure.align_ylabels(axes)
    return figure_svg(figure)


def wind_correction_figure(corrections: Sequence[WindCorrection]) -> str:
    """RMS error per output without and with the wind term, as in Table 3.6.

    Parameters
    ----------
    corrections : sequence of WindCorrection
        From :attr:`Verification.wind_correction`; outputs the wind term does not touch are left out.

    Returns
    -------
    str
        Inline SVG.
    """
    shown = [c for c in corrections if abs(c.rmse_without - c.rmse_with) > 1e-12 * max(c.rmse_without, 1e-300)]
    shown = shown or list(corrections)
    figure, created = new_figure(height_in=2.0)
    ax = cast(Axes, created)
    positions = np.arange(len(shown))
    without = [c.rmse_without / c.rmse_without if c.rmse_without > 0 else 0.0 for c in shown]
    with_wind = [c.rmse_with / c.rmse_without if c.rmse_without > 0 else 0.0 for c in shown]
    ax.bar(positions - 0.2, without, width=0.4, color=_WITHOUT["color"], label="without $G_w$")
    ax.bar(positions + 0.2, with_wind, width=0.4, color=_MODEL["color"], label="with $G_w$")
    for x, c in zip(positions, shown):
        ax.annotate(f"−{c.reduction_percent:.0f} %", (x + 0.2, with_wind[int(x)]), ha="center", va="bottom",
                    fontsize=8, xytext=(0, 2), textcoords="offset points")
    ax.set_xticks(positions, [c.name for c in shown])
    ax.set_ylabel("RMS error / without $G_w$")
    ax.set_ylim(0, 1.2)
    ax.legend(loc="upper right", frameon=False, ncol=2, fontsize=8)
    return figure_svg(figure)


def verification_figures(verification: Verification) -> list[tuple[str, str]]:
    """Every figure of a verification with its caption, in report order.

    Parameters
    ----------
    verification : Verification
        The result of :func:`sysid.verify.verify`.

    Returns
    -------
    list of (str, str)
        ``(svg, caption)``: the wind correction (when there is a wind model), then one per record.
    """
    figures = []
    if verification.wind_correction:
        figures.append((wind_correction_figure(verification.wind_correction),
                        "RMS error of each output with the wind term, relative to the model without it."))
    without = {id(r): w for r, w in zip(verification.records, verification.without_wind)}
    for record in verification.records:
        caption = f"{record.label}: measured (grey) and simulated from the measured inputs"
        if record.unstable:
            caption += "; the model is unstable open loop over this record, see the one-step-ahead errors"
        figures.append((record_figure(record, without_wind=without.get(id(record))), caption + "."))
    return figures
