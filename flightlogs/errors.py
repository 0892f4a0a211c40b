"""The project's exception and warning hierarchy.

Every error the workbench raises on purpose derives from :class:`SysidError`.
It lives here, in the lowest layer, so that ``flightlogs`` can raise it
without importing ``sysid``; ``sysid`` re-exports it and adds its own
subclasses. Each subclass also inherits the closest builtin, so callers that
catch ``ValueError`` or ``KeyError`` keep working. Only ``sysid_cli`` maps
these to exit codes.

Every warning derives from :class:`SysidWarning` and is raised with
``warnings.warn(DataQualityWarning(message), stacklevel=2)``. A function
that builds a result with a ``warnings`` (or ``notes``) field runs its work
inside :func:`collected_warnings`: the messages of the warnings raised
inside become that field (a result handed on keeps its caveats), and the
warnings themselves go on to the caller, so ``-W error`` turns them into
failures and ``sysid`` prints them.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TextIO

__all__ = [
    "SysidError",
    "LogFormatError",
    "DataError",
    "MissingSignalError",
    "ModelError",
    "FitError",
    "SysidWarning",
    "DataQualityWarning",
    "LogCorruptionWarning",
    "FitWarning",
    "CollectedWarnings",
    "collected_warnings",
]


class SysidError(Exception):
    """Root of every error raised on purpose by flight-sysid.

    The message is one sentence a user can act on: it names the file, the
    signal, the line or the byte offset at fault.
    """


class LogFormatError(SysidError, ValueError):
    """A file is not in the format expected, or is damaged beyond reading."""


class DataError(SysidError, ValueError):
    """A file reads, but its content is unusable (NaNs, time going backwards, no overlap)."""


class MissingSignalError(SysidError, KeyError):
    """A canonical signal needed by a step is not in the log."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


class ModelError(SysidError, ValueError):
    """A model structure or model file is invalid (unknown name, bad expression, wrong shape)."""


class FitError(SysidError, RuntimeError):
    """An identification could not be carried out (no usable response, optimiser failure)."""


class SysidWarning(UserWarning):
    """Base of the project's warnings (recoverable corruption, doubtful data, doubtful estimates).

    The message is one sentence that names the file, signal, option or
    parameter concerned. Raised as such for an option given but not used.
    """


class DataQualityWarning(SysidWarning):
    """Data read, but part of it is doubtful, left out or read under an assumption.

    Samples dropped as invalid, logging dropouts, gaps that cut a record, a
    unit assumed, clocks or positions that disagree, wind that cannot stand
    for the wind at the vehicle.
    """


class LogCorruptionWarning(SysidWarning):
    """A reader skipped damaged bytes or messages of a file and read the rest.

    Truncated last messages, unknown message ids, failed checksums, formats
    that disagree with their length.
    """


class FitWarning(SysidWarning):
    """An estimate is doubtful: not identified by the data, at a bound of its range, or not converged."""


class CollectedWarnings:
    """The project warnings (:class:`SysidWarning`) raised inside a :func:`collected_warnings` block, in order."""

    __slots__ = ("_records",)

    def __init__(self) -> None:
        self._records: list[warnings.WarningMessage] = []

    @property
    def messages(self) -> tuple[str, ...]:
        """The message of each warning recorded, in the order raised."""
        return tuple(str(record.message) for record in self._records)

    def discard(self) -> None:
        """Forget the warnings recorded so far: they came from work whose result is replaced.

        A conditioning pass that only measures a clock offset, redone with
        the offset corrected, warns again about what still holds; so does an
        identification run again with the anemometer's clock offset it measured.
        """
        self._records.clear()

    def _record(self, record: warnings.WarningMessage) -> None:
        self._records.append(record)

    def _reemit(self, *, failing: bool) -> None:
        """Raise each warning again, where it was first raised, under the caller's filters.

        While an exception is on its way out (`failing`), a warning that the
        filters turn into an error is dropped, so that the exception is the one seen.
        """
        for record in self._records:
            try:
                warnings.warn_explicit(record.message, record.category, record.filename, record.lineno)
            except SysidWarning:
                if not failing:
                    raise


@contextmanager
def collected_warnings() -> Iterator[CollectedWarnings]:
    """Record the project warnings (:class:`SysidWarning`) raised inside the block, then raise them again.

    Every one is recorded, whatever the filters (a result's ``warnings``
    field must not depend on them); on leaving the block each is raised
    again with its category, file and line, under the caller's filters:
    shown, ignored, or an error under ``-W error``. Other warnings pass
    through untouched. Like :class:`warnings.catch_warnings`, this changes
    process-wide state and is not thread-safe.

    Yields
    ------
    CollectedWarnings
        Their messages so far (``.messages``), for the result being built.

    Examples
    --------
    >>> import warnings
    >>> def helper():
    ...     warnings.warn(DataQualityWarning("q: 3 samples dropped"), stacklevel=2)
    >>> with warnings.catch_warnings(record=True) as seen:
    ...     warnings.simplefilter("always")
    ...     with collected_warnings() as caught:
    ...         helper()
    ...     notes = caught.messages
    >>> notes, [type(w.message).__name__ for w in seen]
    (('q: 3 samples dropped',), ['DataQualityWarning'])
    """
    caught = CollectedWarnings()
    try:
        with warnings.catch_warnings():  # restores the filters and warnings.showwarning on the way out
            warnings.simplefilter("always", SysidWarning)
            passed_on = warnings.showwarning

            def record(
                message: Warning | str,
                category: type[Warning],
                filename: str,
                lineno: int,
                file: TextIO | None = None,
                line: str | None = None,
            ) -> None:
                if issubclass(category, SysidWarning):
                    caught._record(warnings.WarningMessage(message, category, filename, lineno, file, line))
                else:
                    passed_on(message, category, filename, lineno, file, line)

            warnings.showwarning = record
            yield caught
    except BaseException:
        caught._reemit(failing=True)
        raise
    caught._reemit(failing=False)
