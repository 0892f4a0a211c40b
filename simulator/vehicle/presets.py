"""Vehicle presets: the chapter 3 octocopter derived from its identified model, and the chapter 2 Crazyflie.

:func:`vehicle_from_derivatives` inverts the hover linearisation: given the
geometry, mass, inertia and rotors of a multirotor and the stability and
control derivatives of eqs. 3.10-3.13 (Table 3.3), it returns the mixer
gains, rotor drag, flapping and control-force coupling that make the
nonlinear model's linearisation at hover equal that model. The truth of a
simulated flight is therefore known exactly.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

import numpy as np

from simulator.vehicle.identified import CALM_HOVER
from simulator.vehicle.multirotor import Battery, Vehicle

__all__ = [
    "rotor_ring",
    "vehicle_from_derivatives",
    "octocopter",
    "quadcopter",
    "crazyflie",
    "QUAD_X500_HOVER",
    "OCTO_S1000",
    "QUAD_X500",
    "CRAZYFLIE",
]

_RHO_AIR = 1.225  # kg/m^3, sea level


def rotor_ring(
    n_rotors: int, radius_m: float, *, height_m: float = 0.0, first_deg: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Rotors evenly spaced on a circle, spins alternating.

    Parameters
    ----------
    n_rotors : int
        Number of rotors (even).
    radius_m : float
        Centre-to-hub distance, m.
    height_m : float, optional
        Height of the rotor plane above the centre of gravity, m.
    first_deg : float, optional
        Azimuth of rotor 1 clockwise from the nose, deg; default half the spacing (an "X" frame).

    Returns
    -------
    positions : ndarray, shape (n_rotors, 3)
        FRD hub positions, m.
    spins : ndarray, shape (n_rotors,)
        +1, -1, +1, ... (rotor 1 yaws the frame nose-right, as ArduPilot's octo-X motor 1 does in our writer).

    Examples
    --------
    >>> positions, spins = rotor_ring(4, 1.0)
    >>> np.round(positions[0], 4), spins
    (array([ 0.7071,  0.7071, -0.    ]), array([ 1., -1.,  1., -1.]))
    """
    if n_rotors < 3 or n_rotors % 2:
        raise ValueError(f"{n_rotors=} must be even and >= 4")
    start = 180.0 / n_rotors if first_deg is None else first_deg
    azimuth = np.radians(start + 360.0 / n_rotors * np.arange(n_rotors))
    positions = np.column_stack([radius_m * np.cos(azimuth), radius_m * np.sin(azimuth), np.full(n_rotors, -height_m)])
    return positions, np.where(np.arange(n_rotors) % 2 == 0, 1.0, -1.0)


def _hover_command(max_thrust_n: float, expo: float, thrust_n: float) -> float:
    """Speed fraction x with (1 - e) x + e x^2 = thrust / max_thrust."""
    ratio = thrust_n / max_thrust_n
    if expo == 0:
        return ratio
    return float((-(1 - expo) + np.sqrt((1 - expo) ** 2 + 4 * expo * ratio)) / (2 * expo))


def _nominal_voltage(battery: Battery, power_w: float) -> float:
    """Terminal voltage of a full pack delivering `power_w` (V^2 - V_oc V + R P = 0)."""
    disc = battery.full_v**2 - 4 * battery.resistance_ohm * power_w
    if disc <= 0:
        raise ValueError("the battery cannot deliver the hover power")
    return float((battery.full_v + np.sqrt(disc)) / 2)


def vehicle_from_derivatives(
    name: str,
    positions_m: np.ndarray,
    spins: np.ndarray,
    derivatives: Mapping[str, float],
    *,
    mass_kg: float,
    inertia_kg_m2: tuple[float, float, float],
    rotor_radius_m: float,
    max_thrust_n: float,
    thrust_expo: float,
    torque_ratio_m: float,
    max_speed_rad_s: float,
    figure_of_merit: float = 0.6,
    motor_efficiency: float = 0.8,
    battery: Battery | None = None,
    gravity_m_s2: float = 9.81,
) -> Vehicle:
    """A vehicle whose hover linearisation is the model of eqs. 3.10-3.13 with the given derivatives.

    Parameters
    ----------
    name : str
        Label.
    positions_m : ndarray, shape (n_rotors, 3)
        Hub positions from the CG, FRD, m; all at one height.
    spins : ndarray, shape (n_rotors,)
        Spin signs (see :class:`~simulator.vehicle.multirotor.Vehicle`).
    derivatives : Mapping[str, float]
        ``X_u M_u X_lon M_lon Y_v L_v Y_lat L_lat N_yaw Z_thr T_a tau_lat tau_lon tau_yaw tau_thr``
        (Table 3.3 names; control derivatives per % of mixer input, SI otherwise).
    mass_kg : float
        Mass, kg.
    inertia_kg_m2 : tuple of float
        Ixx, Iyy, Izz, kg m^2.
    rotor_radius_m : float
        Propeller radius, m.
    max_thrust_n : float
        Full-command thrust of one rotor at nominal voltage, N.
    thrust_expo : float
        Thrust curve exponent mix, 0 (linear) to 1 (quadratic in command).
    torque_ratio_m : float
        k_m / k_f, m.
    max_speed_rad_s : float
        Full-command rotor speed, rad/s.
    figure_of_merit : float, optional
        Hover figure of merit of a rotor (power model).
    motor_efficiency : float, optional
        Motor and ESC efficiency (power model).
    battery : Battery, optional
        The pack; default a 6S 16 Ah LiPo.
    gravity_m_s2 : float, optional
        Gravity, m/s^2.

    Returns
    -------
    Vehicle

    Notes
    -----
    With ``K = dT/ds`` the thrust slope of one rotor at hover and ``h`` the
    rotor plane's height above the CG (all derivatives per % of input):

    - ``Z_thr = -n K k_thr / m``; ``L_lat = K g_lat sum(y_i^2) / Ixx`` with
      rotor i's roll gain ``-y_i g_lat``; ``M_lon = K g_lon sum(x_i^2) / Iyy``;
    - ``N_yaw = n gamma K g_yaw / Izz`` with the rotor inertia
      ``J = gamma K T_a / max_speed``, so that the torque that accelerates a
      rotor cancels the lag of its drag torque and yaw has no actuator lag,
      as eq. 3.12 says;
    - ``X_lon = -coupling_x Iyy M_lon / m``, ``Y_lat = coupling_y Ixx L_lat / m``;
    - ``X_u = -drag_x g``, ``Y_v = -drag_y g`` (drag per thrust and airspeed,
      thrust = weight in hover);
    - ``M_u = (flap_x + h drag_x) m g / Iyy``, ``L_v = -(flap_y + h drag_y) m g / Ixx``:
      the flapping hub moment plus the moment of the rotor drag acting at the hubs.
    """
    positions = np.asarray(positions_m, dtype=np.float64)
    d = derivatives
    n = positions.shape[0]
    ixx, iyy, izz = inertia_kg_m2
    battery = battery or Battery()
    hover_thrust = mass_kg * gravity_m_s2 / n
    s_hover = _hover_command(max_thrust_n, thrust_expo, hover_thrust)
    slope = max_thrust_n * ((1 - thrust_expo) + 2 * thrust_expo * s_hover)
    x, y, height = positions[:, 0], positions[:, 1], -float(np.mean(positions[:, 2]))
    g_lat = d["L_lat"] * ixx / (slope * np.sum(y * y))
    g_lon = d["M_lon"] * iyy / (slope * np.sum(x * x))
    g_yaw = d["N_yaw"] * izz / (n * torque_ratio_m * slope)
    k_thr = -d["Z_thr"] * mass_kg / (n * slope)
    mixer = np.column_stack([-y * g_lat, x * g_lon, spins * g_yaw, np.full(n, k_thr)])
    drag = np.array([-d["X_u"], -d["Y_v"]]) / gravity_m_s2
    weight = mass_kg * gravity_m_s2
    flapping = np.array([d["M_u"] * iyy / weight - height * drag[0], -d["L_v"] * ixx / weight - height * drag[1]])
    coupling = np.array([-d["X_lon"] * mass_kg / (d["M_lon"] * iyy), d["Y_lat"] * mass_kg / (d["L_lat"] * ixx)])
    power = 1.0 / (figure_of_merit * motor_efficiency * np.sqrt(2 * _RHO_AIR * np.pi * rotor_radius_m**2))
    return Vehicle(
        name=name,
        mass_kg=mass_kg,
        inertia_kg_m2=np.array(inertia_kg_m2),
        rotor_positions_m=positions,
        rotor_spins=spins,
        rotor_radius_m=rotor_radius_m,
        max_thrust_n=max_thrust_n,
        thrust_expo=thrust_expo,
        torque_ratio_m=torque_ratio_m,
        max_speed_rad_s=max_speed_rad_s,
        rotor_inertia_kg_m2=torque_ratio_m * slope * d["T_a"] / max_speed_rad_s,
        motor_time_constant_s=d["T_a"],
        delays_s=np.array([d.get(f"tau_{axis}", 0.0) for axis in ("lat", "lon", "yaw", "thr")]),
        mixer=mixer,
        trim_command=s_hover,
        drag_s_m=drag,
        flapping_s=flapping,
        coupling_1_m=coupling,
        power_w_per_n15=float(power),
        battery=battery,
        nominal_voltage_v=_nominal_voltage(battery, float(power) * n * hover_thrust**1.5),
    )


def octocopter(
    derivatives: Mapping[str, float] = CALM_HOVER,
    *,
    mass_kg: float = 7.0,
    inertia_kg_m2: tuple[float, float, float] = (0.38, 0.40, 0.70),
    rotor_height_m: float = 0.08,
) -> Vehicle:
    """The chapter 3 octocopter (DJI S1000+ frame) with a hover model equal to `derivatives`.

    Parameters
    ----------
    derivatives : Mapping[str, float], optional
        Table 3.3 derivatives; default the calm-wind column.
    mass_kg : float, optional
        Take-off mass, kg (chapter 3: 7.0).
    inertia_kg_m2 : tuple of float, optional
        Ixx, Iyy, Izz, kg m^2. Not in the dissertation: eight 0.3 kg motor,
        ESC and arm sets at 0.52 m give about 0.65 in yaw and half that in
        roll and pitch; the battery and gimbal under the centre add a little.
    rotor_height_m : float, optional
        Rotor plane above the CG, m (battery and camera hang below the frame).

    Returns
    -------
    Vehicle

    Notes
    -----
    From chapter 3: 7.0 kg, 0.381 m propellers with 2.8 kgf maximum thrust,
    1.045 m motor to motor, 16 Ah 6S battery. Assumed: rotor speed 720 rad/s
    at full command, thrust proportional to speed squared, k_m/k_f = 0.016 m
    (15-inch propellers), figure of merit 0.6, motor efficiency 0.8.
    """
    positions, spins = rotor_ring(8, 1.045 / 2, height_m=rotor_height_m)
    return vehicle_from_derivatives(
        "octo_s1000",
        positions,
        spins,
        derivatives,
        mass_kg=mass_kg,
        inertia_kg_m2=inertia_kg_m2,
        rotor_radius_m=0.381 / 2,
        max_thrust_n=2.8 * 9.80665,
        thrust_expo=1.0,
        torque_ratio_m=0.016,
        max_speed_rad_s=720.0,
        battery=Battery(full_v=25.2, empty_v=21.0, capacity_ah=16.0, resistance_ohm=0.02, time_constant_s=0.5),
    )


#: Hover derivatives assumed for a 2 kg X500-class quad (not identified: a second vehicle for tests that must
#: not fit one airframe). Per % of mixer input, SI otherwise.
QUAD_X500_HOVER: Mapping[str, float] = MappingProxyType(
    {
        "X_u": -0.25,
        "M_u": 1.1,
        "X_lon": -0.08,
        "M_lon": 1.3,
        "Y_v": -0.24,
        "L_v": -1.1,
        "Y_lat": 0.08,
        "L_lat": 1.5,
        "N_yaw": 0.16,
        "Z_thr": -0.36,
        "T_a": 0.032,
        "tau_lat": 0.012,
        "tau_lon": 0.012,
        "tau_yaw": 0.010,
        "tau_thr": 0.0,
    }
)


def quadcopter(derivatives: Mapping[str, float] = QUAD_X500_HOVER, *, mass_kg: float = 2.0) -> Vehicle:
    """A 2 kg X500-class quadrotor (0.5 m motor to motor, 10-inch propellers) with a hover model `derivatives`.

    Parameters
    ----------
    derivatives : Mapping[str, float], optional
        Hover derivatives (Table 3.3 names); default :data:`QUAD_X500_HOVER`.
    mass_kg : float, optional
        Take-off mass, kg.

    Returns
    -------
    Vehicle

    Notes
    -----
    Assumed, not measured: 1.0 kgf per rotor at full command, rotor speed
    1100 rad/s, k_m/k_f = 0.012 m, inertia (0.022, 0.024, 0.040) kg m^2,
    rotors 0.05 m above the CG, a 4S 5 Ah pack.
    """
    positions, spins = rotor_ring(4, 0.25, height_m=0.05)
    return vehicle_from_derivatives(
        "quad_x500",
        positions,
        spins,
        derivatives,
        mass_kg=mass_kg,
        inertia_kg_m2=(0.022, 0.024, 0.040),
        rotor_radius_m=0.127,
        max_thrust_n=1.0 * 9.80665,
        thrust_expo=1.0,
        torque_ratio_m=0.012,
        max_speed_rad_s=1100.0,
        battery=Battery(full_v=16.8, empty_v=14.0, capacity_ah=5.0, resistance_ohm=0.03, time_constant_s=0.5),
    )


def crazyflie(*, mass_kg: float = 0.03812) -> Vehicle:
    """The chapter 2 modified Crazyflie 2.0 (Table 2.1), thrust linear in PWM (eq. 2.6).

    Parameters
    ----------
    mass_kg : float, optional
        Mass, kg. Table 2.1 prints 0.3812 kg, but with its k_f = 2.083e-6 N
        per count the four motors give at most 4 k_f 65535 = 0.546 N, less
        than that weight; 0.03812 kg hovers at 68 % PWM and fits the
        inertias, so it is the default.

    Returns
    -------
    Vehicle

    Notes
    -----
    Table 2.1: L = 0.035 m (rotor to centre line: hubs at (+-L, +-L)),
    Ixx 2.661e-5, Iyy 2.858e-5, Izz 5.799e-5 kg m^2, k_f 2.083e-6 N and
    k_m 7.707e-9 N m per PWM count (16-bit), gamma = 3.700e-3 m; motors
    ordered as in eq. 2.9 (1 front right, 2 back right, 3 back left,
    4 front left; 1 and 3 yaw the frame nose-right). Assumed: 45 mm
    propellers, motor lag 0.03 s, delays 0.01 s, rotor drag 0.03 s/m,
    mixer 1 % thrust input = 1 % PWM and 1 % roll, pitch or yaw input =
    0.5 % PWM differential, 1S 250 mAh battery.
    """
    arm = 0.035
    positions = np.array([[arm, arm, 0.0], [-arm, arm, 0.0], [-arm, -arm, 0.0], [arm, -arm, 0.0]])
    spins = np.array([1.0, -1.0, 1.0, -1.0])
    k_f, k_m, pwm_max = 2.083e-6, 7.707e-9, 65535.0
    hover = mass_kg * 9.81 / 4 / (k_f * pwm_max)
    mixer = np.column_stack(
        [-np.sign(positions[:, 1]) * 0.005, np.sign(positions[:, 0]) * 0.005, spins * 0.005, np.full(4, 0.01)]
    )
    battery = Battery(full_v=4.2, empty_v=3.3, capacity_ah=0.25, resistance_ohm=0.15, time_constant_s=0.5)
    power = 1.0 / (0.5 * 0.7 * np.sqrt(2 * _RHO_AIR * np.pi * 0.0225**2))
    return Vehicle(
        name="crazyflie",
        mass_kg=mass_kg,
        inertia_kg_m2=np.array([2.661e-5, 2.858e-5, 5.799e-5]),
        rotor_positions_m=positions,
        rotor_spins=spins,
        rotor_radius_m=0.0225,
        max_thrust_n=k_f * pwm_max,
        thrust_expo=0.0,
        torque_ratio_m=k_m / k_f,
        max_speed_rad_s=2600.0,
        rotor_inertia_kg_m2=3e-9,
        motor_time_constant_s=0.03,
        delays_s=np.full(4, 0.01),
        mixer=mixer,
        trim_command=hover,
        drag_s_m=np.array([0.03, 0.03]),
        flapping_s=np.array([7.6e-6, 7.1e-6]),
        power_w_per_n15=float(power),
        battery=battery,
        nominal_voltage_v=_nominal_voltage(battery, float(power) * 4 * (mass_kg * 9.81 / 4) ** 1.5),
    )


#: The chapter 3 octocopter; its hover linearisation is the calm Table 3.3 model.
OCTO_S1000: Vehicle = octocopter()
#: A 2 kg X500-class quadrotor (assumed derivatives, see :func:`quadcopter`).
QUAD_X500: Vehicle = quadcopter()
#: The chapter 2 Crazyflie of Table 2.1 (mass read as 0.03812 kg, see :func:`crazyflie`).
CRAZYFLIE: Vehicle = crazyflie()
