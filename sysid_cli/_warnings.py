"""The library's warnings in a command: recorded while it runs, then printed once each on stderr.

Library functions raise :class:`~flightlogs.errors.SysidWarning` s (and keep
their messages in the results they build). A command may print some of
those messages itself, in its table (``sysid ingest`` lists each log's
warnings); it says so with :func:`mark_reported`. Whatever else was raised is
printed after the command as ``warning: <message>``, once per message. Other
warnings are shown as Python shows them.

Without ``-W`` or ``PYTHONWARNINGS`` (``sys.warnoptions`` empty) the project's
warnings are shown, whatever filters the process set (a test runner's
``error`` included); with them, those filters decide: ``-W error`` makes each
warning an error (exit 1), ``-W ignore`` hides them.
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Iterable, Iterator, MutableMapping
from contextlib import contextmanager
from typing import Any

import click

from flightlogs.errors import SysidWarning

__all__ = ["mark_reported", "warnings_printed_once"]

_REPORTED = "sysid.reported_warnings"


def mark_reported(messages: Iterable[str]) -> None:
    """Note that the running command printed these warning messages itself, so they are not printed again.

    Parameters
    ----------
    messages : iterable of str
        Messages of warnings the command showed (its table's ``warning:`` lines).
    """
    ctx = click.get_current_context(silent=True)
    if ctx is not None:
        ctx.meta.setdefault(_REPORTED, set()).update(messages)


@contextmanager
def warnings_printed_once(meta: MutableMapping[str, Any]) -> Iterator[None]:
    """Record the warnings raised in the block; then print each project warning not reported, once.

    Parameters
    ----------
    meta : MutableMapping
        The click context's ``meta``, where :func:`mark_reported` notes what
        the command printed.
    """
    caught: list[warnings.WarningMessage] = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            if not sys.warnoptions:  # the user set no filter: show them
                warnings.simplefilter("default", SysidWarning)
            yield
    finally:
        shown = set(meta.get(_REPORTED, ()))
        for record in caught:
            if not issubclass(record.category, SysidWarning):
                warnings.showwarning(
                    record.message, record.category, record.filename, record.lineno, record.file, record.line
                )
            elif (text := str(record.message)) not in shown:
                shown.add(text)
                click.secho(f"warning: {text}", fg="yellow", err=True)
