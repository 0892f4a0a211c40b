"""Write a simulated flight as a PX4 ULog, with the topics a modern PX4 (v1.16) logs.

Topics, named, typed and ordered as PX4 v1.16 defines them (a subset of
each topic's fields): ``vehicle_angular_velocity``, ``vehicle_attitude``
(quaternion FRD → NED), ``vehicle_local_position``, ``vehicle_acceleration``
(specific force, gravity included), ``vehicle_torque_setpoint`` and
``vehicle_thrust_setpoint`` (the mixer inputs, normalised; thrust along body
z, negative up), ``actuator_motors``, ``battery_status``, ``sensor_gps`` (GPS
time, so the reader recovers UTC) and ``wind`` (the estimator's wind). The
parameters describe the airframe (``SYS_AUTOSTART``, ``MAV_TYPE``,
``CA_ROTOR_COUNT`` and the rotor geometry ``CA_ROTOR{i}_PX/PY/KM``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from pathlib import Path
from types import MappingProxyType
from typing import Literal, cast

import numpy as np

from flightlogs.geo import lat_lon_offset
from flightlogs.writers.ulog import TopicData, write_ulog
from simulator.flights.linear import SimulatedFlight

__all__ = ["Airframe", "AIRFRAMES", "write_px4_log"]

_EPOCH = datetime(1970, 1, 1, tzinfo=UTC)
_ORIGIN = (47.397742, 8.545594, 488.0)  # PX4's default home: lat, lon (deg), altitude (m MSL)
_VER_SW_RELEASE = 0x011000FF  # v1.16.0, release
_RATES_HZ = {"battery_status": 10.0, "sensor_gps": 5.0, "wind": 25.0}
_REQUIRED = (
    "p",
    "q",
    "r",
    "phi",
    "theta",
    "psi",
    "vn",
    "ve",
    "vd",
    "ax",
    "ay",
    "az",
    "height_agl",
    "delta_lat",
    "delta_lon",
    "delta_yaw",
    "delta_thr",
)
_Signals = Mapping[str, np.ndarray]
_SDLOG_PROFILE = 1 | 8  # default set + system identification (high-rate rates, setpoints, motors)


@dataclass(frozen=True, slots=True, kw_only=True)
class Airframe:
    """A multirotor as PX4 parameters describe it.

    Parameters
    ----------
    name : str
        ``"quad"`` or ``"octo"``.
    autostart : int
        ``SYS_AUTOSTART`` airframe number.
    mav_type : int
        MAVLink ``MAV_TYPE``.
    angles_deg : tuple of float
        Direction of each rotor arm from the nose, clockwise seen from above,
        deg, in motor order (``CA_ROTOR0`` first).
    spins : tuple of int
        +1 for a counter-clockwise rotor (positive ``CA_ROTOR{i}_KM``: more
        throttle yaws the body right), -1 for clockwise.
    arm_m : float
        Arm length, m.
    cells : int
        Battery cells in series.
    """

    name: str
    autostart: int
    mav_type: int
    angles_deg: tuple[float, ...]
    spins: tuple[int, ...]
    arm_m: float
    cells: int

    def __post_init__(self) -> None:
        if len(self.angles_deg) != len(self.spins) or not self.spins:
            raise ValueError(f"{self.name}: one spin per rotor angle is needed")

    @property
    def rotors(self) -> int:
        """Number of rotors."""
        return len(self.spins)

    def parameters(self) -> dict[str, int | float]:
        """Airframe and control-allocation parameters, as PX4 v1.14+ names them.

        Returns
        -------
        dict of str to int or float
        """
        out: dict[str, int | float] = {
            "SYS_AUTOSTART": self.autostart,
            "MAV_TYPE": self.mav_type,
            "CA_AIRFRAME": 0,
            "CA_ROTOR_COUNT": self.rotors,
            "BAT1_N_CELLS": self.cells,
        }
        for i, (angle, spin) in enumerate(zip(np.radians(self.angles_deg), self.spins)):
            out[f"CA_ROTOR{i}_PX"] = float(round(self.arm_m * np.cos(angle), 4))
            out[f"CA_ROTOR{i}_PY"] = float(round(self.arm_m * np.sin(angle), 4))
            out[f"CA_ROTOR{i}_KM"] = 0.05 * spin
        return out

    def mix(self, thrust: np.ndarray, torque: np.ndarray) -> np.ndarray:
        """Motor commands of normalised thrust and torque setpoints.

        Parameters
        ----------
        thrust : ndarray, shape (n_samples,)
            Collective thrust, 0..1.
        torque : ndarray, shape (n_samples, 3)
            Roll, pitch, yaw torque setpoints, -1..1.

        Returns
        -------
        ndarray, shape (n_samples, rotors)
            Commands, clipped to 0..1.
        """
        angles = np.radians(self.angles_deg)
        mixer = np.column_stack([-np.sin(angles), np.cos(angles), np.asarray(self.spins, float)])
        return cast(np.ndarray, np.clip(thrust[:, None] + torque @ mixer.T, 0.0, 1.0))


#: PX4 quadrotor X (4001; motors front-right, rear-left, front-left, rear-right) and an
#: octorotor X (8001; motors every 45° from 22.5°, alternating spin, as the ArduPilot writer).
AIRFRAMES: Mapping[str, Airframe] = MappingProxyType(
    {
        "quad": Airframe(
            name="quad",
            autostart=4001,
            mav_type=2,
            angles_deg=(45.0, 225.0, 315.0, 135.0),
            spins=(1, 1, -1, -1),
            arm_m=0.25,
            cells=4,
        ),
        "octo": Airframe(
            name="octo",
            autostart=8001,
            mav_type=14,
            angles_deg=tuple(22.5 + 45.0 * k for k in range(8)),
            spins=(1, -1, 1, -1, 1, -1, 1, -1),
            arm_m=0.5,
            cells=6,
        ),
    }
)
_ROTOR_AIRFRAMES = {frame.rotors: frame for frame in AIRFRAMES.values()}


def write_px4_log(
    flight: SimulatedFlight,
    path: str | Path,
    *,
    utc_start: datetime,
    airframe: Literal["quad", "octo"] | None = None,
    log_start_s: float = 20.0,
    hover_thrust: float = 0.5,
) -> Path:
    """Write `flight` as a PX4 ULog.

    Parameters
    ----------
    flight : SimulatedFlight
        The flight. Mixer inputs in % become normalised setpoints (÷100),
        ``delta_thr`` about `hover_thrust`. Signals ``motor_1..n`` (n = 4 or
        8), if present, are in % and written ÷100; otherwise the airframe's
        mixer makes them from the setpoints. ``battery_v`` (V), if present,
        is written, else a pack of the airframe's cells sagging 4 mV/s from
        full.
    path : str or Path
        Destination ``.ulg``.
    utc_start : datetime
        UTC of the first sample (timezone-aware).
    airframe : {"quad", "octo"}, optional
        Airframe; default from the number of motor signals, else ``"octo"``
        (the dissertation's octocopter).
    log_start_s : float, optional
        Log time of the first sample (time since boot), s.
    hover_thrust : float, optional
        Normalised thrust at trim (also written as ``MPC_THR_HOVER``).

    Returns
    -------
    Path
        `path`.

    Raises
    ------
    ValueError
        If `utc_start` is naive, the flight's time base is not increasing,
        a signal the topics need is missing, ``wind_at_vehicle`` does not
        match the time base, or the motor signals are not 4 or 8 or
        contradict `airframe`.

    Notes
    -----
    Every topic has ``timestamp`` (= ``timestamp_sample``) = (`log_start_s`
    + flight time) in µs. Topics are logged at the flight's rate except
    ``battery_status`` (10 Hz), ``sensor_gps`` (5 Hz) and ``wind`` (25 Hz),
    each taking every k-th sample. ``sensor_gps.time_utc_usec`` is
    `utc_start` plus the time since the first sample. Position ``x, y`` is
    the integral of the ground velocity, ``z = -height_agl`` (origin on the
    ground below the take-off point) and ``dist_bottom = height_agl``, valid.
    """
    if utc_start.tzinfo is None:
        raise ValueError(f"{utc_start=} must be timezone-aware (UTC)")
    t = np.asarray(flight.time_s, dtype=np.float64)
    if t.ndim != 1 or t.size < 2 or np.any(np.diff(t) <= 0):
        raise ValueError("flight.time_s must be increasing with at least two samples")
    missing = [name for name in _REQUIRED if name not in flight.signals]
    if missing:
        raise ValueError(f"the flight lacks signals {missing} a PX4 log needs")
    if np.shape(flight.wind_at_vehicle) != (t.size, 2):
        raise ValueError(f"flight.wind_at_vehicle has shape {np.shape(flight.wind_at_vehicle)}, not ({t.size}, 2)")
    frame, motors = _motors(flight, airframe)
    stamps = np.round((t + log_start_s) * 1e6).astype(np.uint64)
    s = flight.signals
    torque = np.column_stack([s["delta_lat"], s["delta_lon"], s["delta_yaw"]]) / 100.0
    thrust = hover_thrust + np.asarray(s["delta_thr"]) / 100.0
    if motors is None:
        motors = frame.mix(thrust, torque)
    rate_hz = 1.0 / float(np.median(np.diff(t)))
    every = {name: max(1, int(round(rate_hz / hz))) for name, hz in _RATES_HZ.items()}
    topics = [
        _vector(
            "vehicle_angular_velocity",
            stamps,
            np.column_stack([s["p"], s["q"], s["r"]]),
            xyz_derivative=np.gradient(np.column_stack([s["p"], s["q"], s["r"]]), t, axis=0),
        ),
        _attitude(stamps, s),
        _local_position(stamps, t, s),
        _vector("vehicle_acceleration", stamps, np.column_stack([s["ax"], s["ay"], s["az"]])),
        _vector("vehicle_torque_setpoint", stamps, torque),
        _vector("vehicle_thrust_setpoint", stamps, np.column_stack([0 * thrust, 0 * thrust, -thrust])),
        _actuator_motors(stamps, motors),
        _battery(stamps, t, s, frame, every["battery_status"]),
        _gps(stamps, t, s, utc_start, every["sensor_gps"]),
        _wind(stamps, flight.wind_at_vehicle, every["wind"]),
    ]
    parameters = frame.parameters() | {"MPC_THR_HOVER": float(hover_thrust), "SDLOG_PROFILE": _SDLOG_PROFILE}
    info: dict[str, str | int | float | np.generic] = {
        "sys_name": "PX4",
        "ver_hw": "FLIGHT_SYSID_SIM",
        "ver_sw": "flight-sysid simulator",
        "ver_sw_release": np.uint32(_VER_SW_RELEASE),
        "sys_os_name": "Linux",
        "sys_toolchain": "flight-sysid",
        "sys_uuid": f"{frame.name}-{frame.autostart}-sim",
        "time_ref_utc": 0,
    }
    return write_ulog(path, topics, info=info, parameters=parameters)


def _motors(flight: SimulatedFlight, airframe: str | None) -> tuple[Airframe, np.ndarray | None]:
    """The airframe, and the flight's motor commands (normalised) if it has any."""
    names = sorted((k for k in flight.signals if k.startswith("motor_")), key=lambda k: int(k[6:]))
    if not names:
        return AIRFRAMES[airframe or "octo"], None
    expected = [f"motor_{i + 1}" for i in range(len(names))]
    if names != expected or len(names) not in _ROTOR_AIRFRAMES:
        raise ValueError(f"motor signals {names} must be motor_1..4 or motor_1..8")
    frame = _ROTOR_AIRFRAMES[len(names)]
    if airframe is not None and airframe != frame.name:
        raise ValueError(f"{airframe=} has {AIRFRAMES[airframe].rotors} rotors; the flight has {len(names)} motors")
    return frame, np.column_stack([flight.signals[k] for k in names]) / 100.0


def _f32(values: np.ndarray | float, n: int | None = None) -> np.ndarray:
    """Values as float32 (a scalar repeated `n` times)."""
    return np.full(n, values, np.float32) if n is not None else np.asarray(values, np.float32)


def _vector(name: str, stamps: np.ndarray, xyz: np.ndarray, **extra: np.ndarray) -> TopicData:
    """A topic of ``timestamp, timestamp_sample, xyz[3]`` (and more float[3] fields)."""
    fields = {"timestamp": stamps, "timestamp_sample": stamps, "xyz": _f32(xyz)}
    return TopicData(name, fields | {key: _f32(value) for key, value in extra.items()})


def _euler_to_quaternion(phi: np.ndarray, theta: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Quaternions ``(w, x, y, z)`` FRD → NED of 3-2-1 Euler angles, shape (n_samples, 4)."""
    cf, sf = np.cos(phi / 2), np.sin(phi / 2)
    ct, st = np.cos(theta / 2), np.sin(theta / 2)
    cp, sp = np.cos(psi / 2), np.sin(psi / 2)
    return np.column_stack(
        [
            cf * ct * cp + sf * st * sp,
            sf * ct * cp - cf * st * sp,
            cf * st * cp + sf * ct * sp,
            cf * ct * sp - sf * st * cp,
        ]
    )


def _attitude(stamps: np.ndarray, s: _Signals) -> TopicData:
    n = stamps.size
    return TopicData(
        "vehicle_attitude",
        {
            "timestamp": stamps,
            "timestamp_sample": stamps,
            "q": _f32(_euler_to_quaternion(s["phi"], s["theta"], s["psi"])),
            "delta_q_reset": np.zeros((n, 4), np.float32),
            "quat_reset_counter": np.zeros(n, np.uint8),
        },
    )


def _position_ne(t: np.ndarray, s: _Signals) -> np.ndarray:
    """North and east position from the take-off point, m, shape (n_samples, 2): integrated ground velocity."""
    velocity = np.column_stack([s["vn"], s["ve"]])
    steps = 0.5 * (velocity[1:] + velocity[:-1]) * np.diff(t)[:, None]
    return np.vstack([np.zeros((1, 2)), np.cumsum(steps, axis=0)])


def _local_position(stamps: np.ndarray, t: np.ndarray, s: _Signals) -> TopicData:
    """Estimator position and velocity (NED, from the ground below take-off), all valid."""
    n = stamps.size
    velocity = np.column_stack([s["vn"], s["ve"], s["vd"]])
    xy = _position_ne(t, s)
    accel = np.gradient(velocity, t, axis=0)
    valid = np.ones(n, bool)
    return TopicData(
        "vehicle_local_position",
        {
            "timestamp": stamps,
            "timestamp_sample": stamps,
            "ref_timestamp": np.full(n, stamps[0], np.uint64),
            "ref_lat": np.full(n, _ORIGIN[0]),
            "ref_lon": np.full(n, _ORIGIN[1]),
            "x": _f32(xy[:, 0]),
            "y": _f32(xy[:, 1]),
            "z": _f32(-np.asarray(s["height_agl"])),
            "vx": _f32(velocity[:, 0]),
            "vy": _f32(velocity[:, 1]),
            "vz": _f32(velocity[:, 2]),
            "z_deriv": _f32(velocity[:, 2]),
            "ax": _f32(accel[:, 0]),
            "ay": _f32(accel[:, 1]),
            "az": _f32(accel[:, 2]),
            "heading": _f32(np.angle(np.exp(1j * np.asarray(s["psi"])))),
            "ref_alt": _f32(_ORIGIN[2], n),
            "dist_bottom": _f32(s["height_agl"]),
            "eph": _f32(0.5, n),
            "epv": _f32(0.8, n),
            "evh": _f32(0.1, n),
            "evv": _f32(0.1, n),
            "xy_valid": valid,
            "z_valid": valid,
            "v_xy_valid": valid,
            "v_z_valid": valid,
            "heading_good_for_control": valid,
            "xy_global": valid,
            "z_global": valid,
            "dist_bottom_valid": valid,
            "dead_reckoning": ~valid,
        },
    )


def _actuator_motors(stamps: np.ndarray, motors: np.ndarray) -> TopicData:
    """``control[12]``: the motors, NaN on unused channels (as PX4 logs them)."""
    control = np.full((stamps.size, 12), np.nan, np.float32)
    control[:, : motors.shape[1]] = motors
    return TopicData(
        "actuator_motors",
        {
            "timestamp": stamps,
            "timestamp_sample": stamps,
            "control": control,
            "reversible_flags": np.zeros(stamps.size, np.uint16),
        },
    )


def _battery(stamps: np.ndarray, t: np.ndarray, s: _Signals, frame: Airframe, every: int) -> TopicData:
    pick = slice(0, None, every)
    volts = np.asarray(s["battery_v"]) if "battery_v" in s else 4.2 * frame.cells - 0.004 * (t - t[0])
    n = stamps[pick].size
    return TopicData(
        "battery_status",
        {
            "timestamp": stamps[pick],
            "voltage_v": _f32(volts[pick]),
            "current_a": _f32(25.0, n),
            "remaining": _f32(np.clip(1.0 - (t[pick] - t[0]) / 1200.0, 0.0, 1.0)),
            "connected": np.ones(n, bool),
            "cell_count": np.full(n, frame.cells, np.uint8),
            "id": np.ones(n, np.uint8),
        },
    )


def _gps(stamps: np.ndarray, t: np.ndarray, s: _Signals, utc_start: datetime, every: int) -> TopicData:
    """GNSS fixes with UTC time; position from the integrated ground velocity."""
    pick = slice(0, None, every)
    utc0_us = (utc_start - _EPOCH) // timedelta(microseconds=1)
    since_us = np.round((t[pick] - t[0]) * 1e6).astype(np.int64)
    n = since_us.size
    north, east = _position_ne(t, s)[pick].T
    dlat, dlon = lat_lon_offset(north, east, np.radians(_ORIGIN[0]))
    lat, lon = _ORIGIN[0] + np.degrees(dlat), _ORIGIN[1] + np.degrees(dlon)
    vn, ve, vd = (np.asarray(s[k])[pick] for k in ("vn", "ve", "vd"))
    return TopicData(
        "sensor_gps",
        {
            "timestamp": stamps[pick],
            "timestamp_sample": stamps[pick],
            "latitude_deg": lat,
            "longitude_deg": lon,
            "altitude_msl_m": _ORIGIN[2] + np.asarray(s["height_agl"])[pick],
            "time_utc_usec": (utc0_us + since_us).astype(np.uint64),
            "device_id": np.full(n, 11_141_893, np.uint32),
            "eph": _f32(0.6, n),
            "epv": _f32(0.9, n),
            "hdop": _f32(0.7, n),
            "vdop": _f32(1.0, n),
            "vel_m_s": _f32(np.hypot(vn, ve)),
            "vel_n_m_s": _f32(vn),
            "vel_e_m_s": _f32(ve),
            "vel_d_m_s": _f32(vd),
            "cog_rad": _f32(np.arctan2(ve, vn)),
            "fix_type": np.full(n, 3, np.uint8),
            "vel_ned_valid": np.ones(n, bool),
            "satellites_used": np.full(n, 16, np.uint8),
        },
    )


def _wind(stamps: np.ndarray, wind_ne: np.ndarray, every: int) -> TopicData:
    pick = slice(0, None, every)
    n = stamps[pick].size
    return TopicData(
        "wind",
        {
            "timestamp": stamps[pick],
            "timestamp_sample": stamps[pick],
            "windspeed_north": _f32(wind_ne[pick, 0]),
            "windspeed_east": _f32(wind_ne[pick, 1]),
            "variance_north": _f32(0.05, n),
            "variance_east": _f32(0.05, n),
        },
    )
