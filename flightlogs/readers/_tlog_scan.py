"""One pass over a MAVLink telemetry log with pymavlink, keeping the fields :mod:`flightlogs.readers.tlog` maps.

Every packet is decoded once; the wanted fields of the wanted message types
are kept per source (system id, component id) with the tlog receive time.
Bytes are accounted for, so that the reader can report what was skipped.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

__all__: list[str] = []

_PROGRESS_EVERY = 2000  # messages between progress callbacks

#: Fields kept per message type; everything else in the stream is decoded and dropped.
FIELDS: dict[str, tuple[str, ...]] = {
    "HEARTBEAT": ("type", "autopilot", "base_mode"),
    "EXTENDED_SYS_STATE": ("landed_state",),
    "ATTITUDE": ("time_boot_ms", "roll", "pitch", "yaw", "rollspeed", "pitchspeed", "yawspeed"),
    "HIGHRES_IMU": ("time_usec", "xacc", "yacc", "zacc"),
    "SCALED_IMU": ("time_boot_ms", "xacc", "yacc", "zacc"),
    "RAW_IMU": ("time_usec", "xacc", "yacc", "zacc"),
    "SCALED_IMU2": ("time_boot_ms", "xacc", "yacc", "zacc"),
    "SCALED_IMU3": ("time_boot_ms", "xacc", "yacc", "zacc"),
    "LOCAL_POSITION_NED": ("time_boot_ms", "z", "vx", "vy", "vz"),
    "GLOBAL_POSITION_INT": ("time_boot_ms", "relative_alt", "vx", "vy", "vz", "lat", "lon"),
    "DISTANCE_SENSOR": ("time_boot_ms", "current_distance", "min_distance", "max_distance", "orientation"),
    "SERVO_OUTPUT_RAW": ("time_usec", "port", *(f"servo{i}_raw" for i in range(1, 17))),
    "SYS_STATUS": ("voltage_battery",),
    "SYSTEM_TIME": ("time_unix_usec", "time_boot_ms"),
    "GPS_RAW_INT": ("time_usec", "fix_type", "lat", "lon"),
    "PARAM_VALUE": ("param_id", "param_value"),
    "STATUSTEXT": ("text",),
    "AUTOPILOT_VERSION": ("flight_sw_version",),
    "ATTITUDE_TARGET": (
        "time_boot_ms",
        "type_mask",
        "body_roll_rate",
        "body_pitch_rate",
        "body_yaw_rate",
        *(f"q[{i}]" for i in range(4)),
    ),
    "RC_CHANNELS": ("time_boot_ms", *(f"chan{i}_raw" for i in range(1, 19))),
}

Key = tuple[int, int]  # (system id, component id)


@dataclass(slots=True, kw_only=True)
class Scan:
    """What one pass over the file keeps: rows of wanted fields per source and type."""

    rows: dict[Key, dict[str, list[tuple[Any, ...]]]] = field(default_factory=dict)
    heartbeats: list[tuple[Key, int, int]] = field(default_factory=list)  # key, type, autopilot
    n_known: int = 0
    known_bytes: int = 0
    other_bytes: int = 0  # well-formed packets of message types this dialect does not know
    stopped: str = ""  # why decoding stopped early, if it did


def _open(path: Path) -> Any:  # pymavlink.mavutil.mavlogfile
    """Open `path` with pymavlink, with a MAVLink 2 parser that also reads MAVLink 1."""
    from pymavlink import mavutil
    from pymavlink.dialects.v20 import all as mavlink2

    conn = mavutil.mavlogfile(str(path), robust_parsing=True)
    conn.mav = mavlink2.MAVLink(conn, srcSystem=255, srcComponent=0)
    conn.mav.robust_parsing = True
    conn.first_byte = False  # keep mavutil from switching its global dialect
    return conn


def scan_tlog(path: Path, size: int, progress: Callable[[int, int], None] | None) -> Scan:
    """Decode every packet once, keeping the wanted fields of the wanted types."""
    from pymavlink.dialects.v20.all import MAVError

    scan = Scan()
    if progress is not None:
        progress(0, size)
    conn = _open(path)
    try:
        count = 0
        while True:
            try:
                msg = conn.recv_msg()
            except (MAVError, struct.error, ValueError, IndexError, TypeError, RuntimeError) as err:
                scan.stopped = f"decoding stopped at byte {conn.f.tell()}: {err}"
                break
            if msg is None:
                break
            count += 1
            if progress is not None and count % _PROGRESS_EVERY == 0:
                progress(min(conn.f.tell(), size), size)
            _keep(scan, msg)
    finally:
        conn.close()
    if progress is not None:
        progress(size, size)
    return scan


def _keep(scan: Scan, msg: Any) -> None:
    """Account for one decoded packet and keep its fields if its type is wanted."""
    msg_id = msg.get_msgId()
    if msg_id == -1:  # BAD_DATA: counted as skipped
        return
    if msg_id < 0:  # UNKNOWN_n: a well-formed packet of another dialect
        scan.other_bytes += 8 + len(msg.get_msgbuf())
        return
    scan.n_known += 1
    scan.known_bytes += 8 + len(msg.get_msgbuf())
    name = msg.get_type()
    fields = FIELDS.get(name)
    if fields is None:
        return
    key = (msg.get_srcSystem(), msg.get_srcComponent())
    row = (msg._timestamp, *(_field(msg, f) for f in fields))
    scan.rows.setdefault(key, {}).setdefault(name, []).append(row)
    if name == "HEARTBEAT":
        scan.heartbeats.append((key, int(msg.type), int(msg.autopilot)))


def _field(msg: Any, name: str) -> Any:
    """A field's value; ``"q[2]"`` is an element of the array field ``q``."""
    if name.endswith("]"):
        array, index = name[:-1].split("[")
        return getattr(msg, array)[int(index)]
    return getattr(msg, name, 0)


def message_table(name: str, rows: list[tuple[Any, ...]]) -> dict[str, np.ndarray]:
    """Columns of one message type as float arrays; ``"rx"`` is the tlog receive time, s."""
    fields = FIELDS[name]
    if name in ("PARAM_VALUE", "STATUSTEXT"):
        return {}
    if not rows:
        return {f: np.empty(0) for f in ("rx", *fields)}
    data = np.asarray(rows, dtype=np.float64)
    return {f: data[:, i] for i, f in enumerate(("rx", *fields))}
