"""Write a flown case as an ordinary ArduCopter 4.x DataFlash ``.bin`` (no SIDS/SIDD).

Messages and rates (400 Hz grid and loop)::

    IMU    400 Hz   gyro, accelerometer
    RATE   400 Hz   RDes R ROut, PDes P POut, YDes Y YOut (deg/s, normalised), ADes A AOut
    ATT    100 Hz   DesRoll Roll DesPitch Pitch DesYaw Yaw (deg, 0.01 deg resolution)
    RCOU   100 Hz   C1..C8 PWM (1100-1900 µs)
    XKF1    50 Hz   VN VE VD, PN PE PD (EKF3 core 0)
    XKF2    25 Hz   VWN VWE wind estimate (core 0; only when the case's wind model asks for one)
    CTUN    25 Hz   ThO, ThH, DAlt, Alt (above home; no rangefinder), CRt
    BAT     10 Hz   Volt, Curr
    RCIN    25 Hz   C1..C4 sticks (roll, pitch, throttle, yaw; 1100-1900 µs), C5 mode switch
    GPS      5 Hz   GMS, GWk (GPS time), Lat, Lng, Status 6 (RTK fixed)
    PARM, MSG (firmware, frame), MODE (Loiter), EV (armed, take-off, landed, disarmed)

The mixer outputs are RATE's ROut, POut, YOut (-1..1) and AOut (0..1), as
Copter ≥ 3.4 logs them with ``TimeUS``. A flight's logging gaps
(``Flight.dropouts_s``) leave out every message inside them.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from flightlogs.writers import MessageBlock, MessageSpec, standard_block, write_dataflash
from independent_sim._common import HOME_ALT_M, battery, geodetic, motor_commands, sample_indices, wind_estimate
from independent_sim.flight import Flight
from independent_sim.nuisances import keep_mask

__all__ = ["ARDUPILOT_RATES", "write_ardupilot"]

#: (rate Hz, phase s) of each message.
ARDUPILOT_RATES: Mapping[str, tuple[float, float]] = {
    "IMU": (400.0, 0.0),
    "RATE": (400.0, 0.0),
    "ATT": (100.0, 0.0025),
    "RCOU": (100.0, 0.0),
    "XKF1": (50.0, 0.005),
    "XKF2": (25.0, 0.005),
    "CTUN": (25.0, 0.0075),
    "BAT": (10.0, 0.0125),
    "GPS": (5.0, 0.0),
    "RCIN": (25.0, 0.01),
}
_EV = MessageSpec(name="EV", format="QB", columns=("TimeUS", "Id"), units="s-", multipliers="F-")
_RCIN = MessageSpec(
    name="RCIN",
    format="Q" + "H" * 14,
    columns=("TimeUS", *(f"C{k}" for k in range(1, 15))),
    units="s" + "Y" * 14,
    multipliers="F" + "-" * 14,
)
_EVENTS = {"armed": 10, "disarmed": 11, "land_complete": 18, "not_landed": 28}
_GPS_EPOCH_UNIX = 315_964_800
_LEAP_S = 18  # GPS - UTC since 2017
_F32 = np.float32

Expected = dict[str, tuple[np.ndarray, np.ndarray]]


def _pick(flight: Flight, name: str) -> tuple[np.ndarray, np.ndarray]:
    index = sample_indices(flight, *ARDUPILOT_RATES[name])
    return index, flight.time_us[index]


def _deg(values: np.ndarray) -> np.ndarray:
    return np.degrees(values)


def _heading_deg(values: np.ndarray) -> np.ndarray:
    """Yaw in [0, 360) at the 0.01° resolution ATT keeps (so 359.996 does not round to 360)."""
    return np.round(np.mod(np.degrees(values), 360.0), 2) % 360.0


def _wrapped_rad(degrees: np.ndarray) -> np.ndarray:
    """Degrees → radians in (-π, π], as the reader wraps ``ATT.Yaw``."""
    return np.asarray(np.pi - np.mod(np.pi - np.radians(degrees), 2 * np.pi))


def _inertial(flight: Flight, expected: Expected) -> list[MessageBlock]:
    m, t = flight.measured, flight.truth
    i, stamp = _pick(flight, "IMU")
    imu = {
        k: m[src][i].astype(_F32)
        for k, src in zip(("GyrX", "GyrY", "GyrZ", "AccX", "AccY", "AccZ"), "p q r ax ay az".split())
    }
    n = i.size
    blocks = [
        standard_block(
            "IMU",
            TimeUS=stamp,
            **imu,
            T=np.full(n, 45.0),
            GH=np.ones(n),
            AH=np.ones(n),
            GHz=np.full(n, 400),
            AHz=np.full(n, 400),
        )
    ]
    for name, column in zip(("p", "q", "r", "ax", "ay", "az"), ("GyrX", "GyrY", "GyrZ", "AccX", "AccY", "AccZ")):
        expected[name] = (stamp / 1e6, imu[column])
    i, stamp = _pick(flight, "RATE")
    vertical = -np.gradient(t["vd"], flight.time_s)[i] * 100.0  # cm/s², up
    rate = {
        "RDes": _deg(t["p_sp"][i]),
        "R": _deg(m["p"][i]),
        "ROut": t["delta_lat"][i],
        "PDes": _deg(t["q_sp"][i]),
        "P": _deg(m["q"][i]),
        "POut": t["delta_lon"][i],
        "YDes": _deg(t["r_sp"][i]),
        "Y": _deg(m["r"][i]),
        "YOut": t["delta_yaw"][i],
        "A": vertical,
        "AOut": t["delta_thr"][i],
    }
    rate = {k: v.astype(_F32) for k, v in rate.items()}
    blocks.append(standard_block("RATE", TimeUS=stamp, **rate))
    for name, column in (("delta_lat", "ROut"), ("delta_lon", "POut"), ("delta_yaw", "YOut"), ("delta_thr", "AOut")):
        expected[name] = (stamp / 1e6, rate[column])
    for name, column in (("p_ref", "RDes"), ("q_ref", "PDes"), ("r_ref", "YDes")):
        expected[name] = (stamp / 1e6, np.radians(rate[column].astype(float)))
    i, stamp = _pick(flight, "ATT")
    att = {
        "DesRoll": _deg(t["phi_sp"][i]),
        "Roll": _deg(m["phi"][i]),
        "DesPitch": _deg(t["theta_sp"][i]),
        "Pitch": _deg(m["theta"][i]),
        "DesYaw": _heading_deg(t["psi_sp"][i]),
        "Yaw": _heading_deg(m["psi"][i]),
    }
    att = {k: np.round(v, 2) for k, v in att.items()}
    error = np.round(np.abs(att["DesRoll"] - att["Roll"]) + np.abs(att["DesPitch"] - att["Pitch"]), 2)
    blocks.append(standard_block("ATT", TimeUS=stamp, **att, ErrRP=np.minimum(error, 600.0), AEKF=np.full(i.size, 3)))
    for name, column in (("phi", "Roll"), ("theta", "Pitch")):
        expected[name] = (stamp / 1e6, np.radians(att[column]))
    expected["psi"] = (stamp / 1e6, _wrapped_rad(att["Yaw"]))
    expected["phi_ref"], expected["theta_ref"] = (
        (stamp / 1e6, np.radians(att["DesRoll"])),
        (stamp / 1e6, np.radians(att["DesPitch"])),
    )
    expected["psi_ref"] = (stamp / 1e6, _wrapped_rad(att["DesYaw"]))
    return blocks


def _navigation(flight: Flight, expected: Expected) -> list[MessageBlock]:
    m, t = flight.measured, flight.truth
    i, stamp = _pick(flight, "XKF1")
    velocity = {k: m[src][i].astype(_F32) for k, src in (("VN", "vn"), ("VE", "ve"), ("VD", "vd"))}
    blocks = [
        standard_block(
            "XKF1",
            TimeUS=stamp,
            Roll=np.round(_deg(m["phi"][i]), 2),
            Pitch=np.round(_deg(m["theta"][i]), 2),
            Yaw=_heading_deg(m["psi"][i]),
            **velocity,
            dPD=velocity["VD"],
            PN=m["x_n"][i].astype(_F32),
            PE=m["y_e"][i].astype(_F32),
            PD=(-m["height"][i]).astype(_F32),
        )
    ]
    for name, column in (("vn", "VN"), ("ve", "VE"), ("vd", "VD")):
        expected[name] = (stamp / 1e6, velocity[column])
    blocks += _wind(flight, expected)
    i, stamp = _pick(flight, "CTUN")
    alt = m["height"][i].astype(_F32)
    climb = np.round(-t["vd"][i] * 100.0)
    blocks.append(
        standard_block(
            "CTUN",
            TimeUS=stamp,
            ThI=np.full(i.size, 0.5),
            ThO=t["delta_thr"][i].astype(_F32),
            ThH=np.full(i.size, flight.plant.trim.delta_thr),
            DAlt=t["height_sp"][i].astype(_F32),
            Alt=alt,
            BAlt=np.round(alt + 0.05, 2),
            TAlt=alt,
            DCRt=np.round(-t["vd_sp"][i] * 100.0),
            CRt=climb,
        )
    )
    expected["height_agl"] = (stamp / 1e6, alt)
    blocks.append(_gps(flight))
    return blocks


def _wind(flight: Flight, expected: Expected) -> list[MessageBlock]:
    """XKF2 of core 0: the EKF's wind estimate VWN, VWE (0.01 m/s as logged), when the case logs one."""
    i, stamp = _pick(flight, "XKF2")
    estimate = wind_estimate(flight, i)
    if estimate is None:
        return []
    north, east = np.round(estimate, 2).T
    expected["est_wind_n"], expected["est_wind_e"] = (stamp / 1e6, north), (stamp / 1e6, east)
    return [standard_block("XKF2", TimeUS=stamp, C=np.zeros(i.size), VWN=north, VWE=east)]


def _gps(flight: Flight) -> MessageBlock:
    """GPS with GPS week and milliseconds of week (UTC + 18 leap seconds), the receiver's position."""
    t = flight.truth
    i, stamp = _pick(flight, "GPS")
    gps_s = stamp / 1e6 + flight.utc_offset_s + _LEAP_S - _GPS_EPOCH_UNIX
    week = np.floor(gps_s / 604800.0)
    lat, lon = geodetic(t["x_n"][i], t["y_e"][i])
    return standard_block(
        "GPS",
        TimeUS=stamp,
        Status=np.full(i.size, 6),
        GMS=np.round((gps_s - week * 604800.0) * 1000.0),
        GWk=week,
        NSats=np.full(i.size, 19),
        HDop=np.full(i.size, 0.62),
        Lat=np.round(lat, 7),
        Lng=np.round(lon, 7),
        Alt=np.round(HOME_ALT_M + t["height"][i], 2),
        Spd=np.hypot(t["vn"][i], t["ve"][i]),
        GCrs=np.mod(np.degrees(np.arctan2(t["ve"][i], t["vn"][i])), 360.0),
        VZ=t["vd"][i],
        U=np.ones(i.size),
    )


def _outputs(flight: Flight, expected: Expected) -> list[MessageBlock]:
    i, stamp = _pick(flight, "RCOU")
    pwm = np.round(1100.0 + 800.0 * motor_commands(flight, i))
    pwm[~flight.armed[i]] = 1000.0
    channels = {f"C{k + 1}": pwm[:, k] for k in range(8)}
    blocks = [standard_block("RCOU", TimeUS=stamp, **channels)]
    expected.update({f"motor_{k + 1}": (stamp / 1e6, pwm[:, k]) for k in range(8)})
    i, stamp = _pick(flight, "BAT")
    voltage, current = battery(flight, i)
    volt = voltage.astype(_F32)
    used_mah = np.cumsum(current) * 0.1 / 3.6
    blocks.append(
        standard_block(
            "BAT",
            TimeUS=stamp,
            Volt=volt,
            VoltR=(voltage + 0.009 * current).astype(_F32),
            Curr=current,
            CurrTot=used_mah,
            EnrgTot=used_mah * 24.0 / 1000.0,
            Temp=np.full(i.size, 31.0),
            Res=np.full(i.size, 0.009),
        )
    )
    expected["battery_v"] = (stamp / 1e6, volt)
    return blocks


def _sticks(flight: Flight, expected: Expected) -> MessageBlock:
    """RCIN: roll, pitch (back = higher PWM), throttle (mid holds height) and yaw on channels 1-4, 1100-1900 µs."""
    i, stamp = _pick(flight, "RCIN")
    rng = np.random.default_rng(flight.case.seed + 7)
    pwm = {}
    for channel, axis in ((1, "lat"), (2, "lon"), (3, "thr"), (4, "yaw")):
        stick = flight.truth[f"stick_{axis}"][i]
        pwm[f"C{channel}"] = np.clip(np.round(1500.0 + 400.0 * stick + rng.integers(-1, 2, i.size)), 1100, 1900)
        normalised = (pwm[f"C{channel}"] - 1500.0) / 400.0
        expected[f"stick_{axis}"] = (stamp / 1e6, (normalised + 1.0) / 2.0 if axis == "thr" else normalised)
    pwm["C5"] = np.full(i.size, 1815.0)  # flight-mode switch (Loiter)
    return MessageBlock(_RCIN, {"TimeUS": stamp, **pwm, **{f"C{k}": np.full(i.size, 1500.0) for k in range(6, 15)}})


def _events(flight: Flight) -> list[MessageBlock]:
    us = flight.time_us
    armed = np.flatnonzero(np.diff(flight.armed.astype(np.int8)))
    airborne = np.flatnonzero(np.diff(flight.airborne.astype(np.int8)))
    ids = [_EVENTS["armed"], _EVENTS["not_landed"], _EVENTS["land_complete"], _EVENTS["disarmed"]]
    times = [us[armed[0] + 1], us[airborne[0] + 1], us[airborne[1] + 1], us[armed[1] + 1]]
    return [
        MessageBlock(_EV, {"TimeUS": np.array(times, np.int64), "Id": np.array(ids)}),
        standard_block("MODE", TimeUS=[us[0]], Mode=[5], ModeNum=[5], Rsn=[1]),
    ]


def _parameters(flight: Flight) -> dict[str, float]:
    g = flight.gains
    return {
        "FRAME_CLASS": 3.0,
        "FRAME_TYPE": 1.0,
        "AHRS_EKF_TYPE": 3.0,
        "SCHED_LOOP_RATE": 400.0,
        "ATC_RAT_RLL_P": g.rate_roll_p,
        "ATC_RAT_RLL_I": g.rate_roll_i,
        "ATC_RAT_RLL_D": g.rate_roll_d,
        "ATC_RAT_PIT_P": g.rate_pitch_p,
        "ATC_RAT_PIT_I": g.rate_pitch_i,
        "ATC_RAT_PIT_D": g.rate_pitch_d,
        "ATC_RAT_YAW_P": g.rate_yaw_p,
        "ATC_RAT_YAW_I": g.rate_yaw_i,
        "ATC_ANG_RLL_P": g.att_roll_p,
        "ATC_ANG_PIT_P": g.att_pitch_p,
        "ATC_ANG_YAW_P": g.att_yaw_p,
        "PSC_POSXY_P": g.pos_xy_p,
        "PSC_VELXY_P": g.vel_xy_p,
        "PSC_VELXY_I": g.vel_xy_i,
        "PSC_POSZ_P": g.pos_z_p,
        "PSC_VELZ_P": g.vel_z_p,
        "INS_GYRO_FILTER": g.gyro_cutoff_hz,
        "MOT_THST_HOVER": flight.plant.trim.delta_thr,
        "MOT_PWM_MIN": 1100.0,
        "MOT_PWM_MAX": 1900.0,
        "LOG_BITMASK": 180222.0,
        **{f"RCMAP_{axis}": float(k) for k, axis in ((1, "ROLL"), (2, "PITCH"), (3, "THROTTLE"), (4, "YAW"))},
        **{
            f"RC{k}_{key}": value
            for k in range(1, 5)
            for key, value in (("MIN", 1100.0), ("TRIM", 1500.0), ("MAX", 1900.0))
        },
    }


def _without_gaps(
    blocks: list[MessageBlock], expected: Expected, spans_s: tuple[tuple[float, float], ...]
) -> tuple[list[MessageBlock], Expected]:
    """Every message, and what the reader must return, less those inside the logging gaps."""
    kept = []
    for block in blocks:
        if "TimeUS" not in block.data:
            kept.append(block)
            continue
        keep = keep_mask(np.asarray(block.data["TimeUS"], np.int64), spans_s)
        kept.append(MessageBlock(block.spec, {k: np.asarray(v)[keep] for k, v in block.data.items()}))
    out = {}
    for name, (time_s, values) in expected.items():
        keep = keep_mask(np.rint(time_s * 1e6).astype(np.int64), spans_s)
        out[name] = (time_s[keep], values[keep])
    return kept, out


def write_ardupilot(flight: Flight, path: Path) -> Expected:
    """Write `flight` as a DataFlash log at `path`.

    Parameters
    ----------
    flight : Flight
        A case flown with the ArduPilot profile.
    path : Path
        Destination ``.bin``.

    Returns
    -------
    dict of str to (ndarray, ndarray)
        For each canonical signal the log carries, the ``(time_s, values)``
        the workbench's reader must return (at the log's resolution).
    """
    if flight.fmt != "dataflash":
        raise ValueError(f"{flight.case.name}: flown with the {flight.fmt} profile, not ArduPilot's")
    expected: Expected = {}
    blocks = _inertial(flight, expected) + _navigation(flight, expected) + _outputs(flight, expected)
    blocks += [_sticks(flight, expected), *_events(flight)]
    if flight.dropouts_s:
        blocks, expected = _without_gaps(blocks, expected, flight.dropouts_s)
    frame = standard_block("MSG", TimeUS=[flight.time_us[0]], Message=np.array(["Frame: OCTA/X"], dtype=object))
    write_dataflash(
        path,
        [*blocks, frame],
        parameters=_parameters(flight),
        firmware="ArduCopter V4.5.7 (2a3dc4b7)",
    )
    return expected
