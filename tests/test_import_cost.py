"""What reading a log and fitting load: the heavy libraries stay out of paths that do not use them.

Each case runs in a fresh interpreter (this one has loaded everything) and lists the top-level
packages of those named here that it imported. SciPy's first import costs 0.17 s and its
scipy.signal 0.75 s, pandas 0.2 s, python-control 0.35 s (with matplotlib): more than reading a
4 MB log.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("scipy", "pandas", "control", "matplotlib", "h5py", "tqdm", "pymavlink", "pyulog")
PX4 = "px4-ulog-rs/quadrotor_local.ulg"
ARDUPILOT = "ardupilot-log-diagnosis/sample.bin"


def _loaded(code: str) -> dict[str, list[str]]:
    """The modules among HEAVY (and scipy's submodules) that running `code` imported."""
    probe = (
        "import sys, json, warnings\nwarnings.simplefilter('ignore')\n"
        + code
        + "\nprint(json.dumps({'top': sorted({m.split('.')[0] for m in sys.modules} & set("
        + repr(HEAVY)
        + ")), 'scipy': sorted(m for m in sys.modules if m.count('.') == 1 and m.startswith('scipy.'))}))"
    )
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, cwd=ROOT, check=True)
    return dict(json.loads(done.stdout.strip().splitlines()[-1]))


@pytest.mark.parametrize(("relative", "reader"), [(PX4, "pyulog"), (ARDUPILOT, "pymavlink")])
def test_reading_and_conditioning_a_log_loads_neither_scipy_nor_pandas(
    real_data: Path, relative: str, reader: str
) -> None:
    loaded = _loaded(
        "from flightlogs.store.campaign import ingest_campaign\n"
        f"ingest_campaign([__import__('pathlib').Path({str(real_data / relative)!r})])"
    )
    assert loaded["top"] == [reader]  # the log's own reader only: no SciPy, pandas, h5py, tqdm, python-control


def test_the_fit_loads_neither_scipy_signal_nor_python_control() -> None:
    loaded = _loaded("import sysid.fit, sysid.freqresp")
    assert "control" not in loaded["top"] and "matplotlib" not in loaded["top"]
    assert "scipy.signal" not in loaded["scipy"] and "scipy.stats" not in loaded["scipy"]
