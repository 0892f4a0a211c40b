"""Ground-effect test-rig CSV files: thrust measured at a series of heights above a surface.

The rig of chapter 2 (section 2.3.2) holds the vehicle upside down on a
digital scale under a table that stands in for the ground; each row is one
reading: the height of the rotor plane above that surface and the thrust.
The default layout is a header line and two columns::

    height_m,thrust_n
    0.025,0.4412
    0.035,0.4254

Column names can be overridden, and other units are read from the name's
suffix (``height_cm``, ``height (mm)``, ``thrust_g``, ``thrust [kg]``; grams and
kilograms are of force, converted with standard gravity) or given
explicitly; a column with the wanted stem in another unit (``height_cm`` for
``height_m``) is taken when it is the only one. Extra columns are ignored; ``#`` starts a comment line; the
delimiter may be a comma, semicolon or tab.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from flightlogs.errors import DataError, LogFormatError
from flightlogs.readers._anemometer_text import Table, load_rows

__all__ = ["RigData", "read_rig_csv", "HEIGHT_UNITS", "THRUST_UNITS"]

#: Height units understood, and their size in metres.
HEIGHT_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254}
#: Thrust units understood, and their size in newtons (g and kg are gram- and kilogram-force).
THRUST_UNITS = {"n": 1.0, "mn": 0.001, "g": 9.80665e-3, "kg": 9.80665, "gf": 9.80665e-3, "kgf": 9.80665}
_SUFFIX = re.compile(r"(?:[_ ]|\s*[(\[])([a-z]+)[)\]]?\s*$", re.IGNORECASE)


@dataclass(frozen=True, slots=True, kw_only=True)
class RigData:
    """Thrust readings of a ground-effect rig, in SI units.

    Parameters
    ----------
    path : Path
        The file read.
    height_m : ndarray, shape (n_rows,)
        Rotor plane above the surface, m (> 0).
    thrust_n : ndarray, shape (n_rows,)
        Measured thrust, N (> 0).
    lines : ndarray of int, shape (n_rows,)
        1-based line of each reading in the file, for messages.
    height_source, thrust_source : str
        Column and unit each came from, e.g. ``"height_cm (cm→m)"``.
    """

    path: Path
    height_m: np.ndarray
    thrust_n: np.ndarray
    lines: np.ndarray
    height_source: str = "height_m"
    thrust_source: str = "thrust_n"

    def __post_init__(self) -> None:
        height = np.ascontiguousarray(self.height_m, dtype=np.float64)
        thrust = np.ascontiguousarray(self.thrust_n, dtype=np.float64)
        lines = np.ascontiguousarray(self.lines, dtype=np.int64)
        if height.ndim != 1 or thrust.shape != height.shape or lines.shape != height.shape or height.size == 0:
            raise ValueError(
                f"{self.path}: height_m {height.shape}, thrust_n {thrust.shape} and lines "
                f"{lines.shape} must be 1-D, non-empty and of equal length"
            )
        for array in (height, thrust, lines):
            array.setflags(write=False)
        object.__setattr__(self, "height_m", height)
        object.__setattr__(self, "thrust_n", thrust)
        object.__setattr__(self, "lines", lines)


def read_rig_csv(
    path: str | Path,
    *,
    height_column: str = "height_m",
    thrust_column: str = "thrust_n",
    height_unit: str | None = None,
    thrust_unit: str | None = None,
) -> RigData:
    """Read a ground-effect rig CSV (one reading per row) into SI units.

    Parameters
    ----------
    path : str or Path
        The CSV file.
    height_column, thrust_column : str, optional
        Header names of the height and thrust columns (matched ignoring case
        and surrounding blanks).
    height_unit : {"m", "cm", "mm", "in"}, optional
        Unit of the height column; default from the column name's suffix.
    thrust_unit : {"n", "mn", "g", "kg", "gf", "kgf"}, optional
        Unit of the thrust column (g and kg are of force); default from the
        column name's suffix.

    Returns
    -------
    RigData
        Heights in m and thrusts in N, in file order.

    Raises
    ------
    DataError
        If the file is empty or not a CSV, a column is missing or its unit
        unknown, or a cell is not a positive finite number (the message names
        the file and line).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> csv = pathlib.Path(tempfile.mkdtemp()) / "rig.csv"
    >>> _ = csv.write_text("height_cm,thrust_g\\n2.5,45.0\\n20,39.1\\n")
    >>> rig = read_rig_csv(csv)
    >>> rig.height_m.tolist(), rig.thrust_n.round(4).tolist()
    ([0.025, 0.2], [0.4413, 0.3834])
    """
    path = Path(path)
    try:
        rows, numbers = load_rows(path)
    except LogFormatError as err:
        raise DataError(str(err)) from err
    except OSError as err:
        raise DataError(f"{path}: cannot be read ({err.strerror or err})") from err
    header = [cell.strip() for cell in rows[0]]
    table = Table(path=path, header=header, rows=rows[1:], lines=numbers[1:])
    if not table.rows:
        raise DataError(f"{path}, line {numbers[0]}: a header but no readings")
    height_name = _column(table, height_column, numbers[0])
    thrust_name = _column(table, thrust_column, numbers[0])
    height_scale, height_label = _unit(path, height_name, height_unit, HEIGHT_UNITS, "height")
    thrust_scale, thrust_label = _unit(path, thrust_name, thrust_unit, THRUST_UNITS, "thrust")
    try:
        height = table.numbers(height_name) * height_scale
        thrust = table.numbers(thrust_name) * thrust_scale
    except LogFormatError as err:
        raise DataError(str(err)) from err
    lines = np.asarray(table.lines)
    for values, name in ((height, height_name), (thrust, thrust_name)):
        bad = np.flatnonzero(values <= 0)
        if bad.size:
            raise DataError(
                f"{path}, line {lines[bad[0]]}: column {name!r} must be > 0, "
                f"got {values[bad[0]] / (height_scale if name == height_name else thrust_scale):g}"
            )
    return RigData(
        path=path,
        height_m=height,
        thrust_n=thrust,
        lines=lines,
        height_source=f"{height_name}{height_label}",
        thrust_source=f"{thrust_name}{thrust_label}",
    )


def _column(table: Table, wanted: str, header_line: int) -> str:
    """The header name matching `wanted` (ignoring case and blanks), else the one with its stem in another unit."""
    for name in table.header:
        if name.strip().lower() == wanted.strip().lower():
            return name
    same_stem = [name for name in table.header if _stem(name) == _stem(wanted)]
    if len(same_stem) == 1:
        return same_stem[0]
    raise DataError(
        f"{table.path}, line {header_line}: no column {wanted!r}; the header has "
        f"{', '.join(repr(n) for n in table.header)} (name the columns to use)"
    )


def _stem(column: str) -> str:
    """A column name without its unit suffix, lower case: ``"Height (cm)"`` -> ``"height"``."""
    return _SUFFIX.sub("", column.strip()).strip().lower()


def _unit(path: Path, column: str, unit: str | None, units: dict[str, float], what: str) -> tuple[float, str]:
    """Scale to SI and a label for the source, from the given unit or the column's suffix."""
    given = unit
    if given is None:
        match = _SUFFIX.search(column)
        given = match.group(1) if match else None
        if given is None or given.lower() not in units:
            raise DataError(
                f"{path}: cannot tell the unit of {what} column {column!r}; name it like "
                f"{what}_{next(iter(units))} or give the unit ({', '.join(units)})"
            )
    key = given.lower()
    if key not in units:
        raise DataError(f"{path}: {what} unit {given!r} is not one of {', '.join(units)}")
    si = "m" if what == "height" else "N"
    return units[key], "" if units[key] == 1.0 else f" ({key}→{si})"
