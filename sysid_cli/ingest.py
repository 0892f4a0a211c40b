"""``sysid ingest``: read flight logs and anemometer files into aligned, segmented records."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import click

from ._common import OutputPath, SysidCommand, emit_json, json_option, progress_bar
from ._flags import as_flags
from ._flights import reading_from, reading_options
from ._warnings import grouped, mark_reported
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
    summary = _summary(campaign, out)
    if not quiet:
        _print_summary(summary)
    emit_json(summary, json_path)


def _summary(campaign: Any, out: Path | None) -> dict[str, Any]:
    from flightlogs.store.summary import conditioned_summary, log_summary, wind_summary

    entries = []
    for log, flight, notes in zip(campaign.logs, campaign.conditioned, campaign.notes):
        entry = log_summary(log)
        if flight is not None:
            entry.update({k: v for k, v in conditioned_summary(flight).items() if k != "warnings"})
            entry["warnings"] += conditioned_summary(flight)["warnings"]
        entry["warnings"] += list(notes)
        entries.append(entry)
    summary: dict[str, Any] = dict(entries[0]) if len(entries) == 1 else {}
    summary["logs"] = entries
    summary["wind"] = [wind_summary(wind) for wind in campaign.winds]
    summary["output"] = str(out) if out is not None else None
    return summary


def _print_summary(summary: dict[str, Any]) -> None:
    say = click.echo
    for entry in summary["logs"]:
        say(
            f"{entry['path']}: {entry['autopilot']} {entry['log_format']}, "
            f"{entry['vehicle'] or 'vehicle unknown'}, {entry['duration_s']:.1f} s"
            + (f", starts {entry['utc_start']}" if entry["utc_start"] else ", no GPS time")
        )
        say(f"  {'signal':<11} {'samples':>8} {'rate Hz':>8}  {'unit':<20} source")
        for name, info in entry["signals"].items():
            say(f"  {name:<11} {info['samples']:>8} {info['rate_hz']:>8.1f}  {info['unit']:<20} {info['source']}")
        if entry["missing"]:
            say(f"  missing: {', '.join(entry['missing'])}")
        alignment = entry.get("wind_alignment")
        if alignment:
            say(
                f"  wind {alignment['wind_file']}: clock offset {alignment['clock_offset_s']:+.3f} s "
                f"({alignment['clock_offset_source']}), transport delay {alignment['transport_delay_s']:.3f} s "
                f"({alignment['transport_delay_source']}"
                + (f", {alignment['distance_m']:.2f} m" if alignment["distance_m"] is not None else "")
                + f"), mean {alignment['mean_speed_m_s']:.2f} m/s"
            )
            if alignment["residual_offset_s"] is not None:
                say(
                    f"    residual clock offset {alignment['residual_offset_s']:+.3f} s against "
                    f"{alignment['residual_against']}, modelled as lagging the air by a first-order "
                    f"{alignment['residual_lag_modelled_s']:g} s (correlation {alignment['residual_correlation']:.2f})"
                )
        for record in entry.get("records", []):
            say(
                f"  record {record['label']}: {record['start_s']:.2f}-{record['end_s']:.2f} s, "
                f"{record['samples']} samples at {entry['rate_hz']:.0f} Hz"
            )
        for segment in entry.get("segments", []):
            axis = segment["axis"] or "-"
            say(
                f"  {segment['kind']:<8} {axis:<4} {segment['start_s']:8.2f}-{segment['end_s']:8.2f} s  ({segment['source']})"
            )
        if "segments" in entry and all(s["kind"] == "hover" for s in entry["segments"]):
            hovers = len(entry["segments"])
            say(
                "  no maneuver found (no sweep, doublet, 3-2-1-1, multisine or pilot's broadband input)"
                + (f"; {hovers} hover stretch{'es' if hovers > 1 else ''}" if hovers else "")
            )
        for warning in grouped(entry["warnings"]):
            say(f"  warning: {as_flags(warning)}")
        mark_reported(entry["warnings"])
    if summary["output"]:
        say(f"wrote {summary['output']}")
