"""``sysid ingest``: read flight logs and anemometer files into aligned, segmented records."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import click

from ._common import OutputPath, SysidCommand, emit_json, json_option, progress_bar
from ._flights import reading_from, reading_options
from ._tables import print_ingest
from ._wind_options import (
    anemometer_at_option,
    parse_position,
    segments_from,
    segments_option,
    transport_delay_option,
    wind_distance_option,
    wind_offset_option,
    wind_option,
)

__all__ = ["ingest", "parse_columns", "parse_position"]

_EPILOG = """\b
Examples:
  sysid ingest flight.ulg --json -
  sysid ingest 00000042.BIN --wind mast.csv --wind-distance 4.6 -o flight.h5
  sysid ingest sweeps/*.bin --wind anemometer/ --wind-distance 4.6 -o campaign.h5
  sysid ingest flight.bin --wind mast.csv --anemometer-at 35.000021,-106.900043 --json -
  sysid ingest flight.ulg --wind mast.csv --columns time=UTC,speed=WS,direction=WD --transport-delay 0.8
"""


def parse_columns(_ctx: click.Context, _param: click.Parameter, value: str | None) -> dict[str, str] | None:
    """Parse ``key=column,key=column`` into a mapping (click callback)."""
    if not value:
        return None
    mapping: dict[str, str] = {}
    for item in value.split(","):
        key, sep, column = item.partition("=")
        if not sep or not key.strip() or not column.strip():
            raise click.BadParameter(f"{item!r} is not KEY=COLUMN (e.g. time=UTC,speed=WS)")
        mapping[key.strip()] = column.strip()
    return mapping


def _wind_columns(ctx: click.Context, param: click.Parameter, value: str | None) -> dict[str, str] | None:
    """:func:`parse_columns`, keeping to the anemometer's keys (time, date, speed, direction, u, v, w)."""
    from flightlogs.readers.anemometer import COLUMN_SYNONYMS

    mapping = parse_columns(ctx, param, value)
    unknown = sorted(set(mapping or {}) - set(COLUMN_SYNONYMS))
    if unknown:
        raise click.BadParameter(
            f"{', '.join(unknown)}: not a column key; use --columns "
            + ",".join(f"{key}=COL" for key in COLUMN_SYNONYMS)
        )
    return mapping


#: Highest ``--rate``, Hz: above any autopilot's logging rate, and a bound on the time base's memory.
_MAX_RATE_HZ = 10_000.0


@click.command(cls=SysidCommand, epilog=_EPILOG)
@click.argument("logs", nargs=-1, required=True, type=click.Path(exists=True, dir_okay=False, path_type=Path))
@wind_option("Anemometer CSV, or a folder of them (repeatable); each log takes the file overlapping it in UTC.")
@click.option(
    "--columns",
    callback=_wind_columns,
    help="Override anemometer column detection: time=,speed=,direction= or time=,u=,v=.",
)
@wind_distance_option()
@click.option(
    "--wind-bearing",
    type=float,
    metavar="DEG",
    help="Direction from the anemometer to the vehicle, deg from north (default: straight upstream).",
)
@anemometer_at_option(
    "Anemometer position, deg (WGS-84); without --wind-distance, the distance and bearing "
    "to the vehicle come from its mean GPS position in the log."
)
@transport_delay_option()
@wind_offset_option()
@click.option(
    "--estimate-wind-offset",
    is_flag=True,
    help="Correct the clock offset by cross-correlating the wind with the vehicle's response.",
)
@click.option(
    "--estimate-transport-delay",
    is_flag=True,
    help="Find the transport delay by that cross-correlation instead (trusting the clock offset).",
)
@click.option(
    "--rate",
    "rate_hz",
    type=click.FloatRange(min=0, min_open=True, max=_MAX_RATE_HZ),
    metavar="HZ",
    help="Rate of the common time base, up to 10 kHz (default: the fastest core signal's).",
)
@segments_option("TOML or CSV of maneuvers (start_s, end_s, axis[, kind]) overriding detection.")
@reading_options()
@click.option("-o", "--out", type=OutputPath(), help="Write signals, records and segments to this HDF5 dataset.")
@json_option
@click.option("-q", "--quiet", is_flag=True, help="No progress bar and no table.")
def ingest(
    logs: tuple[Path, ...],
    wind_paths: tuple[Path, ...],
    columns: dict[str, str] | None,
    wind_distance: float | None,
    wind_bearing: float | None,
    anemometer_at: tuple[float, float] | None,
    transport_delay: float | None,
    wind_offset: float | None,
    estimate_wind_offset: bool,
    estimate_transport_delay: bool,
    rate_hz: float | None,
    segments_file: Path | None,
    table_map: Any,
    vehicle: str | None,
    out: Path | None,
    json_path: str | None,
    quiet: bool,
) -> None:
    """Read LOGS (PX4 .ulg, ArduPilot .bin or MAVLink .tlog, detected from content; CSV or Parquet tables with --map), report every
    canonical signal with its rate, unit and source, align the anemometer wind, and find the maneuvers."""
    from flightlogs.conditioning.condition import ConditioningOptions
    from flightlogs.store.campaign import ingest_campaign
    from flightlogs.store.summary import campaign_summary

    if estimate_wind_offset and estimate_transport_delay:
        raise click.UsageError("--estimate-wind-offset and --estimate-transport-delay shift the wind alike; pick one")
    options = ConditioningOptions(
        rate_hz=rate_hz,
        wind_offset_s=wind_offset,
        estimate_wind_offset=estimate_wind_offset,
        estimate_transport_delay=estimate_transport_delay,
        wind_distance_m=wind_distance,
        wind_bearing_rad=None if wind_bearing is None else math.radians(wind_bearing),
        anemometer_position_rad=anemometer_at,
        transport_delay_s=transport_delay,
        segments=segments_from(segments_file),
    )
    with progress_bar("reading", unit="bytes", quiet=quiet) as bar:
        campaign = ingest_campaign(
            list(logs),
            list(wind_paths),
            columns=columns,
            options=options,
            progress=lambda _name, done, total: bar(done, total),
            reading=reading_from(table_map, vehicle),
        )
    if out is not None:
        from flightlogs.store.dataset import write_dataset  # h5py: loaded only to write

        campaign.require_flights()  # no dataset without a flight in it; some not conditioned: warned below
        write_dataset(out, campaign.logs, campaign.winds, list(campaign.flights))
    summary = campaign_summary(campaign, out)
    if not quiet:
        print_ingest(summary)
    emit_json(summary, json_path)
