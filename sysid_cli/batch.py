"""``sysid batch``: fit hundreds of logs on a Dask cluster, trend each vehicle's parameters, flag drift."""

from __future__ import annotations

import time
from contextlib import ExitStack
from pathlib import Path
from typing import Any

import click

from ._common import OutputPath, SysidCommand, emit_json, json_option, progress_bar
from ._flights import reading_from, reading_options
from ._wind_options import wind_distance_option, wind_offset_option, wind_option

__all__ = ["batch", "expand_logs"]

_EPILOG = """\b
Examples:
  sysid batch fleet/ --mapping fleet/fleet.csv -o results/ --report fleet.html
  sysid batch campaign/*.bin --model hover-wind --wind anemometer/ --group-by day -o results/
  sysid batch fleet/ --scheduler tcp://10.0.0.5:8786 -o /shared/results --json -
  sysid batch fleet/ --against sitl.ulg -o results/ --report fleet.html   # discrepancy per log
"""

#: Files a folder given on the command line contributes (case-insensitive suffixes).
_LOG_SUFFIXES = (".ulg", ".bin", ".tlog")
_TABLE_SUFFIXES = (".csv", ".txt", ".parquet")


def expand_logs(paths: tuple[Path, ...], *, tables: bool = False) -> list[Path]:
    """The logs named, folders searched recursively for ``.ulg``, ``.bin`` and ``.tlog`` files (sorted);
    with `tables` (a ``--map`` given) also ``.csv``, ``.txt`` and ``.parquet``."""
    suffixes = _LOG_SUFFIXES + (_TABLE_SUFFIXES if tables else ())
    found: list[Path] = []
    for path in paths:
        if path.is_dir():
            found += sorted(p for p in path.rglob("*") if p.is_file() and p.suffix.lower() in suffixes)
        else:
            found.append(path)
    return list(dict.fromkeys(found))


@click.command(cls=SysidCommand, epilog=_EPILOG)
@click.argument("logs", nargs=-1, required=True, type=click.Path(exists=True, path_type=Path))
@click.option("--model", "model_name", default="hover", show_default=True, metavar="NAME|FILE", help="Structure.")
@wind_option("Anemometer CSV or folder (repeatable); each log takes the file overlapping it.")
@wind_distance_option()
@wind_offset_option("Anemometer clock minus UTC, s.")
@click.option("--estimate-wind-offset", is_flag=True, help="Refine the clock offset of each log by cross-correlation.")
@reading_options()
@click.option(
    "--mapping",
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    help="CSV of file, vehicle, date[, payload_kg, ...]: each log's keys (default: the log's board id and UTC day).",
)
@click.option(
    "--group-by",
    default="vehicle,day",
    show_default=True,
    metavar="KEYS",
    help="Logs fitted together: vehicle, day, file or a column of --mapping, comma-separated.",
)
@click.option(
    "--against",
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    metavar="SIM",
    help="Also compare each log with this simulated log or model JSON (sysid discrepancy).",
)
@click.option(
    "-o",
    "--out",
    "out_dir",
    type=OutputPath(folder=True),
    required=True,
    help="Results folder (reused: its cache skips unchanged work).",
)
@click.option(
    "--scheduler", metavar="ADDRESS", help="Run on this Dask scheduler (tcp://host:8786) instead of a local cluster."
)
@click.option(
    "--workers", type=click.IntRange(min=1), help="Worker processes of the local cluster [default: one per core]."
)
@click.option(
    "--report", type=OutputPath(within="out_dir"), help="Write the fleet report (HTML); it may lie inside -o."
)
@click.option(
    "--partial",
    is_flag=True,
    help="Fit the axes a group's sweeps identify; the rest unidentified (as sysid fit --partial).",
)
@click.option("--no-group-reports", is_flag=True, help="Skip each group's HTML model report (faster).")
@json_option
@click.option("-q", "--quiet", is_flag=True, help="No progress bar and no summary.")
def batch(
    logs: tuple[Path, ...],
    model_name: str,
    wind_paths: tuple[Path, ...],
    wind_distance: float | None,
    wind_offset: float | None,
    estimate_wind_offset: bool,
    table_map: Any,
    vehicle: str | None,
    mapping: Path | None,
    group_by: str,
    against: Path | None,
    out_dir: Path,
    scheduler: str | None,
    workers: int | None,
    report: Path | None,
    partial: bool,
    no_group_reports: bool,
    json_path: str | None,
    quiet: bool,
) -> None:
    """For every log in LOGS (files or folders), on a Dask cluster: read it, group the logs (by vehicle and
    day by default), and for each group fit the model to its sweeps and verify it on its doublets; then
    trend each vehicle's parameters by date and flag a change larger than the Cramér–Rao bounds allow.
    A log or group that fails is listed with its reason and the batch goes on. Writes results.parquet,
    results.csv (a row per group and parameter), failures.csv and each group's model, verification and
    report under OUT/groups/; a re-run skips the work whose inputs are unchanged (OUT/cache)."""
    from flightlogs.conditioning.condition import ConditioningOptions
    from flightlogs.readers.log_mapping import read_log_mapping
    from flightlogs.store.campaign import expand_wind_paths
    from flightlogs.store.hashing import file_sha256
    from reports.fleet_report import write_fleet_report
    from reports.fleet_table import write_tables
    from reports.model_report import write_model_report
    from sysid.batch import BatchSettings, DriftOptions, batch_client, run_batch
    from sysid.batch.groups import check_keys
    from sysid.fit.identify import IdentifyOptions
    from sysid.model import load_structure

    if scheduler is not None and workers is not None:
        raise click.UsageError("--workers sizes the local cluster; a --scheduler has its own workers")
    keys = tuple(k.strip() for k in group_by.split(",") if k.strip())
    found = expand_logs(logs, tables=table_map is not None)
    if not found:
        raise click.UsageError(f"no log (.ulg, .bin, .tlog) in {', '.join(map(str, logs))}")
    log_mapping = read_log_mapping(mapping) if mapping is not None else None
    check_keys(keys, log_mapping)  # before a cluster is started
    structure = load_structure(model_name)
    winds = expand_wind_paths(list(wind_paths))
    settings = BatchSettings(
        structure=str(Path(model_name).resolve()) if Path(model_name).is_file() else model_name,
        structure_text=structure.text,
        conditioning=ConditioningOptions(
            wind_distance_m=wind_distance, wind_offset_s=wind_offset, estimate_wind_offset=estimate_wind_offset
        ),
        wind_paths=tuple(str(Path(w).resolve()) for w in winds),
        wind_sha256=tuple(file_sha256(w) for w in winds),
        reading=reading_from(table_map, vehicle),
        identify=IdentifyOptions(partial=partial),
    )
    drift = DriftOptions()
    start = time.perf_counter()
    with ExitStack() as stack:
        bars: dict[str, Any] = {}

        def progress(stage: str, done: int, total: int) -> None:
            if stage not in bars:
                bars[stage] = stack.enter_context(progress_bar(stage, quiet=quiet))
            bars[stage](done, total)

        client = stack.enter_context(batch_client(scheduler, workers))
        n_workers = len(client.scheduler_info()["workers"])
        result = run_batch(
            found,
            settings,
            out_dir,
            client,
            by=keys,
            mapping=log_mapping,
            against=against,
            report=None if no_group_reports else write_model_report,
            drift=drift,
            progress=progress,
        )
    seconds = time.perf_counter() - start
    tables = write_tables(out_dir, result)
    run = {
        "cluster": scheduler or f"local, {n_workers} worker process{'es' if n_workers > 1 else ''}",
        "time": f"{seconds:.1f} s ({60 * len(found) / seconds:.1f} logs a minute)",
        "grouped by": ", ".join(keys),
        "model": model_name,
    }
    if report is not None:
        report.parent.mkdir(parents=True, exist_ok=True)  # inside -o (checked before any work)
        write_fleet_report(report, result, run=run, drift=drift)
    summary = _summary(result, tables, report, seconds, n_workers)
    if not quiet:
        _print(summary)
    emit_json(summary, json_path)
    if summary["groups"] and not summary["fitted"]:
        click.secho(
            f"error: none of the {summary['groups']} group(s) was fitted; why, log by log: {summary['failures_csv']}",
            fg="red",
            err=True,
        )
        click.get_current_context().exit(1)


def _summary(
    result: Any, tables: tuple[Path, ...], report: Path | None, seconds: float, workers: int
) -> dict[str, Any]:
    summary: dict[str, Any] = result.digest() | {"workers": workers, "seconds": seconds}
    summary |= {"results": str(tables[0]), "csv": str(tables[1]), "failures_csv": str(tables[2])}
    return summary | {"report": None if report is None else str(report)}


def _print(summary: dict[str, Any]) -> None:
    say = click.echo
    say(
        f"{summary['logs']} logs, {summary['groups']} groups ({summary['fitted']} fitted, {summary['cached']} logs "
        f"and groups from the cache) in {summary['seconds']:.1f} s on {summary['workers']} workers"
    )
    for d in summary["drifts"]:
        say(f"  {'drift' if d['confirmed'] else 'watch'}: {d['vehicle']}: {d['text']}")
    if summary["fitted"] and not any(d["confirmed"] for d in summary["drifts"]):
        say("  drift: none flagged")
    for f in summary["failures"]:
        say(f"  failed ({f['stage']}): {f['reason']}")
    for key in ("results", "csv", "failures_csv", "report"):
        if summary[key]:
            say(f"wrote {summary[key]}")
