"""Heave simulation near the ground: trim, thrust step, the ground-effect spring, the ground, the PID against theory."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal as sps

from simulator.flights.altitude import CRAZYFLIE_ALTITUDE, AltitudeVehicle, simulate_altitude
from simulator.mrac import PidAltitude, PidGains, step_metrics
from simulator.vehicle.presets import CRAZYFLIE
from simulator.world.environment import GroundEffect, SensorNoise

VEHICLE = CRAZYFLIE_ALTITUDE
EQ_2_5 = GroundEffect(model="fitted_4rotor")
QUIET = SensorNoise.off()
SLOPE_PER_M = -0.0373 / VEHICLE.rotor_radius_m  # d(F/F0)/dz of eq. 2.5


class Hold:
    """Constant PWM: the trim, or a given value."""

    def __init__(self, pwm: float | None = None) -> None:
        self.value = pwm
        self.pwm = np.zeros(0)

    def reset(self, height_m: np.ndarray, trim_pwm: np.ndarray) -> None:
        self.pwm = trim_pwm.copy() if self.value is None else np.full_like(trim_pwm, self.value)

    def step(self, height_m: np.ndarray, climb_rate_m_s: np.ndarray, command_m: np.ndarray, dt_s: float) -> np.ndarray:
        return self.pwm


def _ratio(height_m: float) -> float:
    return float(EQ_2_5.ratio(np.array(VEHICLE.height_ratio(height_m))))


def test_the_crazyflie_heave_axis_comes_from_the_preset() -> None:
    assert VEHICLE.mass_kg == CRAZYFLIE.mass_kg
    assert VEHICLE.thrust_per_count_n == pytest.approx(2.083e-6, rel=1e-12)  # Table 2.1
    assert VEHICLE.hover_pwm == pytest.approx(0.03812 * 9.81 / (4 * 2.083e-6), rel=1e-12)
    assert VEHICLE.height_ratio(VEHICLE.height_for_ratio(3.0)) == pytest.approx(3.0)
    # Tables 2.6-2.8 heights 6.2, 4.2, 2.2 cm sit at Z/R 4, 3, 2 within 0.15
    np.testing.assert_allclose(VEHICLE.height_ratio(np.array([0.062, 0.042, 0.022])), [4, 3, 2], atol=0.15)
    with pytest.raises(ValueError, match="thrust_expo"):
        from simulator.vehicle.presets import OCTO_S1000

        AltitudeVehicle.from_vehicle(OCTO_S1000, gear_height_m=0.1)


@pytest.mark.parametrize("height_m", [0.0, 0.02, 0.0645, 0.5])
def test_the_trim_holds_the_vehicle_still_in_and_out_of_ground_effect(height_m: float) -> None:
    run = simulate_altitude(Hold(), np.full(400, height_m), sensors=QUIET)
    assert np.ptp(run.height_m) < 1e-9
    assert run.pwm[0, 0] == pytest.approx(VEHICLE.hover_pwm / _ratio(height_m), rel=1e-12)


def test_a_thrust_step_out_of_ground_effect_follows_the_motor_lag_analytically() -> None:
    """z(t) = g d [s^2/2 - T s + T^2 (1 - exp(-s/T))] with s = t - delay, for PWM (1 + d) times hover."""
    delta, rate = 0.05, 200.0
    run = simulate_altitude(Hold(VEHICLE.hover_pwm * (1 + delta)), np.full(200, 0.5), sensors=QUIET, rate_hz=rate)
    s = np.maximum(run.time_s - VEHICLE.delay_s, 0.0)
    lag = VEHICLE.motor_time_constant_s
    expected = 0.5 + VEHICLE.gravity_m_s2 * delta * (s**2 / 2 - lag * s + lag**2 * (1 - np.exp(-s / lag)))
    rise = expected[-1] - 0.5
    # semi-implicit Euler at h = 1.25 ms: position error ~ h * v, v <= g d t
    tolerance = (1.0 / rate / 4) * VEHICLE.gravity_m_s2 * delta * run.time_s[-1]
    assert np.max(np.abs(run.height_m[:, 0] - expected)) < tolerance < 0.01 * rise


def test_ground_effect_is_a_spring_of_the_eq_2_5_slope() -> None:
    """At a fixed PWM the thrust falls as the vehicle climbs: m z'' = -k (z - z_eq), k = -m g slope / ratio(z_eq)."""
    z_eq = VEHICLE.height_for_ratio(3.0)
    k = -VEHICLE.mass_kg * VEHICLE.gravity_m_s2 * SLOPE_PER_M / _ratio(z_eq)
    omega = np.sqrt(k / VEHICLE.mass_kg)
    run = simulate_altitude(
        Hold(VEHICLE.hover_pwm / _ratio(z_eq)), np.full(4000, z_eq), sensors=QUIET, initial_height_m=z_eq + 0.005
    )
    offset = run.height_m[:, 0] - z_eq
    crossings = run.time_s[1:][np.diff(np.sign(offset)) != 0]
    period = 2 * np.mean(np.diff(crossings))
    assert period == pytest.approx(2 * np.pi / omega, rel=0.01)  # 20 half periods, 5 ms steps
    assert abs(np.mean(offset[: int(len(offset) // 2)])) < 0.05 * 0.005


def test_the_ground_carries_the_vehicle() -> None:
    run = simulate_altitude(Hold(0.0), np.full(400, 0.05), sensors=QUIET)  # clipped to idle: it falls
    assert run.height_m.min() == 0.0
    assert run.height_m[-1, 0] == 0.0 and run.climb_rate_m_s[-1, 0] == 0.0
    assert run.pwm[0, 0] == VEHICLE.idle_pwm


def test_trials_depend_only_on_their_seed() -> None:
    command = np.full(600, 0.03)
    alone = simulate_altitude(PidAltitude(), command, seeds=(7,), initial_height_m=0.0)
    batch = simulate_altitude(PidAltitude(), command, seeds=(3, 7), initial_height_m=0.0)
    np.testing.assert_array_equal(alone.height_m[:, 0], batch.height_m[:, 1])
    assert not np.array_equal(batch.height_m[:, 0], batch.height_m[:, 1])
    noise = batch.measured_height_m - batch.height_m
    assert np.std(noise) == pytest.approx(0.001, rel=0.1)  # MOCAP_NOISE height sigma, 1200 draws


def test_any_model_with_a_ratio_method_acts_on_the_thrust() -> None:
    class Doubling:
        def ratio(self, height_ratio: np.ndarray) -> np.ndarray:
            return np.full_like(np.asarray(height_ratio, dtype=float), 2.0)

    run = simulate_altitude(Hold(), np.full(10, 0.1), ground_effect=Doubling(), sensors=QUIET)
    assert run.pwm[0, 0] == pytest.approx(VEHICLE.hover_pwm / 2)
    np.testing.assert_array_equal(run.thrust_ratio, 2.0)


def _linear_pid_response(time_s: np.ndarray, high_m: float) -> np.ndarray:
    """Take-off from the ground with the PID: the loop linearised about mid-step (no delay), lsim."""
    v, g = VEHICLE, PidGains()
    middle = high_m / 2
    ratio, trim = _ratio(middle), v.hover_pwm / _ratio(middle)
    k_ground = v.thrust_per_pwm_n * trim * SLOPE_PER_M  # dF/dz, N/m
    lag = v.motor_time_constant_s
    # states: z, v, lagged PWM s, integrator I (deviations from mid-step trim); PWM = I + Kp (r - z) - Kd v
    a = np.array(
        [
            [0, 1, 0, 0],
            [k_ground / v.mass_kg, 0, v.thrust_per_pwm_n * ratio / v.mass_kg, 0],
            [-g.kp_pwm_per_m / lag, -g.kd_pwm_s_per_m / lag, -1 / lag, 1 / lag],
            [-g.ki_pwm_per_m_s, 0, 0, 0],
        ]
    )
    b = np.array([[0.0], [0.0], [g.kp_pwm_per_m / lag], [g.ki_pwm_per_m_s]])
    start = v.hover_pwm / _ratio(0.0) - trim
    _, z, _ = sps.lsim(
        sps.StateSpace(a, b, np.eye(4)[:1], np.zeros((1, 1))),
        np.full(time_s.size, high_m - middle),
        time_s,
        X0=np.array([-middle, 0.0, start, start]),
    )
    return z + middle


@pytest.mark.parametrize("height_ratio", [4.0, 2.0])
def test_the_pid_in_ground_effect_follows_its_linear_theory(height_ratio: float) -> None:
    """Table 2.5's PID with eq. 2.5: slow because the ground-effect spring outweighs Kp (integrator-limited)."""
    high = VEHICLE.height_for_ratio(height_ratio)
    command = np.full(8000, high)
    run = simulate_altitude(PidAltitude(), command, sensors=QUIET, initial_height_m=0.0)
    linear = _linear_pid_response(run.time_s, high)
    # neglected: the bilinear term (PWM - trim)(F/F0 - ratio) about mid-step, at most |slope| h/2 times the
    # largest PWM excursion, which the loop's static stiffness (Kp n k_f + k_ground) turns into a height error
    v, g = VEHICLE, PidGains()
    excursion = np.max(np.abs(run.pwm[:, 0] - v.hover_pwm / _ratio(high / 2)))
    force = abs(SLOPE_PER_M) * high / 2 * excursion * v.thrust_per_pwm_n
    stiffness = (g.kp_pwm_per_m - v.hover_pwm * SLOPE_PER_M) * v.thrust_per_pwm_n
    bound = force / stiffness + 1e-3 * high  # plus the 10 ms delay the linear model leaves out
    assert np.max(np.abs(run.height_m[:, 0] - linear)) < bound
    rise = step_metrics(run.time_s, run.height_m[:, 0], linear, before_m=0.0, after_m=high, smoothing_s=0.0)
    assert rise.rise_time_s > 15.0  # chapter 2: 22-31 s; out of ground effect the same PID rises in about 2 s
