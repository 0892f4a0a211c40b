"""Reference model (eq. 2.20), Lyapunov matrix (eq. A.8), regressors, the adaptive law (Appendix A), controllers."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
from scipy.integrate import solve_ivp

from simulator.flights.altitude import CRAZYFLIE_ALTITUDE
from simulator.mrac import (
    REFERENCE_EQ_2_20,
    MracAltitude,
    PidAltitude,
    PidGains,
    ReferenceModel,
    Regressor,
    adaptive_law,
    loop_analysis,
    lyapunov_function,
    lyapunov_matrix,
)

A0, A1, B0, B1 = 5.416, 7.027, -0.1145, 6.273  # eq. 2.20
Q = np.diag([100.0, 1.0])  # chapter 2


def test_reference_model_dc_gain_and_poles_are_those_of_eq_2_20() -> None:
    np.testing.assert_allclose(REFERENCE_EQ_2_20.dc_gain(), [(B1 + A1 * B0) / A0, -B0], rtol=1e-12)
    expected = np.sort(np.roots([1.0, A1, A0]).real)[::-1]  # s^2 + 7.027 s + 5.416
    np.testing.assert_allclose(REFERENCE_EQ_2_20.poles().real, expected, rtol=1e-12)
    assert np.all(REFERENCE_EQ_2_20.poles().imag == 0)  # overdamped: no overshoot beyond the DC gain


def test_reference_step_response_is_the_matrix_exponential_solution() -> None:
    """Unit step from rest: x(t) = A^-1 (e^{At} - I) b."""
    t = np.arange(0.0, 12.0, 0.005)
    states = REFERENCE_EQ_2_20.response(t, np.ones_like(t))
    a, b = REFERENCE_EQ_2_20.a, REFERENCE_EQ_2_20.b
    for k in (1, 100, 600, 2399):
        exact = np.linalg.solve(a, (scipy.linalg.expm(a * t[k]) - np.eye(2)) @ b)
        np.testing.assert_allclose(states[k], exact, rtol=1e-9, atol=1e-12)
    # the first row's height rate is the derivative of the height: central differences on a 1 ms grid,
    # truncation error dt^2/6 max|d3z/dt3| with max|d3z/dt3| <= |A|^2 (|A| |x| + |b|) < 2400 m/s^3
    fine = np.arange(0.0, 3.0, 0.001)
    states = REFERENCE_EQ_2_20.response(fine, np.ones_like(fine))
    rate = REFERENCE_EQ_2_20.height_rate(states, 1.0)
    np.testing.assert_allclose(np.gradient(states[:, 0], fine)[1:-1], rate[1:-1], atol=4e-4)
    assert REFERENCE_EQ_2_20.height_rate(REFERENCE_EQ_2_20.dc_gain(), 1.0) == pytest.approx(0.0, abs=1e-12)


def test_reference_model_rejects_unstable_or_misshaped_matrices() -> None:
    with pytest.raises(ValueError, match="Hurwitz"):
        ReferenceModel(np.array([[0.0, 1.0], [1.0, -1.0]]))
    with pytest.raises(ValueError, match=r"finite \(2, 2\)"):
        ReferenceModel(np.eye(3))


def test_lyapunov_matrix_solves_eq_a8_in_closed_form() -> None:
    p = lyapunov_matrix(REFERENCE_EQ_2_20.a, Q)
    a = REFERENCE_EQ_2_20.a
    np.testing.assert_allclose(a.T @ p + p @ a, -Q, atol=1e-10)
    p12 = 100.0 / (2 * A0)  # companion form: (1,1) entry of A^T P + P A = -2 a0 p12
    p22 = (1.0 + 2 * p12) / (2 * A1)
    np.testing.assert_allclose(p, [[A1 * p12 + A0 * p22, p12], [p12, p22]], rtol=1e-12)
    assert np.all(np.linalg.eigvalsh(p) > 0)


def test_regressors_are_eqs_2_21_and_2_24() -> None:
    z = np.array([0.0, 0.2, 0.062])
    np.testing.assert_array_equal(Regressor("linear")(z), np.column_stack([z, np.ones(3)]))
    phi = Regressor("rbf")(z)
    assert phi.shape == (3, 7)
    np.testing.assert_allclose(phi[1, :6], np.exp(-(6.67**2) * (0.2 - np.arange(6) * 0.2) ** 2), rtol=1e-12)
    assert phi[1, 1] == 1.0 and np.all(phi[:, 6] == 1.0)
    assert Regressor("rbf").labels[-1] == "1" and Regressor("linear").n_basis == 2


def _matched_plant(regressor: Regressor, theta: np.ndarray, gamma: float) -> tuple:
    """Double integrator x' = A x + B (u + Theta^T Phi) with the matching conditions of eq. A.6 for eq. 2.20.

    B = [0, b]; the reference input enters the rate row only ([0, 5.4684], the realisation of eq. 2.20's
    transfer function that B can match), so K_x = (A_ref - A)[1] / b and K_r = 5.4684 / b.
    """
    mass = CRAZYFLIE_ALTITUDE.mass_kg
    b_vec = np.array([0.0, 1.0 / mass])
    a_ref = REFERENCE_EQ_2_20.a
    b_ref = np.array([0.0, B1 + A1 * B0])
    k_x = a_ref[1] * mass
    k_r = b_ref[1] * mass
    p = lyapunov_matrix(a_ref, Q)
    p_b = p @ b_vec
    n = regressor.n_basis

    def rhs(_t: float, y: np.ndarray, r: float) -> np.ndarray:
        x, x_ref, theta_hat = y[:2], y[2:4], y[4:]
        phi = regressor(np.array([x[0]]))[0]
        u = k_x @ x + k_r * r - theta_hat @ phi
        dx = np.array([x[1], 0.0]) + b_vec * (u + theta @ phi)
        dx_ref = a_ref @ x_ref + b_ref * r
        d_theta = adaptive_law(phi[None, :], (x - x_ref)[None, :], p_b, gamma)[0]
        return np.concatenate([dx, dx_ref, d_theta])

    def simulate(command: list[tuple[float, float]]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        y0, times, states, commands = np.zeros(4 + n), [], [], []
        start = 0.0
        for end, r in command:  # piecewise-constant command: integrate each segment separately
            t_eval = np.linspace(start, end, int(round((end - start) * 20)) + 1)
            sol = solve_ivp(rhs, (start, end), y0, args=(r,), t_eval=t_eval, rtol=1e-10, atol=1e-12, method="DOP853")
            times.append(sol.t)
            states.append(sol.y.T)
            commands.append(np.full(sol.t.size, r))
            y0, start = sol.y[:, -1], end
        return np.concatenate(times), np.concatenate(states), np.concatenate(commands)

    return simulate, rhs, p, p_b


@pytest.mark.parametrize(
    ("kind", "theta"),
    [
        ("linear", np.array([-0.6, 0.04])),  # a ground-effect-like spring (N/m) and offset (N)
        ("rbf", np.array([0.03, -0.01, 0.0, 0.0, 0.0, 0.0, 0.01])),
    ],
)
def test_the_adaptive_law_has_the_lyapunov_property_on_a_known_linear_plant(kind: str, theta: np.ndarray) -> None:
    """Appendix A: V = e'Pe + tr(dTheta' Gamma^-1 dTheta) has V' = -e'Qe <= 0, so Theta_hat stays bounded and e -> 0."""
    gamma = 1e-3
    regressor = Regressor(kind)  # type: ignore[arg-type]
    simulate, rhs, p, _ = _matched_plant(regressor, theta, gamma)
    command = [(20.0, 0.06), (40.0, 0.0), (60.0, 0.04), (120.0, 0.02)]
    t, y, r = simulate(command)
    error, delta = y[:, :2] - y[:, 2:4], y[:, 4:] - theta
    v = lyapunov_function(error, delta, p, gamma)
    # V' along the trajectory: analytic, from the right-hand side, equals -e'Qe (eq. A.14)
    v_dot = np.array(
        [
            2 * e @ p @ (d[:2] - d[2:4]) + 2 * dt @ d[4:] / gamma
            for e, dt, d in ((error[k], delta[k], rhs(t[k], y[k], r[k])) for k in range(t.size))
        ]
    )
    np.testing.assert_allclose(v_dot, -np.einsum("ni,ij,nj->n", error, Q, error), rtol=1e-8, atol=1e-12)
    assert np.all(v_dot <= 1e-12)
    assert np.all(np.diff(v) <= 1e-9 * v[0])  # non-increasing up to the integration tolerance
    # bounded: tr(dTheta' Gamma^-1 dTheta) <= V(0), so |dTheta|^2 <= gamma V(0)
    assert np.max(np.sum(delta**2, axis=1)) <= gamma * v[0] * (1 + 1e-9)
    # e -> 0 (Barbalat): over the last 40 s of a held command the error is under 1 % of its peak
    late = t > 80.0
    assert np.max(np.linalg.norm(error[late], axis=1)) < 0.01 * np.max(np.linalg.norm(error, axis=1))


def test_the_adaptive_law_is_gamma_phi_e_pb() -> None:
    phi = np.array([[0.1, 1.0], [0.2, 1.0]])
    error = np.array([[0.01, -0.02], [0.0, 0.1]])
    p_b = np.array([3.0, 0.5])
    gamma = np.diag([2.0, 1e-3])
    expected = np.stack([gamma @ phi[k] * (error[k] @ p_b) for k in range(2)])
    np.testing.assert_allclose(adaptive_law(phi, error, p_b, gamma), expected, rtol=1e-15)
    np.testing.assert_allclose(adaptive_law(phi, error, p_b, 1e-3), 1e-3 * phi * (error @ p_b)[:, None], rtol=1e-15)


def test_pid_is_eq_2_14_in_pwm_with_anti_windup() -> None:
    g = PidGains()
    assert (g.kp_pwm_per_m, g.ki_pwm_per_m_s, g.kd_pwm_s_per_m) == (42692.2, 8219.7, 55434.8)  # Table 2.5
    pid = PidAltitude()
    pid.reset(np.zeros(2), np.array([40000.0, 40000.0]))
    out = pid.step(np.array([0.01, 0.0]), np.array([0.0, 0.1]), 0.03, 0.005)
    np.testing.assert_allclose(
        out, [40000 + g.kp_pwm_per_m * 0.02, 40000 + g.kp_pwm_per_m * 0.03 - g.kd_pwm_s_per_m * 0.1]
    )
    np.testing.assert_allclose(pid.integral_pwm, 40000 + g.ki_pwm_per_m_s * np.array([0.02, 0.03]) * 0.005)
    pid.reset(np.zeros(1), np.array([65000.0]))
    assert pid.step(np.zeros(1), np.zeros(1), 1.0, 0.005)[0] == CRAZYFLIE_ALTITUDE.pwm_max
    assert pid.integral_pwm[0] == 65000.0  # saturated in the direction of the error: no integration


def test_mrac_step_adds_minus_theta_phi_and_integrates_eq_2_19() -> None:
    """e = x - x_ref of eq. A.4 with x_ref = [z_ref, v_z,ref], the two states of eq. 2.20 (not z_ref')."""
    mrac = MracAltitude("linear")
    mrac.reset(np.array([0.0]), np.array([40000.0]))
    dt = 0.005
    p_b = mrac.p @ np.array([0.0, 1.0 / CRAZYFLIE_ALTITUDE.mass_kg])
    first = mrac.step(np.array([0.0]), np.array([0.0]), 0.05, dt)
    # the vehicle and the reference both at rest at the engage height: e = 0, nothing to adapt yet
    np.testing.assert_array_equal(mrac.theta[0], 0.0)
    assert first[0] == pytest.approx(40000 + 42692.2 * 0.05, rel=1e-12)
    height, rate = np.array([0.01]), np.array([0.02])
    pwm = mrac.step(height, rate, 0.05, dt)
    history = mrac.history()
    x_ref = REFERENCE_EQ_2_20.response(np.array([0.0, dt]), np.array([0.05, 0.05]))[1]
    assert x_ref[1] > 0.0 and REFERENCE_EQ_2_20.height_rate(x_ref, 0.05) < 0.0  # v_z,ref differs from z_ref'
    expected = dt * 1e-3 * np.array([height[0], 1.0]) * (np.array([height[0] - x_ref[0], rate[0] - x_ref[1]]) @ p_b)
    np.testing.assert_allclose(mrac.theta[0], expected, rtol=1e-12)
    np.testing.assert_allclose(history.reference_height_m[:, 0], [0.0, x_ref[0]], rtol=1e-12)
    assert history.theta.shape == (2, 1, 2) and history.labels == ("z", "1")
    assert pwm[0] == pytest.approx(40000 + 8219.7 * 0.05 * dt + 42692.2 * 0.04 - 55434.8 * 0.02, rel=1e-12)
    third = mrac.step(height, rate, 0.05, dt)
    adaptive_pwm = -(expected @ np.array([height[0], 1.0])) / CRAZYFLIE_ALTITUDE.thrust_per_pwm_n
    assert third[0] == pytest.approx(
        40000 + 8219.7 * (0.05 + 0.04) * dt + 42692.2 * 0.04 - 55434.8 * 0.02 + adaptive_pwm, rel=1e-12
    )


def test_eq_2_20_is_table_2_5s_pd_loop_with_a_lower_pwm_gain() -> None:
    """Eq. 2.20's denominator s^2 + 7.027 s + 5.416 is s^2 + g Kd s + g Kp: Table 2.5's PD on a double integrator
    with PWM-to-acceleration gain g (5.416 / Kp and 7.027 / Kd agree within 0.1 %), and A + B K_x = A_ref
    (eq. A.6) holds with K_x = -[Kp, Kd] for B = [0, g]. That g, 1.27e-4 m/s^2 per count, is 58 % of n k_f / m
    of the simulated Crazyflie, so the flown PID loop was slower than the simulated one. The simulator cannot
    take it under eq. 2.6: thrust linear through zero with that slope hovers only at 9.81 / g = 77,300 counts,
    above the 16-bit PWM range."""
    v = CRAZYFLIE_ALTITUDE
    gains = PidGains()
    g_p, g_d = A0 / gains.kp_pwm_per_m, A1 / gains.kd_pwm_s_per_m
    assert g_p == pytest.approx(g_d, rel=1e-3)
    b = np.array([0.0, g_p])
    k_x = -np.array([gains.kp_pwm_per_m, gains.kd_pwm_s_per_m])
    np.testing.assert_allclose(np.array([[0.0, 1.0], [0.0, 0.0]]) + np.outer(b, k_x), REFERENCE_EQ_2_20.a, rtol=2e-3)
    assert g_p / (v.thrust_per_pwm_n / v.mass_kg) == pytest.approx(0.580, abs=0.002)
    assert v.gravity_m_s2 / g_p > v.pwm_max > v.hover_pwm


def test_ground_effect_outweighs_the_proportional_gain_near_the_ground() -> None:
    """Why the PID is slow in ground effect: k_ge = m g 0.0373 / (R F/F0) exceeds Kp n k_f."""
    v = CRAZYFLIE_ALTITUDE
    inside = loop_analysis(v.height_for_ratio(3.0))
    ratio = -0.0373 * 3.0 + 1.1651
    expected = v.mass_kg * v.gravity_m_s2 * 0.0373 / (v.rotor_radius_m * ratio)
    assert inside.ground_stiffness_n_m == pytest.approx(expected, rel=1e-6)
    assert inside.proportional_stiffness_n_m == pytest.approx(42692.2 * 4 * 2.083e-6, rel=1e-9)
    assert inside.proportional_share < 0.5 < loop_analysis(v.height_for_ratio(22.0)).proportional_share == 1.0
    assert inside.integrator_time_constant_s > 10.0  # (k_p + k_ge) / k_i
    assert inside.adaptive_integral_gain_n_m_s == pytest.approx(1e-3 * (100 / (2 * A0)) / v.mass_kg, rel=1e-9)
