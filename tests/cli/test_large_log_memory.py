"""Ingest's peak memory against what it keeps, on a 1 GB log (issue 17: large logs in bounded memory).

``sysid ingest LOG -o DATASET`` runs in a fresh process that reports its own peak resident memory;
what it keeps -- the values of the log's canonical signals and of the conditioned records, times
included, at 8 bytes each -- is added up from the dataset it wrote. The floor, the issue's: the whole
process's peak below 1.5 times that. The ruler is the number of values kept, in float64, as the floor
was set: the signals a log gives in float32 have since been held in float32 (422 of their 627 MiB),
which lowered the peak (1686 -> 1387-1401 MiB) but not the resampler's float64 working arrays, so against
the bytes now held the ratio is 1.48-1.50. benchmarks/bench_large.py measures both, with a 1 GB ULog too.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import h5py
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))  # the benchmarks' log writer
from bench_dataflash import synthetic_log

pytestmark = [
    pytest.mark.long,  # about 35 s: the log takes 20 s (and 5.6 GB) to write
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/status"),
]

#: Runs ``sysid ARGS`` in this child and prints its peak resident memory (VmHWM), kB.
_PEAK = """
import re, sys
from sysid_cli.main import cli
try:
    cli(sys.argv[1:])
except SystemExit as end:
    assert not end.code, end.code
print(re.search(r"VmHWM:\\s+(\\d+)", open("/proc/self/status").read()).group(1))
"""


def _peak_mb(log: Path, out: Path) -> float:
    done = subprocess.run(
        [sys.executable, "-c", _PEAK, "ingest", str(log), "-q", "-o", str(out)],
        capture_output=True,
        text=True,
        check=True,
    )
    return int(done.stdout.split()[-1]) / 1024


def _kept_mb(dataset: Path) -> tuple[float, float]:
    """MiB of the signals (a time array shared by a message's signals once) and of the records, 8 bytes a value."""
    with h5py.File(dataset) as h5:
        times: set[int] = set()
        signals = records = 0
        for log in h5["logs"].values():
            for signal in log["signals"].values():
                signals += signal["values"].size * 8
                time_s = signal["time_s"]  # a hard link to the message's time array
                if h5py.h5o.get_info(time_s.id).addr not in times:
                    times.add(h5py.h5o.get_info(time_s.id).addr)
                    signals += time_s.size * 8
        for flight in h5["conditioned"].values():
            for record in flight["records"].values():
                records += sum(array.size * 8 for array in record.values())
    return signals / 2**20, records / 2**20


def test_a_1_gb_log_peaks_below_one_and_a_half_times_what_it_keeps(tmp_path: Path) -> None:
    log = synthetic_log(tmp_path / "large.bin", 8860.0)  # 1.0 GB of 400 Hz System ID flight
    assert log.stat().st_size > 1e9
    dataset = tmp_path / "large.h5"
    peak = _peak_mb(log, dataset)
    log.unlink()
    signals, records = _kept_mb(dataset)
    assert signals > 500 and records > 400  # 1 GB of log: 627 MB of signals, 516 MB of records
    assert peak < 1.5 * (signals + records), f"peak {peak:.0f} MB, signals {signals:.0f} MB, records {records:.0f} MB"
