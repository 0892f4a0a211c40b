"""The tree is formatted and linted by ruff, with the settings in ``pyproject.toml``."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TREE = ["flightlogs", "sysid", "simulator", "reports", "sysid_cli", "tests", "benchmarks"]


def _ruff(*args: str) -> subprocess.CompletedProcess[str]:
    ruff = shutil.which("ruff") or str(Path(sys.executable).with_name("ruff"))
    return subprocess.run([ruff, *args, *TREE], cwd=ROOT, capture_output=True, text=True, check=False)


@pytest.mark.parametrize("command", [("check", "--no-cache"), ("format", "--check", "--no-cache")])
def test_ruff_is_clean(command: tuple[str, ...]) -> None:
    result = _ruff(*command)
    assert result.returncode == 0, result.stdout + result.stderr
