"""Rotations: quaternions, earth to body, eq. 3.1 airspeed, wind in body axes."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from flightlogs.frames import (
    air_velocity_body,
    air_velocity_per_wind,
    earth_to_body,
    quaternion_to_euler,
    wind_to_body_axes,
)

angles = st.tuples(st.floats(-3.1, 3.1), st.floats(-1.5, 1.5), st.floats(-3.1, 3.1))


@settings(max_examples=60, deadline=None)
@given(angles)
def test_quaternion_to_euler_matches_scipy(euler: tuple[float, float, float]) -> None:
    phi, theta, psi = euler
    rotation = Rotation.from_euler("ZYX", [psi, theta, phi])  # body -> NED, yaw-pitch-roll
    x, y, z, w = rotation.as_quat()
    back = quaternion_to_euler(np.array([[w, x, y, z]]))[0]
    np.testing.assert_allclose(back, [phi, theta, psi], atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(angles, st.tuples(st.floats(-20, 20), st.floats(-20, 20), st.floats(-20, 20)))
def test_earth_to_body_is_the_inverse_of_scipys_body_to_earth(euler: tuple, vector: tuple) -> None:
    phi, theta, psi = euler
    rotation = Rotation.from_euler("ZYX", [psi, theta, phi])
    body = earth_to_body(np.array([vector]), np.array([phi]), np.array([theta]), np.array([psi]))[0]
    np.testing.assert_allclose(body, rotation.inv().apply(vector), atol=1e-9)


def test_airspeed_of_a_level_vehicle_in_a_crosswind() -> None:
    # nose east, flying east at 2 m/s, wind blowing towards the north at 3 m/s
    uvw = air_velocity_body(
        np.array([[0.0, 2.0, 0.0]]), np.array([[3.0, 0.0]]), np.zeros(1), np.zeros(1), np.array([np.pi / 2])
    )
    np.testing.assert_allclose(uvw, [[2.0, 3.0, 0.0]], atol=1e-12)  # air from the left: v = +3 (moves right relative)


def test_airspeed_picks_up_w_when_pitched_in_a_headwind() -> None:
    theta = np.radians(-4.36)  # Table 3.2 strong-wind trim pitch
    uvw = air_velocity_body(np.zeros((1, 3)), np.array([[-4.12, 0.0]]), np.zeros(1), np.array([theta]), np.zeros(1))
    assert uvw[0, 0] == pytest.approx(4.12 * np.cos(theta))
    # nose down into the wind: the relative air has a component up the body z axis,
    # w = U sin(theta) < 0, the sign of Table 3.2's W0 = -0.22 m/s
    assert uvw[0, 2] == pytest.approx(4.12 * np.sin(theta)) and uvw[0, 2] < 0


def test_wind_in_body_axes_keeps_the_speed() -> None:
    rng = np.random.default_rng(2)
    wind = rng.normal(size=(50, 2))
    psi = rng.uniform(-np.pi, np.pi, 50)
    body = wind_to_body_axes(wind, psi)
    np.testing.assert_allclose(np.hypot(*body.T), np.hypot(*wind.T))
    np.testing.assert_allclose(wind_to_body_axes(wind, np.zeros(50)), wind)


def test_the_air_velocity_per_wind_is_what_a_wind_of_one_metre_a_second_makes() -> None:
    """Eq. 3.1 is linear in the wind: its slope is the rotation's first two columns, negated, to the last bit."""
    rng = np.random.default_rng(11)
    n = 2000
    angles = [rng.uniform(-0.5, 0.5, n), rng.uniform(-0.5, 0.5, n), rng.uniform(-np.pi, np.pi, n)]
    per_wind = air_velocity_per_wind(*angles)
    assert per_wind.shape == (n, 3, 2)
    for k in range(2):
        unit = np.zeros((n, 2))
        unit[:, k] = 1.0
        np.testing.assert_array_equal(per_wind[:, :, k], air_velocity_body(np.zeros((n, 3)), unit, *angles))
    wind = rng.normal(size=(n, 2))
    change = np.einsum("nij,nj->ni", per_wind, wind)
    np.testing.assert_allclose(change, air_velocity_body(np.zeros((n, 3)), wind, *angles), rtol=0, atol=1e-14)
