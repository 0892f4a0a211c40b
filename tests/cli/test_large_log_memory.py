"""Ingest's peak memory against what it keeps (issue 17: large logs in bounded memory).

``sysid ingest LOG -o DATASET`` runs in a fresh process that reports its own peak resident memory;
what the ingest keeps -- the log's canonical signals and the conditioned records, the arrays the
dataset is written from -- is added up in this process. The floor: the peak above the process's
own start-up (the same command on a log of 1 MB) at most 1.5 times that. benchmarks/bench_large.py
measures the same on 1 GB logs.
"""

from __future__ import annotations

import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))  # the benchmarks' log writer
from bench_dataflash import synthetic_log

from flightlogs.store.campaign import ingest_campaign

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/status")

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


def _kept_mb(log: Path) -> float:
    """MB of the distinct arrays an ingest of `log` keeps: the log's signals and the conditioned records."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        campaign = ingest_campaign([log], [])

    def root(array: np.ndarray) -> np.ndarray:
        while isinstance(array.base, np.ndarray):
            array = array.base
        return array

    arrays = [a for g in campaign.logs for s in g.signals.values() for a in (s.time_s, s.values)]
    arrays += [a for f in campaign.flights for r in f.records for a in (r.time_s, *(r[n] for n in r.signals))]
    return sum({id(root(a)): root(a).nbytes for a in arrays}.values()) / 2**20


def test_a_100_mb_log_peaks_at_most_one_and_a_half_times_what_it_keeps(real_data: Path, tmp_path: Path) -> None:
    log = synthetic_log(tmp_path / "large.bin", 900.0)  # 101 MB of 400 Hz System ID flight
    start_up = _peak_mb(real_data / "ardupilot-log-diagnosis" / "sample.bin", tmp_path / "small.h5")
    peak = _peak_mb(log, tmp_path / "large.h5")
    kept = _kept_mb(log)
    assert log.stat().st_size > 100e6 and kept > 100  # signals and records of 101 MB of log
    assert (peak - start_up) <= 1.5 * kept, f"peak {peak:.0f} MB, start-up {start_up:.0f} MB, kept {kept:.0f} MB"
