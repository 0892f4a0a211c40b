"""Options every command that computes frequency responses shares (``freqresp``, ``fit``): one definition each."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import click

from ._common import LibraryDefault

__all__ = ["gating_options", "windows_option"]

_Decorator = Callable[[Callable[..., Any]], Callable[..., Any]]


def _seconds(_ctx: click.Context, _param: click.Parameter, value: str | None) -> tuple[float, ...] | None:
    if not value:
        return None
    try:
        lengths = tuple(float(part) for part in value.split(","))
    except ValueError:
        raise click.BadParameter(f"{value!r} is not a comma-separated list of seconds (e.g. 2,4,8,12,17)") from None
    bad = [
        part.strip() for part, length in zip(value.split(","), lengths) if not (math.isfinite(length) and length > 0)
    ]
    if bad:
        raise click.BadParameter(f"{', '.join(bad)}: window lengths must be positive seconds (e.g. 2,4,8,12,17)")
    return lengths


def windows_option() -> _Decorator:
    """``--windows S,S,...``: the composite's window lengths, s (as ``windows``, a tuple or None)."""
    return click.option(
        "--windows",
        callback=_seconds,
        metavar="S,S,...",
        help="Window lengths, s (default: five from 2π/(5·omega-min) to half the longest record).",
    )


def gating_options() -> _Decorator:
    """``--min-coherence`` and ``--min-decades``: the gating rule of eq. 3.8, defaults :class:`sysid.freqresp.Gating`'s.

    The command receives ``min_coherence`` and ``min_decades``; ``Gating(min_coherence=..., min_decades=...)``
    checks them.
    """
    coherence = click.option(
        "--min-coherence",
        type=click.FloatRange(0.0, 1.0, min_open=True, max_open=True),
        cls=LibraryDefault,
        default_from=("sysid.freqresp", "Gating", "min_coherence"),
        show_default=True,
        help="Coherence γ² a response's fit range must keep (eq. 3.8; 0.6 for noisy data).",
    )
    decades = click.option(
        "--min-decades",
        type=click.FloatRange(min=0, min_open=True),
        cls=LibraryDefault,
        default_from=("sysid.freqresp", "Gating", "min_decades"),
        show_default=True,
        help="Shortest fit range, decades (eq. 3.8).",
    )
    return lambda command: coherence(decades(command))
