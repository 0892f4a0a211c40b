"""The anemometer options shared by ``ingest``, ``fit``, ``freqresp`` and ``validate``: one type, name and unit each.

Each factory returns a click decorator; `help` says what the option means to
that command where it differs.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

if TYPE_CHECKING:
    from flightlogs.maneuvers.segments import Segment

__all__ = [
    "parse_position",
    "wind_option",
    "wind_distance_option",
    "wind_offset_option",
    "transport_delay_option",
    "anemometer_at_option",
    "segments_option",
    "segments_from",
]

_Decorator = Callable[[Callable[..., Any]], Callable[..., Any]]


def parse_position(_ctx: click.Context, _param: click.Parameter, value: str | None) -> tuple[float, float] | None:
    """Parse ``LAT,LON`` in degrees into latitude and longitude in radians (click callback)."""
    if value is None:
        return None
    parts = value.split(",")
    try:
        lat, lon = (float(part) for part in parts)
    except ValueError:
        raise click.BadParameter(f"{value!r} is not LAT,LON in decimal degrees (e.g. 35.000021,-106.900043)") from None
    if not (math.isfinite(lat) and math.isfinite(lon) and abs(lat) <= 90.0 and abs(lon) <= 180.0):
        raise click.BadParameter(f"{value!r}: latitude must lie within ±90° and longitude within ±180°")
    return math.radians(lat), math.radians(lon)


def wind_option(help: str) -> _Decorator:
    """``--wind PATH`` (repeatable, into ``wind_paths``): anemometer CSV files or folders."""
    return click.option("--wind", "wind_paths", multiple=True, type=click.Path(exists=True, path_type=Path), help=help)


def wind_distance_option(
    help: str = "Anemometer-to-vehicle distance, m (transport delay = distance / mean wind speed).",
) -> _Decorator:
    """``--wind-distance M``: anemometer-to-vehicle distance, m (positive)."""
    return click.option("--wind-distance", type=click.FloatRange(min=0, min_open=True), metavar="M", help=help)


def wind_offset_option(
    help: str = "Anemometer clock minus UTC, s (minus the log's clock when the log has no GPS time).",
) -> _Decorator:
    """``--wind-offset S``: anemometer clock minus UTC, s."""
    return click.option("--wind-offset", type=float, metavar="S", help=help)


def transport_delay_option(help: str = "Use this transport delay, s, instead.") -> _Decorator:
    """``--transport-delay S``: the wind's transport delay, s."""
    return click.option("--transport-delay", type=float, metavar="S", help=help)


def anemometer_at_option(help: str) -> _Decorator:
    """``--anemometer-at LAT,LON`` (deg, into radians as ``anemometer_at``)."""
    return click.option("--anemometer-at", "anemometer_at", callback=parse_position, metavar="LAT,LON", help=help)


def segments_option(help: str) -> _Decorator:
    """``--segments FILE`` (into ``segments_file``): maneuvers overriding detection."""
    return click.option(
        "--segments", "segments_file", type=click.Path(exists=True, dir_okay=False, path_type=Path), help=help
    )


def segments_from(segments_file: Path | None) -> tuple[Segment, ...] | None:
    """The maneuvers of ``--segments`` (:func:`flightlogs.readers.segments_file.read_segments_file`), or None without it."""
    from flightlogs.readers.segments_file import read_segments_file

    return read_segments_file(segments_file) if segments_file is not None else None
