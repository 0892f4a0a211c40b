"""``sysid validate``: predict doublets the model was not fitted to, with and without its wind term."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import click

from ._common import emit_json, json_option, progress_bar
from ._wind_options import (segments_from, segments_option, transport_delay_option, wind_distance_option,
                            wind_offset_option, wind_option)

__all__ = ["validate"]

_EPILOG = """\b
Examples:
  sysid validate model.json doublets/*.ulg --report validate.html
  sysid validate model.json doublets/*.bin --wind anemometer.csv --wind-distance 4.6 -o validation.json --json -
  sysid validate model.json flight.bin --segments doublets.toml --initial-state estimated --report v.html
  sysid report model.json validation.json -o report.html    # the report again, from the saved files
"""


@click.command(epilog=_EPILOG)
@click.argument("model_path", metavar="MODEL.json", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.argument("logs", nargs=-1, required=True, type=click.Path(exists=True, dir_okay=False, path_type=Path))
@wind_option("Anemometer CSV, or a folder of them (repeatable): verifies the wind term G_w too.")
@wind_distance_option()
@transport_delay_option()
@wind_offset_option()
@segments_option("TOML or CSV of maneuvers (start_s, end_s, axis, kind) overriding detection.")
@click.option("--before", "before_s", type=click.FloatRange(min=0), default=0.5, show_default=True, metavar="S",
              help="Quiet stretch kept before each doublet, s.")
@click.option("--after", "after_s", type=click.FloatRange(min=0), default=1.0, show_default=True, metavar="S",
              help="Response kept after each doublet, s (an unstable model diverges over long records).")
@click.option("--initial-state", type=click.Choice(["measured", "estimated", "zero"]), default="measured",
              show_default=True, help="Start each simulation from the measured states, from those corrected by "
                                      "least squares, or from zero.")
@click.option("-o", "--out", type=click.Path(dir_okay=False, writable=True, path_type=Path),
              help="Save the verification with its time histories (JSON) for 'sysid report'.")
@click.option("--report", type=click.Path(dir_okay=False, writable=True, path_type=Path),
              help="Write the HTML model report, with this verification, here.")
@json_option
@click.option("-q", "--quiet", is_flag=True, help="No progress bar and no table.")
def validate(model_path: Path, logs: tuple[Path, ...], wind_paths: tuple[Path, ...], wind_distance: float | None,
             transport_delay: float | None, wind_offset: float | None, segments_file: Path | None, before_s: float,
             after_s: float, initial_state: str, out: Path | None, report: Path | None, json_path: str | None,
             quiet: bool) -> None:
    """Simulate MODEL.json from all the measured inputs of every doublet in LOGS and report the RMS error and
    Theil inequality coefficient per output (with bias and reference shift estimated, as VERIFY does), judging
    each doublet on the outputs of the axis it excites; with --wind, also how much the wind term G_w reduces
    the error."""
    import datetime as dt

    from flightlogs.condition import ConditioningOptions
    from reports.model_report import write_model_report
    from sysid.fit import read_model
    from sysid.verify import VerificationOptions, axis_outputs, verify_logs
    from sysid.verify_io import write_verification

    identified = read_model(model_path)
    model = identified.linear_model(include_wind=False)
    with_wind = identified.linear_model(include_wind=True)
    has_wind = with_wind.inputs != model.inputs
    notes = []
    if has_wind and not wind_paths:
        notes.append("the model's wind term is not verified: no anemometer file was given (--wind)")
    conditioning = ConditioningOptions(
        wind_offset_s=wind_offset, wind_distance_m=wind_distance, transport_delay_s=transport_delay,
        segments=segments_from(segments_file))
    options = VerificationOptions(initial_state=initial_state)  # type: ignore[arg-type]
    with progress_bar("reading", quiet=quiet) as bar:
        verification = verify_logs(model, list(logs), wind_model=with_wind if has_wind and wind_paths else None,
                                   wind_paths=list(wind_paths), axes=axis_outputs(identified),
                                   conditioning=conditioning, options=options, before_s=before_s, after_s=after_s,
                                   progress=lambda _name, done, total: bar(done, total))
    saved = {"initial_state": initial_state, "before_s": before_s, "after_s": after_s,
             "inputs": "all measured", "judged": "on-axis outputs of each doublet's axis",
             "logs": [p.name for p in logs], "wind": [p.name for p in wind_paths]}
    if out is not None:
        created = dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")
        write_verification(out, verification, model=model_path.name, options=saved, created_utc=created)
    if report is not None:
        write_model_report(report, identified, verification=verification, verification_options=saved)
    summary = _summary(verification, model_path, logs, report, notes) | {"output": str(out) if out else None}
    if not quiet:
        _print(summary, to_stderr=json_path == "-")
    emit_json(summary, json_path)


def _summary(verification: Any, model_path: Path, logs: tuple[Path, ...], report: Path | None,
             notes: list[str]) -> dict[str, Any]:
    summary: dict[str, Any] = {
        "model": str(model_path),
        "logs": [str(p) for p in logs],
        "records": [{"label": r.label, "source": str(r.source), "start_s": float(r.time_s[0]),
                     "end_s": float(r.time_s[-1]), "rmse": r.rmse, "tic": r.tic, "unstable": r.unstable,
                     "growth": r.growth, "unstable_modes": list(r.unstable_modes), "notice": r.notice, "reference_shifts": dict(r.reference_shifts),
                     "bias": {o.name: o.bias for o in r.outputs}, "excited": r.excited,
                     "on_axis": [o.name for o in r.judged], "off_axis": list(r.off_axis)}
                    for r in verification.records],
        "summary": {s.name: {"unit": s.unit, "rmse": s.rmse, "tic": s.tic, "records": s.n_records,
                             "one_step_rmse": s.prediction_rmse, "one_step_tic": s.prediction_tic}
                    for s in verification.summary},
        "off_axis": {s.name: {"unit": s.unit, "rmse": s.rmse, "tic": s.tic, "records": s.n_records}
                     for s in verification.off_axis},
        "overall": {"rmse": verification.rmse, "tic": verification.tic},
        "unstable": verification.unstable,
        "report": str(report) if report is not None else None,
        "notes": notes,
    }
    if verification.wind_correction:
        summary["wind_correction"] = {c.name: {"unit": c.unit, "rmse_without": c.rmse_without,
                                               "rmse_with": c.rmse_with, "reduction_percent": c.reduction_percent}
                                      for c in verification.wind_correction}
    return summary


def _print(summary: dict[str, Any], *, to_stderr: bool) -> None:
    def say(text: str = "") -> None:
        click.echo(text, err=to_stderr)

    say(f"{summary['model']}: {len(summary['records'])} records, each judged on the outputs of its axis")
    wind = summary.get("wind_correction", {})
    header = f"  {'output':<8} {'unit':<8} {'RMS error':>10} {'TIC':>6}"
    say(header + (f" {'without G_w':>12} {'reduction':>9}" if wind else ""))
    for name, row in summary["summary"].items():
        line = f"  {name:<8} {row['unit']:<8} {row['rmse']:>10.4g} {row['tic']:>6.2f}"
        if name in wind:
            reduction = wind[name]["reduction_percent"]
            line += f" {wind[name]['rmse_without']:>12.4g} {reduction:>8.1f}%" if math.isfinite(reduction) else ""
        say(line)
    from sysid.verify import mode_names

    unstable = [r for r in summary["records"] if r["unstable"]]
    if len(unstable) > 1:  # one note, not the same sentence per record
        growth = max(r["growth"] for r in unstable)
        names = mode_names([m for r in unstable for m in r["unstable_modes"]])
        say(f"  note: the model is unstable open loop in its {names} and grows up to {growth:.0f}-fold over "
            f"{len(unstable)} records "
            f"({'; '.join(r['label'] for r in unstable)}): small input or initial-state errors diverge there, so "
            "judge them also by the one-step-ahead prediction error (one_step_* in --json)")
    for record in summary["records"]:
        if record["notice"] and (len(unstable) < 2 or not record["unstable"]):
            say(f"  note: {record['label']}: {record['notice']}")
    for note in summary["notes"]:
        say(f"  note: {note}")
    if summary["off_axis"]:
        say("  off-axis (not judged): " + ", ".join(f"{name} TIC {row['tic']:.2f}"
                                                    for name, row in summary["off_axis"].items()))
    for path in (summary["output"], summary["report"]):
        if path:
            say(f"wrote {path}")
