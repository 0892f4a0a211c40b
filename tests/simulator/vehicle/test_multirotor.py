"""The rigid body, rotors, mixer and battery: analytic checks (hover, free fall, yaw torque, batching)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from flightlogs.frames import quaternion_to_euler
from simulator.vehicle.dynamics import Conditions, vehicle_derivative
from simulator.vehicle.linearize import trim_hover
from simulator.vehicle.multirotor import Battery, Vehicle, mixer_commands, n_states, quaternion_from_euler, state_names
from simulator.vehicle.presets import CRAZYFLIE, OCTO_S1000, rotor_ring

G = 9.81


def _hover_state(vehicle: Vehicle, rotors: np.ndarray | None = None) -> np.ndarray:
    state = np.zeros((1, n_states(vehicle)))
    state[0, 2] = -10.0
    state[0, 6] = 1.0
    state[0, 13 : 13 + vehicle.n_rotors] = vehicle.trim_command if rotors is None else rotors
    return state


def _derivative(vehicle: Vehicle, state: np.ndarray, command: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    n = state.shape[0]
    return vehicle_derivative(
        vehicle, state, command, np.zeros((n, 3)), np.full(n, vehicle.mass_kg), Conditions.nominal(n)
    )


@pytest.mark.parametrize("vehicle", [OCTO_S1000, CRAZYFLIE], ids=lambda v: v.name)
def test_hover_trim_thrust_equals_weight(vehicle: Vehicle) -> None:
    trim = trim_hover(vehicle)
    assert trim.total_thrust_n == pytest.approx(vehicle.mass_kg * G, rel=1e-12)
    np.testing.assert_allclose(trim.mixer_input, 0.0, atol=1e-9)  # the mixer's trim is the hover
    np.testing.assert_allclose(trim.euler, 0.0, atol=1e-9)


@pytest.mark.parametrize("vehicle", [OCTO_S1000, CRAZYFLIE], ids=lambda v: v.name)
def test_at_hover_the_accelerometer_reads_minus_g_and_nothing_accelerates(vehicle: Vehicle) -> None:
    state = _hover_state(vehicle)
    dot, specific = _derivative(vehicle, state, np.full((1, vehicle.n_rotors), vehicle.trim_command))
    np.testing.assert_allclose(specific[0], [0.0, 0.0, -G], atol=1e-12)
    np.testing.assert_allclose(dot[0, 3:6], 0.0, atol=1e-12)
    np.testing.assert_allclose(dot[0, 10:13], 0.0, atol=1e-9)


def test_free_fall_reads_zero_specific_force() -> None:
    vehicle = OCTO_S1000
    state = _hover_state(vehicle, rotors=np.zeros(vehicle.n_rotors))
    state[0, 3:6] = [1.0, -2.0, 3.0]  # moving, but in still air with the rotors stopped: no drag either
    dot, specific = _derivative(vehicle, state, np.zeros((1, vehicle.n_rotors)))
    np.testing.assert_allclose(specific[0], 0.0, atol=1e-15)
    np.testing.assert_allclose(dot[0, 3:6], [0.0, 0.0, G], atol=1e-15)


def test_pure_yaw_torque_gives_the_expected_yaw_acceleration() -> None:
    vehicle = OCTO_S1000
    izz = vehicle.inertia_kg_m2[2]
    delta = np.array([[0.0, 0.0, 1.0, 0.0]])  # 1 % yaw
    command = mixer_commands(vehicle, delta)
    slope = 2 * vehicle.max_thrust_n * vehicle.trim_command  # dT/ds of a quadratic thrust curve at hover
    # at the step, only the torque that spins the rotors up acts: J * omega_max * ds/dt per rotor
    dot, specific = _derivative(vehicle, _hover_state(vehicle), command)
    spin_up = vehicle.rotor_inertia_kg_m2 * vehicle.max_speed_rad_s / vehicle.motor_time_constant_s
    expected_now = spin_up * np.sum(vehicle.rotor_spins * (command[0] - vehicle.trim_command)) / izz
    assert dot[0, 12] == pytest.approx(expected_now, rel=1e-9)
    # once the rotors have settled, the drag torques k_m/k_f * dT act instead
    dot_late, specific_late = _derivative(vehicle, _hover_state(vehicle, command[0]), command)
    step = command[0] - vehicle.trim_command
    delta_thrust = slope * step + vehicle.max_thrust_n * step**2
    expected_late = vehicle.torque_ratio_m * np.sum(vehicle.rotor_spins * delta_thrust) / izz
    assert dot_late[0, 12] == pytest.approx(expected_late, rel=1e-9)
    # both equal N_yaw (Table 3.3) to first order: yaw has no actuator lag, as eq. 3.12 says
    assert expected_now == pytest.approx(0.0744, rel=1e-9)
    assert expected_late == pytest.approx(0.0744, rel=1e-3)
    # and a yaw input is pure torque: no force, no roll or pitch
    np.testing.assert_allclose(dot_late[0, 10:12], 0.0, atol=1e-12)
    np.testing.assert_allclose(specific_late[0, :2], 0.0, atol=1e-12)


def test_crazyflie_matches_table_2_1_and_eq_2_9() -> None:
    cf = CRAZYFLIE
    assert cf.max_thrust_n / 65535 == pytest.approx(2.083e-6)
    assert cf.torque_ratio_m == pytest.approx(3.700e-3, rel=1e-3)
    assert cf.trim_command * 65535 == pytest.approx(cf.mass_kg * G / 4 / 2.083e-6)
    # eq. 2.9: roll acceleration of one rotor's PWM is -L k_f / Ixx for rotors 1 and 2 (right side)
    command = np.full((1, 4), cf.trim_command)
    command[0, 0] += 1000 / 65535
    state = _hover_state(cf, command[0])
    dot, _ = _derivative(cf, state, command)
    assert dot[0, 10] == pytest.approx(-0.035 * 2.083e-6 * 1000 / 2.661e-5, rel=1e-9)
    assert dot[0, 11] == pytest.approx(0.035 * 2.083e-6 * 1000 / 2.858e-5, rel=1e-9)


def test_a_batch_gives_each_trial_the_same_numbers_as_alone() -> None:
    rng = np.random.default_rng(4)
    vehicle = OCTO_S1000
    n = 7
    states = np.repeat(_hover_state(vehicle), n, axis=0)
    states[:, 3:6] += rng.normal(size=(n, 3))
    states[:, 6:10] += 0.1 * rng.normal(size=(n, 4))
    states[:, 6:10] /= np.linalg.norm(states[:, 6:10], axis=1, keepdims=True)
    states[:, 10:13] = rng.normal(size=(n, 3))
    commands = rng.uniform(0.3, 0.8, size=(n, vehicle.n_rotors))
    wind = rng.normal(size=(n, 3))
    conditions = Conditions(
        cg_offset_m=rng.normal(scale=0.01, size=(n, 3)), rotor_drag=np.ones(n), thrust_sag=np.ones(n)
    )
    batch, _ = vehicle_derivative(vehicle, states, commands, wind, np.full(n, 7.0), conditions)
    for i in range(n):
        single = Conditions(cg_offset_m=conditions.cg_offset_m[i : i + 1], rotor_drag=np.ones(1), thrust_sag=np.ones(1))
        alone, _ = vehicle_derivative(
            vehicle, states[i : i + 1], commands[i : i + 1], wind[i : i + 1], np.full(1, 7.0), single
        )
        assert np.array_equal(alone[0], batch[i])


def test_battery_sags_with_charge_and_current() -> None:
    battery = Battery(full_v=25.2, empty_v=21.0, capacity_ah=16.0, resistance_ohm=0.02, time_constant_s=0.5)
    assert float(battery.open_circuit_v(0.0)) == 25.2
    assert float(battery.open_circuit_v(16.0 * 3600)) == pytest.approx(21.0)
    vehicle = OCTO_S1000
    dot, _ = _derivative(vehicle, _hover_state(vehicle), np.full((1, 8), vehicle.trim_command))
    current = dot[0, -2]
    assert 20 < current < 60  # about 0.8 kW at 24.5 V
    assert dot[0, -1] == pytest.approx(battery.resistance_ohm * current / battery.time_constant_s)


def test_thrust_drops_with_voltage_only_when_switched_on() -> None:
    vehicle = OCTO_S1000
    state = _hover_state(vehicle)
    state[0, -1] = 2.0  # 2 V of sag
    command = np.full((1, 8), vehicle.trim_command)
    on = Conditions(cg_offset_m=np.zeros((1, 3)), rotor_drag=np.ones(1), thrust_sag=np.ones(1))
    off = Conditions(cg_offset_m=np.zeros((1, 3)), rotor_drag=np.ones(1), thrust_sag=np.zeros(1))
    dot_on, _ = vehicle_derivative(vehicle, state, command, np.zeros((1, 3)), np.full(1, 7.0), on)
    dot_off, _ = vehicle_derivative(vehicle, state, command, np.zeros((1, 3)), np.full(1, 7.0), off)
    assert dot_off[0, 5] == pytest.approx(0.0, abs=1e-12)
    volts = 25.2 - 2.0
    expected = G * (1 - (volts / vehicle.nominal_voltage_v) ** 2)  # thrust ~ speed^2 ~ voltage^2
    assert dot_on[0, 5] == pytest.approx(expected, rel=1e-9)


@settings(max_examples=50, deadline=None)
@given(st.floats(-3.0, 3.0), st.floats(-1.5, 1.5), st.floats(-3.1, 3.1))
def test_quaternion_from_euler_inverts_the_readers_conversion(phi: float, theta: float, psi: float) -> None:
    quat = quaternion_from_euler(np.array([phi]), np.array([theta]), np.array([psi]))
    np.testing.assert_allclose(quaternion_to_euler(quat)[0], [phi, theta, psi], atol=1e-9)


def test_state_layout_and_validation() -> None:
    assert state_names(8)[13] == "s_1" and len(state_names(8)) == n_states(OCTO_S1000)
    positions, spins = rotor_ring(8, 0.5)
    with pytest.raises(ValueError, match="rotor_spins"):
        Vehicle(
            name="bad",
            mass_kg=1.0,
            inertia_kg_m2=np.ones(3),
            rotor_positions_m=positions,
            rotor_spins=spins * 2,
            rotor_radius_m=0.1,
            max_thrust_n=10.0,
            thrust_expo=1.0,
            torque_ratio_m=0.01,
            max_speed_rad_s=500.0,
            rotor_inertia_kg_m2=1e-5,
            motor_time_constant_s=0.05,
            delays_s=np.zeros(4),
            mixer=np.zeros((8, 4)),
            trim_command=0.5,
        )
    with pytest.raises(ValueError, match="mixer"):
        Vehicle(
            name="bad",
            mass_kg=1.0,
            inertia_kg_m2=np.ones(3),
            rotor_positions_m=positions,
            rotor_spins=spins,
            rotor_radius_m=0.1,
            max_thrust_n=10.0,
            thrust_expo=1.0,
            torque_ratio_m=0.01,
            max_speed_rad_s=500.0,
            rotor_inertia_kg_m2=1e-5,
            motor_time_constant_s=0.05,
            delays_s=np.zeros(4),
            mixer=np.zeros((4, 4)),
            trim_command=0.5,
        )
