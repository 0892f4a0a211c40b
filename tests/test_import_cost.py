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


def test_a_fit_of_logs_to_a_json_model_loads_neither_h5py_nor_scipy_io(real_data: Path) -> None:
    """HDF5 (h5py, 35 ms) only for datasets and response files, scipy.io (35 ms) only for a .mat model file."""
    loaded = _loaded(
        "import sysid_cli.fit, sysid.fit.identify, sysid.fit.model_file, flightlogs.store.campaign\n"
        "from flightlogs.store import file_sha256\n"
        f"file_sha256({str(real_data / ARDUPILOT)!r})\n"
        "from sysid.freqresp import frequency_responses"
    )
    assert "h5py" not in loaded["top"] and "scipy.io" not in loaded["scipy"]
    assert "scipy.optimize" in loaded["scipy"]  # the probe did load the fit


def test_the_discrepancy_search_filters_a_flight_without_scipy_signal_ndimage_or_stats() -> None:
    """Its series (anti-alias filter, rate derivatives), lags, averages and bands are numpy (scipy.signal and ndimage: 0.8 s)."""
    loaded = _loaded(
        "import numpy as np\nfrom pathlib import Path\n"
        "from flightlogs.record import Record\n"
        "import sysid.discrepancy\n"
        "from sysid.discrepancy.catalogue._term import averaged, first_order\n"
        "from sysid.discrepancy.search import _band\n"
        "from sysid.discrepancy.series import COMMANDS, flight_series\n"
        "t = np.arange(5000) / 250.0\n"
        "columns = {s: np.sin(t * (k + 1)) for k, s in enumerate(('p', 'q', 'r', 'ax', 'ay', 'az', *COMMANDS))}\n"
        "record = Record(time_s=t, columns=columns, units=dict.fromkeys(columns, '-'), trim={'delta_thr': 2.0},"
        " source=Path('x.ulg'))\n"
        "series = flight_series('x', [record])\n"
        "lagged = first_order(series, series['delta_lat'], 0.03)\n"
        "_band({'p_dot': averaged(series, lagged, 0.5)}, series.rate_hz)"
    )
    assert not {"scipy.signal", "scipy.ndimage", "scipy.stats", "scipy.interpolate"} & set(loaded["scipy"])


def test_the_model_of_the_unknown_runs_without_scikit_learn() -> None:
    """Its matching pursuit is the port in sysid.discrepancy._omp: scikit-learn's import (1.3 s and more) stays out."""
    probe = (
        "import sys, numpy as np\nfrom sysid.discrepancy._omp import omp_gram_path\n"
        "x = np.random.default_rng(0).normal(size=(50, 6))\n"
        "omp_gram_path(x.T @ x, x.T @ x[:, 0], n_nonzero_coefs=3)\n"
        "import sysid.discrepancy\nprint('sklearn' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, cwd=ROOT, check=True)
    assert done.stdout.strip().splitlines()[-1] == "False"
