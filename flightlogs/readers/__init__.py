"""Readers: every supported log and measurement file into a :class:`~flightlogs.flightlog.FlightLog` or its own container.

The public names of :mod:`~flightlogs.readers.anemometer`, :mod:`~flightlogs.readers.ardupilot`,
:mod:`~flightlogs.readers.dataflash`, :mod:`~flightlogs.readers.detect`,
:mod:`~flightlogs.readers.dispatch`, :mod:`~flightlogs.readers.px4_topics`,
:mod:`~flightlogs.readers.rig`, :mod:`~flightlogs.readers.segments_file`, :mod:`~flightlogs.readers.table`, :mod:`~flightlogs.readers.tlog` and :mod:`~flightlogs.readers.ulog`
are re-exported here: write ``from flightlogs.readers import name``. Modules with a leading
underscore are private. Each name loads its module on first use: ``import flightlogs.readers.ulog``
loads neither pymavlink nor the other readers.
"""

from typing import TYPE_CHECKING

from flightlogs._lazy import lazy_names

if TYPE_CHECKING:
    from flightlogs.readers.anemometer import COLUMN_SYNONYMS, SPEED_UNITS, WindMeasurement, read_anemometer_csv
    from flightlogs.readers.ardupilot import flightlog_from_messages, gps_leap_seconds, read_dataflash, system_id_runs
    from flightlogs.readers.dataflash import (
        DataFlashMessages,
        MessageFormat,
        MessageTable,
        decode_messages,
        message_dtype,
        read_messages,
    )
    from flightlogs.readers.detect import detect_format
    from flightlogs.readers.dispatch import ProgressCallback, ReadOptions, read_log
    from flightlogs.readers.px4_topics import (
        AUTOSTART_ROTORS,
        CA_AIRFRAME_NAMES,
        GPS_TOPICS,
        MAV_TYPE_NAMES,
        MAV_TYPE_ROTORS,
        PX4_GROUPS,
        PX4_MOTOR_SOURCES,
        Conversion,
        MotorSource,
        SignalGroup,
        TopicSource,
        describe_vehicle,
        mav_type_vehicle,
        px4_vehicle_type,
        rotor_count,
    )
    from flightlogs.readers.rig import HEIGHT_UNITS, THRUST_UNITS, RigData, read_rig_csv
    from flightlogs.readers.segments_file import read_segments_file, segment_line
    from flightlogs.readers.table import TableColumn, TableMap, is_table, parse_table_map, read_table
    from flightlogs.readers.tlog import read_tlog
    from flightlogs.readers.ulog import read_ulog

__all__ = [
    "WindMeasurement",
    "read_anemometer_csv",
    "COLUMN_SYNONYMS",
    "SPEED_UNITS",
    "read_dataflash",
    "flightlog_from_messages",
    "system_id_runs",
    "gps_leap_seconds",
    "MessageFormat",
    "MessageTable",
    "DataFlashMessages",
    "read_messages",
    "decode_messages",
    "message_dtype",
    "detect_format",
    "read_log",
    "ReadOptions",
    "ProgressCallback",
    "Conversion",
    "TopicSource",
    "SignalGroup",
    "MotorSource",
    "PX4_GROUPS",
    "PX4_MOTOR_SOURCES",
    "GPS_TOPICS",
    "MAV_TYPE_NAMES",
    "MAV_TYPE_ROTORS",
    "AUTOSTART_ROTORS",
    "CA_AIRFRAME_NAMES",
    "rotor_count",
    "describe_vehicle",
    "mav_type_vehicle",
    "px4_vehicle_type",
    "RigData",
    "read_rig_csv",
    "HEIGHT_UNITS",
    "THRUST_UNITS",
    "TableColumn",
    "TableMap",
    "parse_table_map",
    "read_table",
    "is_table",
    "read_tlog",
    "read_ulog",
    "read_segments_file",
    "segment_line",
]

_HOMES = {
    **dict.fromkeys(("COLUMN_SYNONYMS", "SPEED_UNITS", "WindMeasurement", "read_anemometer_csv"), "anemometer"),
    **dict.fromkeys(("flightlog_from_messages", "gps_leap_seconds", "read_dataflash", "system_id_runs"), "ardupilot"),
    **dict.fromkeys(
        ("DataFlashMessages", "MessageFormat", "MessageTable", "decode_messages", "message_dtype", "read_messages"),
        "dataflash",
    ),
    **dict.fromkeys(("detect_format",), "detect"),
    **dict.fromkeys(("ProgressCallback", "ReadOptions", "read_log"), "dispatch"),
    **dict.fromkeys(
        (
            "AUTOSTART_ROTORS",
            "CA_AIRFRAME_NAMES",
            "GPS_TOPICS",
            "MAV_TYPE_NAMES",
            "MAV_TYPE_ROTORS",
            "PX4_GROUPS",
            "PX4_MOTOR_SOURCES",
            "Conversion",
            "MotorSource",
            "SignalGroup",
            "TopicSource",
            "describe_vehicle",
            "mav_type_vehicle",
            "px4_vehicle_type",
            "rotor_count",
        ),
        "px4_topics",
    ),
    **dict.fromkeys(("HEIGHT_UNITS", "THRUST_UNITS", "RigData", "read_rig_csv"), "rig"),
    **dict.fromkeys(("read_segments_file", "segment_line"), "segments_file"),
    **dict.fromkeys(("TableColumn", "TableMap", "is_table", "parse_table_map", "read_table"), "table"),
    **dict.fromkeys(("read_tlog",), "tlog"),
    **dict.fromkeys(("read_ulog",), "ulog"),
}
__getattr__, __dir__ = lazy_names(__name__, _HOMES)
