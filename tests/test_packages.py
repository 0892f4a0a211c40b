"""Every subpackage is reachable from its package (issue 33): ``import sysid; sysid.discrepancy`` works."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("package", ["flightlogs", "sysid", "simulator"])
def test_every_subpackage_is_an_attribute_of_its_package(package: str) -> None:
    module = importlib.import_module(package)
    folders = sorted(p.parent.name for p in (ROOT / package).glob("*/__init__.py") if not p.parent.name.startswith("_"))
    assert folders and set(folders) <= set(dir(module)), set(folders) - set(dir(module))
    for name in folders:
        assert getattr(module, name).__name__ == f"{package}.{name}"
