"""Write a simulated flight as the files a real flight test produces.

An ArduPilot DataFlash log (IMU, ATT, RATE, CTUN, RCOU, BAT, GPS, XKF1, and
SIDS/SIDD for System ID sweeps), the CSV of a ground anemometer on its own
clock upstream of the vehicle, and a truth JSON.

The vehicle hovers over a fixed point (``vehicle_position_deg``). Its GPS
logs the path flown where the simulator knows it (the nonlinear simulator's
``pn pe``, as an autopilot logs its GNSS fix); for the linear model, which
has no position, it wanders about the point as a position hold would let
it: the horizontal velocity, its mean removed, through a leaky integrator of
time constant 2 s (about ±1 m in the demo's light wind, a few millimetres of
mean offset).
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from pathlib import Path

import numpy as np
from scipy import signal as sps

from flightlogs.geo import destination_point, lat_lon_offset
from flightlogs.writers.atomic import atomic_output
from flightlogs.writers.dataflash import MessageBlock, standard_block, text_block, write_dataflash
from flightlogs.writers.jsonio import write_json
from simulator.autopilot.excitation import Maneuver, sweep
from simulator.flights.linear import SimulatedFlight

__all__ = ["AnemometerSetup", "VEHICLE_POSITION_DEG", "write_ardupilot_log", "write_anemometer_csv", "write_truth"]

#: Where the simulated vehicle hovers by default: latitude, longitude, deg (WGS-84).
VEHICLE_POSITION_DEG: tuple[float, float] = (35.0, -106.9)

_GPS_EPOCH = datetime(1980, 1, 6, tzinfo=UTC)
_LEAP_SECONDS = 18
_SID_AXIS = {"lat": 10, "lon": 11, "yaw": 12, "thr": 13}  # ArduPilot SID_AXIS: mixer roll/pitch/yaw/thrust
_BOOT_S = 20.0  # the log starts this long after boot
_HOLD_S = 2.0  # time constant of the position hold's wander


@dataclass(frozen=True, slots=True, kw_only=True)
class AnemometerSetup:
    """Where the ground anemometer stands and how its clock is off.

    Parameters
    ----------
    distance_m : float
        Distance upstream of the vehicle, m (the dissertation: 4.6 m).
    rate_hz : float
        Output rate, Hz (the dissertation: 20 Hz).
    clock_offset_s : float
        Its clock minus UTC, s.
    """

    distance_m: float = 4.6
    rate_hz: float = 20.0
    clock_offset_s: float = 0.0

    def position_rad(
        self, flight: SimulatedFlight, *, vehicle_position_deg: tuple[float, float] = VEHICLE_POSITION_DEG
    ) -> tuple[float, float]:
        """Where the anemometer stands: `distance_m` straight upstream of the vehicle's hover point.

        Parameters
        ----------
        flight : SimulatedFlight
            The flight; the mean of its ``wind_at_vehicle`` sets upstream.
        vehicle_position_deg : tuple of (float, float), optional
            The hover point, latitude and longitude, deg (as given to
            :func:`write_ardupilot_log`).

        Returns
        -------
        tuple of (float, float)
            Latitude and longitude of the anemometer, rad.
        """
        mean_n, mean_e = flight.wind_at_vehicle.mean(axis=0)
        upstream_rad = float(np.arctan2(-mean_e, -mean_n))  # where the air comes from
        lat, lon = np.radians(vehicle_position_deg)
        return destination_point(float(lat), float(lon), upstream_rad, self.distance_m)


def _gps_week_ms(utc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    gps_s = utc - _GPS_EPOCH.timestamp() + _LEAP_SECONDS
    week = np.floor(gps_s / 604_800.0)
    return week.astype(np.int64), np.round((gps_s - week * 604_800.0) * 1000).astype(np.int64)


def write_ardupilot_log(
    flight: SimulatedFlight,
    path: str | Path,
    *,
    utc_start: datetime,
    vehicle_position_deg: tuple[float, float] = VEHICLE_POSITION_DEG,
    board_id: str | None = None,
) -> Path:
    """Write `flight` as an ArduCopter 4.x DataFlash log.

    Parameters
    ----------
    flight : SimulatedFlight
        The flight; mixer inputs in % become normalised outputs (÷100).
    path : str or Path
        Destination ``.bin``.
    utc_start : datetime
        UTC of the first sample (aware).
    vehicle_position_deg : tuple of (float, float), optional
        The point the vehicle hovers over, latitude and longitude, deg; the
        GPS (5 Hz, 3-D fix) logs it plus the path flown (or the position
        hold's wander, see the module notes).
    board_id : str, optional
        The board message ArduPilot logs at boot (``"CubeOrange 00340032 30385106 38373332"``),
        which tells one vehicle from another.

    Returns
    -------
    Path
    """
    t = flight.time_s + _BOOT_S
    us = np.round(t * 1e6).astype(np.int64)
    s = flight.signals
    hover_thr = 0.5
    out = {axis: s[f"delta_{axis}"] / 100.0 for axis in ("lat", "lon", "yaw", "thr")}
    blocks = [
        standard_block(
            "IMU", TimeUS=us, GyrX=s["p"], GyrY=s["q"], GyrZ=s["r"], AccX=s["ax"], AccY=s["ay"], AccZ=s["az"]
        ),
        standard_block(
            "ATT",
            TimeUS=us,
            Roll=np.degrees(s["phi"]),
            Pitch=np.degrees(s["theta"]),
            Yaw=np.mod(np.degrees(s["psi"]), 360.0),
        ),
        standard_block(
            "RATE", TimeUS=us, ROut=out["lat"], POut=out["lon"], YOut=out["yaw"], AOut=hover_thr + out["thr"]
        ),
        standard_block("XKF1", TimeUS=us, VN=s["vn"], VE=s["ve"], VD=s["vd"]),
        # the EKF's wind estimate: here the true wind at the vehicle, quantised as logged (0.01 m/s)
        standard_block(
            "XKF2",
            TimeUS=us[::4],
            VWN=np.round(flight.wind_at_vehicle[::4, 0], 2),
            VWE=np.round(flight.wind_at_vehicle[::4, 1], 2),
        ),
        standard_block("CTUN", TimeUS=us[::10], ThO=hover_thr + out["thr"][::10], Alt=s["height_agl"][::10]),
        standard_block("RCOU", TimeUS=us, **_octo_pwm(out, hover_thr)),
        standard_block("BAT", TimeUS=us[::10], Volt=25.2 - 0.004 * flight.time_s[::10]),
    ]
    gps_t = t[::20]
    week, ms = _gps_week_ms(utc_start.timestamp() + flight.time_s[::20])
    lat_deg, lng_deg = _gps_track(flight, vehicle_position_deg)
    blocks.append(
        standard_block(
            "GPS",
            TimeUS=np.round(gps_t * 1e6).astype(np.int64),
            Status=np.full(gps_t.size, 3),
            GWk=week,
            GMS=ms,
            NSats=np.full(gps_t.size, 14),
            Lat=lat_deg[::20],
            Lng=lng_deg[::20],
        )
    )
    sweeps = [m for m in flight.maneuvers if m.kind == "sweep"]
    if sweeps:
        blocks += _system_id_blocks(flight, sweeps, us)
    if board_id:
        blocks.append(text_block([(int(us[0]), board_id)]))
    parameters = {
        "FRAME_CLASS": 3.0,
        "FRAME_TYPE": 1.0,
        "SID_MAGNITUDE": float(sweeps[0].amplitude) / 100 if sweeps else 0.0,
    }
    return write_dataflash(path, blocks, parameters=parameters, firmware="ArduCopter V4.5.7 (flight-sysid sim)")


def _gps_track(flight: SimulatedFlight, hover_deg: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """Latitude and longitude, deg, of the hover point plus the path flown, or the wander (see the module notes)."""
    truth = getattr(flight, "truth", {})
    if "pn" in truth and "pe" in truth:
        wander = [np.asarray(truth["pn"], dtype=np.float64), np.asarray(truth["pe"], dtype=np.float64)]
    else:
        dt = float(np.median(np.diff(flight.time_s)))
        keep = np.exp(-dt / _HOLD_S)
        wander = [
            sps.lfilter([dt], [1.0, -keep], flight.signals[name] - flight.signals[name].mean()) for name in ("vn", "ve")
        ]
    dlat, dlon = lat_lon_offset(wander[0], wander[1], np.radians(hover_deg[0]))
    return hover_deg[0] + np.degrees(dlat), hover_deg[1] + np.degrees(dlon)


def _octo_pwm(out: dict[str, np.ndarray], hover: float) -> dict[str, np.ndarray]:
    """Octo-X mixer: motor k at angle 22.5° + 45°k, alternating spin."""
    pwm = {}
    for k in range(8):
        angle = np.radians(22.5 + 45.0 * k)
        spin = 1.0 if k % 2 == 0 else -1.0
        level = hover + out["thr"] - np.sin(angle) * out["lat"] + np.cos(angle) * out["lon"] + spin * out["yaw"]
        pwm[f"C{k + 1}"] = np.clip(np.round(1100 + 800 * level), 1000, 2000).astype(np.int64)
    return pwm


def _system_id_blocks(flight: SimulatedFlight, sweeps: list[Maneuver], us: np.ndarray) -> list[MessageBlock]:
    """SIDS when the mode is entered, SIDD while the chirp runs.

    As ArduCopter's mode_systemid.cpp logs them: the chirp starts 1 s after
    the SIDS message and its fade-in and fade-out lie inside the record time TR.
    """
    start_us = np.array([np.round((m.start_s - 1.0 + _BOOT_S) * 1e6) for m in sweeps], dtype=np.int64)
    sids = standard_block(
        "SIDS",
        TimeUS=start_us,
        Ax=[_SID_AXIS[m.axis] for m in sweeps],
        Mag=[m.amplitude / 100 for m in sweeps],
        FSt=[m.f_start_hz for m in sweeps],
        FSp=[m.f_stop_hz for m in sweeps],
        TFin=[m.fade_in_s for m in sweeps],
        TC=[0.0] * len(sweeps),
        TR=[m.duration_s for m in sweeps],
        TFout=[m.fade_out_s for m in sweeps],
    )
    rows: tuple[list[np.ndarray], ...] = ([], [], [], [])
    for maneuver in sweeps:
        inside = (flight.time_s >= maneuver.start_s) & (flight.time_s < maneuver.end_s)
        value, freq = sweep(flight.time_s[inside], maneuver)
        rows[0].append(us[inside])
        rows[1].append(flight.time_s[inside] - maneuver.start_s)
        rows[2].append(value / 100)
        rows[3].append(freq)
    sidd = standard_block(
        "SIDD",
        TimeUS=np.concatenate(rows[0]),
        Time=np.concatenate(rows[1]),
        Targ=np.concatenate(rows[2]),
        F=np.concatenate(rows[3]),
    )
    return [sids, sidd]


def write_anemometer_csv(
    flight: SimulatedFlight, path: str | Path, *, utc_start: datetime, setup: AnemometerSetup
) -> Path:
    """Write the ground anemometer's record of the wind, upstream and on its own clock.

    The anemometer sees each gust ``transport delay = distance / mean speed``
    before the vehicle (Taylor's frozen turbulence), samples at its own rate
    and stamps UTC from its own clock.

    Parameters
    ----------
    flight : SimulatedFlight
        The flight; its ``wind_at_vehicle`` is what the anemometer measured earlier.
    path : str or Path
        Destination ``.csv`` (columns ``utc``, ``speed_m_s``, ``direction_deg``).
    utc_start : datetime
        UTC of the flight's first sample.
    setup : AnemometerSetup
        Distance, rate and clock offset.

    Returns
    -------
    Path
    """
    at_anemometer = getattr(flight, "wind_at_anemometer", None)
    if at_anemometer is not None:  # the simulator sampled the frozen field at the anemometer itself
        sensor_t = np.arange(flight.time_s[0], flight.time_s[-1], 1.0 / setup.rate_hz)
        wind_n = np.interp(sensor_t, flight.time_s, at_anemometer[:, 0])
        wind_e = np.interp(sensor_t, flight.time_s, at_anemometer[:, 1])
    else:  # the vehicle's wind, seen the transport delay earlier
        delay = _transport_delay_s(flight, setup)
        sensor_t = np.arange(flight.time_s[0] - delay, flight.time_s[-1] - delay, 1.0 / setup.rate_hz)
        sensor_t = sensor_t[sensor_t + delay >= flight.time_s[0]]
        wind_n = np.interp(sensor_t + delay, flight.time_s, flight.wind_at_vehicle[:, 0])
        wind_e = np.interp(sensor_t + delay, flight.time_s, flight.wind_at_vehicle[:, 1])
    speed = np.hypot(wind_n, wind_e)
    direction_from = np.mod(np.degrees(np.arctan2(-wind_e, -wind_n)), 360.0)
    lines = ["utc,speed_m_s,direction_deg"]
    for t, v, d in zip(sensor_t, speed, direction_from):
        stamp = utc_start + timedelta(seconds=float(t) + setup.clock_offset_s)
        lines.append(f"{stamp.strftime('%Y-%m-%dT%H:%M:%S.%f')[:-3]}Z,{v:.3f},{d:.1f}")
    with atomic_output(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n")
    return Path(path)


def _transport_delay_s(flight: SimulatedFlight, setup: AnemometerSetup) -> float:
    """The simulator's own delay when it advected a frozen field, else distance / mean speed."""
    simulated = getattr(flight, "transport_delay_s", None)
    if simulated is not None:
        return float(simulated)
    return setup.distance_m / float(np.hypot(*flight.wind_at_vehicle.mean(axis=0)))


def _effective_transport_delay_s(flight: SimulatedFlight, setup: AnemometerSetup) -> float:
    """Delay to where the vehicle actually was on average: a position hold leaves it a few cm up- or
    downwind of its set point, which moves the delay by that distance over the mean wind speed."""
    nominal = _transport_delay_s(flight, setup)
    truth = getattr(flight, "truth", None)
    if not truth or "pn" not in truth or nominal <= 0:
        return nominal
    mean_wind = flight.wind_at_vehicle.mean(axis=0)
    towards = mean_wind / np.hypot(*mean_wind)
    along_m = float(np.mean(truth["pn"] * towards[0] + truth["pe"] * towards[1]))
    return nominal + along_m / (setup.distance_m / nominal)


def write_truth(
    flight: SimulatedFlight,
    path: str | Path,
    *,
    utc_start: datetime,
    setup: AnemometerSetup | None,
    vehicle_position_deg: tuple[float, float] = VEHICLE_POSITION_DEG,
) -> Path:
    """Write what the files conceal: parameters, maneuvers, delays and offsets.

    Parameters
    ----------
    flight : SimulatedFlight
        The flight.
    path : str or Path
        Destination ``.json``.
    utc_start : datetime
        UTC of the first sample.
    setup : AnemometerSetup or None
        The anemometer, if one was written.
    vehicle_position_deg : tuple of (float, float), optional
        The hover point given to :func:`write_ardupilot_log`, deg; with it the
        anemometer's position (``anemometer.position_deg``) is recorded.

    Returns
    -------
    Path
    """
    truth = {
        "parameters": dict(flight.parameters),
        "log_start_s": _BOOT_S,
        "utc_start": utc_start.isoformat(),
        "maneuvers": [
            {
                "axis": m.axis,
                "kind": m.kind,
                "start_s": m.start_s + _BOOT_S,
                "end_s": m.end_s + _BOOT_S,
                "amplitude": m.amplitude,
            }
            for m in flight.maneuvers
        ],
    }
    if setup is not None:
        truth["anemometer"] = {
            "distance_m": setup.distance_m,
            "rate_hz": setup.rate_hz,
            "clock_offset_s": setup.clock_offset_s,
            "transport_delay_s": _transport_delay_s(flight, setup),
            "effective_transport_delay_s": _effective_transport_delay_s(flight, setup),
            "position_deg": [
                float(np.degrees(v)) for v in setup.position_rad(flight, vehicle_position_deg=vehicle_position_deg)
            ],
        }
        truth["vehicle_position_deg"] = list(vehicle_position_deg)
    return write_json(path, truth, indent=2)
