"""Time ``sysid fit`` on one wind condition of the chapter 3 campaign flown by the linear model.

    python benchmarks/bench_fit.py [--condition calm|light|strong] [--trials 5] [--folder DIR] [--threads 2]
    python benchmarks/bench_fit.py --campaign [--folder DIR] [--repeat 3] [--stages]
    python benchmarks/bench_fit.py --campaign --paired [REV] [--repeat 21] [--folder DIR]

Simulates 5 sweeps per axis (4 axes, 20 ArduPilot logs with a ground
anemometer) of the Table 3.3 model in the chosen wind (not timed), then
times the whole ``sysid fit LOGS --wind DIR --model hover-wind`` command in a
fresh process (read, condition, frequency responses, fit, reduction, wind
step, model file): the target is under 20 s on 2 cores. It then times the
stages in-process and, as baselines, the F/G_u fit with scipy's
forward-difference Jacobian instead of the analytic one, and with 5
starting points instead of 1. BLAS threads are pinned to ``--threads``.

With ``--campaign`` it flies the whole chapter 3 campaign instead (``sysid simulate
chapter3-campaign``, 120 trials, not timed) and times ``sysid fit`` of its 60 sweeps (4 axes x
3 winds x 5 trials) with all 120 anemometer files, as a whole process (the project's bytecode written
first, as installing it does), best of ``--repeat``:
issue 16's target is under 4 s. BLAS threads are then the command's own default (one).
``--stages`` then runs the same fit once in this process and prints the wall time of each stage
(reading and conditioning, the responses of each pass, the clock-offset scan, the wind step and its
parts), in the order they start: where the seconds go, for whoever takes the 4 s on next.

This machine's speed drifts from day to day (the same code took 3.4 s one day and 10 s another), so a
time in seconds says little on its own. ``--paired`` times this code against another commit's, checked
out in a temporary git worktree, run in turn (A B A B ..., ``--repeat`` pairs, both started the same way:
this interpreter, the code's folder first on the path), and prints the median of the pairs' ratios. By
default the other commit is :data:`REFERENCE`'s, the code whose fit of the same 60 sweeps (byte for byte:
the simulator writes the same campaign) was measured under issue 16's 4 s on a quiet day; the ratio times
that day's seconds is what this code would take on it, the figure set against the 4 s.
"""

from __future__ import annotations

import argparse
import compileall
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

SPEEDS = {"calm": 0.9, "light": 2.7, "strong": 5.4}
_ROOT = Path(__file__).resolve().parents[1]

#: The commit after issue 16's changes and the wall seconds of its 60-sweep fit, whole process, on
#: 2026-11-27, idle: the median of three runs (3.64, 3.45, 3.41 s; benchmarks/README.md).
REFERENCE = ("4b3b7026fb2893243794017a06f7d28e0ca5e724", 3.45)


def _timed(label: str, function, *args, **kwargs):  # type: ignore[no-untyped-def]
    start = time.perf_counter()
    result = function(*args, **kwargs)
    elapsed = time.perf_counter() - start
    print(f"  {label:<44} {elapsed:7.2f} s")
    return result, elapsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--condition", choices=tuple(SPEEDS), default="light")
    parser.add_argument("--trials", type=int, default=5)
    parser.add_argument("--folder", type=Path, default=None, help="keep the logs here (default: a temporary folder)")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--campaign", action="store_true", help="time sysid fit of the 60 campaign sweeps")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--stages", action="store_true", help="with --campaign: also each stage's wall time")
    parser.add_argument(
        "--paired",
        nargs="?",
        const=REFERENCE[0],
        metavar="REV",
        help="with --campaign: time against commit REV, in turn (default: the issue 16 reference)",
    )
    args = parser.parse_args()
    if args.campaign:
        folder = args.folder or Path(tempfile.mkdtemp(prefix="bench-fit-"))
        if args.paired:
            _paired(folder, args.paired, args.repeat)
        else:
            _campaign(folder, args.repeat, stages=args.stages)
        return
    for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[name] = str(args.threads)

    from flightlogs.conditioning.condition import ConditioningOptions
    from flightlogs.store.campaign import ingest_campaign
    from simulator.campaign.fly import run_scenario
    from simulator.campaign.scenario import WindCondition, load_builtin
    from sysid.fit import FitOptions, IdentifyOptions, fit_frequency_responses, identify_flights

    folder = args.folder or Path(tempfile.mkdtemp(prefix="bench-fit-"))
    folder.mkdir(parents=True, exist_ok=True)
    logs_dir = folder / args.condition
    if not any(logs_dir.glob("*.bin")):
        wind = WindCondition(
            name=args.condition, mean_speed_m_s=SPEEDS[args.condition], direction_from_deg=300.0, turbulence_ratio=0.2
        )
        scenario = replace(load_builtin("linear-sweeps"), trials=args.trials, conditions=(wind,))
        start = time.perf_counter()
        run_scenario(scenario, logs_dir)
        print(
            f"simulated {args.trials} sweeps per axis in {args.condition} wind: {time.perf_counter() - start:.1f} s "
            f"(not part of the timing)"
        )
    logs = sorted(str(p) for p in logs_dir.glob("*.bin"))
    command = [
        "sysid",
        "fit",
        *logs,
        "--wind",
        str(logs_dir),
        "--wind-distance",
        "4.6",
        "--model",
        "hover-wind",
        "-o",
        str(folder / "model.json"),
        "-q",
    ]
    start = time.perf_counter()
    subprocess.run(command, check=True)
    total = time.perf_counter() - start
    print(
        f"sysid fit, {len(logs)} logs, {args.condition} wind, hover-wind: {total:.2f} s wall "
        f"(target < 20 s on 2 cores) {'OK' if total < 20 else 'SLOW'}"
    )

    print("stages, in-process:")
    campaign, _ = _timed(
        "read + condition (ingest_campaign)",
        ingest_campaign,
        [Path(p) for p in logs],
        [logs_dir],
        options=ConditioningOptions(wind_distance_m=4.6),
    )
    flights = [c for c in campaign.conditioned if c is not None]
    model, _ = _timed("responses + fit + reduction + wind step", identify_flights, flights, "hover-wind")
    responses = model.responses
    print("F/G_u fit on the same gated responses (with reduction):")
    _, analytic = _timed("analytic Jacobian, 1 start", fit_frequency_responses, model.structure, responses)
    _, numeric = _timed(
        "forward-difference Jacobian, 1 start",
        fit_frequency_responses,
        model.structure,
        responses,
        options=FitOptions(jacobian="numeric"),
    )
    _, several = _timed(
        "analytic Jacobian, 5 starts", fit_frequency_responses, model.structure, responses, options=FitOptions(starts=5)
    )
    print(
        f"ratios: numeric / analytic = {numeric / analytic:.1f}x, 5 starts / 1 start = {several / analytic:.1f}x; "
        f"J_ave = {model.cost.average:.1f}"
    )
    if IdentifyOptions().fit.starts != 1:  # pragma: no cover - a reminder if the default changes
        print("note: the default number of starts is not 1", file=sys.stderr)


def _compile_project(root: Path = _ROOT) -> None:
    """Write the bytecode of the project checked out at `root` (this one), as installing it does, before the timing.

    An editable install run with ``PYTHONDONTWRITEBYTECODE`` set (as on our CI machines) compiles every one of
    its modules from source in each process, about 0.3 s of the 60-sweep fit that an installed ``sysid`` does
    not spend. Bytecode already written is kept.
    """
    for package in ("flightlogs", "sysid", "sysid_cli", "simulator", "reports"):
        compileall.compile_dir(root / package, quiet=1)


def _campaign_arguments(folder: Path) -> tuple[list[str], int, int]:
    """``sysid fit``'s arguments for the campaign's 60 sweeps in `folder` (flown first if missing, not timed).

    Returns
    -------
    arguments : list of str
        Everything after ``sysid`` but the model file's ``-o``.
    n_logs, n_winds : int
        The sweeps' logs and the anemometer files found.
    """
    logs_dir = folder / "chapter3-campaign"
    folder.mkdir(parents=True, exist_ok=True)  # a --folder given need not exist yet
    if not any(logs_dir.glob("*-sweep-*.bin")):
        start = time.perf_counter()
        subprocess.run(["sysid", "simulate", "chapter3-campaign", "-o", str(logs_dir), "-q"], check=True)
        print(f"simulated the chapter 3 campaign: {time.perf_counter() - start:.1f} s (not part of the timing)")
    logs = sorted(str(p) for p in logs_dir.glob("*-sweep-*.bin"))
    winds = sorted(logs_dir.glob("*-anemometer.csv"))
    arguments = ["fit", *logs, "--wind", str(logs_dir), "--wind-distance", "4.6", "--model", "hover-wind"]
    return [*arguments, "-q"], len(logs), len(winds)


def _campaign(folder: Path, repeat: int, *, stages: bool = False) -> None:
    """Time ``sysid fit`` of the chapter 3 campaign's 60 sweeps, whole process, best of `repeat`; then its stages."""
    arguments, n_logs, n_winds = _campaign_arguments(folder)
    _compile_project()
    command = ["sysid", *arguments, "-o", str(folder / "model.json")]
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True)
        times.append(time.perf_counter() - start)
    best = min(times)
    print(
        f"sysid fit, {n_logs} sweeps, {n_winds} anemometer files, hover-wind: best {best:.2f} s of "
        f"{', '.join(f'{t:.2f}' for t in times)} (this machine today; the 4 s target is judged with --paired)"
    )
    if stages:
        _stages(command[2:])


def _paired(folder: Path, revision: str, pairs: int) -> None:
    """Time the campaign's fit with this code and with commit `revision`'s in turn, `pairs` times each.

    Prints both medians and the median of the pairs' ratios (this code / the other's) with their spread;
    with the issue 16 reference, that ratio times the reference's measured seconds too.
    """
    arguments, n_logs, n_winds = _campaign_arguments(folder)
    root = _ROOT
    other = Path(tempfile.mkdtemp(prefix="bench-fit-reference-")) / "code"
    subprocess.run(["git", "-C", str(root), "worktree", "add", "--detach", str(other), revision], check=True)
    try:
        full = subprocess.run(
            ["git", "-C", str(other), "rev-parse", "HEAD"], check=True, capture_output=True, text=True
        ).stdout.strip()
        for code in (root, other):
            _compile_project(code)
        seconds: dict[Path, list[float]] = {root: [], other: []}
        models = {root: folder / "model.json", other: folder / f"model-{full[:7]}.json"}  # each code's own
        for _ in range(pairs):
            for code in (root, other):
                start = time.perf_counter()
                subprocess.run(
                    [
                        sys.executable,
                        "-c",
                        "from sysid_cli.main import cli; cli()",
                        *arguments,
                        "-o",
                        str(models[code]),
                    ],
                    check=True,
                    capture_output=True,
                    cwd=code,
                    env={**os.environ, "PYTHONPATH": str(code)},
                )
                seconds[code].append(time.perf_counter() - start)
    finally:
        subprocess.run(["git", "-C", str(root), "worktree", "remove", "--force", str(other)], check=False)
    ratios = sorted(a / b for a, b in zip(seconds[root], seconds[other]))
    ratio = statistics.median(ratios)
    print(
        f"sysid fit, {n_logs} sweeps, {n_winds} anemometer files, hover-wind, {pairs} pairs in turn: this code "
        f"{statistics.median(seconds[root]):.2f} s, {full[:7]} {statistics.median(seconds[other]):.2f} s (medians); "
        f"ratio {ratio:.3f} (pairs {ratios[0]:.3f}-{ratios[-1]:.3f})"
    )
    if full == REFERENCE[0]:
        at = ratio * REFERENCE[1]
        print(
            f"at the speed of the day {full[:7]} took {REFERENCE[1]:.2f} s: {at:.2f} s (pairs "
            f"{ratios[0] * REFERENCE[1]:.2f}-{ratios[-1] * REFERENCE[1]:.2f} s; target < 4 s) {'OK' if at < 4 else 'SLOW'}"
        )


#: (module, function) of each stage timed by ``--stages``, where the caller looks it up.
_STAGES = (
    ("flightlogs.store.sources", "conditioned_sources"),
    ("sysid.fit.identify", "fit_frequency_responses"),
    ("sysid.fit.wind_offset", "scan_wind_offset"),
    ("sysid.fit.identify", "moved_flights"),
    ("sysid.fit.identify", "_wind_step"),
    ("sysid.fit.identify", "speed_derivatives"),
    ("sysid.fit.identify", "fit_wind"),
    ("sysid.fit.identify", "step_one_spread"),
)


def _stages(arguments: list[str]) -> None:
    """Run ``sysid fit ARGUMENTS`` in this process once, printing each stage's wall time and when it started."""
    import functools
    import importlib

    from sysid_cli.main import cli

    start = time.perf_counter()
    spans: list[tuple[str, float, float]] = []

    def timed(name: str, function):  # type: ignore[no-untyped-def]
        @functools.wraps(function)
        def wrapper(*args, **kwargs):  # type: ignore[no-untyped-def]
            begun = time.perf_counter()
            try:
                return function(*args, **kwargs)
            finally:
                spans.append((name, begun - start, time.perf_counter() - begun))

        return wrapper

    for module_name, name in _STAGES:
        module = importlib.import_module(module_name)
        setattr(module, name, timed(name, getattr(module, name)))
    cli(["fit", *arguments], standalone_mode=False)
    total = time.perf_counter() - start
    print(f"stages of one in-process run ({total:.2f} s in all), in the order they start:")
    for name, begun, length in sorted(spans, key=lambda span: span[1]):
        print(f"  {name:<26} at {begun:6.2f} s  {length:6.2f} s")


if __name__ == "__main__":
    main()
