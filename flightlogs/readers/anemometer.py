"""Read ground-anemometer wind records (CSV) into earth-frame wind components.

Two layouts are recognised:

``columns``
    A CSV with a header row; the delimiter (comma, semicolon or tab) is
    taken from the header. Columns are found by name (see
    :data:`COLUMN_SYNONYMS`; case, spaces, ``_``, ``-`` and ``.`` ignored) or
    named explicitly through ``columns=``. Time is ISO-8601 (with or without
    zone; naive times are UTC unless ``utc_offset_hours`` says otherwise),
    UNIX epoch seconds or milliseconds (detected from the values), or a
    separate date column (ISO ``YYYY-MM-DD``) with a time-of-day column.
    Wind is speed with meteorological direction (degrees the wind comes
    FROM, 0-360) or meteorological components u (towards east) and v
    (towards north), optionally w (upwards). Speed units come from the
    header: ``speed_kn``, ``Speed (knots)``, ``WS[km/h]``, ``wind speed mph``,
    ``ws_m/s`` ... (see :data:`SPEED_UNITS`).

``responseone``
    A logger capture of the R. M. Young ResponseONE (models 91000/92000)
    ASCII polar output, one reading a line, with no header or any one-line
    header: ``<time>,<sensor line>`` where the sensor line is the
    instrument's own ``a www.ww ddd.d [ttt.t hhh.h pppp.p [nnnnn]] ss*cc``
    (address, speed, direction FROM in degrees, for the 92000 also
    temperature, humidity, pressure and optional rain-gauge tips, status,
    ``*``, hexadecimal XOR checksum of the characters before ``*``). The
    sensor itself carries no clock and no unit: the time is the logger's,
    the unit is m/s unless ``speed_unit`` says otherwise. This layout
    follows the field order of the instrument's ASCII output as described
    in its manual and in open-source drivers; the comma-separated
    timestamp prefix is our convention for a logged capture. Lines failing
    the checksum or with a non-zero status are dropped with a warning.
"""

from __future__ import annotations

import dataclasses
import re
import warnings
from collections.abc import Mapping
from os import PathLike
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from flightlogs.errors import DataError, DataQualityWarning, LogFormatError, collected_warnings
from flightlogs.flightlog import WindMeasurement
from flightlogs.readers._anemometer_text import Table, check_increasing, load_rows, parse_time_columns, parse_times
from flightlogs.readers._responseone import is_responseone, read_readings

__all__ = ["WindMeasurement", "read_anemometer_csv", "COLUMN_SYNONYMS", "SPEED_UNITS"]

#: Column names recognised for each quantity, after lower-casing and removing
#: spaces, ``_``, ``-``, ``.`` and any unit; earlier entries win.
COLUMN_SYNONYMS: Mapping[str, tuple[str, ...]] = MappingProxyType(
    {
        "time": (
            "timestamputc",
            "timeutc",
            "utctime",
            "datetimeutc",
            "utc",
            "datetime",
            "timestamp",
            "time",
            "unixtime",
            "epochtime",
            "epoch",
        ),
        "date": ("date", "dateutc", "utcdate"),
        "speed": ("speed", "ws", "windspeed", "wspd", "wspeed", "windspd", "spd"),
        "direction": ("direction", "dir", "wd", "winddir", "winddirection", "wdir"),
        "u": ("u", "windu", "uwind"),
        "v": ("v", "windv", "vwind"),
        "w": ("w", "windw", "wwind"),
    }
)

#: Speed units recognised in headers (and ``speed_unit``): name → factor to m/s.
SPEED_UNITS: Mapping[str, float] = MappingProxyType(
    {
        "m/s": 1.0,
        "kn": 1852.0 / 3600.0,
        "km/h": 1.0 / 3.6,
        "mph": 0.44704,
        "ft/s": 0.3048,
    }
)
_UNIT_ALIASES = {
    "m/s": "m/s",
    "ms-1": "m/s",
    "ms^-1": "m/s",
    "mps": "m/s",
    "m_s": "m/s",
    "kn": "kn",
    "kt": "kn",
    "kts": "kn",
    "knot": "kn",
    "knots": "kn",
    "km/h": "km/h",
    "kmh": "km/h",
    "kph": "km/h",
    "kmph": "km/h",
    "km_h": "km/h",
    "mph": "mph",
    "mi/h": "mph",
    "ft/s": "ft/s",
    "fps": "ft/s",
    "deg": "deg",
    "degree": "deg",
    "degrees": "deg",
    "°": "deg",
    "rad": "rad",
}
_BRACKET_UNIT = re.compile(r"^(.*?)\s*[\(\[\{]\s*([^\)\]\}]*?)\s*[\)\]\}]\s*$")
_SUFFIX_UNIT = re.compile(
    r"^(.*?)[\s_\-]+(" + "|".join(re.escape(a) for a in sorted(_UNIT_ALIASES, key=len, reverse=True)) + r")$",
    re.IGNORECASE,
)
_KEYS = ("time", "date", "speed", "direction", "u", "v", "w")


def read_anemometer_csv(
    path: str | PathLike[str],
    *,
    columns: Mapping[str, str] | None = None,
    utc_offset_hours: float = 0.0,
    speed_unit: str | None = None,
) -> WindMeasurement:
    """Read an anemometer CSV file into earth-frame wind.

    Parameters
    ----------
    path : str or path-like
        The CSV file (layouts in the module docstring).
    columns : Mapping[str, str], optional
        Column names to use, by quantity: keys among ``"time"``, ``"date"``,
        ``"speed"``, ``"direction"``, ``"u"``, ``"v"``, ``"w"``. Quantities not
        given are found by :data:`COLUMN_SYNONYMS`. An explicit pair (speed
        and direction, or u and v) wins; otherwise speed and direction are
        preferred to u and v. Giving `columns` turns off layout detection.
    utc_offset_hours : float, default 0.0
        Offset of the clock that wrote zone-less times from UTC, h
        (``-7`` for PDT): ``UTC = local - utc_offset_hours``. Ignored for
        times with a zone and for epoch seconds.
    speed_unit : str, optional
        Unit of speeds whose header names none (key or alias of
        :data:`SPEED_UNITS`); m/s when not given, with a warning.

    Returns
    -------
    WindMeasurement

    Raises
    ------
    LogFormatError
        If the file is empty, not a CSV, lacks the columns needed (the
        message lists those found), or has a time that cannot be parsed; the
        message names the file and the 1-based line or the column.
    DataError
        If a used value is empty or NaN, a speed is negative, a direction
        is outside 0-360°, or timestamps repeat or go backwards.
    ValueError
        If `columns` has an unknown key or `speed_unit` is unknown.

    Warns
    -----
    DataQualityWarning
        When m/s is assumed for speeds without a unit, or ResponseONE lines
        flagged by the sensor are dropped.
    LogCorruptionWarning
        When ResponseONE lines failing their checksum are dropped; every
        message is also in ``warnings``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> csv_path = pathlib.Path(tempfile.mkdtemp()) / "wind.csv"
    >>> _ = csv_path.write_text("time,speed_kn,dir\\n2024-05-01T10:00:00Z,10,0\\n"
    ...                         "2024-05-01T10:00:01Z,10,90\\n")
    >>> wind = read_anemometer_csv(csv_path)
    >>> wind.unit, wind.speed_m_s.round(3).tolist()
    ('kn', [5.144, 5.144])
    >>> wind.wind_n.round(3).tolist(), wind.wind_e.round(3).tolist()  # air moves S, then W
    ([-5.144, -0.0], [-0.0, -5.144])
    """
    path = Path(path)
    if columns is not None:
        unknown = sorted(set(columns) - set(_KEYS))
        if unknown:
            raise ValueError(f"columns has unknown keys {unknown}; use {list(_KEYS)}")
    default_unit = _speed_unit_name(speed_unit) if speed_unit is not None else None
    rows, line_numbers = load_rows(path)
    with collected_warnings() as caught:
        if columns is None and is_responseone(rows):
            wind = _read_responseone(path, rows, line_numbers, utc_offset_hours, default_unit)
        else:
            wind = _read_columns(path, rows, line_numbers, columns or {}, utc_offset_hours, default_unit)
    return dataclasses.replace(wind, warnings=caught.messages)


def _read_columns(
    path: Path,
    rows: list[list[str]],
    line_numbers: list[int],
    columns: Mapping[str, str],
    utc_offset_hours: float,
    default_unit: str | None,
) -> WindMeasurement:
    """The ``columns`` layout: a header row, then one sample a row."""
    if not rows:
        raise LogFormatError(f"{path}: no header row and no data (only empty fields or delimiters)")
    header, data, lines = rows[0], rows[1:], line_numbers[1:]
    if not data:
        raise LogFormatError(f"{path}: no data rows below the header (line {line_numbers[0]})")
    used = _resolve_columns(path, header, columns)
    table = Table(path=path, header=header, rows=data, lines=lines)
    utc_s = parse_time_columns(table, used, utc_offset_hours)
    return _wind_from_columns(table, used, utc_s, default_unit)


# --------------------------------------------------------------------------- columns


def _split_unit(name: str) -> tuple[str, str | None]:
    """Split a header into its normalised base name and unit alias (or None)."""
    base, unit = name.strip(), None
    match = _BRACKET_UNIT.match(base)
    if match:
        base, unit = match.group(1), match.group(2)
    else:
        match = _SUFFIX_UNIT.match(base)
        if match and match.group(1):
            base, unit = match.group(1), match.group(2)
    key = _norm(base)
    if unit is not None:
        unit = _UNIT_ALIASES.get(re.sub(r"\s", "", unit.lower()), unit)
    return key, unit


def _resolve_columns(path: Path, header: list[str], explicit: Mapping[str, str]) -> dict[str, str]:
    """Columns used, by quantity: the explicit ones, the rest by synonym."""
    used: dict[str, str] = {}
    for key, name in explicit.items():
        used[key] = _find_header(path, header, name, key)
    keys = [_split_unit(h)[0] for h in header]
    for quantity, synonyms in COLUMN_SYNONYMS.items():
        if quantity in used:
            continue
        for synonym in synonyms:
            hits = [h for h, k in zip(header, keys) if k == synonym and h not in used.values()]
            if len(hits) > 1:
                raise LogFormatError(
                    f"{path}: columns {hits} all look like {quantity}; name one in `columns` ({quantity}=COL)"
                )
            if hits:
                used[quantity] = hits[0]
                break
    polar, cartesian = ("speed", "direction"), ("u", "v")
    if set(cartesian) <= explicit.keys() and not set(polar) <= explicit.keys():
        drop = polar  # the caller asked for u and v
    else:
        drop = cartesian if set(polar) <= used.keys() else polar
    for key in drop:
        used.pop(key, None)
    found = ", ".join(repr(h) for h in header)
    if "time" not in used:
        raise LogFormatError(f"{path}: no time column recognised among {found}; name it in `columns` (time=COL)")
    if not ({"speed", "direction"} <= used.keys() or {"u", "v"} <= used.keys()):
        raise LogFormatError(
            f"{path}: no wind columns recognised (need speed and direction, or u and v) among "
            f"{found}; name them in `columns` (speed=COL,direction=COL or u=COL,v=COL)"
        )
    return used


def _norm(name: str) -> str:
    """Lower case without spaces, ``_``, ``-`` and ``.``."""
    return re.sub(r"[\s_\-\.]", "", name.lower())


def _find_header(path: Path, header: list[str], name: str, key: str) -> str:
    matches = [h for h in header if h == name] or [h for h in header if _norm(h) == _norm(name)]
    if matches:
        return matches[0]
    found = ", ".join(repr(h) for h in header)
    raise LogFormatError(f"{path}: no column {name!r} (given for {key!r}); found {found}")


def _speed_unit_name(unit: str) -> str:
    alias = _UNIT_ALIASES.get(re.sub(r"\s", "", unit.lower()))
    if alias is None or alias not in SPEED_UNITS:
        raise ValueError(f"speed unit {unit!r} is not one of {sorted(SPEED_UNITS)} (or their aliases)")
    return alias


# --------------------------------------------------------------------------- wind


def _wind_from_columns(
    table: Table, used: dict[str, str], utc_s: np.ndarray, default_unit: str | None
) -> WindMeasurement:
    path, kind = table.path, ("speed" if "speed" in used else "u")
    unit, factor = _column_unit(path, used[kind], default_unit, warn=True)
    wind_d = None
    if "w" in used:
        wind_d = -table.numbers(used["w"]) * _column_unit(path, used["w"], default_unit)[1]
    if kind == "speed":
        direction_unit = _split_unit(used["direction"])[1] or "deg"
        speed, direction = _checked_polar(
            path, table.numbers(used["speed"]), table.numbers(used["direction"]), direction_unit, table.lines, used
        )
        return _from_polar(
            path,
            utc_s,
            speed * factor,
            direction,
            wind_d,
            columns=used,
            unit=unit,
            layout="columns",
        )
    wind_e = table.numbers(used["u"]) * factor
    wind_n = table.numbers(used["v"]) * _column_unit(path, used["v"], default_unit)[1]
    direction = np.mod(np.arctan2(-wind_e, -wind_n), 2.0 * np.pi)
    return WindMeasurement(
        path=path,
        utc_s=utc_s,
        wind_n=wind_n,
        wind_e=wind_e,
        speed_m_s=np.hypot(wind_n, wind_e),
        direction_from_rad=direction,
        wind_d=wind_d,
        columns=used,
        unit=unit,
        layout="columns",
    )


def _from_polar(
    path: Path,
    utc_s: np.ndarray,
    speed_m_s: np.ndarray,
    direction_rad: np.ndarray,
    wind_d: np.ndarray | None,
    **metadata: Any,
) -> WindMeasurement:
    """Measurement from speed (m/s) and direction FROM (rad): the air moves the other way."""
    wind_n, wind_e = -speed_m_s * np.cos(direction_rad), -speed_m_s * np.sin(direction_rad)
    return WindMeasurement(
        path=path,
        utc_s=utc_s,
        wind_n=wind_n,
        wind_e=wind_e,
        speed_m_s=speed_m_s,
        direction_from_rad=direction_rad,
        wind_d=wind_d,
        **metadata,
    )


def _column_unit(path: Path, column: str, default_unit: str | None, *, warn: bool = False) -> tuple[str, float]:
    """Speed unit of a column from its header, and its factor to m/s; `warn` when m/s is assumed."""
    unit = _split_unit(column)[1]
    if unit is None:
        if default_unit is None and warn:
            warnings.warn(DataQualityWarning(f"column {column!r} names no unit; m/s assumed"), stacklevel=2)
        unit = default_unit or "m/s"
    if unit not in SPEED_UNITS:
        raise LogFormatError(f"{path}: column {column!r} is in {unit!r}, not a speed unit ({', '.join(SPEED_UNITS)})")
    return unit, SPEED_UNITS[unit]


def _checked_polar(
    path: Path, speed: np.ndarray, direction: np.ndarray, direction_unit: str, lines: list[int], used: Mapping[str, str]
) -> tuple[np.ndarray, np.ndarray]:
    """Speed as given and direction in rad [0, 2π), after checking both line by line."""
    if direction_unit not in ("deg", "rad"):
        raise LogFormatError(
            f"{path}: direction column {used.get('direction')!r} is in {direction_unit!r}, not degrees or radians"
        )
    full_turn = 360.0 if direction_unit == "deg" else 2.0 * np.pi
    negative = np.flatnonzero(speed < 0)
    if negative.size:
        i = int(negative[0])
        raise DataError(f"{path}, line {lines[i]}: speed {speed[i]:g} in column {used.get('speed', '2')!r} is negative")
    outside = np.flatnonzero((direction < 0) | (direction > full_turn))
    if outside.size:
        i = int(outside[0])
        raise DataError(
            f"{path}, line {lines[i]}: direction {direction[i]:g} in column "
            f"{used.get('direction', '3')!r} is outside 0-{full_turn:g} "
            f"{direction_unit}"
        )
    return speed, np.mod(direction * (2.0 * np.pi / full_turn), 2.0 * np.pi)


# --------------------------------------------------------------------------- ResponseONE


def _read_responseone(
    path: Path, rows: list[list[str]], numbers: list[int], utc_offset_hours: float, default_unit: str | None
) -> WindMeasurement:
    """Parse ``<time>,<ResponseONE polar line>`` rows (module docstring)."""
    found = read_readings(path, rows, numbers)
    utc_s = parse_times(path, found.times, found.lines, "1", utc_offset_hours)
    check_increasing(path, utc_s, found.times, found.lines)
    speed, direction = _checked_polar(path, found.speeds, found.directions_deg, "deg", found.lines, {})
    if default_unit is None:
        message = "ResponseONE readings carry no unit; m/s assumed (pass speed_unit=)"
        warnings.warn(DataQualityWarning(message), stacklevel=2)
    unit = default_unit or "m/s"
    columns = {
        "time": found.time_column,
        "speed": "ResponseONE field 2 (wind speed)",
        "direction": "ResponseONE field 3 (wind direction, from)",
    }
    return _from_polar(
        path,
        utc_s,
        speed * SPEED_UNITS[unit],
        direction,
        None,
        columns=columns,
        unit=unit,
        layout="responseone",
    )
