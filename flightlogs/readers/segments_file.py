"""Segment files: maneuvers a user gives by hand, as TOML ``[[segment]]`` tables or CSV rows."""

from __future__ import annotations

import csv
import re
from pathlib import Path
from typing import Any

from flightlogs.errors import DataError
from flightlogs.segment import Segment

__all__ = ["read_segments_file", "segment_line"]

_USER_KEYS = ("start_s", "end_s", "axis", "kind", "f_min_hz", "f_max_hz")


def read_segments_file(path: str | Path) -> tuple[Segment, ...]:
    """Read user-defined segments from a TOML or CSV file.

    Parameters
    ----------
    path : str or Path
        ``.toml`` with ``[[segment]]`` tables (keys ``start_s``, ``end_s``,
        ``axis``, ``kind``, ``f_min_hz``, ``f_max_hz``), or ``.csv`` with rows
        ``start_s,end_s,axis[,kind[,f_min_hz,f_max_hz]]`` (a header row naming
        the columns is optional; ``#`` starts a comment line). `kind` defaults
        to ``"sweep"``; hover rows leave `axis` empty.

    Returns
    -------
    tuple of Segment
        ``source="user"``, in time order.

    Raises
    ------
    DataError
        If the file cannot be read or parsed, holds no segment, or a row is
        invalid (end before start, unknown axis or kind, not a number); the
        message names the file and the line.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = Path(tmp) / "segments.csv"
    ...     _ = path.write_text("start_s,end_s,axis,kind\\n12.5,46.5,lon,sweep\\n")
    ...     read_segments_file(path)[0].axis
    'lon'
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise DataError(f"{path}: cannot be read ({err}).") from err
    suffix = path.suffix.lower()
    if suffix not in (".toml", ".csv"):
        raise DataError(f"{path}: a segments file is .toml or .csv, not {suffix or 'without extension'}.")
    entries = _toml_entries(path, text) if suffix == ".toml" else _csv_entries(path, text)
    if not entries:
        raise DataError(f"{path}: no segment found.")
    segments = []
    for line, entry in entries:
        try:
            segments.append(_user_segment(entry))
        except DataError as err:
            raise DataError(f"{path}:{line}: {err}.") from None
    return tuple(sorted(segments, key=lambda s: s.start_s))


def segment_line(path: str | Path, segment: Segment) -> int | None:
    """The line (from 1) of a CSV segments file whose first two fields are the segment's bounds.

    Parameters
    ----------
    path : str or Path
        The segments file the segment was read from.
    segment : Segment
        One of its segments.

    Returns
    -------
    int or None
        None for a TOML file, or when no row has those bounds.
    """
    path = Path(path)
    if path.suffix.lower() != ".csv":
        return None
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        fields = line.split(",")
        try:
            if len(fields) >= 2 and (float(fields[0]), float(fields[1])) == (segment.start_s, segment.end_s):
                return number
        except ValueError:
            continue
    return None


def _toml_entries(path: Path, text: str) -> list[tuple[int, dict[str, Any]]]:
    import tomllib  # here, not at import: only segment files need it

    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise DataError(f"{path}: not valid TOML ({err}).") from err
    unknown = [key for key in data if key != "segment"]
    if unknown:
        raise DataError(f"{path}: unknown top-level key {unknown[0]!r} (expected [[segment]] tables).")
    tables = data.get("segment", [])
    if not isinstance(tables, list) or not all(isinstance(item, dict) for item in tables):
        raise DataError(f"{path}: 'segment' must be an array of tables, written [[segment]].")
    lines = [n for n, row in enumerate(text.splitlines(), 1) if re.match(r"\s*\[\[\s*segment\s*\]\]", row)]
    return list(zip(lines + [0] * (len(tables) - len(lines)), tables))


def _csv_entries(path: Path, text: str) -> list[tuple[int, dict[str, Any]]]:
    entries: list[tuple[int, dict[str, Any]]] = []
    header = None
    for line, row in enumerate(csv.reader(text.splitlines()), 1):
        cells = [cell.strip() for cell in row]
        if not any(cells) or cells[0].startswith("#"):
            continue
        if header is None and not entries and not _is_number(cells[0]):
            header = [cell.lower() for cell in cells]
            unknown = [name for name in header if name not in _USER_KEYS]
            if unknown:
                raise DataError(f"{path}:{line}: unknown column {unknown[0]!r} (expected {', '.join(_USER_KEYS)}).")
            continue
        names = header or list(_USER_KEYS)
        if len(cells) > len(names):
            raise DataError(f"{path}:{line}: {len(cells)} fields, expected at most {len(names)}.")
        entries.append((line, {name: cell for name, cell in zip(names, cells) if cell != ""}))
    return entries


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _user_segment(entry: dict[str, Any]) -> Segment:
    unknown = [key for key in entry if key not in _USER_KEYS]
    if unknown:
        raise DataError(f"unknown key {unknown[0]!r} (expected {', '.join(_USER_KEYS)})")
    values: dict[str, Any] = {}
    for key in ("start_s", "end_s", "f_min_hz", "f_max_hz"):
        if key in entry:
            try:
                values[key] = float(entry[key])
            except (TypeError, ValueError):
                raise DataError(f"{key}={entry[key]!r} is not a number") from None
        elif key in ("start_s", "end_s"):
            raise DataError(f"{key} is missing")
    if values["end_s"] <= values["start_s"]:
        raise DataError(f"end_s={values['end_s']:g} is not after start_s={values['start_s']:g}")
    axis = str(entry.get("axis", "")).strip().lower()
    kind = str(entry.get("kind", "sweep")).strip().lower()
    return Segment(axis=None if axis in ("", "none") else axis, kind=kind, source="user", **values)  # type: ignore[arg-type]
