"""``sysid validate``: predict doublets the model was not fitted to, with and without its wind term."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from ._common import LibraryDefault, OutputPath, SysidCommand, emit_json, json_option
from ._flags import as_flags
from ._flights import conditioned_flights, is_dataset, reading_from, reading_options
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
    from sysid.verify import VerificationOptions, check_given_doublets, verification_provenance, verify_identified
    from sysid.verify.io import write_verification
    from sysid.verify.logs import SEGMENTS_HINT

    identified = read_model(model_path)
    segments = segments_from(segments_file)
    measured = identified.measured_clock_offset_s if wind_paths and wind_offset is None else None
    conditioning = ConditioningOptions(
        wind_offset_s=wind_offset if measured is None else measured,
        wind_distance_m=wind_distance,
        transport_delay_s=transport_delay,
        segments=segments,
    )
    log_only = {
        "--wind": wind_paths,
        "--wind-distance": wind_distance,
        "--wind-offset": wind_offset,
        "--transport-delay": transport_delay,
        "--segments": segments_file,
        "--map": table_map,
        "--vehicle": vehicle,
    }
    flights = conditioned_flights(
        logs, wind_paths, conditioning, log_only=log_only, quiet=quiet, reading=reading_from(table_map, vehicle)
    )
    if segments_file is not None and segments is not None:
        check_given_doublets(segments_file, segments, flights)
    hint = (
        ""
        if segments_file is not None
        else "give their times to `sysid ingest --segments`"
        if is_dataset(logs[0])
        else SEGMENTS_HINT
    )
    options = VerificationOptions(initial_state=initial_state)  # type: ignore[arg-type]
    verification, said = verify_identified(
        identified, flights, options=options, before_s=before_s, after_s=after_s, hint=hint
    )
    notes = list(said)
    names = {"sources": [p.name for p in logs], "winds": [p.name for p in wind_paths]}
    saved = verification_provenance(options, before_s=before_s, after_s=after_s, **names)
    if out is not None:
        write_verification(out, verification, model=model_path, options=saved)
    if report is not None:
        write_model_report(report, identified, verification=verification, verification_options=saved)
    if measured is not None:
        notes.insert(
            0,
            f"anemometer clock offset {measured:+.2f} s, as the model's fit measured it (`wind_offset_s` to override)",
        )
    summary = {"model": str(model_path), "logs": [str(p) for p in logs]} | verification.digest()
    summary |= {"report": str(report) if report else None, "notes": notes, "output": str(out) if out else None}
    if not quiet:
        _print(summary)
    emit_json(summary, json_path)


def _print(summary: dict[str, Any]) -> None:
    say = click.echo
    say(f"{summary['model']}: {len(summary['records'])} records, each judged on the outputs of its axis")
    wind = summary.get("wind_correction", {})
    header = f"  {'output':<8} {'unit':<8} {'RMS error':>10} {'TIC':>6}"
    band = next((c["band_hz"] for c in wind.values() if c["band_hz"] is not None), None)
    in_band = f"< {band:g} Hz" if band is not None else ""
    say(header + (f" {'without G_w':>12} {'reduction':>9}" + (f" {in_band:>9}" if in_band else "") if wind else ""))
    for name, row in summary["summary"].items():
        line = f"  {name:<8} {row['unit']:<8} {row['rmse']:>10.4g} {row['tic']:>6.2f}"
        if name in wind and wind[name]["reduction_percent"] is not None:
            line += f" {wind[name]['rmse_without']:>12.4g} {wind[name]['reduction_percent']:>8.1f}%"
            if in_band and wind[name]["reduction_in_band_percent"] is not None:
                line += f" {wind[name]['reduction_in_band_percent']:>8.1f}%"
        say(line)
    from sysid.verify import mode_names

    unstable = [r for r in summary["records"] if r["unstable"]]
    if len(unstable) > 1:  # one note, not the same sentence per record
        growth = max(r["growth"] for r in unstable)
        names = mode_names([m for r in unstable for m in r["unstable_modes"]])
        say(
            f"  note: the model is unstable open loop in its {names} and grows up to {growth:.0f}-fold over "
            f"{len(unstable)} records "
            f"({'; '.join(r['label'] for r in unstable)}): small input or initial-state errors diverge there, so "
            "judge them also by the one-step-ahead prediction error (prediction_rmse, prediction_tic in --json)"
        )
    for record in summary["records"]:
        if record["notice"] and (len(unstable) < 2 or not record["unstable"]):
            say(f"  note: {record['label']}: {as_flags(record['notice'])}")
    for note in summary["notes"]:
        say(f"  note: {as_flags(note)}")
    if summary["off_axis"]:
        say(
            "  off-axis (not judged): "
            + ", ".join(f"{name} TIC {row['tic']:.2f}" for name, row in summary["off_axis"].items())
        )
    for path in (summary["output"], summary["report"]):
        if path:
            say(f"wrote {path}")
