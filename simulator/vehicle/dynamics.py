"""Equations of motion of a batch of vehicles (see :mod:`simulator.vehicle.multirotor` for the state layout)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from simulator.vehicle.multirotor import FIRST_ROTOR_STATE as _BASE
from simulator.vehicle.multirotor import Vehicle

_Columns = tuple[np.ndarray, ...]  # per-trial columns, each (n,)

__all__ = ["Conditions", "vehicle_derivative"]


@dataclass(frozen=True, slots=True, kw_only=True)
class Conditions:
    """Per-trial physics switches and offsets for :func:`vehicle_derivative`.

    Parameters
    ----------
    cg_offset_m : ndarray, shape (n_trials, 3)
        Centre of gravity from its design position, FRD body axes, m.
    rotor_drag : ndarray, shape (n_trials,)
        1 to apply rotor drag and flapping, 0 to switch them off.
    thrust_sag : ndarray, shape (n_trials,)
        1 if thrust follows the battery voltage, 0 if it does not.
    ground_effect : callable or None
        Maps Z/R of each rotor, shape (n_trials, n_rotors), to F/F0; None: no ground effect.
    gravity_m_s2 : float
        Gravity, m/s^2.
    """

    cg_offset_m: np.ndarray
    rotor_drag: np.ndarray
    thrust_sag: np.ndarray
    ground_effect: Callable[[np.ndarray], np.ndarray] | None = None
    gravity_m_s2: float = 9.81

    def __post_init__(self) -> None:
        n = np.shape(self.rotor_drag)[0] if np.ndim(self.rotor_drag) == 1 else -1
        if n < 1 or np.shape(self.thrust_sag) != (n,) or np.shape(self.cg_offset_m) != (n, 3):
            raise ValueError("rotor_drag, thrust_sag (n_trials,) and cg_offset_m (n_trials, 3) must agree")

    @classmethod
    def nominal(cls, n_trials: int, *, gravity_m_s2: float = 9.81) -> Conditions:
        """Rotor drag on, thrust sag off, no CG offset, no ground effect.

        Parameters
        ----------
        n_trials : int
            Batch size.
        gravity_m_s2 : float, optional
            Gravity, m/s^2.

        Returns
        -------
        Conditions
        """
        return cls(
            cg_offset_m=np.zeros((n_trials, 3)),
            rotor_drag=np.ones(n_trials),
            thrust_sag=np.zeros(n_trials),
            ground_effect=None,
            gravity_m_s2=gravity_m_s2,
        )


def _rotation(quaternion: np.ndarray) -> tuple[np.ndarray, ...]:
    """The nine entries r_ij of the body-to-NED matrix, each shape (n,)."""
    w, x, y, z = quaternion[:, 0], quaternion[:, 1], quaternion[:, 2], quaternion[:, 3]
    x2, y2, z2 = x + x, y + y, z + z
    xx, yy, zz, xy, xz, yz = x * x2, y * y2, z * z2, x * y2, x * z2, y * z2
    wx, wy, wz = w * x2, w * y2, w * z2
    return (
        1.0 - (yy + zz),
        xy - wz,
        xz + wy,
        xy + wz,
        1.0 - (xx + zz),
        yz - wx,
        xz - wy,
        yz + wx,
        1.0 - (xx + yy),
    )


def _rotor_thrusts(
    vehicle: Vehicle, state: np.ndarray, rot: _Columns, conditions: Conditions
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rotor thrusts (n, n_rotors), N, the voltage scale (n,) and the terminal voltage (n,)."""
    n_r = vehicle.n_rotors
    volts = vehicle.battery.open_circuit_v(state[:, _BASE + n_r]) - state[:, _BASE + n_r + 1]
    scale = 1.0 + conditions.thrust_sag * (volts / vehicle.nominal_voltage_v - 1.0)
    thrust = vehicle.thrust_curve(state[:, _BASE : _BASE + n_r] * scale[:, None])
    if conditions.ground_effect is not None:
        rel = vehicle.rotor_positions_m[None, :, :] - conditions.cg_offset_m[:, None, :]
        height = -(
            state[:, 2:3]
            + rot[6][:, None] * rel[..., 0]
            + rot[7][:, None] * rel[..., 1]
            + rot[8][:, None] * rel[..., 2]
        )
        thrust = thrust * conditions.ground_effect(height / vehicle.rotor_radius_m)
    return thrust, scale, volts


def _loads(vehicle: Vehicle, sums: np.ndarray, air_body: _Columns, conditions: Conditions) -> tuple[_Columns, _Columns]:
    """Body force (3 arrays, N) and moment about the CG (3 arrays, N m) of thrust, drag, flapping and coupling.

    `sums` holds, per trial, the sums over rotors of T, T x, T y, T z and T spin
    (geometric positions); moments about the CG follow by subtracting the CG offset times the total.
    """
    total, t_x, t_y, t_z = sums[:, 0], sums[:, 1], sums[:, 2], sums[:, 3]
    cg = conditions.cg_offset_m
    mx = cg[:, 1] * total - t_y
    my = t_x - cg[:, 0] * total
    z_thrust = t_z - cg[:, 2] * total
    # rotor drag per unit thrust, applied at each hub
    drag_x = (-vehicle.drag_s_m[0] * air_body[0]) * conditions.rotor_drag
    drag_y = (-vehicle.drag_s_m[1] * air_body[1]) * conditions.rotor_drag
    flap = conditions.rotor_drag * total
    mz = drag_y * my + drag_x * mx
    mx = mx - drag_y * z_thrust - vehicle.flapping_s[1] * flap * air_body[1]
    my = my + drag_x * z_thrust + vehicle.flapping_s[0] * flap * air_body[0]
    fx = drag_x * total - vehicle.coupling_1_m[0] * t_x
    fy = drag_y * total - vehicle.coupling_1_m[1] * t_y
    return (fx, fy, -total), (mx, my, mz)


def vehicle_derivative(
    vehicle: Vehicle,
    state: np.ndarray,
    command: np.ndarray,
    wind_ned: np.ndarray,
    mass_kg: np.ndarray,
    conditions: Conditions,
) -> tuple[np.ndarray, np.ndarray]:
    """Time derivative of a batch of states, and the specific force the accelerometer feels.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle.
    state : ndarray, shape (n_trials, n_states)
        States (layout in :func:`state_names`).
    command : ndarray, shape (n_trials, n_rotors)
        Rotor commands after the mixer, fraction of full scale.
    wind_ned : ndarray, shape (n_trials, 3)
        Velocity of the air at the vehicle, NED, m/s.
    mass_kg : ndarray, shape (n_trials,)
        Current mass, kg.
    conditions : Conditions
        Per-trial switches (rotor drag, thrust sag, ground effect, CG offset).

    Returns
    -------
    state_dot : ndarray, shape (n_trials, n_states)
    specific_force : ndarray, shape (n_trials, 3)
        Non-gravitational force per mass in body axes, m/s^2 (``az = -g`` in hover).

    Notes
    -----
    Newton-Euler equations (2.7)-(2.8) with a diagonal inertia, rotor
    angular momentum (gyroscopic) terms, quaternion kinematics and the first
    order rotor lag of eq. 3.2. Operations are element-wise per trial, so a
    trial gives the same numbers alone or in a batch.
    """
    n_r = vehicle.n_rotors
    rot = _rotation(state[:, 6:10])
    air_n, air_e, air_d = (state[:, 3] - wind_ned[:, 0], state[:, 4] - wind_ned[:, 1], state[:, 5] - wind_ned[:, 2])
    air_body = (rot[0] * air_n + rot[3] * air_e + rot[6] * air_d, rot[1] * air_n + rot[4] * air_e + rot[7] * air_d)
    thrust, scale, volts = _rotor_thrusts(vehicle, state, rot, conditions)
    rotors = state[:, _BASE : _BASE + n_r]
    sums = np.einsum("nr,rk->nk", thrust, vehicle.rotor_weights)
    force, moment = _loads(vehicle, sums, air_body, conditions)
    # yaw: drag torques k_m/k_f T plus the torques that spin the rotors up, J omega_max ds/dt
    spin_rate = vehicle.max_speed_rad_s * scale
    j_rotor = vehicle.rotor_inertia_kg_m2
    spun = np.einsum("nr,r->n", command - rotors, vehicle.rotor_spins)
    mz = moment[2] + vehicle.torque_ratio_m * sums[:, 4] + (j_rotor / vehicle.motor_time_constant_s) * spin_rate * spun
    h_z = (-j_rotor) * spin_rate * np.einsum("nr,r->n", rotors, vehicle.rotor_spins)  # rotor angular momentum
    specific = np.empty((state.shape[0], 3))
    for i in range(3):
        specific[:, i] = force[i] / mass_kg
    out = np.empty_like(state)
    _rigid_body(vehicle, state, rot, specific, (moment[0], moment[1], mz), h_z, conditions.gravity_m_s2, out)
    out[:, _BASE : _BASE + n_r] = (command - rotors) * (1.0 / vehicle.motor_time_constant_s)
    current = vehicle.power_w_per_n15 * np.einsum("nr,nr->n", thrust, np.sqrt(thrust)) / volts
    out[:, _BASE + n_r] = current
    battery = vehicle.battery
    out[:, _BASE + n_r + 1] = (battery.resistance_ohm * current - state[:, _BASE + n_r + 1]) / battery.time_constant_s
    return out, specific


def _rigid_body(
    vehicle: Vehicle,
    state: np.ndarray,
    rot: _Columns,
    specific: np.ndarray,
    moment: _Columns,
    h_z: np.ndarray,
    gravity: float,
    out: np.ndarray,
) -> None:
    """Fill ``out[:, :13]``: kinematics, eq. 2.7 in NED and eq. 2.8 with the rotors' angular momentum h_z."""
    out[:, 0:3] = state[:, 3:6]
    sfx, sfy, sfz = specific[:, 0], specific[:, 1], specific[:, 2]
    out[:, 3] = rot[0] * sfx + rot[1] * sfy + rot[2] * sfz
    out[:, 4] = rot[3] * sfx + rot[4] * sfy + rot[5] * sfz
    out[:, 5] = rot[6] * sfx + rot[7] * sfy + rot[8] * sfz + gravity
    w, x, y, z = state[:, 6], state[:, 7], state[:, 8], state[:, 9]
    p, q, r = state[:, 10], state[:, 11], state[:, 12]
    out[:, 6] = -0.5 * (x * p + y * q + z * r)
    out[:, 7] = 0.5 * (w * p + y * r - z * q)
    out[:, 8] = 0.5 * (w * q + z * p - x * r)
    out[:, 9] = 0.5 * (w * r + x * q - y * p)
    ixx, iyy, izz = vehicle.inertia_kg_m2
    out[:, 10] = (moment[0] - (izz - iyy) * q * r - q * h_z) / ixx
    out[:, 11] = (moment[1] - (ixx - izz) * r * p + p * h_z) / iyy
    out[:, 12] = (moment[2] - (iyy - ixx) * p * q) / izz
