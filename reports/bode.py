"""Bode and coherence figures of frequency responses, with the fit range and optional model overlays."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, LogLocator, MaxNLocator, NullFormatter, NullLocator

from flightlogs.writers.atomic import atomic_output
from sysid.freqresp import FrequencyResponse

from .svg import figure_svg, new_figure

__all__ = ["bode_figure", "write_bode_svg"]

#: A model's response for one pair: complex values on the response's omega, or a function of omega (rad/s).
ModelResponse = np.ndarray | Callable[[np.ndarray], np.ndarray]

_DATA = "#1f4e79"
_MODEL = "#c0392b"
_RANGE = "#2e8b57"


def bode_figure(
    responses: Sequence[FrequencyResponse],
    *,
    models: Mapping[str, ModelResponse] | None = None,
    n_cols: int | None = None,
    min_coherence: float | None = None,
    labels: tuple[str, str] = ("flight data", "model"),
) -> Figure:
    """Magnitude (dB), phase (deg) and coherence against frequency (rad/s, log) for each response.

    Each response gets a column block of three stacked panels; blocks fill a
    grid of `n_cols` columns. The fit range is shaded when set; a model
    overlay is drawn where `models` has the response's pair, its phase moved
    by whole turns onto the data's branch (360° apart is the same phase), so
    the two curves are compared where they lie. Frequency ticks are plain
    numbers (0.5 1 2 5 10 ...), labelled once under each column.

    Parameters
    ----------
    responses : sequence of FrequencyResponse
        Responses to draw (at least one).
    models : Mapping[str, ndarray or callable], optional
        By pair (``"q/delta_lon"``): complex response on the response's
        ``omega``, shape (n_freq,), or a function of omega (rad/s) returning it.
    n_cols : int, optional
        Blocks per row; default 1 for one response, else 2.
    min_coherence : float, optional
        Draw this gamma^2 threshold on the coherence panels.
    labels : tuple of str, optional
        Legend names of the responses and of the overlay.

    Returns
    -------
    matplotlib.figure.Figure
        The figure (pass it to :func:`reports.svg.figure_svg`).

    Raises
    ------
    ValueError
        If no response is given or a model's shape does not match its response.

    Examples
    --------
    >>> omega = np.geomspace(1.0, 10.0, 20)
    >>> h = FrequencyResponse(input="delta_lon", output="q", omega=omega, response=1 / (1j * omega + 1),
    ...                       coherence=np.full(20, 0.9), random_error=np.zeros(20),
    ...                       input_autospectrum=np.ones(20), output_autospectrum=np.ones(20),
    ...                       cross_spectrum=np.ones(20, complex), windows_s=(4.0,), fit_range=(1.0, 8.0))
    >>> figure = bode_figure([h], models={"q/delta_lon": lambda w: 1 / (1j * w + 1)})
    >>> len(figure.axes)
    3
    """
    if not responses:
        raise ValueError("no response to draw")
    columns = n_cols if n_cols is not None else (1 if len(responses) == 1 else 2)
    if columns < 1:
        raise ValueError(f"{n_cols=} must be >= 1")
    columns = min(columns, len(responses))
    block_rows = math.ceil(len(responses) / columns)
    width_in, height_in = (7.5 if columns > 1 else 6.0), _figure_height(block_rows)
    figure, axes = new_figure(3 * block_rows, columns, width_in=width_in, height_in=height_in)
    grid = np.asarray(axes, dtype=object).reshape(3 * block_rows, columns)
    _layout(grid, width_in, height_in)
    legend = True
    for k, response in enumerate(responses):
        row, col = divmod(k, columns)
        panels = grid[3 * row : 3 * row + 3, col]
        model = _model_values(models, response)
        _draw(panels, response, model, min_coherence, labels)
        if model is not None and legend:  # one legend per figure: the same two lines in every block
            panels[0].legend(loc="best", fontsize=7, frameon=False)
            legend = False
    for k in range(len(responses), block_rows * columns):
        row, col = divmod(k, columns)
        for ax in grid[3 * row : 3 * row + 3, col]:
            ax.set_visible(False)
    for k in range(len(responses)):
        row, col = divmod(k, columns)
        if k + columns < len(responses):  # another block below shares the frequency axis: label it once
            _hide_frequency_labels(grid[3 * row + 2, col])
    return figure


def write_bode_svg(path: str | Path, responses: Sequence[FrequencyResponse], **options: Any) -> Path:
    """Write :func:`bode_figure` as a standalone SVG file, atomically.

    Parameters
    ----------
    path : str or Path
        Destination ``.svg``.
    responses : sequence of FrequencyResponse
        Responses to draw.
    **options
        Passed to :func:`bode_figure` (``models``, ``n_cols``, ``min_coherence``).

    Returns
    -------
    Path
        The file written.
    """
    svg = figure_svg(bode_figure(responses, **options))
    text = '<?xml version="1.0" encoding="utf-8" standalone="no"?>\n' + svg + "\n"
    with atomic_output(path) as tmp:
        Path(tmp).write_text(text, encoding="utf-8")
    return Path(path)


_PANEL_IN = (1.15, 0.95, 0.7)  # magnitude, phase, coherence heights, inch
# between blocks only the next block's title: the frequency axis is labelled under the last block of a column
_GAP_IN, _BLOCK_GAP_IN, _TOP_IN, _BOTTOM_IN, _LEFT_IN, _RIGHT_IN, _COLUMN_GAP_IN = 0.1, 0.4, 0.3, 0.45, 0.75, 0.1, 0.8


def _figure_height(block_rows: int) -> float:
    block = sum(_PANEL_IN) + 2 * _GAP_IN
    return _TOP_IN + _BOTTOM_IN + block_rows * block + (block_rows - 1) * _BLOCK_GAP_IN


def _layout(grid: np.ndarray, width_in: float, height_in: float) -> None:
    """Place the panels in inches: blocks of three stacked panels, a wider gap between blocks.

    (tight_layout costs seconds on a dozen blocks; the SVG is cropped to its content anyway.)
    """
    rows, columns = grid.shape
    column_width = (width_in - _LEFT_IN - _RIGHT_IN - (columns - 1) * _COLUMN_GAP_IN) / columns
    for col in range(columns):
        left = _LEFT_IN + col * (column_width + _COLUMN_GAP_IN)
        top = height_in - _TOP_IN
        for row in range(rows):
            panel = row % 3
            if row and panel == 0:
                top -= _BLOCK_GAP_IN
            elif panel:
                top -= _GAP_IN
            bottom = top - _PANEL_IN[panel]
            grid[row, col].set_position(
                [left / width_in, bottom / height_in, column_width / width_in, _PANEL_IN[panel] / height_in]
            )
            top = bottom


def _frequency_label(value: float, _position: float) -> str:
    return f"{value:g}"


def _hide_frequency_labels(ax: Axes) -> None:
    ax.set_xlabel("")
    ax.tick_params(axis="x", which="both", labelbottom=False)


def _unwrapped(values: np.ndarray) -> np.ndarray:
    """Unwrapped phase, rad, of the finite values (a model known on part of the grid is NaN elsewhere)."""
    angle = np.angle(values)
    finite = np.isfinite(angle)
    out = np.full(angle.shape, np.nan)
    out[finite] = np.unwrap(angle[finite])
    return out


def _nearest_branch(data: np.ndarray, model: np.ndarray) -> np.ndarray:
    """The model's phase moved by whole turns onto the data's branch, point by point (median of 9 points).

    Where the data's phase wraps (a zero near the jω axis, noise at low
    coherence) the model follows it to the nearer branch; the running median
    keeps one noisy point from moving the model.
    """
    turns = np.round((data - model) / 360.0)
    turns = np.where(np.isfinite(turns), turns, 0.0)
    half = 4
    padded = np.pad(turns, half, mode="edge")
    steady = np.array([np.median(padded[k : k + 2 * half + 1]) for k in range(turns.size)])
    return model + 360.0 * np.round(steady)


def _model_values(models: Mapping[str, ModelResponse] | None, response: FrequencyResponse) -> np.ndarray | None:
    if not models or response.pair not in models:
        return None
    given = models[response.pair]
    values = np.asarray(given(response.omega) if callable(given) else given, dtype=complex)
    if values.shape != response.omega.shape:
        raise ValueError(f"model for {response.pair} has shape {values.shape}, expected {response.omega.shape}")
    return values


def _draw(
    panels: np.ndarray,
    response: FrequencyResponse,
    model: np.ndarray | None,
    min_coherence: float | None,
    labels: tuple[str, str],
) -> None:
    magnitude, phase, coherence = panels
    omega = response.omega
    magnitude.semilogx(omega, response.magnitude_db, color=_DATA, lw=1.2, label=labels[0])
    phase.semilogx(omega, response.phase_deg, color=_DATA, lw=1.2)
    coherence.semilogx(omega, response.coherence, color=_DATA, lw=1.2)
    if model is not None:
        model_phase = _nearest_branch(np.asarray(response.phase_deg, dtype=float), np.degrees(_unwrapped(model)))
        magnitude.semilogx(
            omega, 20 * np.log10(np.maximum(np.abs(model), 1e-300)), color=_MODEL, lw=1.2, ls="--", label=labels[1]
        )
        phase.semilogx(omega, model_phase, color=_MODEL, lw=1.2, ls="--")
    if response.fit_range is not None:
        for ax in panels:
            ax.axvspan(*response.fit_range, color=_RANGE, alpha=0.12, lw=0)
    if min_coherence is not None:
        coherence.axhline(min_coherence, color="0.4", lw=0.8, ls=":")
    conditioned = f" | {', '.join(response.conditioned_on)}" if response.conditioned_on else ""
    units = f" ({response.output_unit}/{response.input_unit})" if response.input_unit or response.output_unit else ""
    magnitude.set_title(f"{response.pair}{conditioned}", fontsize=9)
    if units:  # inside the panel: along a panel an inch tall it ran into the labels of the panels around it
        magnitude.text(0.99, 0.96, units.strip(), transform=magnitude.transAxes, ha="right", va="top", fontsize=6.5)
    magnitude.set_ylabel("magnitude, dB")
    phase.set_ylabel("phase, deg")
    coherence.set_ylabel("γ²")  # "coherence γ²" is taller than its panel
    coherence.set_ylim(0.0, 1.05)
    coherence.set_yticks([0.0, 0.5, 1.0])
    for ax in (magnitude, phase):  # their lowest tick label met the top one of the panel below
        ax.yaxis.set_major_locator(MaxNLocator(nbins=4, prune="lower"))
    coherence.set_xlabel("frequency, rad/s")
    for ax in panels:
        ax.set_xlim(omega[0], omega[-1])
        ax.xaxis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(FuncFormatter(_frequency_label))
        ax.xaxis.set_minor_locator(NullLocator())  # few ticks: a dozen blocks draw in half the time
        ax.xaxis.set_minor_formatter(NullFormatter())
    for ax in panels[:2]:
        _hide_frequency_labels(ax)
