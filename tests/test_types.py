"""The packages type-check under ``mypy --strict`` (house style; issue 13)."""

from __future__ import annotations

from pathlib import Path

import pytest
from mypy import api

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_packages_are_mypy_strict_clean() -> None:
    stdout, stderr, status = api.run(
        [
            "--strict",
            "--config-file",
            str(ROOT / "pyproject.toml"),
            "--ignore-missing-imports",
            "--no-error-summary",
            "--cache-dir",
            str(ROOT / ".mypy_cache"),
            str(ROOT / "flightlogs"),
            str(ROOT / "sysid"),
            str(ROOT / "simulator"),
            str(ROOT / "reports"),
            str(ROOT / "sysid_cli"),
        ]
    )
    assert status == 0, stdout + stderr
