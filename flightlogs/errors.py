"""The project's exception and warning hierarchy.

Every error the workbench raises on purpose derives from :class:`SysidError`.
It lives here, in the lowest layer, so that ``flightlogs`` can raise it
without importing ``sysid``; ``sysid`` re-exports it and adds its own
subclasses. Each subclass also inherits the closest builtin, so callers that
catch ``ValueError`` or ``KeyError`` keep working. Only ``sysid_cli`` maps
these to exit codes.
"""

from __future__ import annotations

__all__ = [
    "SysidError",
    "LogFormatError",
    "DataError",
    "MissingSignalError",
    "ModelError",
    "FitError",
    "SysidWarning",
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
    """Base of the project's warnings (recoverable corruption, doubtful data)."""
