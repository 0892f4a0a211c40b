"""The R. M. Young ResponseONE ASCII polar output, as captured by a logger (``<time>,<reading>``).

Behind :func:`flightlogs.readers.anemometer.read_anemometer_csv`; the layout is
described in :mod:`flightlogs.readers.anemometer`. Readings are checked here (format,
checksum, status); times and values are converted by the caller.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from flightlogs.errors import DataError, DataQualityWarning, LogCorruptionWarning, LogFormatError

__all__: list[str] = []

#: ``a www.ww ddd.d [more fields] ss*cc``: address, speed, direction, status, checksum.
RESPONSEONE = re.compile(
    r"^\s*([0-9A-Za-z])\s+(\d+(?:\.\d*)?)\s+(\d+(?:\.\d*)?)"
    r"((?:\s+[-+]?\d+(?:\.\d*)?)*)\s+([0-9A-Fa-f]{2})\*([0-9A-Fa-f]{2})\s*$"
)


@dataclass(frozen=True, slots=True, kw_only=True)
class Readings:
    """The valid readings of a capture, in file order, and what was dropped."""

    times: list[str]  # the logger's timestamp text of each reading
    speeds: np.ndarray  # (n,) wind speed as sent, in the sensor's unit
    directions_deg: np.ndarray  # (n,) direction the wind comes FROM, deg
    lines: list[int]  # 1-based line of each reading
    time_column: str  # header of the timestamp column, "field 1" without a header


def is_responseone(rows: list[list[str]]) -> bool:
    """True if the first or second row ends with a ResponseONE ASCII polar reading."""
    return any(len(row) >= 2 and RESPONSEONE.match(row[-1]) for row in rows[:2])


def _checksum(text: str) -> int:
    """XOR of the character codes of `text`."""
    value = 0
    for char in text:
        value ^= ord(char)
    return value


def read_readings(path: Path, rows: list[list[str]], numbers: list[int]) -> Readings:
    """Readings of ``<time>,<ResponseONE polar line>`` rows; a bad checksum or status drops a line, with a warning."""
    has_header = not (len(rows[0]) >= 2 and RESPONSEONE.match(rows[0][-1]))
    times, speeds, directions, lines = [], [], [], []
    failed_sum, flagged = [], []
    for row, line in zip(rows[has_header:], numbers[has_header:]):
        match = RESPONSEONE.match(row[-1]) if len(row) >= 2 else None
        if match is None:
            raise LogFormatError(
                f"{path}, line {line}: not a timestamped ResponseONE reading ('<time>,a www.ww ddd.d ... ss*cc')"
            )
        sensor = row[-1].strip()
        if _checksum(sensor[: sensor.index("*")]) != int(match.group(6), 16):
            failed_sum.append(line)
        elif int(match.group(5), 16) != 0:
            flagged.append(line)
        else:
            times.append(row[0])
            speeds.append(float(match.group(2)))
            directions.append(float(match.group(3)))
            lines.append(line)
    if not times:
        raise DataError(
            f"{path}: no valid ResponseONE reading ({len(failed_sum)} failed the "
            f"checksum, {len(flagged)} had a non-zero status)"
        )
    for bad, why, category in (
        (failed_sum, "failing the checksum", LogCorruptionWarning),
        (flagged, "with a non-zero status code", DataQualityWarning),
    ):
        if bad:
            warnings.warn(category(f"dropped {len(bad)} ResponseONE lines {why} (first: line {bad[0]})"), stacklevel=2)
    return Readings(
        times=times,
        speeds=np.array(speeds),
        directions_deg=np.array(directions),
        lines=lines,
        time_column=rows[0][0] if has_header else "field 1",
    )
