"""Matplotlib figures as inline SVG text, the only figure format of our reports."""

from __future__ import annotations

import io
from typing import Any

import matplotlib
from matplotlib.figure import Figure

__all__ = ["figure_svg", "new_figure"]

_STYLE: dict[str, Any] = {
    "svg.fonttype": "none",  # text stays text: selectable, small, printable
    "svg.hashsalt": "flight-sysid",  # identical figures give identical SVG
    "font.family": "sans-serif",
    "font.size": 9.0,
    "axes.grid": True,
    "grid.alpha": 0.35,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "figure.dpi": 96.0,
}


def new_figure(
    n_rows: int = 1, n_cols: int = 1, *, width_in: float = 7.5, height_in: float = 3.2, sharex: bool = False
) -> tuple[Figure, object]:
    """A figure in the house style and its axes (an array when more than one).

    Parameters
    ----------
    n_rows, n_cols : int, optional
        Grid of axes.
    width_in, height_in : float, optional
        Figure size, inch (the report's column is about 7.5 in wide).
    sharex : bool, optional
        Share the x axis between rows.

    Returns
    -------
    figure : matplotlib.figure.Figure
    axes : Axes or ndarray of Axes
    """
    # a bare Figure, never registered with pyplot: nothing to close, nothing kept alive
    matplotlib.rcParams.update(_STYLE)  # type: ignore[arg-type]
    figure = Figure(figsize=(width_in, height_in))
    axes = figure.subplots(n_rows, n_cols, sharex=sharex, squeeze=True)
    return figure, axes


def figure_svg(figure: Figure) -> str:
    """The figure as an ``<svg>`` element to inline in HTML.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        A finished figure.

    Returns
    -------
    str
        SVG markup without the XML prolog, scaled to its container's width.

    Examples
    --------
    >>> fig, ax = new_figure()
    >>> _ = ax.plot([0, 1], [0, 1])
    >>> figure_svg(fig).startswith("<svg")
    True
    """
    buffer = io.StringIO()
    matplotlib.rcParams.update(_STYLE)  # type: ignore[arg-type]
    figure.savefig(buffer, format="svg", bbox_inches="tight", metadata={"Date": None})
    text = buffer.getvalue()
    start = text.index("<svg")
    svg = text[start:]
    # let CSS size the figure to its column; keep the aspect ratio from viewBox
    head_end = svg.index(">")
    head = svg[:head_end]
    for attribute in ("width", "height"):
        marker = f' {attribute}="'
        if marker in head:
            first = head.index(marker)
            last = head.index('"', first + len(marker))
            head = head[:first] + head[last + 1 :]
    return head + ' class="figure" role="img"' + svg[head_end:]
