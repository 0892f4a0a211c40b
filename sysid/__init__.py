"""flight-sysid's identification engine: frequency responses, model structures, the fit, verification.

Each subpackage is a namespace of its own (``from sysid.fit import identify_logs``):
:mod:`sysid.model` (model structures), :mod:`sysid.freqresp` (frequency
responses), :mod:`sysid.fit` (identification), :mod:`sysid.verify` (time-domain
verification), :mod:`sysid.groundeffect` (ground-effect models of chapter 2),
:mod:`sysid.discrepancy` (what a real flight does that its simulation leaves out)
and :mod:`sysid.batch` (fleets of logs on a Dask cluster).
``import sysid`` loads none of them; ``sysid.fit`` loads one on first use.
"""

import importlib as _importlib
from types import ModuleType as _ModuleType

_SUBPACKAGES = ("batch", "discrepancy", "fit", "freqresp", "groundeffect", "model", "verify")
__all__ = list(_SUBPACKAGES)


def __getattr__(name: str) -> _ModuleType:
    if name in _SUBPACKAGES:  # scipy's pattern: subpackages load on first use, not with the package
        return _importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_SUBPACKAGES))
