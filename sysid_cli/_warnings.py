"""The library's warnings in a command: recorded while it runs, then printed once each on stderr.

Library functions raise :class:`~flightlogs.errors.SysidWarning` s (and keep
their messages in the results they build). A command may print some of
those messages itself, in its table (``sysid ingest`` lists each log's
warnings); it says so with :func:`mark_reported`. Whatever else was raised is
printed after the command as ``warning: <message>``, once per message. Other
warnings are shown as Python shows them.

Messages that differ only in the signal they name and their numbers are one
line (:func:`grouped`: ``p, q, r: 2.02 s gap at 72.61 s; record split``,
numbers that differ shown as their range); under a command's ``-q`` they are
one line in all, their count (a single warning is shown as it is).

Without ``-W`` or ``PYTHONWARNINGS`` (``sys.warnoptions`` empty) the project's
warnings are shown, whatever filters the process set (a test runner's
``error`` included); with them, those filters decide: ``-W error`` makes each
warning an error (exit 1), ``-W ignore`` hides them.
"""

from __future__ import annotations

import re
import sys
import warnings
from collections.abc import Iterable, Iterator, MutableMapping, Sequence
from contextlib import contextmanager
from typing import Any

import click

from flightlogs.errors import SysidWarning

from ._flags import as_flags

__all__ = ["QUIET", "grouped", "mark_reported", "warnings_printed_once"]

_REPORTED = "sysid.reported_warnings"
#: ``ctx.meta`` key set by a command run with ``-q``: its warnings are then counted, not listed.
QUIET = "sysid.quiet"
_NAMED = re.compile(r"^([A-Za-z_][\w.]*(?:\[\d+\])?): (.*)$", re.DOTALL)  # "az: ..." or "EKF2[0]: ..."
_NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?")


def grouped(messages: Sequence[str]) -> list[str]:
    """`messages` with those that differ only in the name before their colon and in their numbers made one.

    Parameters
    ----------
    messages : sequence of str
        Warning messages, in the order raised (duplicates already removed).

    Returns
    -------
    list of str
        One line per kind, in the order of each kind's first message: the names joined, each number that
        differs shown as its range.

    Examples
    --------
    >>> grouped(["p: 2.02 s gap at 72.61 s; record split", "q: 2.02 s gap at 72.61 s; record split",
    ...          "phi: 2.10 s gap at 72.59 s; record split", "no wind given"])
    ['p, q, phi: 2.02-2.10 s gap at 72.59-72.61 s; record split', 'no wind given']
    """
    kinds: dict[str, list[tuple[str, list[str]]]] = {}
    for message in messages:
        named = _NAMED.match(message)
        name, body = (named.group(1), named.group(2)) if named else ("", message)
        kinds.setdefault(("named: " if named else "") + _NUMBER.sub("#", body), []).append(
            (name, _NUMBER.findall(body))
        )
    out = []
    for template, members in kinds.items():
        if len(members) == 1:
            name, numbers = members[0]
            body = _render(template.removeprefix("named: "), [[n] for n in numbers])
            out.append(f"{name}: {body}" if name else body)
            continue
        columns = [list(column) for column in zip(*(numbers for _, numbers in members))]
        names = ", ".join(dict.fromkeys(name for name, _ in members))
        body = _render(template.removeprefix("named: "), columns)
        out.append(f"{names}: {body}" if names else f"{body} ({len(members)} times)")
    return out


def _render(template: str, columns: list[list[str]]) -> str:
    """`template` with each ``#`` the number of its column, or the column's range when its numbers differ."""
    parts = template.split("#")
    text = parts[0]
    for column, part in zip(columns, parts[1:]):
        low, high = min(column, key=float), max(column, key=float)
        text += (low if float(low) == float(high) else f"{low}-{high}") + part
    return text


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
        ours: list[str] = []
        for record in caught:
            if not issubclass(record.category, SysidWarning):
                warnings.showwarning(
                    record.message, record.category, record.filename, record.lineno, record.file, record.line
                )
            elif (text := str(record.message)) not in shown:
                shown.add(text)
                ours.append(text)
        lines = grouped(ours)
        if meta.get(QUIET) and len(ours) > 1:
            lines = [f"{len(ours)} warnings of {len(lines)} kinds; without -q they are listed"]
        for line in lines:
            click.secho(f"warning: {as_flags(line)}", fg="yellow", err=True)
