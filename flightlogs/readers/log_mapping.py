"""The operator's record of which vehicle flew which log: a CSV of ``file, vehicle, date, payload_kg, ...``.

Each row names a log (a path relative to the CSV's folder, or a bare file
name) and gives it keys to group and trend by. Any other column is a key
too (``--group-by battery``).
"""

from __future__ import annotations

import csv
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

from flightlogs.errors import DataError

__all__ = ["LogMapping", "read_log_mapping"]


@dataclass(frozen=True, slots=True)
class LogMapping:
    """Keys per log, found by the log's path or, failing that, by its file name.

    Parameters
    ----------
    source : Path
        The CSV read.
    by_path : Mapping[str, Mapping[str, str]]
        Keys of each row, by the log's absolute path.
    columns : tuple of str
        The CSV's columns other than ``file``.
    """

    source: Path
    by_path: Mapping[str, Mapping[str, str]]
    columns: tuple[str, ...]

    def keys_of(self, log: str | Path) -> Mapping[str, str]:
        """The keys of `log` (absolute path), or an empty mapping when no row names it."""
        path = Path(log).resolve()
        found = self.by_path.get(str(path))
        if found is None:
            found = next((keys for p, keys in self.by_path.items() if Path(p).name == path.name), None)
        return found if found is not None else MappingProxyType({})


def read_log_mapping(path: str | Path) -> LogMapping:
    """Read a mapping CSV (header ``file, ...``; empty cells are "not known").

    Parameters
    ----------
    path : str or Path
        The CSV.

    Returns
    -------
    LogMapping

    Raises
    ------
    DataError
        If it has no ``file`` column, a row names no file or names one twice (naming the line).
    """
    path = Path(path)
    try:
        with path.open(newline="", encoding="utf-8-sig") as stream:
            rows = list(csv.reader(stream))
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise DataError(f"{path}: cannot read the log mapping ({err})") from None
    if not rows or "file" not in [c.strip() for c in rows[0]]:
        raise DataError(f"{path}: line 1 must be a header with a 'file' column (file, vehicle, date, ...)")
    header = [c.strip() for c in rows[0]]
    by_path: dict[str, Mapping[str, str]] = {}
    for line, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        cells = dict(zip(header, (cell.strip() for cell in row)))
        name = cells.pop("file", "")
        if not name:
            raise DataError(f"{path}, line {line}: no file named")
        log = str((path.parent / name).resolve())
        if log in by_path:
            raise DataError(f"{path}, line {line}: {name} is named twice")
        by_path[log] = MappingProxyType({k: v for k, v in cells.items() if v})
    return LogMapping(source=path, by_path=MappingProxyType(by_path), columns=tuple(c for c in header if c != "file"))
