"""Shared fixtures: where the real logs live, and a CLI runner."""

from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path
from types import ModuleType

import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]


def _real_data_dir() -> Path:
    override = os.environ.get("SYSID_REAL_DATA")
    return Path(override) if override else REPO_ROOT.parent / "shared" / "data" / "real"


REAL_DATA = _real_data_dir()


@pytest.fixture(scope="session")
def real_data() -> Path:
    """Folder of real logs recorded by others (``../shared/data/real``); never copied here."""
    if not REAL_DATA.is_dir():
        pytest.fail(f"real flight data not found at {REAL_DATA} (set SYSID_REAL_DATA)")
    return REAL_DATA


def _test_helper(name: str, relative: str) -> ModuleType:
    """Load a helper module of the tests by path (tests are not a package under ``--import-mode=importlib``)."""
    spec = importlib.util.spec_from_file_location(name, REPO_ROOT / "tests" / relative)
    assert spec is not None and spec.loader is not None
    module = sys.modules.setdefault(spec.name, importlib.util.module_from_spec(spec))
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="session")
def report_browser() -> ModuleType:
    """``tests/reports/browser.py``: rendering in headless Chromium, and ``sample_verification()``."""
    return _test_helper("_report_browser", "reports/browser.py")


@pytest.fixture(scope="session")
def excitation_tests() -> ModuleType:
    """``tests/flightlogs/maneuvers/test_excitation_recovery.py``'s closed-loop roll hold: ``_closed_loop``, ``_3211``, ``DT``."""
    return _test_helper("_excitation_tests", "flightlogs/maneuvers/test_excitation_recovery.py")


@pytest.fixture(scope="session")
def report_models() -> ModuleType:
    """``tests/reports/test_model_report.py``'s builders: ``small_model()``, ``STAMP``, ``PAIRS``."""
    return _test_helper("_model_report_tests", "reports/test_model_report.py")


# CI runs Hypothesis derandomized, so a green run is reproducible; local runs keep exploring.
from hypothesis import settings as _hypothesis_settings  # noqa: E402

_hypothesis_settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
if os.environ.get("CI"):
    _hypothesis_settings.load_profile("ci")
