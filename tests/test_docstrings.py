"""Every public function and result class documents every parameter (numpydoc)."""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import pkgutil
import re

import pytest

PACKAGES = ["flightlogs", "sysid", "simulator", "reports"]


def _public_objects() -> list[tuple[str, object]]:
    found = []
    for package_name in PACKAGES:
        package = importlib.import_module(package_name)
        modules = [package] + [
            importlib.import_module(info.name)
            for info in pkgutil.walk_packages(package.__path__, prefix=f"{package_name}.")
        ]
        for module in modules:
            for name in getattr(module, "__all__", ()):
                obj = getattr(module, name)
                if getattr(obj, "__module__", None) == module.__name__:
                    found.append((f"{module.__name__}.{name}", obj))
    return found


def _documented(doc: str) -> set[str]:
    """Names listed in a numpydoc 'Parameters' section."""
    match = re.search(r"Parameters\n\s*-+\n(.*?)(\n\s*\n\s*[A-Z][a-z]+\n\s*-+\n|\Z)", doc, re.S)
    if not match:
        return set()
    names = set()
    for line in match.group(1).splitlines():
        head = re.match(r"^\s{0,8}([*\w][\w, *]*?)\s*(:|$)", line)
        if head and not line.startswith(" " * 9):
            names.update(n.strip().lstrip("*") for n in head.group(1).split(","))
    return names


def _parameters(obj: object) -> list[str]:
    if dataclasses.is_dataclass(obj):
        return [f.name for f in dataclasses.fields(obj) if f.init]
    signature = inspect.signature(obj)  # type: ignore[arg-type]
    return [n for n in signature.parameters if n not in {"self", "cls"}]


CASES = [(name, obj) for name, obj in _public_objects() if callable(obj)]


@pytest.mark.parametrize(("name", "obj"), CASES, ids=[name for name, _ in CASES])
def test_public_docstring_documents_parameters(name: str, obj: object) -> None:
    doc = inspect.getdoc(obj) or ""
    assert doc, f"{name} has no docstring"
    if inspect.isclass(obj) and not dataclasses.is_dataclass(obj):
        return  # exceptions, enums and plain classes: a summary is enough
    params = _parameters(obj)
    if not params:
        return
    missing = [p for p in params if p not in _documented(doc)]
    assert not missing, f"{name}: parameters not documented: {missing}"


def test_the_parser_reads_numpydoc() -> None:
    doc = "Summary.\n\nParameters\n----------\nx, y : float\n    Coordinates.\nz : int\n\nReturns\n-------\nfloat\n"
    assert _documented(doc) == {"x", "y", "z"}
