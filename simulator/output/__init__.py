"""Output: a simulated flight written as ArduPilot DataFlash or PX4 ULog, anemometer CSV and truth JSON.

The public names of :mod:`~simulator.output.ardupilot` and :mod:`~simulator.output.px4` are
re-exported here: write ``from simulator.output import name``. Modules with a leading underscore are
private.
"""

from simulator.output.ardupilot import (
    VEHICLE_POSITION_DEG,
    AnemometerSetup,
    write_anemometer_csv,
    write_ardupilot_log,
    write_truth,
)
from simulator.output.px4 import AIRFRAMES, Airframe, write_px4_log

__all__ = [
    "AnemometerSetup",
    "VEHICLE_POSITION_DEG",
    "write_ardupilot_log",
    "write_anemometer_csv",
    "write_truth",
    "Airframe",
    "AIRFRAMES",
    "write_px4_log",
]
