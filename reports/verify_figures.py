"""Figures of a time-domain verification: measured against simulated, per record and output."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, cast

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from sysid.verify import OutputVerification, RecordVerification, Verification, WindCorrection, mode_names

from .model_figures import plain_text
from .svg import figure_svg, new_figure

__all__ = ["record_figure", "wind_correction_figure", "verification_figures", "display_scale"]

_MEASURED: dict[str, Any] = {"color": "#8c959f", "linewidth": 2.2, "solid_capstyle": "round"}
_MODEL: dict[str, Any] = {"color": "#0969da", "linewidth": 1.1}
_WITHOUT: dict[str, Any] = {"color": "#d4760a", "linewidth": 1.1, "linestyle": "--"}


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


def _score(output: OutputVerification, other: OutputVerification | None) -> str:
    if other is None:
        return f"TIC {output.tic:.2f}"
    return f"TIC {output.tic:.2f} with $G_w$, {other.tic:.2f} without"


def _draw_output(
    ax: Axes,
    time_s: np.ndarray,
    output: OutputVerification,
    other: OutputVerification | None,
    *,
    wind: bool,
    small: bool = False,
) -> None:
    """Measured, model (and model without G_w) of one output, with its TIC (small panels: in the title)."""
    scale, unit = display_scale(output.unit)
    thin = 0.75 if small else 1.0
    ax.plot(time_s, output.measured * scale, label="measured", **(_MEASURED | {"linewidth": 2.2 * thin}))
    if other is not None:
        ax.plot(time_s, other.simulated * scale, label="model without $G_w$", **(_WITHOUT | {"linewidth": 1.1 * thin}))
    ax.plot(
        time_s,
        output.simulated * scale,
        label="model with $G_w$" if wind else "model",
        **(_MODEL | {"linewidth": 1.1 * thin}),
    )
    label = f"{plain_text(output.name)} [{plain_text(unit)}]"
    ax.margins(x=0)
    if small:
        ax.set_title(label, fontsize=8, loc="left", pad=3)
        ax.set_title(f"TIC {output.tic:.2f}", fontsize=7.5, loc="right", pad=3, color="#5b6575")
        return
    ax.set_ylabel(label)
    ax.text(
        0.005,
        0.97,
        _score(output, other),
        transform=ax.transAxes,
        ha="left",
        va="top",
        fontsize=8,
        color="#5b6575",
        bbox={"facecolor": "white", "alpha": 0.75, "edgecolor": "none", "pad": 1.0},
    )
    low, high = ax.get_ylim()
    ax.set_ylim(low, high + 0.3 * (high - low))  # room for the score above the traces


_OFF_COLUMNS = 4
_PANEL_IN, _SMALL_IN, _TITLE_IN, _FOOT_IN, _OFF_HEAD_IN = 1.3, 1.15, 0.3, 0.9, 0.45


def record_figure(result: RecordVerification, *, without_wind: RecordVerification | None = None) -> str:
    """Measured and simulated time histories of one record: the judged outputs stacked, the off-axis ones small.

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
    judged, informative = result.judged, result.informative
    off_rows = -(-len(informative) // _OFF_COLUMNS)
    top_in = _TITLE_IN + _PANEL_IN * len(judged) + _FOOT_IN
    bottom_in = _OFF_HEAD_IN + _SMALL_IN * off_rows if informative else 0.0
    figure, _ = new_figure(width_in=7.5, height_in=top_in + bottom_in)
    figure.clear()  # laid out in two parts below, in the house style new_figure set
    parts: list[Any] = (
        list(cast(np.ndarray, figure.subfigures(2, 1, height_ratios=[top_in, bottom_in]))) if informative else [figure]
    )
    axes = np.atleast_1d(cast(np.ndarray, parts[0].subplots(len(judged), 1, sharex=True)))
    parts[0].subplots_adjust(top=1.0 - _TITLE_IN / top_in, bottom=_FOOT_IN / top_in, hspace=0.25)

    def other(name: str) -> OutputVerification | None:
        if without_wind is None or all(o.name != name for o in without_wind.outputs):
            return None
        return without_wind.output(name)

    for ax, output in zip(axes, judged):
        _draw_output(ax, result.time_s, output, other(output.name), wind=without_wind is not None)
    axes[-1].set_xlabel("time [s]")
    axes[0].set_title(plain_text(result.label), fontsize=9, loc="left")
    if result.unstable:
        axes[0].set_title(
            f"{mode_names(result.unstable_modes)} unstable: grows {result.growth:.0f}-fold",
            fontsize=8,
            loc="right",
            color="#9a6700",
        )
    axes[-1].legend(loc="upper center", bbox_to_anchor=(0.5, -0.45), ncol=3, frameon=False, fontsize=8)
    parts[0].align_ylabels(axes)
    if informative:
        grid = cast(np.ndarray, parts[1].subplots(off_rows, _OFF_COLUMNS, sharex=True, squeeze=False))
        parts[1].subplots_adjust(top=1.0 - _OFF_HEAD_IN / bottom_in, bottom=0.25 / bottom_in, hspace=0.65, wspace=0.4)
        for k, ax in enumerate(grid.ravel()):
            if k >= len(informative):
                ax.set_visible(False)
                continue
            _draw_output(
                ax, result.time_s, informative[k], other(informative[k].name), wind=without_wind is not None, small=True
            )
            ax.tick_params(labelsize=7)
        axis = f"the doublet excites {plain_text(result.excited)}" if result.excited else "another axis is excited"
        parts[1].suptitle(
            f"off-axis outputs, for information only (not judged: {axis})",
            x=0.02,
            y=0.995,
            ha="left",
            va="top",
            fontsize=8.5,
            color="#5b6575",
        )
    return figure_svg(figure)


def wind_correction_figure(corrections: Sequence[WindCorrection]) -> str:
    """RMS error per output with the wind term, relative to the model without it, as in Table 3.6.

    Parameters
    ----------
    corrections : sequence of WindCorrection
        From :attr:`Verification.wind_correction`; outputs the wind term changes by less than 0.5 % are left
        out (all are drawn when none changes that much).

    Returns
    -------
    str
        Inline SVG.
    """
    return figure_svg(_wind_figure(corrections))


def _wind_figure(corrections: Sequence[WindCorrection]) -> Figure:
    shown = [c for c in corrections if math.isfinite(c.reduction_percent) and abs(c.reduction_percent) >= 0.5]
    shown = shown or list(corrections)
    figure, created = new_figure(width_in=max(3.0, min(7.5, 1.2 + 0.75 * len(shown))), height_in=2.3)
    ax = cast(Axes, created)
    positions = np.arange(len(shown))
    with_wind = [c.rmse_with / c.rmse_without if c.rmse_without > 0 else 0.0 for c in shown]
    ax.bar(positions - 0.2, np.ones(len(shown)), width=0.4, color=_WITHOUT["color"], label="without $G_w$")
    ax.bar(positions + 0.2, with_wind, width=0.4, color=_MODEL["color"], label="with $G_w$")
    for x, c, ratio in zip(positions, shown, with_wind):
        change = -c.reduction_percent
        text = "0 %" if round(change) == 0 else f"{change:+.0f} %".replace("-", "\N{MINUS SIGN}")
        ax.annotate(
            text, (x + 0.2, ratio), ha="center", va="bottom", fontsize=8, xytext=(0, 2), textcoords="offset points"
        )
    ax.set_xticks(positions, [plain_text(c.name) for c in shown])
    ax.set_ylabel("RMS error / without $G_w$")
    ax.set_ylim(0, max(1.2, 1.18 * max(with_wind, default=1.0)))  # room for the labels above the tallest bar
    # above the axes, never over a bar
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.01), ncol=2, frameon=False, fontsize=8, borderaxespad=0.0)
    return figure


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
        figures.append(
            (
                wind_correction_figure(verification.wind_correction),
                "RMS error of each output with the wind term, relative to the model without it, over the "
                "doublets where the output is on-axis; outputs it changes by less than 0.5 % are left out.",
            )
        )
    without = {id(r): w for r, w in zip(verification.records, verification.without_wind)}
    for record in verification.records:
        caption = f"{record.label}: measured (grey) and simulated from all the measured inputs"
        if record.off_axis:
            caption += f"; judged on {', '.join(o.name for o in record.judged)}, the others shown small below"
        if record.unstable:
            caption += (
                f"; the model's {mode_names(record.unstable_modes)} (unstable open loop) reach the judged "
                "outputs over this record, see the one-step-ahead errors"
            )
        figures.append((record_figure(record, without_wind=without.get(id(record))), caption + "."))
    return figures
