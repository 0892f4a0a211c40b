"""Nonlinear 6-DOF multirotor: rigid body, rotors on arms, mixer, motor lag, battery.

The state of a batch of trials is one array, shape ``(n_trials, n_states)``,
laid out as in :func:`state_names`::

    pn pe pd | vn ve vd | qw qx qy qz | p q r | s_1 .. s_n | charge sag

with position and ground velocity in NED earth axes (m, m/s), the attitude
quaternion rotating FRD body axes into NED, body rates (rad/s), the lagged
rotor commands ``s_i`` (fraction of full scale; the rotor speed is
``s_i * max_speed`` at the nominal voltage), the charge drawn from the
battery (C) and its polarisation sag (V).

The mixer maps the four mixer inputs ``delta_lat, delta_lon, delta_yaw,
delta_thr`` (%, as the dissertation logs them; ``delta_thr`` measured from
the hover trim) to rotor commands. A rotor's thrust is
``max_thrust * f(s * V / V_nominal)`` with ``f(x) = (1 - e) x + e x^2``
(ArduPilot's MOT_THST_EXPO; ``e = 1`` is thrust proportional to speed squared)
and its reaction torque ``torque_ratio * thrust + J * d(omega)/dt`` (k_m/k_f
plus the torque that spins the rotor up).

Rotor drag (blade flapping's H-force) acts in the rotor plane against the
airspeed at the centre of gravity, ``-drag * thrust * (u, v)`` per rotor, at
the rotor; the flapping hub moment is ``flapping * thrust_total * (-v, u)``
about (x, y). These give X_u, Y_v and the speed stability M_u, L_v of
eqs. 3.10-3.11. ``coupling`` is the direct force that Table 3.3 attributes to
the roll and pitch inputs (Y_lat, X_lon): ``F_x = -coupling_x M_y``,
``F_y = coupling_y M_x`` with M the moment of the rotor thrusts about the
geometric centre. The equations of motion are in :mod:`simulator.vehicle.dynamics`,
the presets in :mod:`simulator.vehicle.presets`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import cast

import numpy as np

__all__ = [
    "FIRST_ROTOR_STATE",
    "Battery",
    "Vehicle",
    "state_names",
    "n_states",
    "quaternion_from_euler",
    "mixer_commands",
]

#: Column of the first rotor state (after position, velocity, quaternion, rates).
FIRST_ROTOR_STATE = 13


def _array(value: object, shape: tuple[int, ...], name: str) -> np.ndarray:
    array = np.array(value, dtype=np.float64)
    if array.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite")
    array.setflags(write=False)
    return array


@dataclass(frozen=True, slots=True, kw_only=True)
class Battery:
    """A lithium-polymer pack: open-circuit voltage falls with the charge drawn.

    Parameters
    ----------
    full_v : float
        Open-circuit voltage when full, V.
    empty_v : float
        Open-circuit voltage when the rated capacity is drawn, V.
    capacity_ah : float
        Rated capacity, Ah.
    resistance_ohm : float
        Internal resistance, ohm (sag = resistance * current, reached with
        ``time_constant_s``).
    time_constant_s : float
        Time constant of the sag (the pack's polarisation), s.

    Notes
    -----
    The open-circuit voltage is linear in the charge drawn, a fair model of
    the middle of a LiPo's discharge curve.
    """

    full_v: float = 25.2
    empty_v: float = 21.0
    capacity_ah: float = 16.0
    resistance_ohm: float = 0.02
    time_constant_s: float = 0.5

    def __post_init__(self) -> None:
        if not 0 < self.empty_v < self.full_v:
            raise ValueError(f"need 0 < empty_v={self.empty_v} < full_v={self.full_v}")
        if self.capacity_ah <= 0 or self.resistance_ohm < 0 or self.time_constant_s <= 0:
            raise ValueError("capacity_ah and time_constant_s must be > 0, resistance_ohm >= 0")

    def open_circuit_v(self, charge_c: np.ndarray | float) -> np.ndarray:
        """Open-circuit voltage, V, after drawing `charge_c` coulombs.

        Parameters
        ----------
        charge_c : ndarray or float
            Charge drawn, C.

        Returns
        -------
        ndarray
            Voltage, V, same shape as `charge_c`.
        """
        return self.full_v - (self.full_v - self.empty_v) * np.asarray(charge_c) / (3600.0 * self.capacity_ah)


@dataclass(frozen=True, slots=True, kw_only=True)
class Vehicle:
    """A multirotor's physical and mixer parameters (SI, radians; mixer in % of input).

    Parameters
    ----------
    name : str
        Label, e.g. ``"octo_s1000"``.
    mass_kg : float
        Take-off mass, kg.
    inertia_kg_m2 : ndarray, shape (3,)
        Principal moments of inertia Ixx, Iyy, Izz, kg m^2.
    rotor_positions_m : ndarray, shape (n_rotors, 3)
        Rotor hubs in FRD body axes from the centre of gravity, m (z < 0: above).
    rotor_spins : ndarray, shape (n_rotors,)
        +1 for rotors whose reaction torque yaws the frame nose-right
        (counter-clockwise seen from above), -1 otherwise.
    rotor_radius_m : float
        Propeller radius R, m (ground effect uses Z/R).
    max_thrust_n : float
        Thrust of one rotor at full command and nominal voltage, N.
    thrust_expo : float
        Thrust curve ``f(x) = (1 - e) x + e x^2`` of the speed fraction x, 0..1.
    torque_ratio_m : float
        Drag torque per thrust, k_m / k_f, m.
    max_speed_rad_s : float
        Rotor speed at full command and nominal voltage, rad/s.
    rotor_inertia_kg_m2 : float
        Inertia of one rotor (propeller and motor bell), kg m^2.
    motor_time_constant_s : float
        First-order lag of the rotor speed, T_a of eq. 3.2, s.
    delays_s : ndarray, shape (4,)
        Transport delay of each mixer input (lat, lon, yaw, thr), s.
    mixer : ndarray, shape (n_rotors, 4)
        Rotor command (fraction of full scale) per % of each mixer input.
    trim_command : float
        Rotor command at zero mixer input (hover trim at nominal mass and voltage), fraction.
    idle_command : float
        Lowest rotor command (the motors keep spinning), fraction.
    drag_s_m : ndarray, shape (2,)
        Rotor drag per thrust and per airspeed along body x and y, s/m.
    flapping_s : ndarray, shape (2,)
        Flapping hub moment per thrust and per airspeed about y (from u) and x (from v), s.
    coupling_1_m : ndarray, shape (2,)
        Body force per moment of the rotor thrusts: x per pitch moment, y per roll moment, 1/m.
    power_w_per_n15 : float
        Electrical power per rotor per thrust^1.5 (momentum theory over figure of merit and efficiency), W/N^1.5.
    battery : Battery
        The pack.
    nominal_voltage_v : float
        Terminal voltage at which `max_thrust_n` and `max_speed_rad_s` hold, V.
    """

    name: str
    mass_kg: float
    inertia_kg_m2: np.ndarray
    rotor_positions_m: np.ndarray
    rotor_spins: np.ndarray
    rotor_radius_m: float
    max_thrust_n: float
    thrust_expo: float
    torque_ratio_m: float
    max_speed_rad_s: float
    rotor_inertia_kg_m2: float
    motor_time_constant_s: float
    delays_s: np.ndarray
    mixer: np.ndarray
    trim_command: float
    idle_command: float = 0.05
    drag_s_m: np.ndarray = field(default_factory=lambda: np.zeros(2))
    flapping_s: np.ndarray = field(default_factory=lambda: np.zeros(2))
    coupling_1_m: np.ndarray = field(default_factory=lambda: np.zeros(2))
    power_w_per_n15: float = 0.0
    battery: Battery = field(default_factory=Battery)
    nominal_voltage_v: float = 24.0
    rotor_weights: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        positions = np.array(self.rotor_positions_m, dtype=np.float64)
        if positions.ndim != 2 or positions.shape[1] != 3 or positions.shape[0] < 3:
            raise ValueError(f"rotor_positions_m must have shape (n_rotors >= 3, 3), got {positions.shape}")
        n = positions.shape[0]
        object.__setattr__(self, "rotor_positions_m", _array(positions, (n, 3), "rotor_positions_m"))
        object.__setattr__(self, "inertia_kg_m2", _array(self.inertia_kg_m2, (3,), "inertia_kg_m2"))
        object.__setattr__(self, "rotor_spins", _array(self.rotor_spins, (n,), "rotor_spins"))
        object.__setattr__(self, "delays_s", _array(self.delays_s, (4,), "delays_s"))
        object.__setattr__(self, "mixer", _array(self.mixer, (n, 4), "mixer"))
        for name in ("drag_s_m", "flapping_s", "coupling_1_m"):
            object.__setattr__(self, name, _array(getattr(self, name), (2,), name))
        if self.mass_kg <= 0 or np.any(self.inertia_kg_m2 <= 0):
            raise ValueError("mass_kg and inertia_kg_m2 must be > 0")
        if not np.all(np.abs(self.rotor_spins) == 1):
            raise ValueError("rotor_spins must be +1 or -1")
        if not 0 <= self.thrust_expo <= 1:
            raise ValueError(f"thrust_expo={self.thrust_expo} must be in [0, 1]")
        if self.motor_time_constant_s <= 0 or np.any(self.delays_s < 0):
            raise ValueError("motor_time_constant_s must be > 0 and delays_s >= 0")
        if not 0 <= self.idle_command < self.trim_command < 1:
            raise ValueError(f"need 0 <= idle_command < trim_command={self.trim_command} < 1")
        if min(self.max_thrust_n, self.max_speed_rad_s, self.rotor_radius_m, self.nominal_voltage_v) <= 0:
            raise ValueError("max_thrust_n, max_speed_rad_s, rotor_radius_m and nominal_voltage_v must be > 0")
        weights = np.column_stack([np.ones(n), self.rotor_positions_m, self.rotor_spins])
        weights.setflags(write=False)
        object.__setattr__(self, "rotor_weights", weights)  # sums over rotors of T, T x, T y, T z, T spin

    @property
    def n_rotors(self) -> int:
        """Number of rotors."""
        return int(self.rotor_positions_m.shape[0])

    def thrust_curve(self, speed_fraction: np.ndarray) -> np.ndarray:
        """Thrust of one rotor, N, at the speed fraction (command times voltage ratio).

        Parameters
        ----------
        speed_fraction : ndarray
            Rotor speed over the nominal full speed.

        Returns
        -------
        ndarray
            Thrust, N, same shape.
        """
        x = np.asarray(speed_fraction)
        return cast(np.ndarray, self.max_thrust_n * ((1.0 - self.thrust_expo) * x + self.thrust_expo * x * x))


def state_names(n_rotors: int) -> tuple[str, ...]:
    """Names of the state columns for a vehicle with `n_rotors` rotors.

    Parameters
    ----------
    n_rotors : int
        Number of rotors.

    Returns
    -------
    tuple of str

    Examples
    --------
    >>> state_names(4)[:3], state_names(4)[-3:]
    (('pn', 'pe', 'pd'), ('s_4', 'charge', 'sag'))
    """
    rigid = ("pn", "pe", "pd", "vn", "ve", "vd", "qw", "qx", "qy", "qz", "p", "q", "r")
    return rigid + tuple(f"s_{k + 1}" for k in range(n_rotors)) + ("charge", "sag")


def n_states(vehicle: Vehicle) -> int:
    """Length of the state vector of `vehicle`.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle.

    Returns
    -------
    int
    """
    return FIRST_ROTOR_STATE + vehicle.n_rotors + 2


def quaternion_from_euler(phi: np.ndarray, theta: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Quaternions ``(w, x, y, z)`` (body to NED) of 3-2-1 Euler angles.

    Parameters
    ----------
    phi, theta, psi : ndarray, shape (n,)
        Roll, pitch, yaw, rad.

    Returns
    -------
    ndarray, shape (n, 4)

    Examples
    --------
    >>> np.round(quaternion_from_euler(np.zeros(1), np.zeros(1), np.array([np.pi])), 12)
    array([[0., 0., 0., 1.]])
    """
    cf, sf = np.cos(np.asarray(phi) / 2), np.sin(np.asarray(phi) / 2)
    ct, st = np.cos(np.asarray(theta) / 2), np.sin(np.asarray(theta) / 2)
    cp, sp = np.cos(np.asarray(psi) / 2), np.sin(np.asarray(psi) / 2)
    return np.column_stack(
        [
            cf * ct * cp + sf * st * sp,
            sf * ct * cp - cf * st * sp,
            cf * st * cp + sf * ct * sp,
            cf * ct * sp - sf * st * cp,
        ]
    )


def mixer_commands(vehicle: Vehicle, mixer_input: np.ndarray) -> np.ndarray:
    """Rotor commands from mixer inputs, clipped to [idle, 1].

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle.
    mixer_input : ndarray, shape (n_trials, 4)
        ``delta_lat, delta_lon, delta_yaw, delta_thr``, % (thrust from hover trim).

    Returns
    -------
    ndarray, shape (n_trials, n_rotors)
        Commands, fraction of full scale.
    """
    mix = vehicle.mixer
    command = vehicle.trim_command + mixer_input[:, 0:1] * mix[:, 0]
    for axis in (1, 2, 3):  # term by term: the same rounding whatever the batch size
        command = command + mixer_input[:, axis : axis + 1] * mix[:, axis]
    return cast(np.ndarray, np.minimum(np.maximum(command, vehicle.idle_command), 1.0))
