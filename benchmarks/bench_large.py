"""Benchmark (issue 17): ``sysid ingest`` of 1 GB logs, its peak memory against what it keeps.

Usage::

    python benchmarks/bench_large.py [--gb 1.0] [FILE ...]

Without files it writes, into a temporary folder (not timed), a DataFlash log of about ``--gb`` GB
(:func:`bench_dataflash.synthetic_log`: two IMUs, ATT, RATE, RCOU and System ID messages at 400 Hz)
and a PX4 ULog of about the same size (:func:`bench_ingest.synthetic_ulog`: the Table 3.3 model's
closed loop with a sweep every 40 s, 250 Hz). For each file:

* ``peak``: GNU time's maximum resident set of ``sysid ingest FILE -o out.h5 -q``, a fresh process;
* ``kept``: the bytes of the arrays the same ingest holds when it is done, measured in another
  process that runs it and adds up the distinct arrays: the log's canonical signals (times and
  values, a time array shared by the signals of one message counted once) and the conditioned
  records; ``signals`` is the first part alone;
* ``peak / kept``, ``peak / values`` (what is kept at 8 bytes a value, float64, as issue 17's floor was
  set before float32 fields were held in float32), ``peak / signals`` and ``peak / file``. Issue 17 asks
  peak ≤ 1.5 × the signals kept.

Run on an idle machine; the DataFlash log takes about 20 s to write, the ULog a few minutes.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_dataflash import synthetic_log
from bench_ingest import compile_bytecode, synthetic_ulog

_SYSID = str(Path(sys.executable).with_name("sysid"))

#: Run in a child: ingest as ``sysid ingest`` does, then print the bytes of the signals and of the records.
_KEPT = """
import sys, warnings
import numpy as np
from flightlogs.store.campaign import ingest_campaign
warnings.simplefilter("ignore")
campaign = ingest_campaign([sys.argv[1]], [])
def root(a):
    while isinstance(a.base, np.ndarray):
        a = a.base
    return a
signals = {id(root(a)): root(a) for log in campaign.logs for s in log.signals.values() for a in (s.time_s, s.stored_values)}
arrays = [a for f in campaign.flights for r in f.records for a in (r.time_s, *(r[n] for n in r.signals))]
records = {id(root(a)): root(a) for a in arrays}
records = {k: v for k, v in records.items() if k not in signals}
held = [sum(a.nbytes for a in part.values()) for part in (signals, records)]
values = [sum(a.size * 8 for a in part.values()) for part in (signals, records)]
print(*held, *values)
"""


def peak_mb(path: Path, out: Path) -> tuple[float, float]:
    """Wall seconds and peak resident MB of ``sysid ingest PATH -o OUT -q``."""
    start = time.perf_counter()
    done = subprocess.run(
        ["/usr/bin/time", "-v", _SYSID, "ingest", str(path), "-q", "-o", str(out)],
        capture_output=True,
        text=True,
        check=True,
    )
    seconds = time.perf_counter() - start
    found = re.search(r"Maximum resident set size \(kbytes\): (\d+)", done.stderr)
    assert found is not None, done.stderr
    return seconds, int(found.group(1)) / 1024


def kept_mb(path: Path) -> tuple[float, float, float]:
    """MiB of the signals and of the records an ingest of `path` keeps, as held, and of both at 8 bytes a value."""
    done = subprocess.run([sys.executable, "-c", _KEPT, str(path)], capture_output=True, text=True, check=True)
    signals, records, signal_values, record_values = (int(v) / 2**20 for v in done.stdout.split())
    return signals, records, signal_values + record_values


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("files", nargs="*", type=Path)
    parser.add_argument("--gb", type=float, default=1.0, help="size of each synthetic log, GB")
    args = parser.parse_args(argv)
    compile_bytecode()
    with tempfile.TemporaryDirectory() as tmp:
        files = list(args.files)
        if not files:
            files = [synthetic_log(Path(tmp) / "large.bin", 8860.0 * args.gb)]  # 113 kB/s
            files.append(synthetic_ulog(Path(tmp) / "large.ulg", 10100.0 * args.gb))  # 99 kB/s
        print(
            f"{'file':14s} {'MB':>6s} {'ingest -o':>9s} {'peak MB':>8s} {'signals':>8s} {'records':>8s} "
            f"{'peak/kept':>9s} {'peak/values':>11s} {'peak/signals':>12s} {'peak/file':>9s}"
        )
        for path in files:
            size_mb = path.stat().st_size / 2**20
            seconds, peak = peak_mb(path, Path(tmp) / "out.h5")
            signals, records, values = kept_mb(path)
            print(
                f"{path.name:14s} {size_mb:6.0f} {seconds:8.1f}s {peak:8.0f} {signals:8.0f} {records:8.0f} "
                f"{peak / (signals + records):9.2f} {peak / values:11.2f} {peak / signals:12.2f} {peak / size_mb:9.2f}",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
