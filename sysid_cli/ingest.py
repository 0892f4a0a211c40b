"""``sysid ingest``: read a flight log (and anemometer CSVs) into canonical signals."""

from __future__ import annotations

from pathlib import Path

import click

from ._common import emit_json, json_option, progress_bar

__all__ = ["ingest", "parse_columns"]

_EPILOG = """\b
Examples:
  sysid ingest flight.ulg --json -
  sysid ingest 00000042.BIN --wind mast.csv -o flight.h5
  sysid ingest flight.ulg --wind mast.csv --columns time=UTC,speed=WS,direction=WD
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


@click.command(epilog=_EPILOG)
@click.argument("log", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option(
    "--wind", "wind_paths", multiple=True,
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    help="Anemometer CSV (repeatable).",
)
@click.option(
    "--columns", callback=parse_columns,
    help="Override anemometer column detection: time=,speed=,direction= or time=,u=,v=.",
)
@click.option(
    "-o", "--out", type=click.Path(dir_okay=False, writable=True, path_type=Path),
    help="Write the canonical signals to this HDF5 dataset.",
)
@json_option
@click.option("-q", "--quiet", is_flag=True, help="No progress bar and no table.")
def ingest(
    log: Path,
    wind_paths: tuple[Path, ...],
    columns: dict[str, str] | None,
    out: Path | None,
    json_path: str | None,
    quiet: bool,
) -> None:
    """Read LOG (PX4 .ulg, ArduPilot .bin or MAVLink .tlog, detected from content)
    and report every canonical signal found, with its rate, unit and source."""
    from flightlogs.anemometer import read_anemometer_csv
    from flightlogs.reader import read_log
    from flightlogs.store import write_dataset
    from flightlogs.summary import log_summary, wind_summary

    with progress_bar(f"reading {log.name}", quiet=quiet) as progress:
        flight = read_log(log, progress=progress)
    winds = [read_anemometer_csv(path, columns=columns) for path in wind_paths]
    if out is not None:
        write_dataset(out, [flight], winds)

    summary = log_summary(flight)
    summary["wind"] = [wind_summary(wind) for wind in winds]
    summary["output"] = str(out) if out is not None else None
    if not quiet:
        _print_table(summary, to_stderr=json_path == "-")
    emit_json(summary, json_path)


def _print_table(summary: dict, *, to_stderr: bool) -> None:
    def say(text: str = "") -> None:
        click.echo(text, err=to_stderr)

    say(f"{summary['path']}: {summary['autopilot']} {summary['log_format']}, "
        f"{summary['vehicle'] or 'vehicle unknown'}, {summary['duration_s']:.1f} s"
        + (f", starts {summary['utc_start']}" if summary["utc_start"] else ", no GPS time"))
    say(f"  {'signal':<11} {'samples':>8} {'rate Hz':>8}  {'unit':<11} source")
    for name, info in summary["signals"].items():
        say(f"  {name:<11} {info['samples']:>8} {info['rate_hz']:>8.1f}  {info['unit']:<11} {info['source']}")
    if summary["missing"]:
        say(f"  missing: {', '.join(summary['missing'])}")
    for wind in summary["wind"]:
        say(f"  wind {wind['path']}: {wind['samples']} samples at {wind['rate_hz']:.1f} Hz, "
            f"{wind['utc_start']} to {wind['utc_end']}, mean {wind['mean_speed_m_s']:.2f} m/s")
    for warning in summary["warnings"]:
        say(f"  warning: {warning}")
    if summary["output"]:
        say(f"  wrote {summary['output']}")
