"""One entry point that reads any supported flight log."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from flightlogs.flightlog import FlightLog
from flightlogs.readers.detect import detect_format

__all__ = ["read_log", "ProgressCallback"]

#: Called with (bytes done, bytes in total) while a log is read.
ProgressCallback = Callable[[int, int], None]


def read_log(path: str | Path, *, progress: ProgressCallback | None = None) -> FlightLog:
    """Read a PX4 ULog, ArduPilot DataFlash or MAVLink telemetry log.

    The format is detected from the content (:func:`detect_format`), so a
    renamed file reads as what it is.

    Parameters
    ----------
    path : str or Path
        The log file.
    progress : callable, optional
        ``progress(done, total)`` in bytes, for a progress bar.

    Returns
    -------
    FlightLog
        Canonical signals with their sources, metadata and warnings.

    Raises
    ------
    LogFormatError
        If the file cannot be read as any supported format.
    """
    path = Path(path)
    log_format = detect_format(path)
    if log_format == "ulog":
        from flightlogs.readers.ulog import read_ulog

        return read_ulog(path, progress=progress)
    if log_format == "dataflash":
        from flightlogs.readers.ardupilot import read_dataflash

        return read_dataflash(path, progress=progress)
    from flightlogs.readers.tlog import read_tlog

    return read_tlog(path, progress=progress)
