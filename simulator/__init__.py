"""flight-sysid's flight simulator: flights with known truth, written as real logs.

Each subpackage is a namespace of its own (``from simulator.campaign import run_scenario``),
from the bottom up: :mod:`simulator.world` (wind, ground effect, sensors),
:mod:`simulator.vehicle` (rigid body, rotors, presets, linearisation),
:mod:`simulator.autopilot` (control and excitation), :mod:`simulator.flights`
(nonlinear, linear and heave-only flights), :mod:`simulator.output` (DataFlash and
ULog files), :mod:`simulator.campaign` (scenarios) and :mod:`simulator.mrac`
(adaptive altitude control). ``import simulator`` loads none of them;
``simulator.flights`` loads one on first use.
"""

import importlib as _importlib
from types import ModuleType as _ModuleType

_SUBPACKAGES = ("autopilot", "campaign", "flights", "mrac", "output", "vehicle", "world")
__all__ = list(_SUBPACKAGES)


def __getattr__(name: str) -> _ModuleType:
    if name in _SUBPACKAGES:  # scipy's pattern: subpackages load on first use, not with the package
        return _importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_SUBPACKAGES))
