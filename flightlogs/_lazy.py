"""Packages whose re-exported names load their modules on first use (SciPy's pattern).

``import flightlogs.readers.ulog`` then does not load pymavlink, nor ``import flightlogs`` numpy.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Collection, Mapping

__all__ = ["lazy_names"]


def lazy_names(
    package: str, homes: Mapping[str, str], submodules: Collection[str] = ()
) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """A package's ``__getattr__`` and ``__dir__``: each name in `homes` from its module, loaded when first asked for.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    homes : Mapping[str, str]
        Re-exported name → the submodule defining it (``"read_ulog": "ulog"``).
    submodules : Collection[str], optional
        Submodules that are names of the package themselves (``flightlogs.readers``).

    Returns
    -------
    tuple of callable
        ``(__getattr__, __dir__)`` to assign in the package.
    """

    def __getattr__(name: str) -> object:
        if name in submodules:
            return importlib.import_module(f"{package}.{name}")
        if name in homes:
            return getattr(importlib.import_module(f"{package}.{homes[name]}"), name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(homes) | set(submodules))

    return __getattr__, __dir__
