"""Benchmark: ``sysid discrepancy SIM REAL -q`` as a whole process against reading the same two logs.

    python benchmarks/bench_discrepancy_pair.py [--repeat 5] [--effect lag|none|drag|delay] [--before DIR]

Writes, not timed, one SIM and one REAL 4-minute PX4 ULog from ``tests/independent_sim`` (the plan of
``independent_sim.pairs.physics_pair_case``: lon, lat and yaw sweeps, a 15 m reposition out and back,
20 s at 0.35 m; 240 s at 250 Hz; the REAL vehicle's actuator lag ×1.6 by default). Then times, in
fresh processes, start to exit, interleaved run by run (A B A B ...: a loaded machine's drift falls on
both alike), best of ``--repeat``:

* ``read``: the baseline, ``sysid ingest SIM -q`` then ``sysid ingest REAL -q`` (each log read,
  conditioned and searched for its maneuvers: the cheapest whole-process read the command line offers);
* ``discrepancy``: ``sysid discrepancy SIM REAL -q`` (both logs read and the search run);
* with ``--before DIR`` (a checkout of other code, say ``git worktree add DIR main``), the same
  ``sysid discrepancy`` with that code first on the path: the search before and after, in one run.

Prints the seconds of each, their ratios and the seconds per pair; the package's bytecode is compiled
first, as installing a wheel does. One BLAS thread, as the command line runs it.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

_ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(_ROOT), str(_ROOT / "tests")]  # the generator lives in tests/

from independent_sim.corpus import write_case  # noqa: E402
from independent_sim.pairs import delayed, physics_pair_case, scaled  # noqa: E402

_SYSID = str(Path(sys.executable).with_name("sysid"))  # the installed command, as a user runs it
_PACKAGES = ("flightlogs", "sysid", "sysid_cli", "reports", "simulator")
_CHANGES = {
    "lag": scaled(1.6, "T_a"),
    "none": (),
    "drag": scaled(2.0, "X_u", "Y_v"),
    "delay": delayed(0.030),
}


def _environment(code: Path | None) -> dict[str, str]:
    """The environment of a timed process: one BLAS thread; `code` first on the path if given."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    if code is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(code), *filter(None, [os.environ.get("PYTHONPATH")])])
    return env


def _seconds(commands: list[list[str]], env: dict[str, str]) -> float:
    """Wall seconds of `commands` run one after the other, each a fresh process."""
    start = time.perf_counter()
    for command in commands:
        done = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
        if done.returncode != 0:
            raise RuntimeError(f"{' '.join(command)} exited {done.returncode}: {done.stderr.strip()[-2000:]}")
    return time.perf_counter() - start


def _compile(root: Path) -> None:
    packages = [str(root / name) for name in _PACKAGES if (root / name).is_dir()]
    subprocess.run([sys.executable, "-m", "compileall", "-q", *packages], check=True, capture_output=True)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="timed runs of each command (best is kept)")
    parser.add_argument("--effect", choices=sorted(_CHANGES), default="lag", help="what the REAL vehicle does")
    parser.add_argument("--before", type=Path, help="a checkout of other code to time the search of, too")
    parser.add_argument("--seed", type=int, default=3301)
    args = parser.parse_args()
    _compile(_ROOT)
    if args.before is not None:
        _compile(args.before)
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        sim = write_case(physics_pair_case("sim", args.seed), folder).log
        real = write_case(physics_pair_case("real", args.seed + 1, changes=_CHANGES[args.effect]), folder).log
        runs: dict[str, tuple[list[list[str]], dict[str, str]]] = {
            "read (ingest SIM + ingest REAL)": (
                [[_SYSID, "ingest", str(sim), "-q"], [_SYSID, "ingest", str(real), "-q"]],
                _environment(None),
            ),
            "discrepancy SIM REAL": ([[_SYSID, "discrepancy", str(sim), str(real), "-q"]], _environment(None)),
        }
        if args.before is not None:
            runs["discrepancy, --before code"] = (runs["discrepancy SIM REAL"][0], _environment(args.before.resolve()))
        for commands, env in runs.values():  # warm-up: the file cache, the imports' first reading
            _seconds(commands, env)
        best = dict.fromkeys(runs, float("inf"))
        for _ in range(args.repeat):
            for label, (commands, env) in runs.items():
                best[label] = min(best[label], _seconds(commands, env))
        size = (sim.stat().st_size + real.stat().st_size) / 1e6
    read, search = best["read (ingest SIM + ingest REAL)"], best["discrepancy SIM REAL"]
    print(f"pair: two 240 s ULogs, {size:.1f} MB in all; REAL: {args.effect}; best of {args.repeat}, interleaved")
    for label, seconds in best.items():
        print(f"  {label:34s} {seconds:7.2f} s  {seconds / read:5.2f}× the read")
    print(f"  seconds per pair (discrepancy): {search:.2f}; the search beyond the read: {search - read:.2f} s")
    if args.before is not None:
        before = best["discrepancy, --before code"]
        print(f"  discrepancy now / before: {search / before:.2f} ({before:.2f} s -> {search:.2f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
