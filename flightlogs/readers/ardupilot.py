"""Map ArduPilot DataFlash messages to the canonical signals.

:func:`read_dataflash` decodes a ``.bin`` log with :mod:`flightlogs.readers.dataflash`
and builds a :class:`~flightlogs.flightlog.FlightLog`:

============================  ================================================
canonical                     DataFlash source
============================  ================================================
``p q r``, ``ax ay az``       IMU GyrX..Z (rad/s), AccX..Z (m/s²), instance 0
``phi theta psi``             ATT Roll, Pitch, Yaw (deg → rad, yaw in (-π, π])
``delta_lat/lon/yaw``         RATE ROut, POut, YOut
``delta_thr``                 RATE AOut, else CTUN ThO / ThrOut
``motor_1..n``                RCOU C1..Cn (or Ch1..Chn), PWM µs
``battery_v``                 BAT Volt (instance 0), else CURR Volt (cV → V)
``height_agl``                RFND Dist / Dist1, else CTUN Alt (above home)
``vn ve vd``                  XKF1 / NKF1 / EKF1 VN VE VD (core 0)
``est_wind_n/e``              XKF2 / NKF2 / EKF2 VWN VWE (core 0)
``latitude longitude``        GPS Lat, Lng (instance 0, Status ≥ 3, deg → rad)
``excitation``                SIDD Targ
``p_ref q_ref r_ref``         RATE RDes, PDes, YDes (deg/s, Copter ≤3.3
                              cdeg/s → rad/s)
``phi_ref`` .. ``psi_ref``    ATT DesRoll, DesPitch, DesYaw (deg → rad, yaw
                              in (-π, π])
``stick_lat/lon/yaw/thr``     RCIN C(RCMAP_ROLL/PITCH/YAW/THROTTLE),
                              normalised with RCn_MIN/TRIM/MAX
============================  ================================================

The references (``*_ref``, ``stick_*``) are optional and never reported
missing; :mod:`flightlogs.readers._references` maps them.

Times are ``TimeUS`` / 1e6 or, in logs before Copter 3.4, ``TimeMS`` / 1e3.
The System ID maneuvers (SIDS messages) are not signals; they are in
:attr:`FlightLog.system_id_runs <flightlogs.flightlog.FlightLog>`, built by
:func:`system_id_runs`.
"""

from __future__ import annotations

import calendar
import dataclasses
import re
import warnings
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import cast

import numpy as np

from flightlogs.errors import DataQualityWarning, LogCorruptionWarning, LogFormatError, collected_warnings
from flightlogs.flightlog import FlightLog, Signal, SystemIdRun
from flightlogs.readers._references import dataflash_references
from flightlogs.readers._series import make_signal
from flightlogs.readers.dataflash import DataFlashMessages, MessageTable, MissingColumnError, read_messages

__all__ = ["read_dataflash", "flightlog_from_messages", "SystemIdRun", "system_id_runs", "gps_leap_seconds"]

_TYPES = (
    "IMU",
    "ATT",
    "RATE",
    "CTUN",
    "RCOU",
    "BAT",
    "CURR",
    "RFND",
    "XKF1",
    "XKF2",
    "NKF1",
    "NKF2",
    "EKF1",
    "EKF2",
    "GPS",
    "SIDD",
    "SIDS",
    "PARM",
    "MSG",
    "RCIN",
    "EV",
    "ARM",
)
_MOTOR_CHANNELS = tuple(f"{prefix}{k}" for prefix in ("C", "Ch") for k in range(1, 13))  # up to DODECAHEXA's 12
#: The columns the mapping reads, decoded in one pass over the file (a column not listed is decoded when read).
_COLUMNS: dict[str, tuple[str, ...]] = {
    "IMU": ("GyrX", "GyrY", "GyrZ", "AccX", "AccY", "AccZ"),
    "ATT": ("Roll", "Pitch", "Yaw", "DesRoll", "DesPitch", "DesYaw"),
    "RATE": ("ROut", "POut", "YOut", "AOut", "RDes", "PDes", "YDes"),
    "CTUN": ("ThO", "ThrOut", "Alt"),
    "RCOU": _MOTOR_CHANNELS,
    "RCIN": tuple(f"C{k}" for k in range(1, 17)),
    "EV": ("Id",),
    "ARM": ("ArmState",),
    "BAT": ("Volt",),
    "CURR": ("Volt",),
    "RFND": ("Dist", "Dist1"),
    **{name: ("VN", "VE", "VD") for name in ("XKF1", "NKF1", "EKF1")},
    **{name: ("VWN", "VWE") for name in ("XKF2", "NKF2", "EKF2")},
    "GPS": ("Status", "Lat", "Lng", "GWk", "GMS", "Week"),
    "SIDD": ("Targ",),
}
_GPS_FIX_3D = 3  # GPS.Status: 3 = 3-D fix, 4-6 DGPS and RTK
_GPS_EPOCH_UNIX = 315964800  # 1980-01-06T00:00:00Z
_LEAP_DATES = (
    "1981-07",
    "1982-07",
    "1983-07",
    "1985-07",
    "1988-01",
    "1990-01",
    "1991-01",
    "1992-07",
    "1993-07",
    "1994-07",
    "1996-01",
    "1997-07",
    "1999-01",
    "2006-01",
    "2009-01",
    "2012-07",
    "2015-07",
    "2017-01",
)  # GPS-UTC becomes 1, 2, ... 18 s on the 1st of these months
_LEAP_UNIX = np.array([calendar.timegm((int(d[:4]), int(d[5:]), 1, 0, 0, 0)) for d in _LEAP_DATES])
_FRAME_CLASS_MOTORS = {1: 4, 2: 6, 3: 8, 4: 8, 5: 6, 7: 3, 10: 2, 12: 12, 14: 10}
_FRAME_NAME_MOTORS = {
    "QUAD": 4,
    "HEXA": 6,
    "OCTA": 8,
    "OCTA_QUAD": 8,
    "OCTAQUAD": 8,
    "Y6": 6,
    "TRI": 3,
    "BICOPTER": 2,
    "DODECA_HEXA": 12,
    "DODECAHEXA": 12,
    "DECA": 10,
}
_SYSID_AXES = {
    1: "input roll angle",
    2: "input pitch angle",
    3: "input yaw angle",
    4: "recovery roll angle",
    5: "recovery pitch angle",
    6: "recovery yaw angle",
    7: "rate roll",
    8: "rate pitch",
    9: "rate yaw",
    10: "mixer roll",
    11: "mixer pitch",
    12: "mixer yaw",
    13: "mixer thrust",
}
_FIRMWARE_KINDS = {
    "Copter": "multirotor",
    "Plane": "fixed wing",
    "Rover": "rover",
    "Sub": "submarine",
    "Blimp": "blimp",
}
_FIRMWARE = re.compile(r"^(APM:\w+|Ardu\w+|ArduPilot\w*)\s+V\d")
#: The board and its 96-bit unique id, as ArduPilot logs them at boot (``"fmuv5 00290019 32375118 32363435"``).
_BOARD_ID = re.compile(r"^\S+( [0-9A-F]{8}){3}$")


def read_dataflash(path: str | Path, *, progress: Callable[[int, int], None] | None = None) -> FlightLog:
    """Read an ArduPilot DataFlash ``.bin`` log as canonical signals.

    Parameters
    ----------
    path : str or Path
        The log file.
    progress : callable, optional
        ``progress(done, total)`` in bytes while decoding.

    Returns
    -------
    FlightLog
        Signals in SI units and radians (mixer inputs and motors as logged,
        with their unit), parameters (first value of each PARM), the vehicle
        (firmware and frame), the UTC offset from GPS time, the System ID
        runs (:func:`system_id_runs`), and warnings.

    Raises
    ------
    LogFormatError
        If the file is not a readable DataFlash log.

    Warns
    -----
    LogCorruptionWarning, DataQualityWarning
        As :func:`~flightlogs.readers.dataflash.decode_messages` and
        :func:`flightlog_from_messages`.
    """
    return flightlog_from_messages(read_messages(path, types=_TYPES, columns=_COLUMNS, progress=progress))


def flightlog_from_messages(messages: DataFlashMessages) -> FlightLog:
    """Build the :class:`FlightLog` of already decoded DataFlash messages.

    Parameters
    ----------
    messages : DataFlashMessages
        Output of :func:`~flightlogs.readers.dataflash.read_messages`.

    Returns
    -------
    FlightLog
        As :func:`read_dataflash`. Only the first of several appended logs is
        mapped when their layouts differ (the later ones are in ``NAME@1``
        tables); a warning says so. Samples whose time does not move forward
        (appended logs of one layout) are dropped with a warning.
        ``warnings`` holds those of `messages`, then these.

    Warns
    -----
    DataQualityWarning
        For appended logs not mapped, samples dropped, an EKF wind estimate
        that is zero throughout, GNSS samples without a 3-D fix.
    """
    with collected_warnings() as caught:
        try:
            log = _flightlog(messages)
        except MissingColumnError as err:
            raise LogFormatError(
                f"{messages.path}: {err.args[0]}; a damaged FMT message? The log cannot be mapped."
            ) from err
    return dataclasses.replace(log, warnings=messages.warnings + caught.messages)


def _flightlog(messages: DataFlashMessages) -> FlightLog:
    if any("@" in key for key in messages.tables):
        message = (
            f"{messages.path.name}: appended logs with other layouts are not mapped; only the first log's messages are."
        )
        warnings.warn(DataQualityWarning(message), stacklevel=2)
    parameters = _parameters(messages)
    signals: dict[str, Signal] = {}
    times: dict[int, tuple[MessageTable, np.ndarray | None]] = {}  # a table's times, shared by its signals (the
    # table is kept with them: an id is unique only while its object lives)

    def add(
        name: str,
        table: MessageTable,
        column: str,
        unit: str,
        source: str,
        convert: Callable[[np.ndarray], np.ndarray] | None = None,
    ) -> None:
        if column not in table.columns:  # a format that lacks the field (a damaged FMT, another firmware)
            message = f"{messages.path.name}: {table.format.name} has no column {column}; {name} is not read from it"
            warnings.warn(LogCorruptionWarning(message), stacklevel=2)
            return
        if id(table) not in times:
            times[id(table)] = (table, table.time_s)
        time_s, values = times[id(table)][1], table[column]  # a float32 field is kept so (Signal)
        if time_s is None:
            return
        signal = make_signal(name, time_s, convert(values.astype(np.float64)) if convert else values, unit, source)
        if signal is not None:
            signals[name] = signal

    _map_imu_attitude(messages, add)
    _map_mixer(messages, add)
    n_motors = _map_motors(messages, parameters, add)
    _map_battery_height(messages, add)
    _map_estimator(messages, parameters, add)
    _map_position(messages, add)
    runs = system_id_runs(messages)
    _map_excitation(messages, runs, add)
    dataflash_references(messages, parameters, add, wrap_yaw=_wrap_deg)
    signals |= _flight_states(messages, signals)
    return FlightLog(
        path=messages.path,
        log_format="dataflash",
        autopilot="ardupilot",
        signals=signals,
        vehicle=_vehicle(messages, parameters, n_motors),
        vehicle_type=_vehicle_type(messages, parameters),
        board_id=next((t for t in _texts(messages) if _BOARD_ID.match(t)), ""),
        parameters=parameters,
        utc_offset_s=_utc_offset(messages),
        system_id_runs=runs,
    )


_Add = Callable[..., None]


def _first_instance(messages: DataFlashMessages, name: str) -> tuple[MessageTable, str] | None:
    """Lowest instance of `name` and its label for sources (``"IMU[0]"``)."""
    found = messages.instances(name) if name in messages.tables else {}
    if not found:
        return None
    instance = min(found)
    return found[instance], f"{name}[{instance}]"


def _map_imu_attitude(messages: DataFlashMessages, add: _Add) -> None:
    imu = _first_instance(messages, "IMU")
    if imu is not None:
        table, label = imu
        for name, column, unit in (
            ("p", "GyrX", "rad/s"),
            ("q", "GyrY", "rad/s"),
            ("r", "GyrZ", "rad/s"),
            ("ax", "AccX", "m/s^2"),
            ("ay", "AccY", "m/s^2"),
            ("az", "AccZ", "m/s^2"),
        ):
            if column in table:
                add(name, table, column, unit, f"{label}.{column}")
    att = messages.get("ATT")
    if att is not None:
        for name, column in (("phi", "Roll"), ("theta", "Pitch")):
            if column in att:
                add(name, att, column, "rad", f"ATT.{column} (deg→rad)", np.deg2rad)
        if "Yaw" in att:
            add("psi", att, "Yaw", "rad", "ATT.Yaw (deg→rad, wrapped to (-π, π])", _wrap_deg)


def _wrap_deg(yaw_deg: np.ndarray) -> np.ndarray:
    """Degrees → radians in (-π, π]."""
    return cast(np.ndarray, np.pi - np.mod(np.pi - np.deg2rad(yaw_deg), 2.0 * np.pi))


def _map_mixer(messages: DataFlashMessages, add: _Add) -> None:
    """RATE outputs: normalised since Copter 3.4 (TimeUS logs), ±4500-scaled before."""
    rate, ctun = messages.get("RATE"), messages.get("CTUN")
    legacy = rate is not None and "TimeUS" not in rate
    axis_unit = "servo units (±4500 full scale, Copter ≤3.3)" if legacy else "normalised (-1..1)"
    thr_unit = "per mille (0..1000, Copter ≤3.3)" if legacy else "normalised (0..1)"
    if rate is not None:
        for name, column in (("delta_lat", "ROut"), ("delta_lon", "POut"), ("delta_yaw", "YOut")):
            if column in rate:
                add(name, rate, column, axis_unit, f"RATE.{column}")
        if "AOut" in rate:
            add("delta_thr", rate, "AOut", thr_unit, "RATE.AOut")
            return
    throttle = next((c for c in ("ThO", "ThrOut") if ctun is not None and c in ctun), None)
    if ctun is not None and throttle is not None:
        legacy = "TimeUS" not in ctun
        unit = "per mille (0..1000, Copter ≤3.3)" if legacy else "normalised (0..1)"
        add("delta_thr", ctun, throttle, unit, f"CTUN.{throttle}")


def _motor_count(messages: DataFlashMessages, parameters: dict[str, float]) -> tuple[int | None, str]:
    """Motors of the frame: FRAME_CLASS, else the "Frame: QUAD" MSG; None if unknown."""
    frame_class = parameters.get("FRAME_CLASS")
    if frame_class is not None and int(frame_class) in _FRAME_CLASS_MOTORS:
        return _FRAME_CLASS_MOTORS[int(frame_class)], f"FRAME_CLASS={int(frame_class)}"
    frame = _frame_text(messages)
    if frame:
        key = frame.split("/")[0].strip().upper()
        if key in _FRAME_NAME_MOTORS:
            return _FRAME_NAME_MOTORS[key], f"frame {frame}"
    return None, ""


def _map_motors(messages: DataFlashMessages, parameters: dict[str, float], add: _Add) -> int | None:
    rcou = messages.get("RCOU")
    if rcou is None:
        return None
    prefix = "C" if "C1" in rcou else "Ch"
    channels = []
    for k in range(1, 33):
        if f"{prefix}{k}" not in rcou:
            break
        channels.append(f"{prefix}{k}")
    count, _ = _motor_count(messages, parameters)
    if count is None:  # no frame information: the leading channels that move
        moving = [np.ptp(rcou[c]) > 0 for c in channels]
        count = moving.index(False) if False in moving else len(moving)
    for k, column in enumerate(channels[:count], start=1):
        add(f"motor_{k}", rcou, column, "us", f"RCOU.{column} (PWM)")
    return count or None


#: EV ids (AP_Logger LogEvent) that set a flight state: the state and the value it takes.
_EVENTS = {10: ("armed", 1.0), 11: ("armed", 0.0), 18: ("landed", 1.0), 28: ("landed", 0.0)}


def _flight_states(messages: DataFlashMessages, signals: Mapping[str, Signal]) -> dict[str, Signal]:
    """``armed`` and ``landed`` from the ARM messages or the EV events, held from each event to the next.

    Each state starts, at the log's first sample, as the opposite of its first
    event (a log opens disarmed, on the ground). EV messages without a time
    (Copter 3.3) cannot be placed and give nothing.
    """
    start = min((float(s.time_s[0]) for s in signals.values() if s.samples), default=None)
    found: dict[str, list[tuple[float, float]]] = {"armed": [], "landed": []}
    sources: dict[str, str] = {}
    arm = messages.get("ARM")
    if arm is not None and arm.time_s is not None and "ArmState" in arm:
        found["armed"] += zip(arm.time_s.tolist(), (arm["ArmState"] != 0).astype(float).tolist())
        sources["armed"] = "ARM.ArmState"
    ev = messages.get("EV")
    if ev is not None and ev.time_s is not None and "Id" in ev:
        for time_s, event in zip(ev.time_s.tolist(), ev["Id"].astype(int).tolist()):
            if event in _EVENTS and not (event in (10, 11) and "armed" in sources):
                name, value = _EVENTS[event]
                found[name].append((time_s, value))
        sources.setdefault("armed", "EV.Id (10 armed, 11 disarmed)")
        sources["landed"] = "EV.Id (18 land complete, 28 not landed)"
    states = {}
    for name, events in found.items():
        if not events or start is None:
            continue
        events.sort()
        times = np.array([min(start, events[0][0] - 1e-3), *(t for t, _ in events)])
        values = np.array([1.0 - events[0][1], *(v for _, v in events)])
        signal = make_signal(name, times, values, "1", f"{sources[name]}, held to the next event")
        if signal is not None:
            states[name] = signal
    return states


def _map_battery_height(messages: DataFlashMessages, add: _Add) -> None:
    bat = _first_instance(messages, "BAT")
    curr = messages.get("CURR")
    if bat is not None and "Volt" in bat[0]:
        add("battery_v", bat[0], "Volt", "V", f"{bat[1]}.Volt")
    elif curr is not None and "Volt" in curr:
        integer = curr.format.format[curr.format.columns.index("Volt")] in "hHiI"
        if integer:  # Copter ≤3.3 logs centivolts
            add("battery_v", curr, "Volt", "V", "CURR.Volt (cV→V)", lambda v: v / 100.0)
        else:
            add("battery_v", curr, "Volt", "V", "CURR.Volt")
    rfnd = _first_instance(messages, "RFND")
    column = next((c for c in ("Dist", "Dist1") if rfnd is not None and c in rfnd[0]), None)
    if rfnd is not None and column is not None:
        table, label = rfnd
        char = table.format.format[table.format.columns.index(column)]
        if char in "hHiI":  # integer centimetres without a format multiplier
            add("height_agl", table, column, "m", f"{label}.{column} (cm→m)", lambda v: v / 100.0)
        else:  # 'C'/'c' carry the 0.01 multiplier, 'f' is metres
            add("height_agl", table, column, "m", f"{label}.{column}")
        return
    ctun = messages.get("CTUN")
    if ctun is not None and "Alt" in ctun:
        add("height_agl", ctun, "Alt", "m", "CTUN.Alt (altitude above home; no rangefinder)")


def _map_estimator(messages: DataFlashMessages, parameters: dict[str, float], add: _Add) -> None:
    """EKF velocity and wind, from the EKF the AHRS uses when the log says so."""
    order = ("XKF", "NKF", "EKF") if parameters.get("AHRS_EKF_TYPE") == 3 else ("NKF", "XKF", "EKF")
    for prefix in order:
        found = _first_instance(messages, f"{prefix}1")
        if found is None or "VN" not in found[0]:
            continue
        table, label = found
        for name, column in (("vn", "VN"), ("ve", "VE"), ("vd", "VD")):
            add(name, table, column, "m/s", f"{label}.{column}")
        wind = _first_instance(messages, f"{prefix}2")
        if wind is not None and "VWN" in wind[0]:
            add("est_wind_n", wind[0], "VWN", "m/s", f"{wind[1]}.VWN")
            add("est_wind_e", wind[0], "VWE", "m/s", f"{wind[1]}.VWE")
            if not np.any(wind[0]["VWN"]) and not np.any(wind[0]["VWE"]):
                message = f"{wind[1]}: the EKF wind estimate is zero throughout (not estimated)."
                warnings.warn(DataQualityWarning(message), stacklevel=2)
        return


def _map_position(messages: DataFlashMessages, add: _Add) -> None:
    """GNSS latitude and longitude where the receiver has a 3-D fix (Status ≥ 3)."""
    found = _first_instance(messages, "GPS")
    if found is None or not {"Status", "Lat", "Lng"} <= set(found[0].columns):
        return
    table, label = found
    fixed = table["Status"] >= _GPS_FIX_3D
    if not fixed.any():
        message = f"{label}: the receiver never had a 3-D fix (Status < 3); no position read."
        warnings.warn(DataQualityWarning(message), stacklevel=2)
        return
    if not fixed.all():
        message = (
            f"{label}.Lat, Lng: dropped {int((~fixed).sum())} of {fixed.size} samples without a 3-D fix (Status < 3)."
        )
        warnings.warn(DataQualityWarning(message), stacklevel=2)
    table = table.select(fixed)
    add("latitude", table, "Lat", "rad", f"{label}.Lat (deg→rad, Status ≥ 3)", np.deg2rad)
    add("longitude", table, "Lng", "rad", f"{label}.Lng (deg→rad, Status ≥ 3)", np.deg2rad)


def _map_excitation(messages: DataFlashMessages, runs: tuple[SystemIdRun, ...], add: _Add) -> None:
    sidd = messages.get("SIDD")
    if sidd is None or "Targ" not in sidd:
        return
    axes = sorted({run.axis for run in runs})
    named = ", ".join(f"{a} ({_SYSID_AXES.get(a, 'other')})" for a in axes)
    unit = f"as logged (SID_AXIS {named})" if axes else "as logged"
    add("excitation", sidd, "Targ", unit, "SIDD.Targ")


def system_id_runs(messages: DataFlashMessages) -> tuple[SystemIdRun, ...]:
    """The System ID maneuvers of a log, for segmentation (:attr:`FlightLog.system_id_runs`).

    Parameters
    ----------
    messages : DataFlashMessages
        Decoded log holding SIDS (and SIDD) messages.

    Returns
    -------
    tuple of SystemIdRun
        One per SIDS message, in time order; empty without SIDS.

    Examples
    --------
    >>> from flightlogs.readers.dataflash import decode_messages
    >>> from flightlogs.writers.dataflash import encode_dataflash, standard_block
    >>> sids = standard_block("SIDS", TimeUS=[5_000_000], Ax=[7], Mag=[10.0], FSt=[0.5], FSp=[20.0])
    >>> run, = system_id_runs(decode_messages(encode_dataflash([sids])))
    >>> run.axis_name, run.f_stop_hz
    ('rate roll', 20.0)
    """
    sids, sidd = messages.get("SIDS"), messages.get("SIDD")
    if sids is None or sids.time_s is None:
        return ()
    starts = sids.time_s
    sidd_time = sidd.time_s if sidd is not None and sidd.time_s is not None else np.empty(0)
    runs = []
    for k, start in enumerate(starts):
        stop = starts[k + 1] if k + 1 < starts.size else np.inf
        inside = sidd_time[(sidd_time >= start) & (sidd_time < stop)]
        axis = int(sids["Ax"][k])
        runs.append(
            SystemIdRun(
                start_s=float(start),
                end_s=float(inside[-1]) if inside.size else float("nan"),
                axis=axis,
                axis_name=_SYSID_AXES.get(axis, "other"),
                magnitude=float(sids["Mag"][k]),
                f_start_hz=float(sids["FSt"][k]),
                f_stop_hz=float(sids["FSp"][k]),
                fade_in_s=float(sids["TFin"][k]),
                const_s=float(sids["TC"][k]),
                record_s=float(sids["TR"][k]),
                fade_out_s=float(sids["TFout"][k]),
            )
        )
    return tuple(runs)


def _parameters(messages: DataFlashMessages) -> dict[str, float]:
    """PARM Name → Value, the first value of each name."""
    parm = messages.get("PARM")
    if parm is None or "Name" not in parm:
        return {}
    names, first = np.unique(parm["Name"], return_index=True)
    values = parm["Value"].astype(np.float64)
    return {str(n): float(values[i]) for n, i in sorted(zip(names, first), key=lambda p: p[1])}


def _texts(messages: DataFlashMessages) -> list[str]:
    msg = messages.get("MSG")
    return [str(m) for m in msg["Message"]] if msg is not None and "Message" in msg else []


def _frame_text(messages: DataFlashMessages) -> str:
    """``"QUAD"`` from a ``"Frame: QUAD"`` MSG, or ``""``."""
    return next((t.split(":", 1)[1].strip() for t in _texts(messages) if t.startswith("Frame:")), "")


def _vehicle_type(messages: DataFlashMessages, parameters: dict[str, float]) -> str:
    """``multirotor`` for ArduCopter (a helicopter frame aside), the firmware's kind otherwise, ``""`` if unlogged."""
    firmware = next((t for t in _texts(messages) if _FIRMWARE.match(t)), "")
    kind = next((k for k in _FIRMWARE_KINDS if k in firmware), None)
    if kind is None:
        return ""
    if kind != "Copter":
        return f"{_FIRMWARE_KINDS[kind]} ({firmware.split()[0]})"
    return "helicopter (FRAME_CLASS 6)" if parameters.get("FRAME_CLASS") == 6 else "multirotor"


def _vehicle(messages: DataFlashMessages, parameters: dict[str, float], n_motors: int | None) -> str:
    texts = _texts(messages)
    firmware = next((t for t in texts if _FIRMWARE.match(t)), "ArduPilot (firmware not logged)")
    parts = [firmware]
    frame = _frame_text(messages)
    if frame:
        parts.append(f"frame {frame}")
    for name in ("FRAME_CLASS", "FRAME_TYPE", "FRAME"):
        if name in parameters:
            parts.append(f"{name}={parameters[name]:g}")
    if n_motors:
        parts.append(f"{n_motors} motors")
    return "; ".join(parts)


def gps_leap_seconds(gps_seconds: np.ndarray | float) -> np.ndarray:
    """GPS − UTC, s, for times counted in GPS seconds from the UNIX epoch.

    Parameters
    ----------
    gps_seconds : float or ndarray, shape (n,)
        ``315964800 + week·604800 + seconds of week``: GPS time on the UNIX
        scale, before leap seconds are removed, s.

    Returns
    -------
    ndarray of int
        Leap seconds in force at each time (16 from 2012-07-01, 17 from
        2015-07-01, 18 from 2017-01-01, back to 0 before 1981-07-01).

    Examples
    --------
    >>> gps_leap_seconds(np.array([1.4e9, 1.47e9, 1.5e9]))  # 2014, 2016, 2017
    array([16, 17, 18])
    """
    gps_seconds = np.asarray(gps_seconds, dtype=np.float64)
    thresholds = _LEAP_UNIX + np.arange(1, _LEAP_UNIX.size + 1)
    return np.searchsorted(thresholds, gps_seconds, side="right")


def _utc_offset(messages: DataFlashMessages) -> float | None:
    """UNIX seconds minus log time, from GPS week and ms of week; None without a fix."""
    found = _first_instance(messages, "GPS")
    if found is None:
        return None
    gps = found[0]
    if "GWk" in gps and "TimeUS" in gps:
        week, week_ms, time_s = gps["GWk"], gps["GMS"], gps["TimeUS"] / 1e6
    elif "Week" in gps and "T" in gps:  # Copter ≤3.3: TimeMS is GPS time of week, T the boot time
        week, week_ms, time_s = gps["Week"], gps["TimeMS"], gps["T"] / 1e3
    else:
        return None
    valid = week > 0
    if not valid.any():
        return None
    gps_s = _GPS_EPOCH_UNIX + week[valid].astype(np.float64) * 604800.0 + week_ms[valid] / 1e3
    utc_s = gps_s - gps_leap_seconds(gps_s)
    return float(np.median(utc_s - time_s[valid]))
