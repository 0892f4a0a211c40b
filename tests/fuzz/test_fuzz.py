"""Fuzzing's CI slice and its regression cases (issue 17).

Every input kept under ``regressions/TARGET/`` broke the rule of :mod:`fuzz.targets` once (a
traceback instead of an error naming the file) and is replayed here: DataFlash logs whose FMT
lacks a field the reader maps (PARM without Value, MULT without Id, XKF1 without VE) or types a
number as text (FMTU's FmtType, PARM's TimeUS) (found by the fuzzer in mutated prefixes of the real logs, rebuilt small with
our writer, so no real log is copied here), an anemometer file of one delimiter, and damaged
datasets (h5py's KeyError, a JSON attribute cut, a version-1 dataset whose damaged global heap hung
libhdf5, a segment whose kind is damaged to ""; gzip-compressed). The slice runs each target's
atheris fuzzer for a few hundred inputs from a fixed seed (libFuzzer's ``-seed``), so a reader that
breaks on the first mutations of its seeds fails the suite; the long run is ``tests/fuzz/run.py``
(documented in ``benchmarks/README.md``).
"""

from __future__ import annotations

import gzip
import subprocess
import sys
from pathlib import Path

import pytest

from fuzz.targets import TARGETS, check

_HERE = Path(__file__).resolve().parent
_REGRESSIONS = sorted(p for p in (_HERE / "regressions").glob("*/*") if p.is_file())
#: Inputs per target in the slice, and the longest input: what fits 3 minutes on 2 cores with the rest.
_SLICE = {
    "dataflash": (300, 16384),
    "ulog": (40, 4096),
    "tlog": (200, 16384),
    "anemometer": (600, 8192),
    "segments_csv": (2000, 4096),
    "segments_toml": (2000, 4096),
    "model": (200, 200_000),
    "scenario": (1000, 4096),
    "dataset": (60, 400_000),
}

pytestmark = pytest.mark.filterwarnings("ignore")


@pytest.mark.parametrize("case", _REGRESSIONS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_a_former_defect_stays_fixed(case: Path, tmp_path: Path) -> None:
    target = TARGETS[case.parent.name]
    data = gzip.decompress(case.read_bytes()) if case.suffix == ".gz" else case.read_bytes()
    check(target, data, tmp_path / f"input{target.suffix}")


@pytest.mark.timeout(240)
@pytest.mark.parametrize("name", sorted(_SLICE))
def test_the_fuzzer_finds_nothing_in_its_first_inputs(name: str, tmp_path: Path) -> None:
    runs, max_len = _SLICE[name]
    command = [sys.executable, str(_HERE / "run.py"), name, f"-runs={runs}", "-seed=1", f"-max_len={max_len}"]
    command += ["-timeout=10", "-rss_limit_mb=2048", f"-artifact_prefix={tmp_path}/", f"-corpus={tmp_path / 'corpus'}"]
    done = subprocess.run(command, capture_output=True, text=True, timeout=230, check=False)
    crashes = sorted(p.name for p in tmp_path.glob("crash-*")) + sorted(p.name for p in tmp_path.glob("timeout-*"))
    assert done.returncode == 0 and not crashes, f"{crashes}\n{done.stderr[-3000:]}"
    assert f"Done {runs} runs" in done.stderr
