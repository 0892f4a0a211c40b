"""The linear hover's axes turn with its heading: a log read with its own yaw gives the airspeeds it flew.

The fleet's healthy flights were each named a CG offset against their first flight (p_dot, 11 % cut on
fleet seed 7) until the wind reached the model's axes turned by the yaw state: the logged ground velocity,
read on the logged heading, held a part of the wind along a heading the airframe never felt.
"""

from __future__ import annotations

import numpy as np

from flightlogs.frames import wind_to_body_axes
from simulator.autopilot.excitation import Maneuver
from simulator.flights.linear import _NOISE, WindField, simulate_hover

_NOISE_M_S = _NOISE["vn"]  # the logged ground velocity's noise per axis, m/s


def test_the_logged_ground_velocity_read_on_the_logged_heading_is_the_airspeed_flown() -> None:
    yaw_sweep = (Maneuver(axis="yaw", kind="sweep", start_s=2.0, amplitude=20.0, duration_s=20.0),)
    wind = WindField(mean_speed_m_s=3.0, direction_from_deg=40.0, turbulence_ratio=0.2)
    flight = simulate_hover(26.0, yaw_sweep, wind=wind, seed=4)
    s = flight.signals
    assert np.degrees(np.ptp(s["psi"])) > 20.0  # the sweep turns the vehicle: the test can tell the axes apart
    ground = np.column_stack([s["vn"], s["ve"]]) - flight.wind_at_vehicle
    read = wind_to_body_axes(ground, s["psi"])  # as the conditioning reads u and v (eq. 3.1, level)
    flown = np.column_stack([s["u"], s["v"]])
    error = np.sqrt(np.mean((read - flown) ** 2, axis=0))
    assert np.all(error < 1.5 * _NOISE_M_S), error
    # read as north and east (the axes before this change), the same log is off by the turned wind
    unturned = np.sqrt(np.mean((ground - flown) ** 2, axis=0))
    assert np.all(unturned > 3.0 * _NOISE_M_S), unturned
