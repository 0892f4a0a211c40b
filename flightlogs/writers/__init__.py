"""Writers: valid PX4 ULog and ArduPilot DataFlash files from numpy columns, and atomic output files.

The public names of :mod:`~flightlogs.writers.atomic`, :mod:`~flightlogs.writers.dataflash` and
:mod:`~flightlogs.writers.ulog` are re-exported here: write ``from flightlogs.writers import name``.
Modules with a leading underscore are private. Each name loads its module on first use (the DataFlash
writer imports pymavlink's tables): ``import flightlogs.writers.jsonio`` stays light.
"""

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from flightlogs.writers.atomic import atomic_output
    from flightlogs.writers.dataflash import (
        STANDARD_FORMATS,
        MessageBlock,
        MessageSpec,
        encode_dataflash,
        parameter_block,
        standard_block,
        text_block,
        write_dataflash,
    )
    from flightlogs.writers.ulog import TopicData, encode_ulog, write_ulog

__all__ = [
    "atomic_output",
    "MessageSpec",
    "MessageBlock",
    "STANDARD_FORMATS",
    "standard_block",
    "parameter_block",
    "text_block",
    "encode_dataflash",
    "write_dataflash",
    "TopicData",
    "encode_ulog",
    "write_ulog",
]

_HOMES = {
    "atomic_output": "atomic",
    **dict.fromkeys(
        (
            "STANDARD_FORMATS",
            "MessageBlock",
            "MessageSpec",
            "encode_dataflash",
            "parameter_block",
            "standard_block",
            "text_block",
            "write_dataflash",
        ),
        "dataflash",
    ),
    **dict.fromkeys(("TopicData", "encode_ulog", "write_ulog"), "ulog"),
}


def __getattr__(name: str) -> object:
    if name in _HOMES:
        import importlib

        return getattr(importlib.import_module(f"{__name__}.{_HOMES[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_HOMES))
