"""Declarative map from PX4 uORB topics to canonical signals.

:func:`flightlogs.readers.ulog.read_ulog` walks :data:`PX4_GROUPS` in order. For each
group it tries the sources in preference order, and within a source the
topic's instances from 0 upwards, and keeps the first that yields data; the
chosen ``topic[instance].field`` is recorded as the signal's ``source``.
Motor commands (:data:`PX4_MOTOR_SOURCES`) have a variable channel count and
are handled apart.

Conventions (PX4's): body axes FRD, earth axes NED, SI units, radians.
Choices made here:

* ``delta_thr`` is ``-vehicle_thrust_setpoint.xyz[2]``: PX4 logs the thrust
  along body z (negative up), the sign is flipped so that more thrust is
  positive, as it already is in the old ``actuator_controls_0.control[3]``.
  The source string carries the minus sign.
* ``latitude longitude`` prefer the estimator's ``vehicle_global_position``
  (samples with ``lat_lon_valid`` set), then the receiver's ``sensor_gps``
  or ``vehicle_gps_position`` (samples with ``fix_type`` ≥ 3, a 3-D fix).
* ``height_agl`` prefers a downward rangefinder (``distance_sensor``), then
  the estimator's ``dist_bottom`` when ``dist_bottom_valid`` is set in every
  sample (it is terrain-relative, where ``-z`` is relative to the origin the
  estimator started at), then ``-vehicle_local_position.z``.
* The references (:data:`flightlogs.signals.REFERENCE_SIGNALS`):
  ``p_ref q_ref r_ref`` from ``vehicle_rates_setpoint``; ``phi_ref theta_ref
  psi_ref`` from ``vehicle_attitude_setpoint.roll_body/pitch_body/yaw_body``
  (logs before about v1.9), else its quaternion ``q_d``; the sticks from
  ``manual_control_setpoint`` (``roll pitch yaw throttle`` from v1.14 on,
  ``y x r z`` before). PX4 logs the pitch stick positive forward (nose down):
  ``stick_lon`` is its negative, positive back (nose up) like ``q``; the
  source string carries the minus sign. ``stick_thr`` is kept as logged:
  ``throttle`` spans -1..1, the older ``z`` 0..1.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Literal

__all__ = [
    "Conversion",
    "TopicSource",
    "SignalGroup",
    "MotorSource",
    "PX4_GROUPS",
    "PX4_MOTOR_SOURCES",
    "GPS_TOPICS",
    "MAPPED_TOPICS",
    "MAV_TYPE_NAMES",
    "MAV_TYPE_ROTORS",
    "AUTOSTART_ROTORS",
    "CA_AIRFRAME_NAMES",
    "rotor_count",
    "mav_type_vehicle",
    "px4_vehicle_type",
    "describe_vehicle",
]

#: How the fields of a source become the signals of a group.
#: ``copy``: one field per signal; ``negate``: the same with the sign flipped;
#: ``degrees``: one field per signal, degrees to radians; ``degrees_e7``: the
#: same from integers in 1e-7 degrees (GNSS positions before PX4 v1.14);
#: ``quaternion_to_euler``: four fields ``w, x, y, z`` give ``phi, theta, psi``;
#: ``rangefinder``: ``distance_sensor`` fields ``current_distance``,
#: ``min_distance``, ``max_distance`` (in that order) give the distance where
#: it is within range, the signal quality is not 0 and the sensor faces down;
#: ``arming_state``: ``vehicle_status.arming_state`` gives 1 where it is 2 (armed), else 0.
Conversion = Literal["copy", "negate", "degrees", "degrees_e7", "quaternion_to_euler", "rangefinder", "arming_state"]


@dataclass(frozen=True, slots=True, kw_only=True)
class TopicSource:
    """One candidate topic and its fields for a group of signals.

    Parameters
    ----------
    topic : str
        uORB topic name as logged, e.g. ``"vehicle_angular_velocity"``.
    fields : tuple of str
        Field names as pyulog flattens them (``"xyz[0]"``), one per signal
        of the group, or the inputs of `conversion`.
    conversion : Conversion
        How `fields` become the group's signals.
    valid : tuple of str
        Boolean fields of the same topic flagging each signal's samples as
        valid (one name per signal, or empty when the topic has none).
        Samples flagged invalid are dropped; a flag absent from an old log
        counts as always set.
    min_valid_fraction : float
        Smallest fraction of valid samples for a signal to be taken from this
        source (1.0: every sample must be valid, else the next source is tried).
    at_least : tuple of (str, float)
        Fields of the same topic that must reach a value for a sample to be
        valid, e.g. ``(("fix_type", 3),)`` for a 3-D GNSS fix; a field absent
        from an old log is not checked.
    """

    topic: str
    fields: tuple[str, ...]
    conversion: Conversion = "copy"
    valid: tuple[str, ...] = ()
    min_valid_fraction: float = 0.0
    at_least: tuple[tuple[str, float], ...] = ()

    def __post_init__(self) -> None:
        if not 0.0 <= self.min_valid_fraction <= 1.0:
            raise ValueError(f"{self.min_valid_fraction=} must be within [0, 1]")


@dataclass(frozen=True, slots=True)
class SignalGroup:
    """Canonical signals read together from one source.

    Parameters
    ----------
    names : tuple of str
        Canonical signal names, in the order of the sources' outputs.
    unit : str
        Unit of the values after conversion.
    sources : tuple of TopicSource
        Candidates in order of preference.
    """

    names: tuple[str, ...]
    unit: str
    sources: tuple[TopicSource, ...]

    def __post_init__(self) -> None:
        for source in self.sources:
            outputs = (
                3
                if source.conversion == "quaternion_to_euler"
                else (1 if source.conversion == "rangefinder" else len(source.fields))
            )
            if outputs != len(self.names):
                raise ValueError(f"{source.topic}: {outputs} outputs for signals {self.names}")
            if source.valid and len(source.valid) != len(self.names):
                raise ValueError(f"{source.topic}: one validity flag per signal is needed")


@dataclass(frozen=True, slots=True, kw_only=True)
class MotorSource:
    """A topic holding one command per motor channel.

    Parameters
    ----------
    topic : str
        uORB topic name.
    field_pattern : str
        Field name with ``{i}`` for the channel index from 0, e.g. ``"control[{i}]"``.
    unit : str
        Unit of the commands.
    count_from : {"channels", "airframe"}
        How the number of motors is found: ``"channels"`` counts channels that
        are not NaN throughout (capped by ``CA_ROTOR_COUNT``); ``"airframe"``
        takes it from ``CA_ROTOR_COUNT``, ``MAV_TYPE`` or ``SYS_AUTOSTART``,
        capped by the logged ``noutputs``.
    """

    topic: str
    field_pattern: str
    unit: str
    count_from: Literal["channels", "airframe"]


def _xyz(topic: str, field: str, **options: object) -> TopicSource:
    return TopicSource(topic=topic, fields=tuple(f"{field}[{i}]" for i in range(3)), **options)  # type: ignore[arg-type]


#: Topics with ``time_utc_usec`` (GPS time) and the receiver's position, in order of preference.
GPS_TOPICS: tuple[str, ...] = ("sensor_gps", "vehicle_gps_position")
_FIX_3D = (("fix_type", 3.0),)  # GNSS samples without a 3-D fix carry no position

#: Canonical signal groups and their PX4 sources, in order of preference.
PX4_GROUPS: tuple[SignalGroup, ...] = (
    SignalGroup(
        ("p", "q", "r"),
        "rad/s",
        (
            _xyz("vehicle_angular_velocity", "xyz"),
            TopicSource(topic="vehicle_attitude", fields=("rollspeed", "pitchspeed", "yawspeed")),  # before 2019
            TopicSource(topic="control_state", fields=("roll_rate", "pitch_rate", "yaw_rate")),  # 2016-2017
            _xyz("sensor_combined", "gyro_rad"),
            _xyz("sensor_combined", "gyro_rad_s"),  # before 2017
            TopicSource(topic="sensor_gyro", fields=("x", "y", "z")),
        ),
    ),
    SignalGroup(
        ("phi", "theta", "psi"),
        "rad",
        (
            TopicSource(
                topic="vehicle_attitude", fields=tuple(f"q[{i}]" for i in range(4)), conversion="quaternion_to_euler"
            ),
            TopicSource(topic="vehicle_attitude", fields=("roll", "pitch", "yaw")),  # before 2016
            TopicSource(
                topic="control_state", fields=tuple(f"q[{i}]" for i in range(4)), conversion="quaternion_to_euler"
            ),
        ),
    ),
    SignalGroup(
        ("vn", "ve", "vd"),
        "m/s",
        (
            TopicSource(
                topic="vehicle_local_position",
                fields=("vx", "vy", "vz"),
                valid=("v_xy_valid", "v_xy_valid", "v_z_valid"),
            ),
        ),
    ),
    SignalGroup(
        ("height_agl",),
        "m",
        (
            TopicSource(
                topic="distance_sensor",
                fields=("current_distance", "min_distance", "max_distance"),
                conversion="rangefinder",
                min_valid_fraction=0.5,
            ),
            TopicSource(
                topic="vehicle_local_position",
                fields=("dist_bottom",),
                valid=("dist_bottom_valid",),
                min_valid_fraction=1.0,
            ),
            TopicSource(topic="vehicle_local_position", fields=("z",), conversion="negate", valid=("z_valid",)),
        ),
    ),
    SignalGroup(
        ("ax", "ay", "az"),
        "m/s^2",
        (
            _xyz("vehicle_acceleration", "xyz"),
            _xyz("sensor_combined", "accelerometer_m_s2"),
            TopicSource(topic="sensor_accel", fields=("x", "y", "z")),
        ),
    ),
    SignalGroup(
        ("delta_lat", "delta_lon", "delta_yaw"),
        "normalised",
        (
            _xyz("vehicle_torque_setpoint", "xyz"),
            TopicSource(topic="actuator_controls_0", fields=("control[0]", "control[1]", "control[2]")),
        ),
    ),
    SignalGroup(
        ("delta_thr",),
        "normalised",
        (
            TopicSource(topic="vehicle_thrust_setpoint", fields=("xyz[2]",), conversion="negate"),
            TopicSource(topic="actuator_controls_0", fields=("control[3]",)),
        ),
    ),
    SignalGroup(
        ("armed",),
        "1",
        (
            TopicSource(topic="actuator_armed", fields=("armed",)),
            TopicSource(topic="vehicle_status", fields=("arming_state",), conversion="arming_state"),
        ),
    ),
    SignalGroup(("landed",), "1", (TopicSource(topic="vehicle_land_detected", fields=("landed",)),)),
    SignalGroup(
        ("battery_v",),
        "V",
        (
            TopicSource(topic="battery_status", fields=("voltage_v",)),
            TopicSource(topic="battery_status", fields=("voltage_filtered_v",)),
        ),
    ),
    SignalGroup(
        ("est_wind_n", "est_wind_e"),
        "m/s",
        (
            TopicSource(topic="wind", fields=("windspeed_north", "windspeed_east")),
            TopicSource(topic="wind_estimate", fields=("windspeed_north", "windspeed_east")),
        ),
    ),
    SignalGroup(
        ("latitude", "longitude"),
        "rad",
        (
            TopicSource(
                topic="vehicle_global_position",
                fields=("lat", "lon"),
                conversion="degrees",
                valid=("lat_lon_valid",) * 2,
            ),
            TopicSource(
                topic="sensor_gps", fields=("latitude_deg", "longitude_deg"), conversion="degrees", at_least=_FIX_3D
            ),  # v1.14 on
            TopicSource(topic="sensor_gps", fields=("lat", "lon"), conversion="degrees_e7", at_least=_FIX_3D),
            TopicSource(
                topic="vehicle_gps_position",
                fields=("latitude_deg", "longitude_deg"),
                conversion="degrees",
                at_least=_FIX_3D,
            ),
            TopicSource(topic="vehicle_gps_position", fields=("lat", "lon"), conversion="degrees_e7", at_least=_FIX_3D),
        ),
    ),
    # references the controllers follow, and the pilot's sticks: optional, never reported missing
    SignalGroup(
        ("p_ref", "q_ref", "r_ref"),
        "rad/s",
        (TopicSource(topic="vehicle_rates_setpoint", fields=("roll", "pitch", "yaw")),),
    ),
    SignalGroup(
        ("phi_ref", "theta_ref", "psi_ref"),
        "rad",
        (
            TopicSource(topic="vehicle_attitude_setpoint", fields=("roll_body", "pitch_body", "yaw_body")),  # old
            TopicSource(
                topic="vehicle_attitude_setpoint",
                fields=tuple(f"q_d[{i}]" for i in range(4)),
                conversion="quaternion_to_euler",
                valid=("q_d_valid",) * 3,
            ),
        ),
    ),
    SignalGroup(
        ("stick_lat", "stick_yaw"),
        "1",
        (
            TopicSource(topic="manual_control_setpoint", fields=("roll", "yaw"), valid=("valid",) * 2),  # v1.14 on
            TopicSource(topic="manual_control_setpoint", fields=("y", "r")),
        ),
    ),
    SignalGroup(
        ("stick_lon",),
        "1",
        (
            TopicSource(topic="manual_control_setpoint", fields=("pitch",), conversion="negate", valid=("valid",)),
            TopicSource(topic="manual_control_setpoint", fields=("x",), conversion="negate"),
        ),
    ),
    SignalGroup(
        ("stick_thr",),
        "1",
        (
            TopicSource(topic="manual_control_setpoint", fields=("throttle",), valid=("valid",)),  # -1..1
            TopicSource(topic="manual_control_setpoint", fields=("z",)),  # 0..1
        ),
    ),
)

#: Motor command topics in order of preference.
PX4_MOTOR_SOURCES: tuple[MotorSource, ...] = (
    MotorSource(topic="actuator_motors", field_pattern="control[{i}]", unit="normalised", count_from="channels"),
    MotorSource(topic="actuator_outputs", field_pattern="output[{i}]", unit="PWM us", count_from="airframe"),
)

#: Every topic a canonical signal, a motor command or the UTC offset is read from: the only topics
#: pyulog is asked to keep (a log's other topics are walked past, not stored).
MAPPED_TOPICS: frozenset[str] = frozenset(
    [source.topic for group in PX4_GROUPS for source in group.sources]
    + [source.topic for source in PX4_MOTOR_SOURCES]
    + list(GPS_TOPICS)
)

#: MAVLink ``MAV_TYPE`` values seen on multirotors and their names.
MAV_TYPE_NAMES: dict[int, str] = {
    0: "generic",
    1: "fixed wing",
    2: "quadrotor",
    3: "coaxial",
    4: "helicopter",
    13: "hexarotor",
    14: "octorotor",
    15: "tricopter",
    19: "VTOL tailsitter duorotor",
    20: "VTOL tailsitter quadrotor",
    21: "VTOL tiltrotor",
    22: "VTOL fixed rotor",
    29: "dodecarotor",
}

#: Number of lift rotors by ``MAV_TYPE``.
MAV_TYPE_ROTORS: dict[int, int] = {2: 4, 3: 2, 13: 6, 14: 8, 15: 3, 29: 12}

#: Number of rotors by ``SYS_AUTOSTART`` range (PX4 airframe numbering, multirotors).
AUTOSTART_ROTORS: tuple[tuple[range, int], ...] = (
    (range(4000, 6000), 4),  # quadrotor x, +
    (range(6000, 8000), 6),  # hexarotor x, +
    (range(8000, 10000), 8),  # octorotor x, +
    (range(10000, 11000), 4),  # quadrotor wide
    (range(11000, 12000), 6),  # hexarotor coaxial
    (range(12000, 13000), 8),  # octorotor coaxial
    (range(14000, 16000), 3),  # tricopter
)

#: ``CA_AIRFRAME`` values of PX4's control allocation (v1.14 on).
CA_AIRFRAME_NAMES: dict[int, str] = {
    0: "multirotor",
    1: "fixed-wing",
    2: "standard VTOL",
    3: "tiltrotor VTOL",
    4: "tailsitter VTOL",
    5: "rover (Ackermann)",
    6: "rover (differential)",
    7: "motors",
    8: "custom",
    9: "helicopter (tail ESC)",
    10: "helicopter (tail servo)",
    11: "helicopter (coaxial)",
}


def mav_type_vehicle(mav_type: int | None) -> str:
    """``"multirotor"`` for a multirotor ``MAV_TYPE``, ``""`` for none or generic (0), else what it is.

    Parameters
    ----------
    mav_type : int or None
        MAVLink ``MAV_TYPE`` (PX4's parameter, a HEARTBEAT's ``type``).

    Examples
    --------
    >>> mav_type_vehicle(13), mav_type_vehicle(0), mav_type_vehicle(1), mav_type_vehicle(10)
    ('multirotor', '', 'fixed wing (MAV_TYPE 1)', 'MAV_TYPE 10')
    """
    if mav_type is None or mav_type == 0:
        return ""
    if mav_type in MAV_TYPE_ROTORS:
        return "multirotor"
    return f"{MAV_TYPE_NAMES[mav_type]} (MAV_TYPE {mav_type})" if mav_type in MAV_TYPE_NAMES else f"MAV_TYPE {mav_type}"


def px4_vehicle_type(parameters: Mapping[str, float]) -> str:
    """What a PX4 log's ``CA_AIRFRAME`` and ``MAV_TYPE`` say the vehicle is (see :func:`mav_type_vehicle`).

    Parameters
    ----------
    parameters : Mapping[str, float]
        The log's parameters.

    Examples
    --------
    >>> px4_vehicle_type({"MAV_TYPE": 2.0, "CA_AIRFRAME": 0.0}), px4_vehicle_type({"CA_AIRFRAME": 1.0})
    ('multirotor', 'fixed-wing (CA_AIRFRAME 1)')
    """
    airframe = _int_param(parameters, "CA_AIRFRAME")
    if airframe is not None and airframe != 0:
        return f"{CA_AIRFRAME_NAMES.get(airframe, 'airframe')} (CA_AIRFRAME {airframe})"
    found = mav_type_vehicle(_int_param(parameters, "MAV_TYPE"))
    return found or ("multirotor" if airframe == 0 else "")


def rotor_count(parameters: Mapping[str, float], *, allocator_only: bool = False) -> int:
    """Number of lift rotors the parameters describe, 0 when they do not tell.

    Parameters
    ----------
    parameters : Mapping[str, float]
        Autopilot parameters.
    allocator_only : bool
        Only trust ``CA_ROTOR_COUNT`` (control allocation, PX4 v1.14 on).

    Returns
    -------
    int
        ``CA_ROTOR_COUNT`` if set, else from ``MAV_TYPE``, else from the
        ``SYS_AUTOSTART`` airframe number; 0 if none of them names a multirotor.

    Examples
    --------
    >>> rotor_count({"MAV_TYPE": 13.0}), rotor_count({"SYS_AUTOSTART": 4001.0})
    (6, 4)
    >>> rotor_count({"MAV_TYPE": 1.0})  # fixed wing
    0
    """
    allocated = _int_param(parameters, "CA_ROTOR_COUNT")
    if allocated or allocator_only:
        return max(allocated or 0, 0)
    rotors = MAV_TYPE_ROTORS.get(_int_param(parameters, "MAV_TYPE") or -1, 0)
    if rotors:
        return rotors
    autostart = _int_param(parameters, "SYS_AUTOSTART") or 0
    return next((count for ids, count in AUTOSTART_ROTORS if autostart in ids), 0)


def describe_vehicle(info: Mapping[str, Any], parameters: Mapping[str, float]) -> str:
    """One line naming flight stack, hardware, firmware and airframe parameters.

    Parameters
    ----------
    info : Mapping[str, Any]
        ULog info messages (``sys_name``, ``ver_hw``, ``ver_sw``).
    parameters : Mapping[str, float]
        Autopilot parameters (``SYS_AUTOSTART``, ``MAV_TYPE``, ``CA_AIRFRAME``).

    Returns
    -------
    str
        E.g. ``"PX4 on PX4_FMU_V6C, firmware 94cb2012792b, SYS_AUTOSTART 4001,
        MAV_TYPE 2 (quadrotor), CA_AIRFRAME 0 (multirotor)"``.

    Examples
    --------
    >>> describe_vehicle({"sys_name": "PX4", "ver_hw": "PX4_FMU_V6C"}, {"MAV_TYPE": 2.0})
    'PX4 on PX4_FMU_V6C, MAV_TYPE 2 (quadrotor)'
    """
    head = str(info.get("sys_name") or "PX4")
    if info.get("ver_hw"):
        head += f" on {info['ver_hw']}"
    parts = [head]
    if info.get("ver_sw"):
        parts.append(f"firmware {str(info['ver_sw'])[:12]}")
    named: tuple[tuple[str, dict[int, str]], ...] = (
        ("SYS_AUTOSTART", {}),
        ("MAV_TYPE", MAV_TYPE_NAMES),
        ("CA_AIRFRAME", CA_AIRFRAME_NAMES),
    )
    for key, names in named:
        value = _int_param(parameters, key)
        if value is not None:
            parts.append(f"{key} {value}" + (f" ({names[value]})" if value in names else ""))
    return ", ".join(parts)


def _int_param(parameters: Mapping[str, float], key: str) -> int | None:
    """An integer parameter, or None if absent or not finite."""
    value = parameters.get(key)
    return int(value) if value is not None and math.isfinite(value) else None
