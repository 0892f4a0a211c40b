"""Specific force from velocities and attitude (flightlogs.kinematics): against analytic motion."""

from __future__ import annotations

import numpy as np
import pytest

from flightlogs.frames import earth_to_body
from flightlogs.kinematics import SPECIFIC_FORCE_WINDOW_S, slope, specific_force

G = 9.80665


def test_a_constant_acceleration_in_a_turn_reads_as_the_accelerometer_would() -> None:
    """v = a t with attitude changing: f = R (a - g), exact for a quadratic's slope (the window's own order)."""
    t = np.arange(0.0, 4.0, 0.02)
    accel = np.array([0.8, -0.3, -0.5])
    velocity = np.outer(t, accel) + np.array([2.0, 1.0, 0.0])
    phi, theta, psi = 0.2 * np.sin(t), 0.1 * np.cos(0.5 * t), 0.4 * t
    expected = earth_to_body(np.tile(accel - [0.0, 0.0, G], (t.size, 1)), phi, theta, psi)
    np.testing.assert_allclose(specific_force(t, velocity, phi, theta, psi), expected, atol=1e-9)


def test_a_sine_is_differentiated_with_the_window_s_known_gain() -> None:
    """A quadratic's slope over n samples of sin(omega t) has about the gain 3 (sin x - x cos x) / x^3 of the
    parabolic kernel, x = omega n dt / 2: at 1 Hz, 100 Hz and 0.2 s (21 samples), 0.957."""
    dt, omega = 0.01, 2 * np.pi
    t = np.arange(0.0, 20.0, dt)
    x = omega * (int(round(SPECIFIC_FORCE_WINDOW_S / dt)) | 1) * dt / 2
    gain = 3 * (np.sin(x) - x * np.cos(x)) / x**3
    inner = slice(100, -100)
    derivative, exact = slope(t, np.sin(omega * t))[inner], omega * np.cos(omega * t)[inner]
    assert float(np.dot(derivative, exact) / np.dot(exact, exact)) == pytest.approx(gain, rel=1e-3)
    assert gain == pytest.approx(0.957, abs=1e-3)


def test_no_slope_reaches_across_a_gap() -> None:
    """Two stretches at different constant velocities, 3 s apart: no spike where they meet."""
    t = np.concatenate([np.arange(0.0, 5.0, 0.02), np.arange(8.0, 13.0, 0.02)])
    v = np.where(t < 6.0, 1.0, 4.0)
    assert np.max(np.abs(slope(t, v))) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("n", [1, 2, 4])
def test_a_stretch_shorter_than_the_window_uses_central_differences(n: int) -> None:
    t = np.arange(n) * 0.02
    expected = np.zeros(n) if n == 1 else np.full(n, 3.0)
    np.testing.assert_allclose(slope(t, 3.0 * t), expected, atol=1e-12)
