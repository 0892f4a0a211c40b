"""Read MAVLink telemetry logs (``.tlog``) into a :class:`~flightlogs.flightlog.FlightLog`.

A tlog is what a ground station (Mission Planner, QGroundControl, MAVProxy)
records from the telemetry link: each MAVLink packet prefixed by the 8-byte
big-endian receive time in microseconds. Telemetry is streamed at a few hertz
at most, so a tlog serves format tests and slow signals, rarely identification.

Mapping to canonical signals (first message type present wins):

=========================  ===============================================  ===========
canonical                  MAVLink source                                   conversion
=========================  ===============================================  ===========
``phi theta psi``          ``ATTITUDE.roll/pitch/yaw``                      rad
``p q r``                  ``ATTITUDE.rollspeed/pitchspeed/yawspeed``       rad/s
``ax ay az``               ``HIGHRES_IMU.xacc..``; else ``SCALED_IMU``,     m/s²; mG × g0/1000
                           ``RAW_IMU``, ``SCALED_IMU2``, ``SCALED_IMU3``
``vn ve vd``               ``LOCAL_POSITION_NED.vx/vy/vz``;                 m/s; cm/s / 100
                           else ``GLOBAL_POSITION_INT.vx/vy/vz``
``height_agl``             ``DISTANCE_SENSOR`` facing down; else            cm / 100; −z;
                           ``LOCAL_POSITION_NED.z``; else                   mm / 1000
                           ``GLOBAL_POSITION_INT.relative_alt``
``motor_1..n``             ``SERVO_OUTPUT_RAW.servoN_raw``                  µs, as logged
``battery_v``              ``SYS_STATUS.voltage_battery``                   mV / 1000
``latitude longitude``     ``GLOBAL_POSITION_INT.lat/lon`` (not 0, 0);      1e-7 deg → rad
                           else ``GPS_RAW_INT.lat/lon`` (``fix_type`` ≥ 3)
``p_ref q_ref r_ref``      ``ATTITUDE_TARGET.body_roll_rate..``             rad/s
``phi_ref`` .. ``psi_ref`` ``ATTITUDE_TARGET.q``                            quaternion → Euler
``stick_*``                ``RC_CHANNELS.chanN_raw``, N from ``RCMAP_*``    normalised with
                           (ArduPilot) or ``RC_MAP_*`` (PX4)                ``RCn_MIN/TRIM/MAX``
=========================  ===============================================  ===========

The references (``*_ref``, ``stick_*``) are optional, never reported missing;
:mod:`flightlogs.readers._references` maps them. PX4 streams
``ATTITUDE_TARGET``; ArduPilot mostly does not.

Mixer inputs (``delta_*``) are not in the telemetry stream and are reported
missing.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from typing import Any, cast

import numpy as np

from flightlogs.errors import DataQualityWarning, LogCorruptionWarning, LogFormatError, collected_warnings
from flightlogs.flightlog import FlightLog, Signal
from flightlogs.readers._references import tlog_references
from flightlogs.readers._series import make_signal
from flightlogs.readers._tlog_scan import FIELDS, Key, Scan, message_table, scan_tlog
from flightlogs.readers.px4_topics import mav_type_vehicle

__all__ = ["read_tlog"]

_G0 = 9.80665  # standard gravity, m/s^2 (ArduPilot GRAVITY_MSS)
_AUTOPILOTS = {3: "ardupilot", 12: "px4"}  # MAV_AUTOPILOT
_MOTORS_BY_MAV_TYPE = {2: 4, 3: 2, 13: 6, 14: 8, 15: 3, 29: 12, 35: 10}
#: MAV_TYPE values that are not the vehicle (tracker, GCS, companion, gimbal, peripherals)
_NOT_A_VEHICLE = {5, 6, 18, 26, 27, 30, 31, 32, 33, 34, 36, 37, 38, 39, 40, 41, 42, 44, 48}
_MAV_AUTOPILOT_INVALID = 8
_FIRMWARE_PREFIXES = ("APM:", "ArduCopter", "ArduPlane", "ArduRover", "ArduSub", "Frame:")
_U32_US_PERIOD_S = 2.0**32 * 1e-6  # SERVO_OUTPUT_RAW.time_usec is uint32 µs
_REBOOT_DROP_S = 1.0  # a backward step of the boot clock larger than this is a reboot

#: Messages whose time field is the autopilot's boot clock, and its scale to seconds.
_BOOT_CLOCK = {
    "ATTITUDE": ("time_boot_ms", 1e-3),
    "HIGHRES_IMU": ("time_usec", 1e-6),
    "SCALED_IMU": ("time_boot_ms", 1e-3),
    "RAW_IMU": ("time_usec", 1e-6),
    "SCALED_IMU2": ("time_boot_ms", 1e-3),
    "SCALED_IMU3": ("time_boot_ms", 1e-3),
    "LOCAL_POSITION_NED": ("time_boot_ms", 1e-3),
    "GLOBAL_POSITION_INT": ("time_boot_ms", 1e-3),
    "DISTANCE_SENSOR": ("time_boot_ms", 1e-3),
    "SYSTEM_TIME": ("time_boot_ms", 1e-3),
}

_Tables = dict[str, dict[str, np.ndarray]]  # message type -> field -> column
_Signals = dict[str, Signal]


def read_tlog(path: str | PathLike[str], *, progress: Callable[[int, int], None] | None = None) -> FlightLog:
    """Read a MAVLink telemetry log into canonical signals.

    Parameters
    ----------
    path : str or path-like
        The ``.tlog`` file (MAVLink 1 and 2 packets, each after an 8-byte
        big-endian receive timestamp in µs).
    progress : callable, optional
        Called as ``progress(bytes_done, bytes_total)`` every few thousand
        messages and once at the end.

    Returns
    -------
    FlightLog
        ``log_format="tlog"``. Every signal is on the autopilot's boot clock
        (``time_boot_ms``/``time_usec`` of the message, s), not the ground
        station's receive time. ``utc_offset_s`` comes from ``SYSTEM_TIME``
        (else a ``GPS_RAW_INT`` with a 3-D fix and UNIX time), None when
        neither holds UTC. ``parameters`` are the first ``PARAM_VALUE`` seen
        for each name. ``warnings`` says how many bytes were skipped as
        corrupt or truncated and which samples were dropped.

    Raises
    ------
    LogFormatError
        If the file is empty, holds no intact MAVLink message, or has no
        heartbeat from an ArduPilot or PX4 vehicle.
    FileNotFoundError
        If `path` does not exist.

    Warns
    -----
    LogCorruptionWarning
        When bytes were skipped as corrupt or truncated.
    DataQualityWarning
        For reboots, samples dropped and signals left out; every message is
        also in ``warnings``.

    Notes
    -----
    Decoding goes through pymavlink's ``mavutil.mavlogfile`` with a MAVLink 2
    parser from the ``all`` dialect (which also reads MAVLink 1 packets).
    ``mavutil.mavlink_connection`` is not used: on a file it returns the
    mmap reader, which skips unrecognised bytes without counting them, it
    switches pymavlink's global dialect on the first MAVLink 2 packet, and it
    executes a file whose path contains ``/bin/``.

    Only messages from the vehicle are used: the system and component of the
    first heartbeat whose ``type`` is a vehicle (not a GCS, type 6, nor a
    companion, gimbal or peripheral) and whose ``autopilot`` is 3 (ArduPilot)
    or 12 (PX4). ``SYS_STATUS`` carries no time field; its samples are placed
    on the boot clock through the receive-time offset of the latest timed
    message before them. ``SERVO_OUTPUT_RAW.time_usec`` (uint32 µs) is
    unwrapped every 71.6 min the same way. The number of motors follows
    ``HEARTBEAT.type`` (quad 4, hexa 6, octo 8, tri 3, coaxial 2, deca 10,
    dodeca 12); for ArduPilot, ``SERVOn_FUNCTION`` parameters (33-40 and
    82-85 are motors 1-12) map motors to output channels, else motor k is
    channel k.

    Examples
    --------
    >>> from flightlogs.readers.tlog import read_tlog
    >>> log = read_tlog("flight.tlog")  # doctest: +SKIP
    >>> log["p"].source  # doctest: +SKIP
    'ATTITUDE.rollspeed'
    """
    path = Path(path)
    size = path.stat().st_size
    if size == 0:
        raise LogFormatError(f"{path}: the file is empty, not a MAVLink telemetry log")
    scan = scan_tlog(path, size, progress)
    if scan.n_known == 0:
        raise LogFormatError(f"{path}: no intact MAVLink message found; not a telemetry log")
    key, mav_type, autopilot = _vehicle(scan, path)
    rows = scan.rows.get(key, {})
    with collected_warnings() as caught:
        skipped = size - scan.known_bytes - scan.other_bytes
        if skipped:
            message = (
                f"{path.name}: skipped {skipped} of {size} bytes as corrupt or truncated "
                f"({100.0 * skipped / size:.2g}%); read the {scan.n_known} intact messages"
                + (f" ({scan.stopped})" if scan.stopped else "")
            )
            warnings.warn(LogCorruptionWarning(message), stacklevel=2)
        tables = {name: message_table(name, rows.get(name, [])) for name in FIELDS}
        clock = _BootClock.from_tables(tables)
        parameters = _parameters(rows.get("PARAM_VALUE", []))
        signals: dict[str, Signal] = {}
        if clock.reboots:
            message = (
                f"{path.name}: the autopilot rebooted {clock.reboots} time(s) during the log; later "
                "boot sessions are placed on the first one's clock through the receive time"
            )
            warnings.warn(DataQualityWarning(message), stacklevel=2)
        for builder in (_attitude, _imu, _velocity, _height):
            builder(tables, clock, signals)
        _motors(tables, clock, mav_type, autopilot, parameters, signals)
        _battery(tables, clock, signals)
        _states(tables, clock, signals)
        _position(tables, clock, signals)
        tlog_references(
            tables,
            lambda table: clock.log_time_s(table["time_boot_ms"] * 1e-3, table["rx"]),
            autopilot,  # type: ignore[arg-type]
            parameters,
            lambda *series: _add(signals, *series),
        )
        return FlightLog(
            path=path,
            log_format="tlog",
            autopilot=autopilot,  # type: ignore[arg-type]
            signals=signals,
            vehicle=_vehicle_string(rows, mav_type),
            vehicle_type=mav_type_vehicle(mav_type),
            parameters=parameters,
            utc_offset_s=_utc_offset(tables, clock),
            warnings=caught.messages,
        )


# --------------------------------------------------------------------------- vehicle and clock


def _vehicle(scan: Scan, path: Path) -> tuple[Key, int, str]:
    """Source key, MAV_TYPE and autopilot name of the vehicle's own heartbeats."""
    others: set[int] = set()
    for key, mav_type, autopilot in scan.heartbeats:
        if mav_type in _NOT_A_VEHICLE or autopilot == _MAV_AUTOPILOT_INVALID:
            continue
        if autopilot in _AUTOPILOTS:
            return key, mav_type, _AUTOPILOTS[autopilot]
        others.add(autopilot)
    if others:
        raise LogFormatError(
            f"{path}: the vehicle's HEARTBEAT names autopilot {sorted(others)} (MAV_AUTOPILOT); "
            "only ArduPilot (3) and PX4 (12) are supported"
        )
    raise LogFormatError(f"{path}: no HEARTBEAT from a vehicle, so the autopilot is unknown")


@dataclass(frozen=True, slots=True, kw_only=True)
class _BootClock:
    """Maps tlog receive times and message times onto one log clock.

    Built from every timed vehicle message, in receive order: at receive
    time ``rx[i]`` the boot clock read ``boot[i]``. A drop of the boot clock
    by more than ``_REBOOT_DROP_S`` starts a new boot session; later
    sessions are shifted by the change of the median receive-minus-boot
    offset, so the log clock is the first session's boot clock continued.
    """

    rx: np.ndarray  # receive time of each timed message, s, sorted
    offset: np.ndarray  # rx - boot, s
    session: np.ndarray  # boot session of each entry, 0, 1, ...
    shift: np.ndarray  # (n_sessions,) added to boot times of each session, s

    @classmethod
    def from_tables(cls, tables: _Tables) -> _BootClock:
        rx_parts, boot_parts = [], []
        for name, (time_field, scale) in _BOOT_CLOCK.items():
            table = tables[name]
            if table["rx"].size:
                rx_parts.append(table["rx"])
                boot_parts.append(table[time_field] * scale)
        if not rx_parts:
            empty = np.empty(0)
            return cls(rx=empty, offset=empty, session=np.empty(0, dtype=np.int64), shift=np.zeros(1))
        rx = np.concatenate(rx_parts)
        boot = np.concatenate(boot_parts)
        order = np.argsort(rx, kind="stable")
        rx, boot = rx[order], boot[order]
        session = np.concatenate(([0], np.cumsum(np.diff(boot) < -_REBOOT_DROP_S)))
        offset = rx - boot
        medians = np.array([np.median(offset[session == s]) for s in range(session[-1] + 1)])
        return cls(rx=rx, offset=offset, session=session, shift=medians - medians[0])

    @property
    def reboots(self) -> int:
        """Number of autopilot reboots seen."""
        return int(self.shift.size - 1)

    def _index(self, rx: np.ndarray) -> np.ndarray:
        return np.clip(np.searchsorted(self.rx, rx, side="right") - 1, 0, self.rx.size - 1)

    def log_time_s(self, boot_s: np.ndarray, rx: np.ndarray) -> np.ndarray:
        """Log-clock time, s, of messages stamped `boot_s` and received at `rx`."""
        if self.rx.size == 0 or self.shift.size == 1:
            return boot_s
        return cast(np.ndarray, boot_s + self.shift[self.session[self._index(rx)]])

    def boot_time_s(self, rx: np.ndarray) -> np.ndarray | None:
        """Boot-clock time, s, of receive times `rx` (own session); None if nothing is timed."""
        if self.rx.size == 0:
            return None
        return cast("np.ndarray | None", rx - self.offset[self._index(rx)])


def _log_time(table: dict[str, np.ndarray], msg: str, clock: _BootClock) -> np.ndarray:
    """Log-clock time, s, of each row of a timed message table."""
    time_field, scale = _BOOT_CLOCK[msg]
    return clock.log_time_s(table[time_field] * scale, table["rx"])


# --------------------------------------------------------------------------- signals


def _add(signals: _Signals, name: str, time_s: np.ndarray, values: np.ndarray, unit: str, source: str) -> None:
    signal = make_signal(name, time_s, values, unit, source)
    if signal is not None:
        signals[name] = signal


def _attitude(tables: _Tables, clock: _BootClock, signals: _Signals) -> None:
    table = tables["ATTITUDE"]
    if not table["rx"].size:
        return
    time_s = _log_time(table, "ATTITUDE", clock)
    for name, field_name in (
        ("phi", "roll"),
        ("theta", "pitch"),
        ("psi", "yaw"),
        ("p", "rollspeed"),
        ("q", "pitchspeed"),
        ("r", "yawspeed"),
    ):
        unit = "rad" if name in ("phi", "theta", "psi") else "rad/s"
        _add(signals, name, time_s, table[field_name], unit, f"ATTITUDE.{field_name}")


def _imu(tables: _Tables, clock: _BootClock, signals: _Signals) -> None:
    for msg in ("HIGHRES_IMU", "SCALED_IMU", "RAW_IMU", "SCALED_IMU2", "SCALED_IMU3"):
        table = tables[msg]
        if not table["rx"].size:
            continue
        time_s = _log_time(table, msg, clock)
        gain, note = (1.0, "") if msg == "HIGHRES_IMU" else (_G0 * 1e-3, " (mG × 0.00980665)")
        for axis in "xyz":
            _add(signals, f"a{axis}", time_s, table[f"{axis}acc"] * gain, "m/s^2", f"{msg}.{axis}acc{note}")
        return


def _velocity(tables: _Tables, clock: _BootClock, signals: _Signals) -> None:
    for msg, gain, note in (("LOCAL_POSITION_NED", 1.0, ""), ("GLOBAL_POSITION_INT", 0.01, " (cm/s / 100)")):
        table = tables[msg]
        if not table["rx"].size:
            continue
        time_s = _log_time(table, msg, clock)
        for name, field_name in (("vn", "vx"), ("ve", "vy"), ("vd", "vz")):
            _add(signals, name, time_s, table[field_name] * gain, "m/s", f"{msg}.{field_name}{note}")
        return


def _height(tables: _Tables, clock: _BootClock, signals: _Signals) -> None:
    table = tables["DISTANCE_SENSOR"]
    down = table["orientation"] == 25  # MAV_SENSOR_ROTATION_PITCH_270
    if down.any():
        dist = table["current_distance"][down]
        valid = (dist >= table["min_distance"][down]) & (dist <= table["max_distance"][down])
        if (~valid).any():
            message = (
                f"DISTANCE_SENSOR.current_distance: dropped {int((~valid).sum())} "
                f"of {dist.size} readings outside the sensor's range"
            )
            warnings.warn(DataQualityWarning(message), stacklevel=2)
        time_s = _log_time(table, "DISTANCE_SENSOR", clock)[down][valid]
        _add(
            signals,
            "height_agl",
            time_s,
            dist[valid] * 0.01,
            "m",
            "DISTANCE_SENSOR.current_distance (cm / 100)",
        )
        return
    for msg, field_name, gain, note in (
        ("LOCAL_POSITION_NED", "z", -1.0, " (negated)"),
        ("GLOBAL_POSITION_INT", "relative_alt", 1e-3, " (mm / 1000)"),
    ):
        table = tables[msg]
        if table["rx"].size:
            _add(
                signals,
                "height_agl",
                _log_time(table, msg, clock),
                table[field_name] * gain,
                "m",
                f"{msg}.{field_name}{note}",
            )
            return


def _motor_channels(n_motors: int, autopilot: str, parameters: dict[str, float]) -> list[int]:
    """Output channel (1-16) of motors 1..n_motors."""
    channels = list(range(1, n_motors + 1))
    if autopilot != "ardupilot":
        return channels
    function_of = {ch: parameters.get(f"SERVO{ch}_FUNCTION") for ch in range(1, 17)}
    for motor in range(1, n_motors + 1):
        function = 32 + motor if motor <= 8 else 73 + motor  # k_motor1..8 = 33..40, 9..12 = 82..85
        found = [ch for ch, f in function_of.items() if f is not None and int(f) == function]
        if found:
            channels[motor - 1] = found[0]
    return channels


def _motors(
    tables: _Tables,
    clock: _BootClock,
    mav_type: int,
    autopilot: str,
    parameters: dict[str, float],
    signals: _Signals,
) -> None:
    table = tables["SERVO_OUTPUT_RAW"]
    if not table["rx"].size:
        return
    n_motors = _MOTORS_BY_MAV_TYPE.get(mav_type)
    if n_motors is None:
        message = f"SERVO_OUTPUT_RAW: MAV_TYPE {mav_type} is not a known multirotor; motor outputs not mapped"
        warnings.warn(DataQualityWarning(message), stacklevel=2)
        return
    main = table["port"] == 0
    rx = table["rx"][main]
    boot_s = table["time_usec"][main] * 1e-6
    expected = clock.boot_time_s(rx)
    if expected is not None:  # undo the uint32 wrap-around (every 71.6 min)
        boot_s = boot_s + np.round((expected - boot_s) / _U32_US_PERIOD_S) * _U32_US_PERIOD_S
    time_s = clock.log_time_s(boot_s, rx)
    for motor, channel in enumerate(_motor_channels(n_motors, autopilot, parameters), start=1):
        field_name = f"servo{channel}_raw"
        _add(signals, f"motor_{motor}", time_s, table[field_name][main], "us", f"SERVO_OUTPUT_RAW.{field_name}")


def _battery(tables: _Tables, clock: _BootClock, signals: _Signals) -> None:
    table = tables["SYS_STATUS"]
    if not table["rx"].size:
        return
    millivolts = table["voltage_battery"]
    monitored = (millivolts != 0) & (millivolts != 65535)
    if not monitored.any():
        message = "SYS_STATUS.voltage_battery is 0 or 65535 throughout (no battery monitor); battery_v omitted"
        warnings.warn(DataQualityWarning(message), stacklevel=2)
        return
    boot_s = clock.boot_time_s(table["rx"])
    if boot_s is None:
        message = "SYS_STATUS has no time field and no timed message maps it to the boot clock; battery_v omitted"
        warnings.warn(DataQualityWarning(message), stacklevel=2)
        return
    if (~monitored).any():
        message = (
            f"SYS_STATUS.voltage_battery: dropped {int((~monitored).sum())} of "
            f"{millivolts.size} samples reading 0 or 65535 (no monitor)"
        )
        warnings.warn(DataQualityWarning(message), stacklevel=2)
    time_s = clock.log_time_s(boot_s, table["rx"])
    _add(
        signals,
        "battery_v",
        time_s[monitored],
        millivolts[monitored] * 1e-3,
        "V",
        "SYS_STATUS.voltage_battery (mV / 1000; time from the receive clock)",
    )


_ARMED_FLAG = 128  # MAV_MODE_FLAG_SAFETY_ARMED of HEARTBEAT.base_mode
_ON_GROUND = 1  # MAV_LANDED_STATE_ON_GROUND; 0 is undefined, 2-4 in air, taking off, landing


def _states(tables: _Tables, clock: _BootClock, signals: _Signals) -> None:
    """``armed`` from the vehicle's HEARTBEAT and ``landed`` from EXTENDED_SYS_STATE, on the receive clock."""
    for name, message, field, state in (
        ("armed", "HEARTBEAT", "base_mode", "128: armed"),
        ("landed", "EXTENDED_SYS_STATE", "landed_state", "1: on the ground"),
    ):
        table = tables[message]
        boot_s = clock.boot_time_s(table["rx"]) if table["rx"].size else None
        if boot_s is None:
            continue
        raw = table[field].astype(np.int64)
        if name == "armed":
            values, known = ((raw & _ARMED_FLAG) != 0).astype(np.float64), np.ones(raw.size, dtype=bool)
        else:
            values, known = (raw == _ON_GROUND).astype(np.float64), raw != 0
        if known.any():
            time_s = clock.log_time_s(boot_s, table["rx"])[known]
            _add(signals, name, time_s, values[known], "1", f"{message}.{field} ({state}; time from the receive clock)")


def _position(tables: _Tables, clock: _BootClock, signals: _Signals) -> None:
    """Latitude and longitude: the estimator's global position, else the receiver's with a 3-D fix."""
    table = tables["GLOBAL_POSITION_INT"]
    if (known := _not_null_island(table)).any():
        _add_position(
            signals,
            "GLOBAL_POSITION_INT",
            table,
            _log_time(table, "GLOBAL_POSITION_INT", clock),
            known,
            "at 0, 0 (no position yet)",
            "",
        )
        return
    table = tables["GPS_RAW_INT"]
    fixed = (table["fix_type"] >= 3) & _not_null_island(table)
    boot_s = clock.boot_time_s(table["rx"])
    if fixed.any() and boot_s is not None:
        _add_position(
            signals,
            "GPS_RAW_INT",
            table,
            clock.log_time_s(boot_s, table["rx"]),
            fixed,
            "without a 3-D fix (fix_type < 3) or at 0, 0",
            "; time from the receive clock",
        )


def _not_null_island(table: dict[str, np.ndarray]) -> np.ndarray:
    """Rows whose position is not exactly 0, 0 (what MAVLink sends before there is one)."""
    return cast(np.ndarray, (table["lat"] != 0) | (table["lon"] != 0))


def _add_position(
    signals: _Signals,
    msg: str,
    table: dict[str, np.ndarray],
    time_s: np.ndarray,
    keep: np.ndarray,
    why: str,
    note: str,
) -> None:
    if (~keep).any():
        message = f"{msg}.lat, lon: dropped {int((~keep).sum())} of {keep.size} samples {why}"
        warnings.warn(DataQualityWarning(message), stacklevel=2)
    for name, field_name in (("latitude", "lat"), ("longitude", "lon")):
        _add(
            signals,
            name,
            time_s[keep],
            np.deg2rad(table[field_name][keep] * 1e-7),
            "rad",
            f"{msg}.{field_name} (1e-7 deg→rad{note})",
        )


# --------------------------------------------------------------------------- metadata


def _utc_offset(tables: _Tables, clock: _BootClock) -> float | None:
    """UNIX time minus log time, s, from SYSTEM_TIME, else GPS_RAW_INT with UTC."""
    table = tables["SYSTEM_TIME"]
    valid = (table["time_unix_usec"] > 1e15) & (table["time_boot_ms"] > 0)  # 0: no GPS time yet
    if valid.any():
        log_s = _log_time(table, "SYSTEM_TIME", clock)[valid]
        return float(np.median(table["time_unix_usec"][valid] * 1e-6 - log_s))
    table = tables["GPS_RAW_INT"]
    valid = (table["time_usec"] > 1e15) & (table["fix_type"] >= 3)  # 1e15 µs: UNIX, not boot
    boot_s = clock.boot_time_s(table["rx"][valid])
    if valid.any() and boot_s is not None:
        log_s = clock.log_time_s(boot_s, table["rx"][valid])
        return float(np.median(table["time_usec"][valid] * 1e-6 - log_s))
    return None


def _parameters(rows: list[tuple[Any, ...]]) -> dict[str, float]:
    """First value seen of each parameter."""
    parameters: dict[str, float] = {}
    for _rx, name, value in rows:
        name = str(name).rstrip("\x00")
        if name and name not in parameters:
            parameters[name] = float(value)
    return parameters


def _vehicle_string(rows: dict[str, list[tuple[Any, ...]]], mav_type: int) -> str:
    """Firmware, board and frame lines from STATUSTEXT/AUTOPILOT_VERSION, then MAV_TYPE."""
    from pymavlink.dialects.v20 import all as mavlink2

    parts: list[str] = []
    for _rx, text in rows.get("STATUSTEXT", []):
        text = str(text).rstrip("\x00").strip()
        if text.startswith(_FIRMWARE_PREFIXES) or text.startswith(("PX4v", "fmuv", "CubeOrange", "CubeBlack")):
            if text not in parts:
                parts.append(text)
    versions = rows.get("AUTOPILOT_VERSION", [])
    if versions and not any(p.startswith(_FIRMWARE_PREFIXES[:5]) for p in parts):
        v = int(versions[0][1])
        parts.insert(0, f"firmware {v >> 24 & 0xFF}.{v >> 16 & 0xFF}.{v >> 8 & 0xFF}")
    entry = mavlink2.enums["MAV_TYPE"].get(mav_type)
    kind = entry.name.removeprefix("MAV_TYPE_").lower() if entry else f"MAV_TYPE {mav_type}"
    parts.append(f"{kind} (MAV_TYPE {mav_type})")
    return "; ".join(parts[:5])
