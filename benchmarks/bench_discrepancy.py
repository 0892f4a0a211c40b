"""Discrepancy discovery over a matrix of SIM / REAL pairs from our simulator: confusion matrix and timings.

    python benchmarks/bench_discrepancy.py [--seeds 21 22 23] [--nulls 20]

For each seed: one SIM flight of the mission of :mod:`simulator.campaign.discrepancy_pairs` (hover, lon/lat/yaw
sweeps, height steps to 0.3 m; 160 s, octocopter), and REAL flights with each effect at two strengths,
two doubles (ground_effect+time_delay, mass_change+time_delay) and null flights (no effect, other
noise seeds and timing). Every pair is written as PX4 ULogs, read back and searched; the table is the
confusion matrix (rows: truth, columns: verdict), then the share of singles named, of nulls answered
"none", of doubles with both named, the median held-out improvement and the seconds per pair (reading
both logs and searching; the simulation is not counted).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
import warnings
from collections import Counter, defaultdict
from pathlib import Path

from flightlogs.conditioning.condition import condition_flight
from flightlogs.readers import read_log
from simulator.campaign.discrepancy_pairs import EFFECTS, MODERATE, write_pair_set
from sysid.discrepancy import discover, flight_series

SINGLES = [e for e in EFFECTS if e != "none"]
DOUBLES = {
    "ground_effect+time_delay": ("ground_effect", "time_delay"),
    "mass_change+time_delay": ("mass_change", "time_delay"),
}


def _series(path: Path):  # type: ignore[no-untyped-def]
    return flight_series(path.name, condition_flight(read_log(path)).records)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[21, 22, 23])
    parser.add_argument("--nulls", type=int, default=20, help="null pairs in all (spread over the seeds)")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    rows: list[tuple[str, str, str, tuple[str, ...], float, float]] = []  # kind, truth, verdict, found, improvement, s
    per_seed_nulls = -(-args.nulls // len(args.seeds))
    for seed in args.seeds:
        pairs = {f"{e}@strong": [EFFECTS[e]] for e in SINGLES}
        pairs |= {f"{e}@moderate": [MODERATE[e]] for e in SINGLES if MODERATE[e] is not EFFECTS[e]}
        pairs |= {f"{name}@strong": [EFFECTS[a], EFFECTS[b]] for name, (a, b) in DOUBLES.items()}
        pairs |= {f"none@{k}": [EFFECTS["none"]] for k in range(per_seed_nulls)}
        with tempfile.TemporaryDirectory() as folder:
            started = time.perf_counter()
            sim, reals = write_pair_set(pairs, Path(folder), seed)
            print(f"seed {seed}: {len(reals)} pairs simulated in {time.perf_counter() - started:.0f} s", flush=True)
            for name, path in reals.items():
                truth, strength = name.split("@")
                started = time.perf_counter()
                result = discover([_series(sim)], [_series(path)])
                seconds = time.perf_counter() - started
                kind = "double" if "+" in truth else "null" if truth == "none" else "single"
                found = tuple(f.effect for f in result.findings)
                improvement = result.findings[0].improvement_percent if result.findings else float("nan")
                rows.append(
                    (
                        kind,
                        f"{truth}@{strength}" if kind != "null" else "none",
                        result.verdict,
                        found,
                        improvement,
                        seconds,
                    )
                )
                print(f"  {name:34s} -> {result.verdict:14s} {found} {improvement:6.1f} % {seconds:5.1f} s", flush=True)
    _table(rows)
    return 0


def _table(rows: list[tuple[str, str, str, tuple[str, ...], float, float]]) -> None:
    confusion: dict[str, Counter[str]] = defaultdict(Counter)
    for _kind, truth, verdict, _found, _, _ in rows:
        confusion[truth.split("@")[0]][verdict] += 1
    columns = sorted({v for c in confusion.values() for v in c})
    print("\nconfusion (rows truth, columns verdict)")
    print(f"{'':26s}" + "".join(f"{c[:13]:>14s}" for c in columns))
    for truth in sorted(confusion):
        print(f"{truth:26s}" + "".join(f"{confusion[truth][c]:14d}" for c in columns))
    singles = [r for r in rows if r[0] == "single"]
    nulls = [r for r in rows if r[0] == "null"]
    doubles = [r for r in rows if r[0] == "double"]
    named = sum(r[2] == r[1].split("@")[0] for r in singles)
    print(f"\nsingles named: {named}/{len(singles)}")
    for strength in ("strong", "moderate"):
        subset = [r for r in singles if r[1].endswith(strength)]
        print(f"  {strength}: {sum(r[2] == r[1].split('@')[0] for r in subset)}/{len(subset)}")
    print(f"nulls 'none': {sum(r[2] == 'none' for r in nulls)}/{len(nulls)}")
    both = sum(set(r[1].split("@")[0].split("+")) <= set(r[3]) for r in doubles)
    print(f"doubles, both named: {both}/{len(doubles)}")
    improvements = [r[4] for r in singles + doubles if r[4] == r[4]]
    if improvements:
        print(f"median held-out improvement (named effects): {statistics.median(improvements):.1f} %")
    seconds = [r[5] for r in rows]
    print(
        f"seconds per pair (read both logs + search): median {statistics.median(seconds):.1f}, max {max(seconds):.1f}"
    )


if __name__ == "__main__":
    raise SystemExit(main())
