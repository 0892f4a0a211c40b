"""Discrepancy discovery over a matrix of SIM / REAL pairs from our simulator: confusion matrix and timings.

    python benchmarks/bench_discrepancy.py [--vehicles octo quad] [--seeds 21 22 23] [--nulls 4]
        [--effects ...] [--no-doubles]

For each vehicle (the chapter 3 octocopter, a 2 kg quad) and seed: one SIM flight of the mission of
:mod:`simulator.campaign.discrepancy_pairs` (hover, lon/lat/yaw sweeps, legs north and east, height steps
down to Z/R = 2; 4 minutes), and REAL flights with each of the eight effects at two strengths, four
doubles and `--nulls` null flights (no effect, another noise seed), every REAL flight's events moved
by 5 %, alternately later and earlier. Every pair is written as PX4 ULogs, read
back and searched; the table is the confusion matrix (rows: truth, columns: verdict), then the share of
singles named, of nulls answered "none", of doubles with both named, the median held-out improvement and
the seconds per pair (reading both logs and searching; the simulation is not counted).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
import warnings
from collections import Counter, defaultdict
from pathlib import Path

from flightlogs.conditioning.condition import ConditioningOptions, condition_flight
from flightlogs.readers import read_log
from simulator.campaign.discrepancy_pairs import EFFECTS, STRENGTHS, VEHICLES, write_pair_set
from sysid.discrepancy import discover, flight_series

SINGLES = [e for e in EFFECTS if e != "none"]
DOUBLES = (
    ("ground_effect", "time_delay"),
    ("rotor_drag", "battery_sag"),
    ("mass_change", "time_delay"),
    ("wind", "cg_offset"),
)
Row = tuple[str, str, str, str, tuple[str, ...], float, float]  # kind, vehicle, truth, verdict, found, improvement, s


def _series(path: Path):  # type: ignore[no-untyped-def]
    # as `sysid discrepancy` without --report: no maneuver detection (the search needs none)
    return flight_series(path.name, condition_flight(read_log(path), options=ConditioningOptions(segments=())).records)


def _pairs(nulls: int, effects: list[str], doubles: bool) -> dict[str, list[tuple[str, str]]]:
    pairs: dict[str, list[tuple[str, str]]] = {}
    for strength in STRENGTHS:
        for effect in effects:
            pairs[f"{effect}@{strength}"] = [(effect, strength)]
    if doubles:
        pairs |= {f"{a}+{b}@strong": [(a, "strong"), (b, "strong")] for a, b in DOUBLES}
    pairs |= {f"none@{k}": [("none", "strong")] for k in range(nulls)}
    return pairs


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicles", nargs="+", default=list(VEHICLES), choices=list(VEHICLES))
    parser.add_argument("--seeds", type=int, nargs="+", default=[21, 22, 23])
    parser.add_argument("--nulls", type=int, default=4, help="null pairs per vehicle and seed")
    parser.add_argument("--effects", nargs="+", default=SINGLES, choices=SINGLES, help="single effects to fly")
    parser.add_argument("--no-doubles", action="store_true", help="leave the doubles out")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    rows: list[Row] = []
    for vehicle in args.vehicles:
        for seed in args.seeds:
            with tempfile.TemporaryDirectory() as folder:
                started = time.perf_counter()
                sim, reals = write_pair_set(
                    _pairs(args.nulls, args.effects, not args.no_doubles),
                    Path(folder),
                    seed,
                    VEHICLES[vehicle],
                    stretch=0.05,
                )
                print(f"{vehicle} seed {seed}: {len(reals)} pairs simulated in {time.perf_counter() - started:.0f} s")
                for name, path in reals.items():
                    truth, strength = name.split("@")
                    started = time.perf_counter()
                    result = discover([_series(sim)], [_series(path)])
                    seconds = time.perf_counter() - started
                    kind = "double" if "+" in truth else "null" if truth == "none" else "single"
                    found = tuple(f.effect for f in result.findings)
                    improvement = result.findings[0].improvement_percent if result.findings else float("nan")
                    label = f"{truth}@{strength}" if kind != "null" else "none"
                    rows.append((kind, vehicle, label, result.verdict, found, improvement, seconds))
                    print(
                        f"  {vehicle} {name:30s} -> {result.verdict:14s} {found} {improvement:6.1f} % {seconds:5.1f} s",
                        flush=True,
                    )
    _table(rows)
    return 0


def _table(rows: list[Row]) -> None:
    confusion: dict[str, Counter[str]] = defaultdict(Counter)
    for _kind, _vehicle, truth, verdict, _found, _, _ in rows:
        confusion[truth.split("@")[0]][verdict] += 1
    columns = sorted({v for c in confusion.values() for v in c})
    print("\nconfusion (rows truth, columns verdict)")
    print(f"{'':26s}" + "".join(f"{c[:13]:>14s}" for c in columns))
    for truth in sorted(confusion):
        print(f"{truth:26s}" + "".join(f"{confusion[truth][c]:14d}" for c in columns))
    for vehicle in sorted({r[1] for r in rows}):
        _shares([r for r in rows if r[1] == vehicle], vehicle)
    _shares(rows, "all")


def _shares(rows: list[Row], label: str) -> None:
    singles = [r for r in rows if r[0] == "single"]
    nulls = [r for r in rows if r[0] == "null"]
    doubles = [r for r in rows if r[0] == "double"]
    named = [r[3] == r[2].split("@")[0] for r in singles]
    by_strength = ", ".join(
        f"{s} {sum(r[3] == r[2].split('@')[0] for r in singles if r[2].endswith(s))}/"
        f"{sum(r[2].endswith(s) for r in singles)}"
        for s in ("strong", "moderate")
    )
    both = sum(set(r[2].split("@")[0].split("+")) <= set(r[4]) for r in doubles)
    print(
        f"\n{label}: singles named {sum(named)}/{len(singles)} ({by_strength}); "
        f"nulls 'none' {sum(r[3] == 'none' for r in nulls)}/{len(nulls)}; doubles, both named {both}/{len(doubles)}"
    )
    improvements = [r[5] for r in singles + doubles if r[5] == r[5]]
    if improvements:
        print(f"  median held-out improvement (named effects): {statistics.median(improvements):.1f} %")
    seconds = [r[6] for r in rows]
    print(
        f"  seconds per pair (read both logs + search): median {statistics.median(seconds):.1f}, max {max(seconds):.1f}"
    )


if __name__ == "__main__":
    raise SystemExit(main())
