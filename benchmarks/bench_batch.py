"""Logs a minute of ``sysid batch`` with 1 and 2 local workers, and what a task and the scheduler cost.

    python benchmarks/bench_batch.py [--vehicles 4] [--flights 10] [--folder DIR]

Flies a fleet (``simulator.campaign.fleet``: each flight the demo's test
card, sweeps and doublets on the four axes, 206 s; not timed), then runs the
whole ``sysid batch FLEET --mapping fleet.csv -o FRESH --no-group-reports``
command as a process with ``--workers 1`` and ``--workers 2``, each on an
empty results folder (nothing from the cache), and prints logs a minute and
the speed-up. It then measures, in-process on a local cluster of one
worker, the mean compute time of each kind of task (a log's survey, a
group's fit: ``distributed``'s own task stream) and the scheduler's cost per
task (2000 empty tasks on two workers), from which it projects a cluster of
20 nodes of 2 cores.
"""

from __future__ import annotations

import argparse
import glob
import subprocess
import sys
import tempfile
import time
from pathlib import Path

_CLI = [sys.executable, "-c", "from sysid_cli.main import cli; cli()"]


def _noop(x: int) -> int:
    return x


def _batch_seconds(fleet: Path, workers: int, out: Path) -> float:
    start = time.perf_counter()
    done = subprocess.run(
        [*_CLI, "batch", str(fleet), "--mapping", str(fleet / "fleet.csv"), "-o", str(out), "--workers", str(workers)]
        + ["--no-group-reports", "-q"],
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        raise RuntimeError(done.stderr)
    return time.perf_counter() - start


def _task_costs(fleet: Path, results: Path) -> tuple[float, float, float]:
    """Mean compute s of a survey and of a fit on one worker, and the scheduler's s per empty task on two."""
    from distributed import get_task_stream

    from flightlogs.readers.log_mapping import read_log_mapping
    from sysid.batch import BatchSettings, batch_client, run_batch
    from sysid.model import load_structure

    logs = sorted(glob.glob(str(fleet / "V*" / "*.bin")))
    settings = BatchSettings(structure="hover", structure_text=load_structure("hover").text)
    with batch_client(workers=1) as client, get_task_stream(client) as stream:
        run_batch(logs, settings, results, client, mapping=read_log_mapping(fleet / "fleet.csv"))
    spans: dict[str, list[float]] = {}
    for task in stream.data:
        name = task["key"][0] if isinstance(task["key"], tuple) else str(task["key"])
        kind = "survey" if "survey" in name else "fit" if "fit" in name else "other"
        compute = sum(s["stop"] - s["start"] for s in task["startstops"] if s["action"] == "compute")
        spans.setdefault(kind, []).append(compute)
    with batch_client(workers=2) as client:
        client.gather(client.map(_noop, range(100)))  # warm
        start = time.perf_counter()
        client.gather(client.map(_noop, range(2000)))
        per_task = (time.perf_counter() - start) / 2000
    mean = {k: sum(v) / len(v) for k, v in spans.items()}
    return mean["survey"], mean["fit"], per_task


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--vehicles", type=int, default=4)
    parser.add_argument("--flights", type=int, default=10)
    parser.add_argument("--folder", type=Path, help="Keep the fleet here (default: a temporary folder).")
    args = parser.parse_args()
    from simulator.campaign.fleet import FleetPlan, write_fleet

    with tempfile.TemporaryDirectory() as tmp:
        fleet = args.folder or Path(tmp) / "fleet"
        plan = FleetPlan(vehicles=args.vehicles, flights=args.flights, degrading_vehicle=1, corrupted=None)
        n = len(write_fleet(fleet, plan).logs)
        print(f"fleet: {n} logs of {plan.vehicles} vehicles ({fleet})")
        seconds = {w: _batch_seconds(fleet, w, Path(tmp) / f"out{w}") for w in (1, 2)}
        for w, s in seconds.items():
            print(f"  sysid batch, {w} worker{'s' if w > 1 else ''}: {s:7.1f} s  {60 * n / s:6.1f} logs a minute")
        print(f"  speed-up 2 workers / 1: {seconds[1] / seconds[2]:.2f}x")
        survey, fit, overhead = _task_costs(fleet, Path(tmp) / "tasks")
        print(f"  per task on one worker: survey {survey:.3f} s, fit + verification {fit:.3f} s")
        print(f"  scheduler: {1000 * overhead:.2f} ms a task (2000 empty tasks, 2 workers)")
        fixed = seconds[1] - n * (survey + fit)  # start-up, cluster, grouping, table: not spread over workers
        for logs in (n, 200, 2000):
            cluster = fixed + logs * (survey + fit) / 40 + 2 * logs * overhead
            print(
                f"  projected, {logs} logs on 20 nodes x 2 cores: {cluster:6.1f} s "
                f"({60 * logs / cluster:6.0f} logs a minute; fixed cost {fixed:.1f} s, compute {logs * (survey + fit) / 40:.1f} s)"
            )


if __name__ == "__main__":
    main()
