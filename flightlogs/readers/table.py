"""Tabular flight data (CSV or Parquet: motion capture, web-tool and MATLAB exports) read through a column map.

A table holds one sample a row and one quantity a column. The
:class:`TableMap` says which column is which canonical signal and in what
unit, e.g. ``time=0,delta_lat=1,p=2:deg/s`` (a column by its header name or
0-based index; the unit after a colon, converted to SI). Every map names the
time column; its unit is given (``time=t:ms``), read from the header
(``time_ms``, ``TimeUS``, ``t [s]``) or found from the median interval, which
a warning then says. A unit in brackets in a header (``p [deg/s]``) counts
as given. Times that read as UNIX time (after 1973) give the log's UTC.

A CSV may use any delimiter (comma, semicolon, tab, bar or spaces), with a
header row or without; ``#`` starts a comment line. A Parquet file is told
by its magic bytes. Empty cells and NaN are missing samples: each signal
keeps the rows where it has a value, so a table of signals logged at
different rates reads as it was logged.
"""

from __future__ import annotations

import csv
import io
import re
import tomllib
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from flightlogs.errors import DataError, DataQualityWarning, LogFormatError
from flightlogs.flightlog import FlightLog, Signal
from flightlogs.readers._table_derived import FRAMES, RotorLayout, derived_signals
from flightlogs.readers._units import AS_LOGGED, SI_SIZES, canonical_unit, si_factor
from flightlogs.signals import describe, is_canonical

__all__ = ["TableColumn", "TableMap", "parse_table_map", "read_table", "is_table"]

_PARQUET_MAGIC = b"PAR1"
_DELIMITERS = ",;\t|"
_BRACKET_UNIT = re.compile(r"^(.*?)\s*[\(\[]\s*([^\)\]]+?)\s*[\)\]]\s*$")
_TIME_SUFFIX = re.compile(r"(?:^|[_\s-]|(?<=[a-z]))(s|ms|us|ns|sec|msec|usec)$", re.IGNORECASE)
_UNIX_AFTER_S = 1e8  # a table time beyond this (1973) is UNIX time, not time since boot


@dataclass(frozen=True, slots=True)
class TableColumn:
    """Where one canonical signal is in a table, and its unit.

    Parameters
    ----------
    column : str or int
        Header name, or 0-based column index.
    unit : str or None
        Unit of the column's values (canonical spelling, see
        :func:`flightlogs.readers._units.canonical_unit`); None for the unit in
        the header's brackets, else the signal's SI unit (time: found from the
        median interval).
    """

    column: str | int
    unit: str | None = None


@dataclass(frozen=True, slots=True)
class TableMap:
    """Which column of a table is which canonical signal (``time`` included).

    Parameters
    ----------
    columns : Mapping[str, TableColumn]
        By canonical name; must hold ``"time"``.
    rotors : RotorLayout or None, optional
        The rotor layout, from a TOML map's ``[rotors]`` table: with it the
        mixer inputs are derived from the motors (see
        :mod:`flightlogs.readers._table_derived`).

    Raises
    ------
    DataError
        If ``time`` is missing, a name is not canonical or a unit does not fit its signal.
    """

    columns: Mapping[str, TableColumn]
    rotors: RotorLayout | None = None

    def __post_init__(self) -> None:
        if "time" not in self.columns:
            raise DataError("column map: no time column (give time=<column>, e.g. time=0 or time=t:ms)")
        for name, column in self.columns.items():
            if name != "time" and not is_canonical(name):
                raise DataError(
                    f"column map: {name!r} is not a canonical signal name (p, q, r, phi, theta, psi, vn, ve, vd, "
                    "ax, ay, az, delta_lat ... delta_thr, height_agl, motor_N; the list is in flightlogs.signals)"
                )
            if column.unit is not None:
                _conversion(name, column.unit)
        object.__setattr__(self, "columns", dict(self.columns))  # a copy (a mapping proxy would not pickle for Dask)


def parse_table_map(text: str) -> TableMap:
    """A column map from ``name=column[:unit],...`` or from a TOML file of such entries.

    Parameters
    ----------
    text : str
        ``time=0,delta_lat=1,p=2:deg/s``, or the path of a ``.toml`` file
        whose keys are canonical names (at the top level or under
        ``[columns]``) and whose values are ``"column[:unit]"`` strings or
        column indices; its ``[rotors]`` table (``frame = "quad_x"`` or
        ``angles_deg`` and ``spins``; ``full_scale`` for rotor speeds;
        ``gains``, the mixer's roll, pitch and yaw gains, 1 by default) lets
        the mixer inputs be derived from the motors.

    Returns
    -------
    TableMap

    Raises
    ------
    DataError
        If an entry is not ``name=column``, or see :class:`TableMap`.

    Examples
    --------
    >>> m = parse_table_map("time=t:ms,delta_lat=1,p=roll rate:deg/s")
    >>> m.columns["p"]
    TableColumn(column='roll rate', unit='deg/s')
    >>> m.columns["delta_lat"].column
    1
    """
    if text.strip().lower().endswith(".toml"):
        return _toml_map(Path(text.strip()))
    entries: dict[str, TableColumn] = {}
    for entry in (e.strip() for e in text.split(",")):
        name, equals, spec = entry.partition("=")
        if not equals or not name.strip() or not spec.strip():
            raise DataError(f"column map: {entry!r} is not name=column (e.g. p=2 or p=roll_rate:deg/s)")
        entries[name.strip()] = _column(name.strip(), spec.strip())
    return TableMap(entries)


def _toml_map(path: Path) -> TableMap:
    try:
        document = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as err:
        raise DataError(f"{path}: the column map cannot be read ({err.strerror or err})") from err
    except tomllib.TOMLDecodeError as err:
        raise DataError(f"{path}: not a TOML column map ({err})") from err
    table = document.get("columns", {k: v for k, v in document.items() if k != "rotors"})
    entries: dict[str, TableColumn] = {}
    for name, spec in table.items():
        if isinstance(spec, bool) or not isinstance(spec, (int, str)):
            raise DataError(f"{path}: {name} = {spec!r} is neither a column name nor a column index")
        entries[name] = TableColumn(spec) if isinstance(spec, int) else _column(name, spec)
    return TableMap(entries, _rotors(path, document.get("rotors")))


def _rotors(path: Path, table: object) -> RotorLayout | None:
    """The ``[rotors]`` table of a TOML map: a named frame or angles and spins, and the full-scale speed."""
    if table is None:
        return None
    if not isinstance(table, dict):
        raise DataError(f"{path}: rotors must be a table ([rotors] with frame or angles_deg and spins)")
    unknown = set(table) - {"frame", "angles_deg", "spins", "full_scale", "gains"}
    if unknown:
        raise DataError(
            f"{path}: [rotors] has {', '.join(sorted(unknown))}; it takes frame or angles_deg and spins, "
            "full_scale and gains"
        )
    frame = table.get("frame")
    if frame is not None:
        if frame not in FRAMES:
            raise DataError(
                f"{path}: [rotors] frame {frame!r} is not one of {', '.join(FRAMES)} (or give angles_deg and spins)"
            )
        angles, spins = FRAMES[frame]
    else:
        angles, spins = table.get("angles_deg", ()), table.get("spins", ())
    full_scale, gains = table.get("full_scale"), table.get("gains", (1.0, 1.0, 1.0))
    try:
        roll, pitch, yaw = (float(g) for g in gains)
        return RotorLayout(
            tuple(float(a) for a in angles),
            tuple(int(s) for s in spins),
            None if full_scale is None else float(full_scale),
            (roll, pitch, yaw),
        )
    except (TypeError, ValueError) as err:
        raise DataError(
            f"{path}: [rotors] angles_deg, spins, full_scale and gains (3) must be numbers ({err})"
        ) from err


def _column(name: str, spec: str) -> TableColumn:
    """``column[:unit]``; a colon followed by no known unit is an unknown unit."""
    column, colon, unit = spec.rpartition(":")
    if not colon:
        column, unit = spec, ""
    reference: str | int = int(column) if column.strip().isdigit() else column.strip()
    return TableColumn(reference, canonical_unit(unit) if unit.strip() else None)


def _conversion(name: str, unit: str) -> tuple[str, float]:
    """The unit a signal is held in and the factor to it from `unit`; DataError for a unit we do not know."""
    si = "s" if name == "time" else describe(name).unit
    if si == "as logged":
        if unit == "%":
            return "normalised", 0.01
        if unit in AS_LOGGED:
            return AS_LOGGED[unit], 1.0
        raise DataError(f"column map: {name}: unknown unit {unit!r} (known: {', '.join(sorted({*AS_LOGGED, '%'}))})")
    factor = si_factor(unit, si)
    if factor is None:
        raise DataError(
            f"column map: {name} is in {si}; unknown unit {unit!r} for it (known: {', '.join(SI_SIZES[si])})"
        )
    return si, factor


def is_table(path: Path) -> bool:
    """Whether `path` is a Parquet file or a text table of numbers (two or more delimited columns).

    Parameters
    ----------
    path : Path
        Any file.
    """
    try:
        with Path(path).open("rb") as stream:
            head = stream.read(4096)
    except OSError:
        return False
    if head.startswith(_PARQUET_MAGIC):
        return True
    if b"\x00" in head:
        return False
    lines = [line for line in head.decode("utf-8", errors="replace").splitlines()[:5] if line.strip()]
    return bool(lines) and _delimiter(lines[0]) is not None


def read_table(
    path: str | Path, table_map: TableMap, *, progress: Callable[[int, int], None] | None = None
) -> FlightLog:
    """Read a CSV or Parquet table through its column map.

    Parameters
    ----------
    path : str or Path
        The table.
    table_map : TableMap
        Which column is which signal.
    progress : callable, optional
        ``progress(done, total)`` in bytes.

    Returns
    -------
    FlightLog
        ``log_format="table"``, ``autopilot="unknown"``; each signal on the
        rows where its column has a value, in SI units.

    Raises
    ------
    LogFormatError
        If the file is not a table.
    DataError
        If a mapped column is missing, empty or not numbers, time is missing
        or goes back, or a unit does not fit (each names the column, and the
        line or row).

    Warns
    -----
    DataQualityWarning
        When the time column's unit was found from its interval, not given.
    """
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as err:
        raise LogFormatError(f"{path}: cannot be read ({err.strerror or err})") from err
    columns = _parquet(path, raw, table_map) if raw.startswith(_PARQUET_MAGIC) else _csv(path, raw, table_map)
    time_column = columns.pop("time")
    time_s, utc_offset_s, note = _time(path, time_column, table_map.columns["time"])
    signals = {}
    for name, column in columns.items():
        unit, factor = _conversion(name, column.unit)
        has_value = np.isfinite(column.values)
        if not has_value.any():
            raise DataError(f"{path}: {_named(column.label)} ({name}) has no value in any row")
        shown = _named(column.label) + (f" ({column.unit} → {unit})" if column.unit != unit else "")
        signals[name] = Signal(
            name=name,
            time_s=time_s[has_value],
            values=column.values[has_value] * factor,
            unit=unit,
            source=f"{path.name} {shown}",
        )
    signals.update(derived_signals(signals, table_map.rotors))
    if note:
        warnings.warn(DataQualityWarning(note), stacklevel=2)
    if progress is not None:
        progress(len(raw), len(raw))
    return FlightLog(
        path=path,
        log_format="table",
        autopilot="unknown",
        signals=signals,
        vehicle=f"table of {len(signals)} mapped column(s)",
        utc_offset_s=utc_offset_s,
        warnings=(note,) if note else (),
    )


@dataclass(frozen=True, slots=True)
class _Column:
    """One mapped column read: its header label, values (NaN where empty), unit and where each row came from."""

    label: str
    values: np.ndarray
    unit: str
    rows: np.ndarray  # 1-based file line (CSV) or 0-based row (Parquet) of each value, (n_rows,)
    where: str  # "line" or "row"


# --------------------------------------------------------------------------- time


def _time(path: Path, column: _Column, given: TableColumn) -> tuple[np.ndarray, float | None, str]:
    """Times in s from the log's start (UNIX time → UTC offset), and the note when the unit was found, not given."""
    values = column.values
    missing = np.flatnonzero(~np.isfinite(values))
    if missing.size:
        raise DataError(
            f"{path}, {column.where} {column.rows[missing[0]]}: the time {_named(column.label)} has no value"
        )
    back = np.flatnonzero(np.diff(values) < 0)
    if back.size:
        k = back[0] + 1
        raise DataError(
            f"{path}, {column.where} {column.rows[k]}: time goes back in {_named(column.label)} "
            f"({values[k]:.9g} after {values[k - 1]:.9g}); a table's rows must be in time order"
        )
    if values.size < 2:
        raise DataError(f"{path}: fewer than two rows with a time in {_named(column.label)}")
    unit, note = column.unit, ""
    if given.unit is None and column.unit == "":
        step = float(np.median(np.diff(values)))
        unit = "s" if step < 0.5 else "ms" if step < 500 else "us"
        note = (
            f"{path.name}: time {_named(column.label)} read in {unit} (its median interval is {step:.6g}, "
            f"{1.0 / (step * SI_SIZES['s'][unit]):.3g} Hz in {unit}); give time={column.label}:<unit> if it is not"
        )
    _, factor = _conversion("time", unit)
    seconds = values * factor
    if seconds[0] > _UNIX_AFTER_S:
        return seconds - seconds[0], float(seconds[0]), note
    return seconds, None, note


# --------------------------------------------------------------------------- CSV


def _csv(path: Path, raw: bytes, table_map: TableMap) -> dict[str, _Column]:
    if b"\x00" in raw[:4096]:
        raise LogFormatError(f"{path}: binary content, neither a CSV nor a Parquet table")
    text = raw.decode("utf-8-sig", errors="replace")
    numbered = [
        (n, line) for n, line in enumerate(text.splitlines(), 1) if line.strip() and not line.lstrip().startswith("#")
    ]
    if not numbered:
        raise LogFormatError(f"{path}: the table is empty")
    delimiter = _delimiter(numbered[0][1])
    if delimiter is None:
        raise LogFormatError(f"{path}, line {numbered[0][0]}: one column only; a table needs a time and a signal")
    first = _split(numbered[0][1], delimiter)
    header = first if not all(_is_number(cell) for cell in first) else None
    data = numbered[1:] if header is not None else numbered
    if not data:
        raise LogFormatError(f"{path}: a header and no data rows")
    width = len(first)
    labels = header if header is not None else [str(k) for k in range(width)]  # shown as column 2, not '2'
    indices = {name: _index(path, labels, header is not None, name, c.column) for name, c in table_map.columns.items()}
    _check_widths(path, data, delimiter, width)
    frame = _frame(path, data, delimiter, width, sorted(set(indices.values())))
    lines = np.array([n for n, _ in data])
    out = {}
    for name, index in indices.items():
        cells = frame[index]
        values = _numbers(path, cells, lines, labels[index])
        out[name] = _Column(labels[index], values, _unit(labels[index], table_map.columns[name], name), lines, "line")
    return out


def _named(label: str) -> str:
    """``column 2`` for a table without a header, ``column 'roll rate'`` for one with."""
    return f"column {label}" if label.isdigit() else f"column {label!r}"


def _delimiter(line: str) -> str | None:
    """The delimiter of a row: the most frequent of , ; tab |, else runs of spaces; None for one column."""
    best = max(_DELIMITERS, key=line.count)
    if line.count(best):
        return best
    return " " if len(line.split()) > 1 else None


def _split(line: str, delimiter: str) -> list[str]:
    """A row's fields; a quoted field may hold the delimiter (``"roll rate, deg/s"``)."""
    if delimiter == " ":
        return line.split()
    if '"' not in line:
        return [cell.strip() for cell in line.split(delimiter)]
    return [cell.strip() for cell in next(csv.reader([line], delimiter=delimiter, skipinitialspace=True))]


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return cell.strip().lower() in ("", "nan")
    return True


def _index(path: Path, labels: list[str], has_header: bool, name: str, column: str | int) -> int:
    """The 0-based index of `column`; DataError naming it and the columns there are."""
    if isinstance(column, int):
        if column < len(labels):
            return column
        raise DataError(f"{path}: no column {column} for {name}: the table has {len(labels)} (0-{len(labels) - 1})")
    if not has_header:
        raise DataError(f"{path}: {name} names column {column!r} but the table has no header row (give its index)")
    wanted = column.strip().lower()
    for k, label in enumerate(labels):
        match = _BRACKET_UNIT.match(label)
        if label.strip().lower() == wanted or (match is not None and match.group(1).strip().lower() == wanted):
            return k
    raise DataError(f"{path}: no column {column!r} for {name} (columns: {', '.join(labels)})")


def _check_widths(path: Path, data: list[tuple[int, str]], delimiter: str, width: int) -> None:
    """LogFormatError naming the first row whose number of fields is not the first row's."""
    for line, text in data:
        fields = len(_split(text, delimiter)) if delimiter == " " or '"' in text else text.count(delimiter) + 1
        if fields != width:
            raise LogFormatError(f"{path}, line {line}: {fields} fields where the first row has {width}")


def _frame(
    path: Path, data: list[tuple[int, str]], delimiter: str, width: int, used: list[int]
) -> dict[int, np.ndarray]:
    """The `used` columns' cells as text arrays, by index (every row has `width` fields: :func:`_check_widths`)."""
    import pandas as pd

    body = "\n".join(line for _, line in data)
    frame = pd.read_csv(
        io.StringIO(body),
        sep=r"\s+" if delimiter == " " else delimiter,
        header=None,
        names=range(width),
        usecols=used,
        dtype=str,
        keep_default_na=False,
        skipinitialspace=True,
        engine="c",
    )
    return {k: frame[k].to_numpy(dtype=str) for k in used}


def _numbers(path: Path, cells: np.ndarray, lines: np.ndarray, label: str) -> np.ndarray:
    """The cells as floats, NaN where empty; DataError naming the first line that is not a number."""
    stripped = np.char.strip(cells)
    empty = (stripped == "") | (np.char.lower(stripped) == "nan")
    values = np.full(cells.shape, np.nan)
    try:
        values[~empty] = stripped[~empty].astype(np.float64)
    except ValueError:
        for k in np.flatnonzero(~empty):
            if not _is_number(stripped[k]):
                raise DataError(
                    f"{path}, line {lines[k]}: {_named(label)} is not a number ({str(stripped[k])!r})"
                ) from None
    return values


def _unit(label: str, column: TableColumn, name: str) -> str:
    """The column's unit: given, else in the header's brackets (or a time suffix), else SI ('' for time: found later)."""
    if column.unit is not None:
        return column.unit
    match = _BRACKET_UNIT.match(label)
    if match is not None:
        unit = canonical_unit(match.group(2))
        _conversion(name, unit)
        return unit
    if name == "time":
        suffix = _TIME_SUFFIX.search(label.strip())
        return canonical_unit(suffix.group(1)) if suffix and label.strip().lower() != suffix.group(1).lower() else ""
    si = describe(name).unit
    return "normalised" if si == "as logged" else si


# --------------------------------------------------------------------------- Parquet


def _parquet(path: Path, raw: bytes, table_map: TableMap) -> dict[str, _Column]:
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(io.BytesIO(raw))
    except pa.ArrowException as err:
        raise LogFormatError(f"{path}: not a readable Parquet file ({err})") from None
    labels = list(table.column_names)
    out = {}
    for name, column in table_map.columns.items():
        index = _index(path, labels, True, name, column.column) if isinstance(column.column, str) else column.column
        if index >= len(labels):
            _index(path, labels, True, name, index)
        data = table.column(index)
        unit = _unit(labels[index], column, name)
        if pa.types.is_timestamp(data.type):
            data = data.cast(pa.int64())
            unit = unit or {"s": "s", "ms": "ms", "us": "us", "ns": "ns"}[table.schema.field(index).type.unit]
        if not (pa.types.is_integer(data.type) or pa.types.is_floating(data.type) or pa.types.is_boolean(data.type)):
            raise DataError(f"{path}: {_named(labels[index])} ({name}) holds {data.type}, not numbers")
        values = data.to_numpy(zero_copy_only=False).astype(np.float64)
        out[name] = _Column(labels[index], values, unit, np.arange(values.size), "row")
    return out
