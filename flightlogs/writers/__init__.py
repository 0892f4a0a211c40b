"""Writers: valid PX4 ULog and ArduPilot DataFlash files from numpy columns, and atomic output files.

The public names of :mod:`~flightlogs.writers.atomic`, :mod:`~flightlogs.writers.dataflash` and
:mod:`~flightlogs.writers.ulog` are re-exported here: write ``from flightlogs.writers import name``.
Modules with a leading underscore are private.
"""

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
