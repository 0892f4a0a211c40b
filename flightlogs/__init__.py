"""flight-sysid's flight-log layer: read, condition, segment and store flight logs.

The core types are re-exported here: the errors (:mod:`flightlogs.errors`), the
canonical signal names (:mod:`flightlogs.signals`), :class:`FlightLog` and
:class:`Signal` (:mod:`flightlogs.flightlog`), :class:`Record`
(:mod:`flightlogs.record`) and the frame conversions (:mod:`flightlogs.frames`).
Two small modules of the core are namespaces of their own: the geodesy on the
mean Earth sphere (:mod:`flightlogs.geo`) and the runs of True in a boolean
mask (:mod:`flightlogs.masks`).
The subpackages are namespaces of their own (``from flightlogs.readers import
read_log``): :mod:`flightlogs.readers`, :mod:`flightlogs.writers`,
:mod:`flightlogs.maneuvers`, :mod:`flightlogs.conditioning` and
:mod:`flightlogs.store`; ``flightlogs.readers`` loads one on first use.
"""

from typing import TYPE_CHECKING as _TYPE_CHECKING

from flightlogs._lazy import lazy_names as _lazy_names
from flightlogs.errors import (
    CollectedWarnings,
    DataError,
    DataQualityWarning,
    FitError,
    FitWarning,
    LogCorruptionWarning,
    LogFormatError,
    MissingSignalError,
    ModelError,
    SysidError,
    SysidWarning,
    collected_warnings,
)
from flightlogs.signals import (
    CANONICAL_SIGNALS,
    ESTIMATOR_SIGNALS,
    LOGGED_SIGNALS,
    SignalSpec,
    describe,
    is_canonical,
)

if _TYPE_CHECKING:
    from flightlogs.flightlog import Autopilot, FlightLog, LogFormat, Signal, SystemIdRun, WindMeasurement
    from flightlogs.frames import air_velocity_body, earth_to_body, quaternion_to_euler, wind_to_body_axes
    from flightlogs.record import Record

_SUBPACKAGES = ("conditioning", "maneuvers", "readers", "store", "writers")
#: Core names that load their module (numpy, pandas) on first use: ``import flightlogs.errors`` stays light.
_LAZY = {
    "Signal": "flightlog",
    "SystemIdRun": "flightlog",
    "FlightLog": "flightlog",
    "WindMeasurement": "flightlog",
    "Autopilot": "flightlog",
    "LogFormat": "flightlog",
    "Record": "record",
    "quaternion_to_euler": "frames",
    "earth_to_body": "frames",
    "air_velocity_body": "frames",
    "wind_to_body_axes": "frames",
}
__all__ = [
    "SysidError",
    "LogFormatError",
    "DataError",
    "MissingSignalError",
    "ModelError",
    "FitError",
    "SysidWarning",
    "DataQualityWarning",
    "LogCorruptionWarning",
    "FitWarning",
    "CollectedWarnings",
    "collected_warnings",
    "SignalSpec",
    "CANONICAL_SIGNALS",
    "LOGGED_SIGNALS",
    "ESTIMATOR_SIGNALS",
    "is_canonical",
    "describe",
    "Signal",
    "SystemIdRun",
    "FlightLog",
    "WindMeasurement",
    "Autopilot",
    "LogFormat",
    "Record",
    "quaternion_to_euler",
    "earth_to_body",
    "air_velocity_body",
    "wind_to_body_axes",
    *_SUBPACKAGES,
]


__getattr__, __dir__ = _lazy_names(__name__, _LAZY, _SUBPACKAGES)
