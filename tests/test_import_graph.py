"""The import direction of DESIGN.md: sysid_cli -> reports -> sysid -> flightlogs."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LAYERS = ["flightlogs", "sysid", "reports", "sysid_cli"]
# Third-party packages a layer may not import (only the CLI has click, only reports matplotlib).
FORBIDDEN_THIRD_PARTY = {
    "flightlogs": {"click", "matplotlib", "jinja2"},
    "sysid": {"click", "matplotlib", "jinja2"},
    "reports": {"click"},
    "sysid_cli": set(),
}


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
    return names


def _modules(package: str) -> list[Path]:
    return sorted((ROOT / package).rglob("*.py"))


@pytest.mark.parametrize("package", LAYERS)
def test_no_upward_or_forbidden_imports(package: str) -> None:
    rank = LAYERS.index(package)
    upward = set(LAYERS[rank + 1 :])
    offenders = []
    for module in _modules(package):
        bad = _imports(module) & (upward | FORBIDDEN_THIRD_PARTY[package])
        if bad:
            offenders.append(f"{module.relative_to(ROOT)} imports {sorted(bad)}")
    assert not offenders, "\n".join(offenders)


def test_the_checker_sees_imports(tmp_path: Path) -> None:
    probe = tmp_path / "probe.py"
    probe.write_text("import click\nfrom sysid.x import y\nfrom . import z\n")
    assert _imports(probe) == {"click", "sysid"}
