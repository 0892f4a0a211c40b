"""One entry point that reads any supported flight log, or a table through its column map."""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from flightlogs.errors import DataError, DataQualityWarning, LogFormatError
from flightlogs.flightlog import FlightLog
from flightlogs.readers.detect import detect_format

if TYPE_CHECKING:
    from flightlogs.readers.table import TableMap

__all__ = ["read_log", "ReadOptions", "ProgressCallback"]

#: Called with (bytes done, bytes in total) while a log is read.
ProgressCallback = Callable[[int, int], None]


@dataclass(frozen=True, slots=True, kw_only=True)
class ReadOptions:
    """How files are read: the column map of tables, and whether a log of another vehicle is refused.

    Parameters
    ----------
    table_map : TableMap or None
        Which column of a CSV or Parquet table is which signal
        (:func:`~flightlogs.readers.table.parse_table_map`); logs ignore it.
    force_multirotor : bool
        Read a log whose vehicle type is not a multirotor (a fixed wing, a
        rover, a helicopter) as one, with a warning, instead of refusing it.
    """

    table_map: TableMap | None = None
    force_multirotor: bool = False


def read_log(
    path: str | Path, *, progress: ProgressCallback | None = None, reading: ReadOptions = ReadOptions()
) -> FlightLog:
    """Read a PX4 ULog, ArduPilot DataFlash or MAVLink telemetry log, or a CSV or Parquet table.

    The format is detected from the content (:func:`detect_format`), so a
    renamed file reads as what it is. A file that is none of the three logs
    but a table is read through ``reading.table_map``
    (:func:`~flightlogs.readers.table.read_table`). The models identified
    here are a multirotor's: a log that says it is another vehicle
    (:attr:`FlightLog.vehicle_type`) is refused unless ``reading.force_multirotor``.

    Parameters
    ----------
    path : str or Path
        The log file.
    progress : callable, optional
        ``progress(done, total)`` in bytes, for a progress bar.
    reading : ReadOptions, optional
        The column map of tables, and whether another vehicle is read as a multirotor.

    Returns
    -------
    FlightLog
        Canonical signals with their sources, metadata and warnings.

    Raises
    ------
    LogFormatError
        If the file cannot be read as any supported format, or is a table and no column map is given.
    DataError
        If a table does not fit its map (see :func:`~flightlogs.readers.table.read_table`), or the log is
        of a vehicle that is not a multirotor.
    """
    log = _read(Path(path), progress, reading.table_map)
    if log.vehicle_type in ("", "multirotor"):
        return log
    if not reading.force_multirotor:
        raise DataError(
            f"{log.path}: a {log.vehicle_type}, not a multirotor; the models here are a multirotor's "
            "(read it as one with `force_multirotor`)"
        )
    forced = f"{log.path.name}: a {log.vehicle_type}, read as a multirotor as asked"
    warnings.warn(DataQualityWarning(forced), stacklevel=2)
    return dataclasses.replace(log, warnings=(*log.warnings, forced))


def _read(path: Path, progress: ProgressCallback | None, table_map: TableMap | None) -> FlightLog:
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
