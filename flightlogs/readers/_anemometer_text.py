"""Anemometer CSV files as text: rows, cells, numbers and timestamps.

Behind :func:`flightlogs.readers.anemometer.read_anemometer_csv`, which documents the
layouts. Timestamps are ISO-8601 (with or without zone, or a date column and
a time-of-day column) or UNIX epoch seconds or milliseconds, converted to UNIX
seconds UTC.
"""

from __future__ import annotations

import calendar
import csv
import io
import math
import re
import warnings
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import cast

import numpy as np

from flightlogs.errors import DataError, LogFormatError
from flightlogs.readers._responseone import RESPONSEONE

__all__: list[str] = []

_ISO = re.compile(
    r"^(\d{4})-(\d{2})-(\d{2})[T ](\d{2}):(\d{2})(?::(\d{2})(?:[.,](\d+))?)?"
    r"\s*(Z|[+-]\d{2}(?::?\d{2})?)?$",
    re.IGNORECASE,
)
_TIME_OF_DAY = re.compile(r"^\d{1,2}:\d{2}")  # a time of day without a date
_MISSING = {"", "nan", "na", "n/a", "null", "none", "-", "--"}  # cell texts that hold no value
_TO_STRIP = re.compile(r"[#\s]")  # what a cell's strip (whitespace) or a comment would take out


# --------------------------------------------------------------------------- rows and cells


def load_rows(path: Path) -> tuple[list[list[str]], list[int]]:
    """Non-blank, non-comment CSV rows with their 1-based line numbers."""
    raw = path.read_bytes()
    if not raw.strip():
        raise LogFormatError(f"{path}: the file is empty")
    if b"\x00" in raw[:4096]:
        raise LogFormatError(f"{path}: binary content (NUL bytes), not a CSV file")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = raw.decode("cp1252", errors="replace")
    lines = enumerate(text.splitlines(), 1)
    number, first = next(
        ((n, line) for n, line in lines if line.strip() and not line.lstrip().startswith("#")), (1, "")
    )
    delimiter = max(",;\t", key=first.count)
    if RESPONSEONE.match(first):
        raise LogFormatError(
            f"{path}, line {number}: a ResponseONE reading without a timestamp; "
            "the sensor has no clock, so log lines as '<time>,<reading>'"
        )
    if first.count(delimiter) == 0:
        raise LogFormatError(f"{path}, line {number}: no comma, semicolon or tab; not a CSV file")
    if not ('"' in text or "\x00" in text or "\r" in (unix := text.replace("\r\n", "\n"))):
        return _split_rows(unix, delimiter)
    reader = csv.reader(io.StringIO(text), delimiter=delimiter, skipinitialspace=True)
    rows: list[list[str]] = []
    numbers: list[int] = []
    try:
        for row in reader:
            if not row or not "".join(row).strip() or row[0].lstrip().startswith("#"):
                continue
            rows.append([cell.strip() for cell in row])
            numbers.append(reader.line_num)
    except csv.Error as err:
        raise LogFormatError(f"{path}, line {reader.line_num}: not valid CSV ({err})") from err
    return rows, numbers


def _split_rows(text: str, delimiter: str) -> tuple[list[list[str]], list[int]]:
    """:func:`load_rows` of a text without quotes whose lines end in ``\\n``: each line split at the delimiter,
    as :mod:`csv` splits it (the same rows and line numbers), at a third of its cost; a text with nothing to
    strip or skip (no whitespace in a cell, no comment, no blank line: what loggers write) split whole, in two
    thirds of the time again (0.8 ms for an 800-line file)."""
    lines = text.split("\n")
    if lines[-1] == "":
        lines.pop()  # the last line's ending
    bare = text.replace("\n", "").replace(delimiter, "")  # the cells' characters
    if not _TO_STRIP.search(bare) and all(line.strip(delimiter) for line in lines):
        return [line.split(delimiter) for line in lines], list(range(1, len(lines) + 1))
    rows: list[list[str]] = []
    numbers: list[int] = []
    for number, line in enumerate(text.split("\n"), 1):
        cells = [cell.strip() for cell in line.split(delimiter)]
        if cells[0].startswith("#") or not any(cells):
            continue
        rows.append(cells)
        numbers.append(number)
    return rows, numbers


@dataclass(frozen=True, slots=True, kw_only=True)
class Table:
    """Header, data rows and their line numbers, with typed column access."""

    path: Path
    header: list[str]
    rows: list[list[str]]
    lines: list[int]

    def cells(self, column: str) -> list[str]:
        """Text of `column` in every row ('' where a short row ends early)."""
        index = self.header.index(column)
        width = len(self.header)
        lengths = set(map(len, self.rows))
        if lengths and index < min(lengths) and max(lengths) <= width:  # every row holds the column, none more
            return [row[index] for row in self.rows]
        out = []
        for row, line in zip(self.rows, self.lines):
            if len(row) > width and any(row[width:]):
                raise LogFormatError(f"{self.path}, line {line}: {len(row)} fields but the header has {width}")
            out.append(row[index] if index < len(row) else "")
        return out

    def numbers(self, column: str) -> np.ndarray:
        """Finite float values of `column`; DataError naming the line otherwise."""
        cells = self.cells(column)
        try:  # plain numbers, converted at once; anything else (blanks, commas, nan) row by row, to name the line
            values = np.array(cells, dtype=np.float64)
        except ValueError:
            pass
        else:
            if np.isfinite(values).all():
                return values
        values = np.empty(len(self.rows))
        for i, (text, line) in enumerate(zip(self.cells(column), self.lines)):
            values[i] = _number(text, f"{self.path}, line {line}: column {column!r}")
        return values


def _number(text: str, where: str) -> float:
    if text.lower() in _MISSING:
        raise DataError(f"{where} has no value ({text!r})")
    try:
        value = float(text)
    except ValueError:
        try:
            value = float(text.replace(",", "."))  # decimal comma
        except ValueError:
            raise DataError(f"{where} is not a number ({text!r})") from None
    if not math.isfinite(value):
        raise DataError(f"{where} has no finite value ({text!r})")
    return value


# --------------------------------------------------------------------------- time


def parse_time_columns(table: Table, used: dict[str, str], utc_offset_hours: float) -> np.ndarray:
    """UNIX seconds UTC of every row, from the time column (and date column)."""
    column = used["time"]
    texts = table.cells(column)
    label = repr(column)
    if "date" in used:
        if texts and _TIME_OF_DAY.match(texts[0]):
            dates = table.cells(used["date"])
            texts = [f"{d}T{t}" if d and t else "" for d, t in zip(dates, texts)]
            label = f"{used['date']!r} + {column!r}"
        else:
            del used["date"]  # the time column holds whole timestamps
    utc_s = parse_times(table.path, texts, table.lines, label, utc_offset_hours)
    check_increasing(table.path, utc_s, texts, table.lines)
    return utc_s


def parse_times(path: Path, texts: list[str], lines: list[int], label: str, utc_offset_hours: float) -> np.ndarray:
    """ISO-8601 or epoch (s or ms) texts to UNIX seconds UTC."""
    offset_s = utc_offset_hours * 3600.0
    epoch_scale = _epoch_scale(texts[0]) if texts else None
    fast = _iso_at_once(texts, offset_s) if epoch_scale is None else None
    if fast is not None:
        return fast
    out = np.empty(len(texts))
    for i, (text, line) in enumerate(zip(texts, lines)):
        where = f"{path}, line {line}: time column {label}"
        if text.lower() in _MISSING:
            raise DataError(f"{where} is empty")
        value = None
        if epoch_scale is not None:
            if _epoch_scale(text) == epoch_scale:
                value = float(text) * epoch_scale
        else:
            value = _iso_to_unix(text, offset_s)
        if value is None:
            kind = (
                "UNIX time in " + ("s" if epoch_scale == 1.0 else "ms")
                if epoch_scale is not None
                else "ISO-8601 (date and time)"
            )
            if epoch_scale is None and re.fullmatch(r"[-+]?\d+(\.\d*)?", text):
                kind = "ISO-8601 nor UNIX time (s or ms since 1970, from 1973 on)"
            hint = "; add a date column" if _TIME_OF_DAY.match(text) else ""
            raise LogFormatError(f"{where} holds {text!r}, which is not {kind}{hint}")
        out[i] = value
    return out


def _iso_at_once(texts: list[str], naive_offset_s: float) -> np.ndarray | None:
    """UNIX seconds of ISO-8601 texts all in UTC ('Z') or all zone-less, parsed by numpy at once; else None.

    The seconds are the whole seconds plus the fraction, added as :func:`_iso_to_unix` adds them
    (the same float); any text numpy does not read, or a zone offset, goes row by row.
    """
    if not texts:
        return None
    raw = np.array(texts)
    head = raw.astype("U16").view("U1").reshape(raw.size, -1)  # 'YYYY-MM-DDTHH:MM', as _ISO requires
    if head.shape[1] != 16 or not (
        np.char.isdigit(head[:, [0, 1, 2, 3, 5, 6, 8, 9, 11, 12, 14, 15]]).all()
        and (head[:, [4, 7]] == "-").all()
        and np.isin(head[:, 10], ["T", " "]).all()
        and (head[:, 13] == ":").all()
    ):
        return None
    utc = np.char.endswith(raw, "Z")
    if utc.all():
        raw, shift = np.char.rstrip(raw, "Z"), 0.0
    elif not utc.any():
        shift = naive_offset_s
    else:
        return None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a zone offset numpy would read with a warning
            stamps = raw.astype("datetime64[ns]").astype(np.int64)
    except (ValueError, OverflowError, Warning):
        return None
    if (stamps == np.iinfo(np.int64).min).any():  # NaT
        return None
    whole, fraction = np.divmod(stamps, 1_000_000_000)
    return cast(np.ndarray, (whole.astype(np.float64) + fraction / 1e9) - shift)


def _epoch_scale(text: str) -> float | None:
    """1.0 for UNIX seconds, 1e-3 for milliseconds, None if `text` is neither."""
    try:
        value = float(text)
    except ValueError:
        return None
    if 1e8 <= value < 1e11:  # 1973 .. 5138 in seconds
        return 1.0
    if 1e11 <= value < 1e14:  # the same span in milliseconds
        return 1e-3
    return None


def _iso_to_unix(text: str, naive_offset_s: float) -> float | None:
    """UNIX seconds of an ISO-8601 date-time; zone-less times are shifted by `naive_offset_s`."""
    match = _ISO.match(text)
    if match:
        year, month, day, hour, minute, second, fraction, zone = match.groups()
        try:
            stamp = datetime(int(year), int(month), int(day), int(hour), int(minute), int(second or 0), tzinfo=UTC)
        except ValueError:
            return None
        seconds = calendar.timegm(stamp.timetuple()) + (float("0." + fraction) if fraction else 0.0)
        if zone is None:
            return seconds - naive_offset_s
        if zone.upper() == "Z":
            return seconds
        sign = -1.0 if zone[0] == "-" else 1.0
        digits = zone[1:].replace(":", "")
        return seconds - sign * (int(digits[:2]) * 3600 + int(digits[2:] or 0) * 60)
    try:
        stamp = datetime.fromisoformat(text)
    except ValueError:
        return None
    if stamp.tzinfo is None:
        return stamp.replace(tzinfo=UTC).timestamp() - naive_offset_s
    return stamp.timestamp()


def check_increasing(path: Path, utc_s: np.ndarray, texts: list[str], lines: list[int]) -> None:
    steps = np.diff(utc_s)
    bad = np.flatnonzero(steps <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        kind = "repeats" if steps[i - 1] == 0 else "goes backwards from"
        raise DataError(
            f"{path}, line {lines[i]}: time {texts[i]!r} {kind} the time on line "
            f"{lines[i - 1]} ({texts[i - 1]!r}); timestamps must increase"
        )
