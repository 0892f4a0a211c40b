"""One entry point that reads any supported flight log."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from flightlogs.errors import LogFormatError
from flightlogs.flightlog import FlightLog
from flightlogs.readers.detect import detect_format

if TYPE_CHECKING:
    from flightlogs.readers.table import TableMap

__all__ = ["read_log", "ProgressCallback"]

#: Called with (bytes done, bytes in total) while a log is read.
ProgressCallback = Callable[[int, int], None]


def read_log(
    path: str | Path, *, progress: ProgressCallback | None = None, table_map: TableMap | None = None
) -> FlightLog:
    """Read a PX4 ULog, ArduPilot DataFlash or MAVLink telemetry log, or a CSV or Parquet table.

    The format is detected from the content (:func:`detect_format`), so a
    renamed file reads as what it is. A file that is none of the three logs
    but a table is read through `table_map` (:func:`~flightlogs.readers.table.read_table`).

    Parameters
    ----------
    path : str or Path
        The log file.
    progress : callable, optional
        ``progress(done, total)`` in bytes, for a progress bar.
    table_map : TableMap, optional
        Which column of a table is which signal; logs ignore it.

    Returns
    -------
    FlightLog
        Canonical signals with their sources, metadata and warnings.

    Raises
    ------
    LogFormatError
        If the file cannot be read as any supported format, or is a table and no `table_map` is given.
    DataError
        If a table does not fit its map (see :func:`~flightlogs.readers.table.read_table`).
    """
    path = Path(path)
    try:
        log_format = detect_format(path)
    except LogFormatError:
        from flightlogs.readers.table import is_table, read_table

        if not is_table(path):
            raise
        if table_map is None:
            raise LogFormatError(
                f"{path}: a table (CSV or Parquet), not a flight log; it is read with a column map naming its time "
                "and signal columns (e.g. time=0,delta_lat=1,p=2:deg/s)"
            ) from None
        return read_table(path, table_map, progress=progress)
    if log_format == "ulog":
        from flightlogs.readers.ulog import read_ulog

        return read_ulog(path, progress=progress)
    if log_format == "dataflash":
        from flightlogs.readers.ardupilot import read_dataflash

        return read_dataflash(path, progress=progress)
    from flightlogs.readers.tlog import read_tlog

    return read_tlog(path, progress=progress)
