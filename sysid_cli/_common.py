"""Options and output helpers shared by the commands."""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import click

from flightlogs.atomic import atomic_output

__all__ = ["json_option", "emit_json", "progress_bar"]

json_option = click.option(
    "--json",
    "json_path",
    type=click.Path(dir_okay=False, allow_dash=True, path_type=str),
    default=None,
    help="Write a machine-readable summary to PATH ('-' for stdout).",
)


def _clean(value: Any) -> Any:
    """JSON has no NaN: write null instead."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    return value


def emit_json(summary: dict[str, Any], json_path: str | None) -> None:
    """Write `summary` as JSON to a file (atomically) or to stdout for ``-``."""
    if json_path is None:
        return
    text = json.dumps(_clean(summary), indent=2, allow_nan=False) + "\n"
    if json_path == "-":
        sys.stdout.write(text)
        return
    with atomic_output(json_path) as tmp:
        Path(tmp).write_text(text)


@contextmanager
def progress_bar(label: str, *, quiet: bool = False) -> Iterator[Callable[[int, int], None]]:
    """Yield a ``progress(done, total)`` callback that drives a tqdm bar on stderr.

    The bar appears only on a terminal and only once work has lasted about a second.
    """
    from tqdm import tqdm

    bar = tqdm(
        desc=label, total=0, unit="B", unit_scale=True, delay=1.0, leave=False,
        disable=True if quiet else None, file=sys.stderr,
    )

    def update(done: int, total: int) -> None:
        if bar.total != total:
            bar.total = total
        bar.n = done
        bar.refresh() if bar.n >= total else bar.update(0)

    try:
        yield update
    finally:
        bar.close()
