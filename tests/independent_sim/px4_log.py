"""Write a flown case as an ordinary PX4 ULog (v1.14-style topics, nothing about the excitation).

Topics, rates and phases (1 kHz grid, rate loop at 250 Hz)::

    vehicle_angular_velocity   250 Hz  +0 ms   gyro (unfiltered, bias and noise)
    vehicle_torque_setpoint    250 Hz  +0 ms   controller output + excitation
    vehicle_thrust_setpoint    250 Hz  +0 ms   xyz[2] = -thrust
    vehicle_rates_setpoint     125 Hz  +0 ms
    vehicle_acceleration       200 Hz  +1 ms   (left out when the case asks for sensor_combined only)
    sensor_combined            100 Hz  +1 ms   gyro_rad, accelerometer_m_s2 (200 Hz without vehicle_acceleration)
    vehicle_attitude           125 Hz  +2 ms   q (estimate)
    vehicle_attitude_setpoint   50 Hz  +0 ms   q_d
    vehicle_local_position      50 Hz  +3 ms   x y z vx vy vz (estimate), no rangefinder
    wind                        10 Hz  +6 ms   windspeed_north, windspeed_east (EKF estimate; only when
                                               the case's wind model asks for one)
    manual_control_setpoint     50 Hz  +5 ms   roll pitch yaw throttle (a pilot's sweep; centred otherwise)
    actuator_motors            100 Hz  +0 ms   8 motors, control[8..11] NaN
    sensor_gps                  10 Hz  +7 ms   time_utc_usec, position
    battery_status              10 Hz  +4 ms
    vehicle_status               2 Hz          arming_state
    vehicle_land_detected        1 Hz          landed (and at each change)

Nothing records the excitation itself (no chirp or system-identification
topic): the torque and thrust setpoints carry controller output plus
excitation, as in an ordinary flight log. A flight's logging gaps
(``Flight.dropouts_s``, an SD card stalling) leave out every topic's samples
inside them.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from flightlogs.writers import TopicData, write_ulog
from independent_sim._common import (
    HOME_ALT_M,
    battery,
    geodetic,
    motor_commands,
    quaternion,
    sample_indices,
    wind_estimate,
)
from independent_sim.flight import Flight
from independent_sim.nuisances import keep_mask

__all__ = ["PX4_RATES", "write_px4"]

#: (rate Hz, phase s) of each topic.
PX4_RATES: Mapping[str, tuple[float, float]] = {
    "vehicle_angular_velocity": (250.0, 0.0),
    "vehicle_torque_setpoint": (250.0, 0.0),
    "vehicle_rates_setpoint": (125.0, 0.0),
    "vehicle_acceleration": (200.0, 0.001),
    "sensor_combined": (100.0, 0.001),
    "vehicle_attitude": (125.0, 0.002),
    "vehicle_attitude_setpoint": (50.0, 0.0),
    "vehicle_local_position": (50.0, 0.003),
    "wind": (10.0, 0.006),
    "manual_control_setpoint": (50.0, 0.005),
    "actuator_motors": (100.0, 0.0),
    "sensor_gps": (10.0, 0.007),
    "battery_status": (10.0, 0.004),
    "vehicle_status": (2.0, 0.0),
}
_F32 = np.float32

Expected = dict[str, tuple[np.ndarray, np.ndarray]]


def _stamps(flight: Flight, topic: str) -> tuple[np.ndarray, np.ndarray]:
    index = sample_indices(flight, *PX4_RATES[topic])
    return index, flight.time_us[index]


def _xyz(*columns: np.ndarray) -> np.ndarray:
    return np.column_stack(columns).astype(_F32)


def _sensors(flight: Flight, expected: Expected) -> list[TopicData]:
    m = flight.measured
    i, stamp = _stamps(flight, "vehicle_angular_velocity")
    gyro = _xyz(m["p"][i], m["q"][i], m["r"][i])
    derivative = np.gradient(gyro.astype(float), stamp / 1e6, axis=0).astype(_F32)
    topics = [
        TopicData(
            "vehicle_angular_velocity",
            {"timestamp": stamp, "timestamp_sample": stamp, "xyz": gyro, "xyz_derivative": derivative},
        )
    ]
    expected.update({name: (stamp / 1e6, gyro[:, k]) for k, name in enumerate(("p", "q", "r"))})
    only_combined = flight.case.px4_accel_topic == "sensor_combined"
    i = sample_indices(flight, *PX4_RATES["vehicle_acceleration" if only_combined else "sensor_combined"])
    stamp = flight.time_us[i]
    n, interval_us = stamp.size, int(stamp[1] - stamp[0])
    topics.append(
        TopicData(
            "sensor_combined",
            {
                "timestamp": stamp,
                "gyro_rad": _xyz(m["p"][i], m["q"][i], m["r"][i]),
                "gyro_integral_dt": np.full(n, interval_us, np.uint32),
                "accelerometer_timestamp_relative": np.zeros(n, np.int32),
                "accelerometer_m_s2": _xyz(m["ax"][i], m["ay"][i], m["az"][i]),
                "accelerometer_integral_dt": np.full(n, interval_us, np.uint32),
                "accelerometer_clipping": np.zeros(n, np.uint8),
                "gyro_clipping": np.zeros(n, np.uint8),
            },
        )
    )
    if not only_combined:
        i, stamp = _stamps(flight, "vehicle_acceleration")
        accel = _xyz(m["ax"][i], m["ay"][i], m["az"][i])
        topics.append(TopicData("vehicle_acceleration", {"timestamp": stamp, "timestamp_sample": stamp, "xyz": accel}))
    else:
        accel = topics[-1].fields["accelerometer_m_s2"]
    expected.update({name: (stamp / 1e6, accel[:, k]) for k, name in enumerate(("ax", "ay", "az"))})
    return topics


def _estimates(flight: Flight, expected: Expected) -> list[TopicData]:
    m = flight.measured
    i, stamp = _stamps(flight, "vehicle_attitude")
    q = quaternion(m["phi"][i], m["theta"][i], m["psi"][i]).astype(_F32)
    n = stamp.size
    topics = [
        TopicData(
            "vehicle_attitude",
            {
                "timestamp": stamp,
                "timestamp_sample": stamp,
                "q": q,
                "delta_q_reset": np.zeros((n, 4), _F32),
                "quat_reset_counter": np.zeros(n, np.uint8),
            },
        )
    ]
    expected.update({name: (stamp / 1e6, m[name][i]) for name in ("phi", "theta", "psi")})
    i, stamp = _stamps(flight, "vehicle_local_position")
    n, valid = stamp.size, np.ones(stamp.size, bool)
    z = (-m["height"][i]).astype(_F32)
    velocity = {k: m[k][i].astype(_F32) for k in ("vn", "ve", "vd")}
    topics.append(
        TopicData(
            "vehicle_local_position",
            {
                "timestamp": stamp,
                "timestamp_sample": stamp,
                "xy_valid": valid,
                "z_valid": valid,
                "v_xy_valid": valid,
                "v_z_valid": valid,
                "x": m["x_n"][i].astype(_F32),
                "y": m["y_e"][i].astype(_F32),
                "z": z,
                "vx": velocity["vn"],
                "vy": velocity["ve"],
                "vz": velocity["vd"],
                "z_deriv": velocity["vd"],
                "heading": m["psi"][i].astype(_F32),
                "dist_bottom": -z,
                "dist_bottom_valid": np.zeros(n, bool),
                "ref_lat": np.full(n, geodetic(np.zeros(1), np.zeros(1))[0][0]),
                "ref_lon": np.full(n, geodetic(np.zeros(1), np.zeros(1))[1][0]),
                "ref_alt": np.full(n, HOME_ALT_M, _F32),
            },
        )
    )
    expected.update({name: (stamp / 1e6, velocity[name]) for name in velocity})
    expected["height_agl"] = (stamp / 1e6, -z)
    return topics + _wind(flight, expected)


def _wind(flight: Flight, expected: Expected) -> list[TopicData]:
    """``wind`` (v1.14): the EKF's wind estimate, when the case logs one; no airspeed sensor, so no innovations."""
    i, stamp = _stamps(flight, "wind")
    estimate = wind_estimate(flight, i)
    if estimate is None:
        return []
    north, east = estimate.astype(_F32).T
    variance = np.full(i.size, 0.04, _F32)  # (0.2 m/s)²
    zero = np.zeros(i.size, _F32)
    expected["est_wind_n"], expected["est_wind_e"] = (stamp / 1e6, north), (stamp / 1e6, east)
    return [
        TopicData(
            "wind",
            {
                "timestamp": stamp,
                "timestamp_sample": stamp,
                "windspeed_north": north,
                "windspeed_east": east,
                "variance_north": variance,
                "variance_east": variance,
                "tas_innov": zero,
                "tas_innov_var": zero,
                "beta_innov": zero,
                "beta_innov_var": zero,
            },
        )
    ]


def _setpoints(flight: Flight, expected: Expected) -> list[TopicData]:
    """The mixer inputs (torque and thrust setpoints) and the references of the cascade."""
    t = flight.truth
    i, stamp = _stamps(flight, "vehicle_torque_setpoint")
    torque = _xyz(t["delta_lat"][i], t["delta_lon"][i], t["delta_yaw"][i])
    thrust = _xyz(np.zeros(i.size), np.zeros(i.size), -t["delta_thr"][i])
    topics = [
        TopicData("vehicle_torque_setpoint", {"timestamp": stamp, "timestamp_sample": stamp, "xyz": torque}),
        TopicData("vehicle_thrust_setpoint", {"timestamp": stamp, "timestamp_sample": stamp, "xyz": thrust}),
    ]
    for k, name in enumerate(("delta_lat", "delta_lon", "delta_yaw")):
        expected[name] = (stamp / 1e6, torque[:, k])
    expected["delta_thr"] = (stamp / 1e6, -thrust[:, 2])
    i, stamp = _stamps(flight, "vehicle_rates_setpoint")
    rates = {field: t[name][i].astype(_F32) for field, name in (("roll", "p_sp"), ("pitch", "q_sp"), ("yaw", "r_sp"))}
    topics.append(
        TopicData(
            "vehicle_rates_setpoint",
            {
                "timestamp": stamp,
                **rates,
                "thrust_body": _xyz(np.zeros(i.size), np.zeros(i.size), -t["delta_thr"][i]),
                "reset_integral": np.zeros(i.size, bool),
            },
        )
    )
    expected.update(
        {name: (stamp / 1e6, rates[field]) for field, name in (("roll", "p_ref"), ("pitch", "q_ref"), ("yaw", "r_ref"))}
    )
    i, stamp = _stamps(flight, "vehicle_attitude_setpoint")
    topics.append(
        TopicData(
            "vehicle_attitude_setpoint",
            {
                "timestamp": stamp,
                "yaw_sp_move_rate": np.zeros(i.size, _F32),
                "q_d": quaternion(t["phi_sp"][i], t["theta_sp"][i], t["psi_sp"][i]).astype(_F32),
                "thrust_body": _xyz(np.zeros(i.size), np.zeros(i.size), -t["delta_thr"][i]),
                "reset_integral": np.zeros(i.size, bool),
            },
        )
    )
    expected.update({f"{name}_ref": (stamp / 1e6, t[f"{name}_sp"][i]) for name in ("phi", "theta", "psi")})
    return [*topics, _sticks(flight, expected)]


def _sticks(flight: Flight, expected: Expected) -> TopicData:
    """manual_control_setpoint (v1.14): roll, pitch (forward positive), yaw, throttle (-1..1, 0 holds height)."""
    t = flight.truth
    i, stamp = _stamps(flight, "manual_control_setpoint")
    rng = np.random.default_rng(flight.case.seed + 7)
    sense = {"lat": ("roll", 1.0), "lon": ("pitch", -1.0), "yaw": ("yaw", 1.0), "thr": ("throttle", 1.0)}
    sticks = {}
    for axis, (field, sign) in sense.items():
        centred = 0.002 * rng.standard_normal(i.size)  # a centred stick is never still
        sticks[field] = (sign * t[f"stick_{axis}"][i] + centred).astype(_F32)
        expected[f"stick_{axis}"] = (stamp / 1e6, sign * sticks[field])
    return TopicData(
        "manual_control_setpoint",
        {
            "timestamp": stamp,
            "timestamp_sample": stamp,
            "valid": np.ones(i.size, bool),
            "data_source": np.ones(i.size, np.uint8),
            **sticks,
            "flaps": np.zeros(i.size, _F32),
            "sticks_moving": np.abs(np.column_stack(list(sticks.values()))).max(axis=1) > 0.02,
        },
    )


def _vehicle(flight: Flight, expected: Expected) -> list[TopicData]:
    i, stamp = _stamps(flight, "actuator_motors")
    control = np.full((i.size, 12), np.nan, _F32)
    control[:, :8] = motor_commands(flight, i)
    expected.update({f"motor_{k + 1}": (stamp / 1e6, control[:, k]) for k in range(8)})
    topics = [
        TopicData(
            "actuator_motors",
            {
                "timestamp": stamp,
                "timestamp_sample": stamp,
                "reversible_flags": np.zeros(i.size, np.uint16),
                "control": control,
            },
        )
    ]
    i, stamp = _stamps(flight, "battery_status")
    voltage, current = battery(flight, i)
    topics.append(
        TopicData(
            "battery_status",
            {
                "timestamp": stamp,
                "connected": np.ones(i.size, bool),
                "voltage_v": voltage.astype(_F32),
                "current_a": current.astype(_F32),
                "remaining": np.clip((voltage - 21.0) / 4.2, 0, 1).astype(_F32),
                "cell_count": np.full(i.size, 6, np.uint8),
            },
        )
    )
    expected["battery_v"] = (stamp / 1e6, voltage.astype(_F32))
    i, stamp = _stamps(flight, "sensor_gps")
    lat, lon = geodetic(flight.truth["x_n"][i], flight.truth["y_e"][i])
    topics.append(
        TopicData(
            "sensor_gps",
            {
                "timestamp": stamp,
                "timestamp_sample": stamp,
                "device_id": np.full(i.size, 11_469_321, np.uint32),
                "latitude_deg": lat,
                "longitude_deg": lon,
                "altitude_msl_m": HOME_ALT_M + flight.truth["height"][i],
                "fix_type": np.full(i.size, 6, np.uint8),
                "eph": np.full(i.size, 0.02, _F32),
                "epv": np.full(i.size, 0.03, _F32),
                "vel_n_m_s": flight.truth["vn"][i].astype(_F32),
                "vel_e_m_s": flight.truth["ve"][i].astype(_F32),
                "vel_d_m_s": flight.truth["vd"][i].astype(_F32),
                "vel_ned_valid": np.ones(i.size, bool),
                "time_utc_usec": (stamp + round(flight.utc_offset_s * 1e6)).astype(np.uint64),
                "satellites_used": np.full(i.size, 18, np.uint8),
            },
        )
    )
    return topics + _state_topics(flight)


def _state_topics(flight: Flight) -> list[TopicData]:
    i, stamp = _stamps(flight, "vehicle_status")
    topics = [
        TopicData(
            "vehicle_status",
            {
                "timestamp": stamp,
                "arming_state": np.where(flight.armed[i], 2, 1).astype(np.uint8),
                "nav_state": np.full(i.size, 2, np.uint8),  # POSCTL
                "vehicle_type": np.ones(i.size, np.uint8),  # rotary wing
                "is_vtol": np.zeros(i.size, bool),
            },
        )
    ]
    per_second = sample_indices(flight, 1.0)
    changes = np.flatnonzero(np.diff(flight.airborne.astype(np.int8))) + 1
    i = np.unique(np.concatenate([per_second, changes]))
    landed = ~flight.airborne[i]
    topics.append(
        TopicData(
            "vehicle_land_detected",
            {
                "timestamp": flight.time_us[i],
                "freefall": np.zeros(i.size, bool),
                "ground_contact": landed,
                "maybe_landed": landed,
                "landed": landed,
                "in_ground_effect": flight.truth["height"][i] < 1.0,
            },
        )
    )
    return topics


def _parameters(flight: Flight) -> dict[str, int | float]:
    g = flight.gains
    return {
        "CA_ROTOR_COUNT": 8,
        "MAV_TYPE": 14,
        "SYS_AUTOSTART": 8001,
        "MC_ROLLRATE_P": g.rate_roll_p,
        "MC_ROLLRATE_I": g.rate_roll_i,
        "MC_ROLLRATE_D": g.rate_roll_d,
        "MC_PITCHRATE_P": g.rate_pitch_p,
        "MC_PITCHRATE_I": g.rate_pitch_i,
        "MC_PITCHRATE_D": g.rate_pitch_d,
        "MC_YAWRATE_P": g.rate_yaw_p,
        "MC_YAWRATE_I": g.rate_yaw_i,
        "MC_ROLL_P": g.att_roll_p,
        "MC_PITCH_P": g.att_pitch_p,
        "MC_YAW_P": g.att_yaw_p,
        "MPC_XY_P": g.pos_xy_p,
        "MPC_Z_P": g.pos_z_p,
        "MPC_XY_VEL_P_ACC": g.vel_xy_p,
        "MPC_XY_VEL_I_ACC": g.vel_xy_i,
        "MPC_Z_VEL_P_ACC": g.vel_z_p,
        "MPC_Z_VEL_I_ACC": g.vel_z_i,
        "MPC_THR_HOVER": flight.plant.trim.delta_thr,
        "IMU_GYRO_CUTOFF": g.gyro_cutoff_hz,
        "IMU_GYRO_RATEMAX": 250,
        "SDLOG_PROFILE": 1 | 8,  # default + high rate
    }


def _without_gaps(
    topics: list[TopicData], expected: Expected, spans_s: tuple[tuple[float, float], ...]
) -> tuple[list[TopicData], Expected]:
    """Every topic, and what the reader must return, less the samples inside the logging gaps."""
    kept = []
    for topic in topics:
        keep = keep_mask(np.asarray(topic.fields["timestamp"]), spans_s)
        kept.append(TopicData(topic.name, {k: np.asarray(v)[keep] for k, v in topic.fields.items()}, topic.multi_id))
    out = {}
    for name, (time_s, values) in expected.items():
        keep = keep_mask(np.rint(time_s * 1e6).astype(np.int64), spans_s)
        out[name] = (time_s[keep], values[keep])
    return kept, out


def write_px4(flight: Flight, path: Path) -> Expected:
    """Write `flight` as a ULog at `path`.

    Parameters
    ----------
    flight : Flight
        A case flown with the PX4 profile.
    path : Path
        Destination ``.ulg``.

    Returns
    -------
    dict of str to (ndarray, ndarray)
        For each canonical signal the log carries, the ``(time_s, values)``
        the workbench's reader must return (float32 as written).
    """
    if flight.fmt != "ulog":
        raise ValueError(f"{flight.case.name}: flown with the {flight.fmt} profile, not PX4's")
    expected: Expected = {}
    topics = _sensors(flight, expected) + _estimates(flight, expected) + _setpoints(flight, expected)
    topics += _vehicle(flight, expected)
    if flight.dropouts_s:
        topics, expected = _without_gaps(topics, expected, flight.dropouts_s)
    armed_at = int(flight.time_us[np.argmax(flight.armed)])
    takeoff_at = int(flight.time_us[np.argmax(flight.airborne)])
    landed_at = int(flight.time_us[len(flight.airborne) - np.argmax(flight.airborne[::-1])])
    messages = [
        (armed_at, "[commander] Armed by RC"),
        (takeoff_at, "[commander] Takeoff detected"),
        (landed_at, "[commander] Landing detected"),
    ]
    info: dict[str, str | int | float] = {
        "sys_name": "PX4",
        "ver_hw": "CUBEPILOT_CUBEORANGE",
        "ver_sw": "2f0d2b1e7c4a9e1d3b6a5c8f0e9d7c6b5a4f3e2d",
        "ver_sw_release": 0x010E0300,
        "sys_uuid": f"independent-sim-{flight.case.seed:06d}",
        "time_ref_utc": 0,
    }
    write_ulog(path, topics, info=info, parameters=_parameters(flight), messages=messages)
    return expected
