"""Options every command that computes frequency responses shares (``freqresp``, ``fit``): one definition each."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import click

__all__ = ["windows_option"]

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
