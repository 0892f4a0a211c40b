"""Issue 33: every writer returns what it wrote (a caller chains it, a command prints it), never None."""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import pytest

PACKAGES = ("flightlogs", "sysid", "reports", "simulator")


def _writers() -> list[tuple[str, str]]:
    """(module, name) of every public module-level function called write_* in the library packages."""
    found = []
    for package in PACKAGES:
        root = importlib.import_module(package)
        for info in pkgutil.walk_packages(root.__path__, f"{package}."):
            if any(part.startswith("_") for part in info.name.split(".")[1:]):
                continue
            module = importlib.import_module(info.name)
            for name, function in inspect.getmembers(module, inspect.isfunction):
                if name.startswith("write_") and function.__module__ == info.name:
                    found.append((info.name, name))
    return found


WRITERS = _writers()


def test_the_writers_are_found() -> None:
    names = {name for _, name in WRITERS}
    assert {"write_dataset", "write_responses", "write_bode_svg", "write_model", "write_verification"} <= names


@pytest.mark.parametrize(("module", "name"), WRITERS, ids=[f"{m}.{n}" for m, n in WRITERS])
def test_a_writer_returns_the_paths_it_wrote(module: str, name: str) -> None:
    returned = str(inspect.signature(getattr(importlib.import_module(module), name)).return_annotation)
    assert returned != "None" and ("Path" in returned or returned.endswith("Files")), f"{module}.{name} -> {returned}"
