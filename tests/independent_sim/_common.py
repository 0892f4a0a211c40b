"""Helpers both log writers use: sampling a flight at a topic's rate, motors, battery, GPS, quaternions, wind estimate."""

from __future__ import annotations

import math

import numpy as np

from independent_sim._mixer import PITCH_ARM, ROLL_ARM, YAW_SPIN
from independent_sim.effects import pack_current, pack_voltage
from independent_sim.flight import Flight
from independent_sim.wind import ESTIMATE_NOISE_M_S, lagged_estimate

__all__ = [
    "sample_indices",
    "motor_commands",
    "battery",
    "geodetic",
    "quaternion",
    "wind_estimate",
    "HOME_LAT_DEG",
    "HOME_LON_DEG",
    "HOME_ALT_M",
]

#: Take-off point (a field in Nebraska), degrees, and its altitude above mean sea level, m.
HOME_LAT_DEG, HOME_LON_DEG, HOME_ALT_M = 40.849120, -96.470310, 362.0
_EARTH_RADIUS_M = 6_371_000.0


def sample_indices(flight: Flight, rate_hz: float, offset_s: float = 0.0) -> np.ndarray:
    """Fine-grid indices of a topic published at `rate_hz`, `offset_s` after the grid's start.

    Parameters
    ----------
    flight : Flight
        The flown case.
    rate_hz : float
        Topic rate, Hz; its period must be a whole number of grid steps.
    offset_s : float
        Phase of the topic, s (a whole number of grid steps).

    Returns
    -------
    ndarray of int
    """
    step_s = flight.step_us / 1e6
    stride, phase = round(1.0 / (rate_hz * step_s)), round(offset_s / step_s)
    if abs(stride * step_s * rate_hz - 1.0) > 1e-9 or abs(phase * step_s - offset_s) > 1e-9:
        raise ValueError(f"{rate_hz=} Hz and {offset_s=} s must fall on the {step_s * 1e3:g} ms grid")
    return np.arange(phase, flight.time_s.size, stride)


def motor_commands(flight: Flight, index: np.ndarray) -> np.ndarray:
    """Normalised motor commands (0..1) of the octocopter X mixer, shape (n, 8).

    Parameters
    ----------
    flight : Flight
        The flown case.
    index : ndarray of int
        Fine-grid samples.

    Returns
    -------
    ndarray, shape (n, 8)
        ``thrust + 0.5 (roll, pitch) + 0.3 yaw`` per motor; 0.05 idle when
        armed on the ground, 0 disarmed.
    """
    t = flight.truth
    motors = (
        t["delta_thr"][index, None]
        + 0.5 * (t["delta_lat"][index, None] * ROLL_ARM + t["delta_lon"][index, None] * PITCH_ARM)
        + 0.3 * t["delta_yaw"][index, None] * YAW_SPIN
    )
    idle = np.where(flight.armed[index], 0.05, 0.0)
    return np.clip(np.maximum(motors, idle[:, None]), 0.0, 1.0)


def battery(flight: Flight, index: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Battery voltage (6S, V) and current (A): discharge over the flight, sag with thrust.

    Parameters
    ----------
    flight : Flight
        The flown case.
    index : ndarray of int
        Fine-grid samples.

    Returns
    -------
    tuple of ndarray
        Voltage, V, and current, A.
    """
    thrust = flight.truth["delta_thr"][index]
    used_s = np.cumsum(flight.airborne) * flight.step_us / 1e6
    return pack_voltage(thrust, used_s[index]), pack_current(thrust)


def geodetic(north_m: np.ndarray, east_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Latitude and longitude, degrees, of a local offset from the take-off point.

    Parameters
    ----------
    north_m, east_m : ndarray
        Offset, m.

    Returns
    -------
    tuple of ndarray
        Latitude and longitude, degrees.
    """
    lat = HOME_LAT_DEG + np.degrees(north_m / _EARTH_RADIUS_M)
    lon = HOME_LON_DEG + np.degrees(east_m / (_EARTH_RADIUS_M * math.cos(math.radians(HOME_LAT_DEG))))
    return lat, lon


def quaternion(phi: np.ndarray, theta: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Hamilton quaternion ``w, x, y, z`` of ZYX Euler angles (body to NED), shape (n, 4).

    Parameters
    ----------
    phi, theta, psi : ndarray, shape (n,)
        Roll, pitch, yaw, rad.

    Returns
    -------
    ndarray, shape (n, 4)

    Examples
    --------
    >>> np.round(quaternion(np.zeros(1), np.zeros(1), np.array([np.pi])), 6) + 0.0
    array([[0., 0., 0., 1.]])
    """
    cr, sr = np.cos(phi / 2), np.sin(phi / 2)
    cp, sp = np.cos(theta / 2), np.sin(theta / 2)
    cy, sy = np.cos(psi / 2), np.sin(psi / 2)
    return np.column_stack(
        [
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        ]
    )


def wind_estimate(flight: Flight, index: np.ndarray) -> np.ndarray | None:
    """The autopilot's wind estimate at some fine-grid samples, or None when the case logs none.

    Parameters
    ----------
    flight : Flight
        The flown case.
    index : ndarray of int, shape (m,)
        Fine-grid samples (a topic's).

    Returns
    -------
    ndarray, shape (m, 2), or None
        North and east wind, m/s: the true wind at the vehicle (``truth["wind_n"]``,
        ``truth["wind_e"]``) low-passed on the fine grid with the case's
        ``estimate_time_constant_s`` (:func:`~independent_sim.wind.lagged_estimate`),
        sampled, plus white noise of :data:`~independent_sim.wind.ESTIMATE_NOISE_M_S`
        (a generator of its own: the other streams of the case are unchanged).
    """
    model = flight.case.wind
    if model is None or model.estimate_time_constant_s is None:
        return None
    true = np.column_stack([flight.truth["wind_n"], flight.truth["wind_e"]])
    lagged = lagged_estimate(flight.time_s, true, model.estimate_time_constant_s)[index]
    rng = np.random.default_rng((flight.case.seed, 0x77E5))
    noisy: np.ndarray = lagged + ESTIMATE_NOISE_M_S * rng.standard_normal(lagged.shape)
    return noisy
