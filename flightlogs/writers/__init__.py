"""Writers: valid PX4 ULog and ArduPilot DataFlash files from numpy columns, and atomic output files.

The public names of :mod:`~flightlogs.writers.atomic`, :mod:`~flightlogs.writers.dataflash` and
:mod:`~flightlogs.writers.ulog` are re-exported here: write ``from flightlogs.writers import name``.
Modules with a leading underscore are private. Each name loads its module on first use (the DataFlash
writer imports pymavlink's tables): ``import flightlogs.writers.jsonio`` stays light.
"""

from typing import TYPE_CHECKING

from flightlogs._lazy import lazy_names

if TYPE_CHECKING:
    from flightlogs.writers.atomic import atomic_folder, atomic_output, folder_in_place
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
    "atomic_folder",
    "atomic_output",
    "folder_in_place",
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
    "atomic_folder": "atomic",
    "atomic_output": "atomic",
    "folder_in_place": "atomic",
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


__getattr__, __dir__ = lazy_names(__name__, _HOMES)
