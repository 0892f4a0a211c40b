"""``sysid validate``: predict doublets the model was not fitted to, with and without its wind term."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from ._common import LibraryDefault, OutputPath, SysidCommand, emit_json, json_option, progress_bar
from ._flights import check_sources, reading_from, reading_options
from ._tables import print_validation
from ._wind_options import (
    segments_from,
    segments_option,
    transport_delay_option,
    wind_distance_option,
    wind_offset_option,
    wind_option,
)

__all__ = ["validate"]

_EPILOG = """\b
Examples:
  sysid validate model.json doublets/*.ulg --report validate.html
  sysid validate model.json doublets/*.bin --wind anemometer.csv --wind-distance 4.6 -o validation.json --json -
  sysid validate model.json flight.bin --segments doublets.toml --initial-state estimated --report v.html
  sysid report model.json validation.json -o report.html    # the report again, from the saved files
"""


@click.command(cls=SysidCommand, epilog=_EPILOG)
@click.argument("model_path", metavar="MODEL.json", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.argument("logs", nargs=-1, required=True, type=click.Path(exists=True, dir_okay=False, path_type=Path))
@wind_option("Anemometer CSV, or a folder of them (repeatable): verifies the wind term G_w too.")
@wind_distance_option()
@transport_delay_option()
@wind_offset_option()
@segments_option("TOML or CSV of maneuvers (start_s, end_s, axis, kind) overriding detection.")
@reading_options()
@click.option(
    "--before",
    "before_s",
    type=click.FloatRange(min=0),
    cls=LibraryDefault,
    default_from=("sysid.verify", "doublet_records", "before_s"),
    show_default=True,
    metavar="S",
    help="Quiet stretch kept before each doublet, s.",
)
@click.option(
    "--after",
    "after_s",
    type=click.FloatRange(min=0),
    cls=LibraryDefault,
    default_from=("sysid.verify", "doublet_records", "after_s"),
    show_default=True,
    metavar="S",
    help="Response kept after each doublet, s (an unstable model diverges over long records).",
)
@click.option(
    "--initial-state",
    type=click.Choice(["measured", "estimated", "zero"]),
    default="measured",
    show_default=True,
    help="Start each simulation from the measured states, from those corrected by least squares, or from zero.",
)
@click.option(
    "-o", "--out", type=OutputPath(), help="Save the verification with its time histories (JSON) for 'sysid report'."
)
@click.option("--report", type=OutputPath(), help="Write the HTML model report, with this verification, here.")
@json_option
@click.option("-q", "--quiet", is_flag=True, help="No progress bar and no table.")
def validate(
    model_path: Path,
    logs: tuple[Path, ...],
    wind_paths: tuple[Path, ...],
    wind_distance: float | None,
    transport_delay: float | None,
    wind_offset: float | None,
    segments_file: Path | None,
    table_map: Any,
    vehicle: str | None,
    before_s: float,
    after_s: float,
    initial_state: str,
    out: Path | None,
    report: Path | None,
    json_path: str | None,
    quiet: bool,
) -> None:
    """Simulate MODEL.json from all the measured inputs of every doublet in LOGS (flight logs, or HDF5 datasets
    written by ``sysid ingest -o``) and report the RMS error and
    Theil inequality coefficient per output (with bias and reference shift estimated, as VERIFY does), judging
    each doublet on the outputs of the axis it excites; with --wind, also how much the wind term G_w reduces
    the error."""

    from flightlogs.conditioning.condition import ConditioningOptions
    from reports.model_report import write_model_report
    from sysid.fit import read_model
    from sysid.verify import VerificationOptions, verify_logs
    from sysid.verify.io import write_verification

    log_only: dict[str, Any] = {"--wind": wind_paths, "--wind-distance": wind_distance, "--wind-offset": wind_offset}
    log_only |= {"--transport-delay": transport_delay, "--segments": segments_file, "--map": table_map}
    check_sources(logs, log_only | {"--vehicle": vehicle})
    identified = read_model(model_path)
    conditioning = ConditioningOptions(
        wind_offset_s=wind_offset,
        wind_distance_m=wind_distance,
        transport_delay_s=transport_delay,
        segments=segments_from(segments_file),
    )
    with progress_bar("reading", unit="bytes", quiet=quiet) as bar:
        validation = verify_logs(
            identified,
            logs,
            wind_paths=wind_paths,
            conditioning=conditioning,
            segments_path=segments_file,
            options=VerificationOptions(initial_state=initial_state),  # type: ignore[arg-type]
            before_s=before_s,
            after_s=after_s,
            progress=lambda _name, done, total: bar(done, total),
            reading=reading_from(table_map, vehicle),
        )
    verification, saved = validation.verification, validation.provenance
    if out is not None:
        write_verification(out, verification, model=model_path, options=saved)
    if report is not None:
        write_model_report(report, identified, verification=verification, verification_options=saved)
    summary = {"model": str(model_path), "logs": [str(p) for p in logs]} | verification.digest()
    notes = [*verification.record_notes(), *validation.notes]
    summary |= {"report": str(report) if report else None, "notes": notes, "output": str(out) if out else None}
    if not quiet:
        print_validation(summary)
    emit_json(summary, json_path)
