"""Benchmark: ``sysid ingest`` as a whole process against pymavlink and pyulog reading the same files.

Usage::

    python benchmarks/bench_ingest.py [FILE ...] [--seconds 1000] [--hours 2] [--repeat 3]

Without files it writes into a temporary folder, not timed:

* a synthetic ArduCopter System ID log of about 113 MB (``--seconds`` of flight at 400 Hz,
  :func:`bench_dataflash.synthetic_log`);
* a continuous ``--hours`` ordinary ArduCopter flight at 100 Hz (no System ID messages: the
  maneuvers are searched for over the whole log; about 200 MB for 2 hours);
* a PX4 ULog of a 980 s System ID flight (24 sweeps, all four axes, 250 Hz, about 97 MB) flown by
  the Table 3.3 linear model in closed loop and written by the simulator's PX4 writer;

and takes the real ULogs of ``../shared/data/real``. For each file:

* ``baseline``: DataFlash, pymavlink's ``DFReader_binary`` walk reading every field of every
  message (in this process, once; its values are compared with ours field by field, bitwise);
  ULog, pyulog's own parse of the file as a whole process, ``python -c "from pyulog import ULog;
  ULog(path)"`` (best of ``--repeat``): start-up and imports included on both sides;
* ``ingest``: ``sysid ingest FILE -q`` in a fresh process, start to exit (best of ``--repeat``), the
  package's bytecode compiled first as a wheel's install does;
* ``ingest -o``: the same writing the HDF5 dataset;
* the ratios of the baseline to each, and the peak resident memory of the ``-o`` process over the
  file's size.

The exit status is 1 if any DataFlash value differs from pymavlink's. Run on an idle machine.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_dataflash import REAL, check_identical, synthetic_log

from flightlogs.readers.dataflash import read_messages

_SYSID = [str(Path(sys.executable).with_name("sysid"))]  # the installed command, as a user runs it


def run_ingest(path: Path, out: Path | None) -> tuple[float, float]:
    """Wall seconds and peak resident MB of one ``sysid ingest`` process."""
    command = [*_SYSID, "ingest", str(path), "-q", *(["-o", str(out)] if out is not None else [])]
    start = time.perf_counter()  # GNU time measures the peak: a child of this (large) process would count its image
    done = subprocess.run(["/usr/bin/time", "-f", "%M", *command], capture_output=True, text=True, check=False)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        raise RuntimeError(f"sysid ingest {path} exited {done.returncode}: {done.stderr.strip()}")
    if out is not None:
        out.unlink()
    return seconds, int(done.stderr.strip().splitlines()[-1]) / 1024.0


def pyulog_seconds(path: Path, repeat: int) -> float:
    """Best of `repeat` pyulog parses of the whole file, each a fresh process, s."""
    command = [sys.executable, "-c", "import sys; from pyulog import ULog; ULog(sys.argv[1])", str(path)]
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True)
        best = min(best, time.perf_counter() - start)
    return best


def synthetic_ulog(path: Path, seconds: float = 980.0) -> Path:
    """A PX4 System ID flight: a 34 s sweep every 40 s, the axes in turn, 250 Hz, the linear model's closed loop."""
    from datetime import UTC, datetime

    from simulator.autopilot.excitation import Maneuver
    from simulator.flights.linear import simulate_hover
    from simulator.output.px4 import write_px4_log

    amplitude = {"lat": 8.0, "lon": 8.0, "yaw": 10.0, "thr": 4.0}
    axes = tuple(amplitude)
    sweeps = tuple(
        Maneuver(
            axis=axes[k % 4], kind="sweep", start_s=10.0 + 40.0 * k, amplitude=amplitude[axes[k % 4]], duration_s=34.0
        )
        for k in range(int((seconds - 10.0) // 40.0))
    )
    flight = simulate_hover(seconds, sweeps, rate_hz=250.0, substeps=2, seed=5)
    return write_px4_log(flight, path, utc_start=datetime(2025, 5, 1, 10, tzinfo=UTC))


def compile_bytecode() -> None:
    """Write the package's bytecode, as installing a wheel does (pyulog's and pymavlink's came that way).

    With ``PYTHONDONTWRITEBYTECODE`` set (this machine sets it) an editable install otherwise compiles
    every module of ours at each start: 40-60 ms of a 0.4 s ingest of a small log.
    """
    root = Path(__file__).resolve().parents[1]
    packages = [str(root / name) for name in ("flightlogs", "sysid", "sysid_cli", "reports", "simulator")]
    subprocess.run([sys.executable, "-m", "compileall", "-q", *packages], check=True, capture_output=True)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("files", nargs="*", type=Path)
    parser.add_argument("--seconds", type=float, default=1000.0, help="length of the synthetic DataFlash log, s")
    parser.add_argument("--hours", type=float, default=2.0, help="length of the continuous DataFlash log, h")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    compile_bytecode()
    ok = True
    with tempfile.TemporaryDirectory() as tmp:
        files = list(args.files)
        if not files:
            files = [synthetic_log(Path(tmp) / "synthetic_sysid.bin", args.seconds)]
            continuous = Path(tmp) / f"continuous_{args.hours:g}h.bin"
            files.append(synthetic_log(continuous, 3600.0 * args.hours, rate_hz=100.0, system_id=False))
            files.append(synthetic_ulog(Path(tmp) / "synthetic_sysid.ulg"))
            files += sorted(p for p in (REAL / "px4-ulog-rs").glob("*.ulg") if "corrupt" not in p.name)
            files += sorted((REAL / "kd0aij-impulse-response").glob("*.ulg"))
        print(
            f"{'file':28s} {'MB':>6s} {'baseline':>9s} {'ingest':>8s} {'ratio':>6s} {'-o':>8s} {'ratio':>6s} "
            f"{'peak MB':>8s} {'xfile':>6s} identical"
        )
        for path in files:
            size_mb = path.stat().st_size / 2**20  # MiB, as the peak (kB / 1024)
            if path.suffix.lower() == ".ulg":
                baseline, same = pyulog_seconds(path, args.repeat), "-"
            else:
                equal, baseline, _ = check_identical(path, read_messages(path))
                ok &= equal
                same = "yes" if equal else "NO"
            plain = min(run_ingest(path, None)[0] for _ in range(args.repeat))
            written = [run_ingest(path, Path(tmp) / "out.h5") for _ in range(args.repeat)]
            seconds, peak = min(s for s, _ in written), max(m for _, m in written)
            print(
                f"{path.name[:28]:28s} {size_mb:6.1f} {baseline:8.3f}s {plain:7.3f}s {baseline / plain:6.2f}x "
                f"{seconds:7.3f}s {baseline / seconds:6.2f}x {peak:8.0f} {peak / size_mb:5.1f}x {same}"
            )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
