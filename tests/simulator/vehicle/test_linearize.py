"""Linearising the nonlinear octocopter at hover reproduces the calm Table 3.3 model (eqs. 3.10-3.13)."""

from __future__ import annotations

import numpy as np
import pytest

from simulator.vehicle.dynamics import Conditions
from simulator.vehicle.identified import CALM_HOVER
from simulator.vehicle.linearize import (
    EQ33_STATES,
    compare_eigenvalues,
    hover_derivatives,
    linearize_hover,
    reference_model,
    trim_hover,
)
from simulator.vehicle.presets import CRAZYFLIE, OCTO_S1000, QUAD_X500, QUAD_X500_HOVER, octocopter
from simulator.world.environment import GroundEffect


@pytest.fixture(scope="module")
def linearised():
    return linearize_hover(OCTO_S1000)


def test_reference_eigenvalues_in_si_units() -> None:
    """tables.md: with g = 9.81 the calm longitudinal model gives 0.878 +- 1.694i and -2.073."""
    eig = reference_model().eigenvalues
    lon = eig[np.argsort(-eig.real)]
    assert np.any(np.isclose(eig, 0.878 + 1.694j, atol=1e-3))
    assert np.any(np.isclose(eig, 0.878 - 1.694j, atol=1e-3))
    assert np.any(np.isclose(eig, -2.073, atol=1e-3))
    assert lon[0].real == pytest.approx(0.878, abs=1e-3)
    # Table 3.7's 1.3532 +- 2.5202i and -3.0235 follow from g = 32.174 (ft/s^2)
    imperial = reference_model(gravity_m_s2=32.174).eigenvalues
    assert np.any(np.isclose(imperial, 1.3532 + 2.5202j, atol=2e-3))
    assert np.any(np.isclose(imperial, -3.0235, atol=2e-3))


def test_linearised_eigenvalues_within_5_percent_of_the_reference(linearised) -> None:
    """Done-when: each reference eigenvalue paired with one of the nonlinear model's, within 5 %."""
    comparison = compare_eigenvalues(reference_model(), linearised)
    nonzero = np.abs(comparison.reference) > 1e-9
    assert np.all(comparison.error[nonzero] < 0.05), comparison
    # the zero eigenvalues (heave velocity, yaw rate, heading) stay zero: no Z_w, no N_r in calm air
    assert np.all(np.abs(comparison.paired[~nonzero]) < 1e-6)
    assert linearised.dropped_coupling < 1e-6  # the yaw actuator and the mixer's null space act on nothing kept


def test_linearised_derivatives_equal_table_3_3(linearised) -> None:
    derived = hover_derivatives(linearised)
    for name in (
        "X_u",
        "M_u",
        "X_lon",
        "M_lon",
        "Y_v",
        "L_v",
        "Y_lat",
        "L_lat",
        "N_yaw",
        "Z_thr",
        "T_a",
        "tau_lat",
        "tau_lon",
        "tau_yaw",
    ):
        assert derived[name] == pytest.approx(CALM_HOVER[name], rel=1e-6, abs=1e-12), name
    assert abs(derived["Z_w"]) < 1e-9 and abs(derived["N_r"]) < 1e-9
    assert linearised.states == EQ33_STATES
    np.testing.assert_allclose(linearised.a, reference_model().a, atol=1e-6)
    np.testing.assert_allclose(linearised.b, reference_model().b, atol=1e-6)


def test_other_derivatives_give_a_vehicle_with_those_derivatives() -> None:
    light = dict(CALM_HOVER) | {
        "X_u": -0.2423,
        "M_u": 0.7099,
        "X_lon": -0.0976,
        "M_lon": 0.5413,
        "Y_v": -0.3905,
        "L_v": -0.7984,
        "Y_lat": 0.1193,
        "L_lat": 0.6472,
        "N_yaw": 0.0719,
        "Z_thr": -0.8777,
    }
    derived = hover_derivatives(linearize_hover(octocopter(light)))
    for name in ("X_u", "M_u", "L_v", "N_yaw", "Z_thr"):
        assert derived[name] == pytest.approx(light[name], rel=1e-6)


def test_strong_wind_trim_pitches_into_the_wind() -> None:
    """Table 3.2: nose-down trim into the wind (-4.36 deg at 4.12 m/s in the dissertation)."""
    trim = trim_hover(OCTO_S1000, wind_ned=(-5.4, 0.0, 0.0), heading_rad=0.0)  # from the north, nose north
    phi, theta, psi = trim.euler
    assert -10.0 < np.degrees(theta) < -2.0
    assert abs(phi) < 1e-6 and abs(psi) < 1e-9
    assert trim.mixer_input[1] < 0  # pitch-down input against the speed stability M_u


def test_ground_effect_lowers_the_hover_command_by_the_thrust_ratio() -> None:
    conditions = Conditions(
        cg_offset_m=np.zeros((1, 3)),
        rotor_drag=np.ones(1),
        thrust_sag=np.zeros(1),
        ground_effect=GroundEffect(model="fitted_4rotor").ratio,
    )
    height = 2.0 * CRAZYFLIE.rotor_radius_m  # Z/R = 2 (rotors at the CG's height)
    trim = trim_hover(CRAZYFLIE, conditions=conditions, height_m=height)
    commands = CRAZYFLIE.trim_command + CRAZYFLIE.mixer @ trim.mixer_input
    f0 = np.sum(2.083e-6 * 65535 * commands)  # eq. 2.6
    assert CRAZYFLIE.mass_kg * 9.81 / f0 == pytest.approx(-0.0373 * 2 + 1.1651, rel=1e-9)


def test_a_cg_offset_is_trimmed_by_the_pitch_input_it_needs() -> None:
    """With the CG 1 cm forward the rotors must pitch the nose up by m g dx: delta_lon = m g dx / (M_lon Iyy)."""
    dx = 0.01
    conditions = Conditions(cg_offset_m=np.array([[dx, 0.0, 0.0]]), rotor_drag=np.ones(1), thrust_sag=np.zeros(1))
    trim = trim_hover(OCTO_S1000, conditions=conditions)
    expected = OCTO_S1000.mass_kg * 9.81 * dx / (CALM_HOVER["M_lon"] * OCTO_S1000.inertia_kg_m2[1])
    assert trim.mixer_input[1] == pytest.approx(expected, rel=0.01)
    assert trim.total_thrust_n == pytest.approx(OCTO_S1000.mass_kg * 9.81, rel=1e-3)


def test_the_quad_linearises_to_its_own_derivatives() -> None:
    """The second vehicle is built the same way: its hover eigenvalues are those of its derivatives' model."""
    comparison = compare_eigenvalues(reference_model(QUAD_X500_HOVER), linearize_hover(QUAD_X500))
    nonzero = np.abs(comparison.reference) > 1e-9
    assert np.all(comparison.error[nonzero] < 0.05), comparison


def test_a_cg_offset_trims_the_quad_with_the_moment_it_needs() -> None:
    """dx = 9.5 mm on the quad: the solver's own convergence flag once refused this converged trim."""
    dx = 0.0095
    conditions = Conditions(cg_offset_m=np.array([[dx, 0.0, 0.0]]), rotor_drag=np.ones(1), thrust_sag=np.zeros(1))
    trim = trim_hover(QUAD_X500, conditions=conditions, height_m=3.0)
    expected = QUAD_X500.mass_kg * 9.81 * dx / (QUAD_X500_HOVER["M_lon"] * QUAD_X500.inertia_kg_m2[1])
    assert trim.mixer_input[1] == pytest.approx(expected, rel=0.02)
