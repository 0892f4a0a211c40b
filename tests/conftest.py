"""Shared fixtures: where the real logs live, and a CLI runner.

Shared builders (closed-loop flights, a small model, a small verification) are in
``tests/builders.py``, imported as ``import builders``.
"""

from __future__ import annotations

import os
from pathlib import Path

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


# CI runs Hypothesis derandomized, so a green run is reproducible; local runs keep exploring.
from hypothesis import settings as _hypothesis_settings  # noqa: E402

_hypothesis_settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
if os.environ.get("CI"):
    _hypothesis_settings.load_profile("ci")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Longest files first: those that declare a longer timeout start before the rest (xdist hands out whole
    files in this order, ``--no-loadscope-reorder``), so that the longest one is not the last to start."""

    def budget(item: pytest.Item) -> float:
        marker = item.get_closest_marker("timeout")
        return float(marker.args[0]) if marker is not None and marker.args else 0.0

    items.sort(key=lambda item: -budget(item))
