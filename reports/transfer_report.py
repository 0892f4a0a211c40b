"""The transfer-function fit report: each pair's Bode with the fit and the coherence, and its parameters."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from sysid.fit.transfer import TransferFunctionFit

from .bode import bode_figure
from .html import render_html, write_html
from .svg import figure_svg

__all__ = ["render_transfer_report", "write_transfer_report"]


def render_transfer_report(fits: Sequence[TransferFunctionFit], *, sources: Sequence[str] = ()) -> str:
    """The report as one HTML document.

    Parameters
    ----------
    fits : sequence of TransferFunctionFit
        The fits, one pair each.
    sources : sequence of str, optional
        The files the responses came from.

    Returns
    -------
    str
        Self-contained HTML.
    """
    sections = []
    for fit in fits:
        figure = bode_figure(
            [fit.response],
            models={fit.structure.pair: fit.evaluate},
            labels=("flight data", "transfer function"),
        )
        sections.append(
            {
                "fit": fit,
                "svg": figure_svg(figure),
                "poles": [f"{p.real:.4g}{p.imag:+.4g}j" if p.imag else f"{p.real:.4g}" for p in fit.poles],
                "zeros": [f"{z.real:.4g}{z.imag:+.4g}j" if z.imag else f"{z.real:.4g}" for z in fit.zeros],
            }
        )
    return render_html("transfer.html", title="Transfer-function fits", sections=sections, sources=list(sources))


def write_transfer_report(
    path: str | Path, fits: Sequence[TransferFunctionFit], *, sources: Sequence[str] = ()
) -> Path:
    """Write the report atomically.

    Parameters
    ----------
    path : str or Path
        Destination HTML file; its folder must exist.
    fits : sequence of TransferFunctionFit
        The fits.
    sources : sequence of str, optional
        The files the responses came from.

    Returns
    -------
    Path
        The path written.
    """
    return write_html(path, render_transfer_report(fits, sources=sources))
