"""Trim and numerical linearisation of the nonlinear vehicle, and the eq. 3.4 reference model.

:func:`linearize_hover` differentiates :func:`~simulator.vehicle.multirotor.vehicle_derivative`
at a numerically found trim and expresses the result in the state order of
eq. 3.3, ``u v w p q r phi theta psi d_lat d_lon d_thr`` with inputs
``delta_lat delta_lon delta_yaw delta_thr`` (%). The rotor states are
mapped onto the mixer axes (``d = pinv(mixer) (s - s_trim)``); the yaw
actuator state and the mixer's null space do not act on the rigid body and
are dropped (their coupling is reported). :func:`reference_model` builds
the same matrices from Table 3.3 (eqs. 3.10-3.13), and
:func:`compare_eigenvalues` pairs the two spectra.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import cast

import numpy as np
from scipy import linalg, optimize

from simulator.vehicle.dynamics import Conditions, vehicle_derivative
from simulator.vehicle.identified import CALM_HOVER
from simulator.vehicle.multirotor import Vehicle, mixer_commands, n_states, quaternion_from_euler

__all__ = [
    "EQ33_STATES",
    "MIXER_INPUTS",
    "Trim",
    "LinearModel",
    "EigenComparison",
    "trim_hover",
    "linearize_hover",
    "reference_model",
    "hover_derivatives",
    "compare_eigenvalues",
]

#: State order of eq. 3.3.
EQ33_STATES = ("u", "v", "w", "p", "q", "r", "phi", "theta", "psi", "d_lat", "d_lon", "d_thr")
#: Inputs of eq. 3.4 (mixer inputs, %).
MIXER_INPUTS = ("delta_lat", "delta_lon", "delta_yaw", "delta_thr")
_RIGID = EQ33_STATES[:9]


@dataclass(frozen=True, slots=True, kw_only=True)
class Trim:
    """A steady hover over a point in a steady wind.

    Parameters
    ----------
    state : ndarray, shape (n_states,)
        Full vehicle state (layout of :func:`~simulator.vehicle.multirotor.state_names`).
    mixer_input : ndarray, shape (4,)
        Trim ``delta_lat, delta_lon, delta_yaw, delta_thr``, %.
    wind_ned : ndarray, shape (3,)
        The steady wind, m/s.
    total_thrust_n : float
        Sum of rotor thrusts, N.
    """

    state: np.ndarray
    mixer_input: np.ndarray
    wind_ned: np.ndarray
    total_thrust_n: float

    @property
    def euler(self) -> np.ndarray:
        """Roll, pitch, yaw, rad, shape (3,)."""
        from flightlogs.frames import quaternion_to_euler

        return cast(np.ndarray, quaternion_to_euler(self.state[None, 6:10])[0])


@dataclass(frozen=True, slots=True, kw_only=True)
class LinearModel:
    """A continuous linear model x' = A x + B u(t - tau).

    Parameters
    ----------
    a : ndarray, shape (n_states, n_states)
        State matrix, SI (per % for actuator states).
    b : ndarray, shape (n_states, n_inputs)
        Input matrix, per % of mixer input.
    states : tuple of str
        State names.
    inputs : tuple of str
        Input names.
    delays_s : Mapping[str, float]
        Transport delay of each input, s.
    dropped_coupling : float
        Largest effect on the kept states of the states dropped in the reduction (0 for a reference model).
    """

    a: np.ndarray
    b: np.ndarray
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    delays_s: Mapping[str, float] = field(default_factory=dict)
    dropped_coupling: float = 0.0

    def __post_init__(self) -> None:
        n, m = len(self.states), len(self.inputs)
        if np.shape(self.a) != (n, n) or np.shape(self.b) != (n, m):
            raise ValueError(f"a must be ({n}, {n}) and b ({n}, {m}), got {np.shape(self.a)} and {np.shape(self.b)}")

    @property
    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of `a`, 1/s, shape (n_states,)."""
        return np.linalg.eigvals(self.a)


@dataclass(frozen=True, slots=True, kw_only=True)
class EigenComparison:
    """Eigenvalues of a reference model paired with the nearest of another model's.

    Parameters
    ----------
    reference : ndarray, shape (n,)
        Reference eigenvalues, 1/s.
    paired : ndarray, shape (n,)
        The other model's eigenvalue matched to each, 1/s.
    error : ndarray, shape (n,)
        ``|paired - reference| / |reference|``; absolute (1/s) where the reference is zero.
    """

    reference: np.ndarray
    paired: np.ndarray
    error: np.ndarray


def _full_state(
    vehicle: Vehicle, rigid: np.ndarray, rotors: np.ndarray, wind: np.ndarray, sag: float, height_m: float
) -> np.ndarray:
    """A full state from eq. 3.3 rigid-body coordinates (air-relative body velocity, Euler angles)."""
    u, v, w, p, q, r, phi, theta, psi = rigid
    quat = quaternion_from_euler(np.array([phi]), np.array([theta]), np.array([psi]))[0]
    cf, sf, ct, st, cp, sp = np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta), np.cos(psi), np.sin(psi)
    body_to_ned = np.array(
        [
            [ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp],
            [ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp],
            [-st, sf * ct, cf * ct],
        ]
    )
    state = np.zeros(n_states(vehicle))
    state[2] = -height_m
    state[3:6] = body_to_ned @ np.array([u, v, w]) + wind
    state[6:10] = quat
    state[10:13] = p, q, r
    state[13 : 13 + vehicle.n_rotors] = rotors
    state[-1] = sag
    return state


def _reduced_derivative(
    vehicle: Vehicle,
    rigid: np.ndarray,
    rotors: np.ndarray,
    mixer_input: np.ndarray,
    wind: np.ndarray,
    sag: float,
    conditions: Conditions,
    height_m: float,
) -> np.ndarray:
    """d/dt of (u v w p q r phi theta psi s_1..s_n) at one point."""
    state = _full_state(vehicle, rigid, rotors, wind, sag, height_m)
    command = mixer_commands(vehicle, mixer_input[None, :])
    dot, _ = vehicle_derivative(
        vehicle, state[None, :], command, wind[None, :], np.array([vehicle.mass_kg]), conditions
    )
    dot = dot[0]
    _, _, _, p, q, r, phi, theta, _ = rigid
    quat = state[6:10]
    w0, x0, y0, z0 = quat
    ned_to_body = np.array(
        [
            [1 - 2 * (y0 * y0 + z0 * z0), 2 * (x0 * y0 + w0 * z0), 2 * (x0 * z0 - w0 * y0)],
            [2 * (x0 * y0 - w0 * z0), 1 - 2 * (x0 * x0 + z0 * z0), 2 * (y0 * z0 + w0 * x0)],
            [2 * (x0 * z0 + w0 * y0), 2 * (y0 * z0 - w0 * x0), 1 - 2 * (x0 * x0 + y0 * y0)],
        ]
    )
    velocity_body = rigid[:3]
    body_accel = ned_to_body @ dot[3:6] - np.cross([p, q, r], velocity_body)
    euler_dot = [
        p + (q * np.sin(phi) + r * np.cos(phi)) * np.tan(theta),
        q * np.cos(phi) - r * np.sin(phi),
        (q * np.sin(phi) + r * np.cos(phi)) / np.cos(theta),
    ]
    return np.concatenate([body_accel, dot[10:13], euler_dot, dot[13 : 13 + vehicle.n_rotors]])


def trim_hover(
    vehicle: Vehicle,
    *,
    wind_ned: tuple[float, float, float] = (0.0, 0.0, 0.0),
    heading_rad: float = 0.0,
    conditions: Conditions | None = None,
    height_m: float = 10.0,
) -> Trim:
    """Find the hover over a fixed point: attitude, mixer inputs and battery sag with zero accelerations.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle (at its nominal mass).
    wind_ned : tuple of float, optional
        Steady wind, m/s.
    heading_rad : float, optional
        Heading held, rad.
    conditions : Conditions, optional
        Switches for one trial; default :meth:`Conditions.nominal`.
    height_m : float, optional
        Height of the CG above ground, m.

    Returns
    -------
    Trim

    Raises
    ------
    RuntimeError
        If no trim is found (the rotors cannot hold the vehicle).
    """
    conditions = conditions or Conditions.nominal(1)
    wind = np.asarray(wind_ned, dtype=np.float64)

    def build(unknowns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        phi, theta, *delta, sag = unknowns
        delta_arr = np.array(delta)
        rotors = mixer_commands(vehicle, delta_arr[None, :])[0]
        rigid = np.zeros(9)
        rigid[6:9] = phi, theta, heading_rad
        velocity_body = _air_body(phi, theta, heading_rad, -wind)
        rigid[:3] = velocity_body
        return _full_state(vehicle, rigid, rotors, wind, sag, height_m), delta_arr

    def residual(unknowns: np.ndarray) -> np.ndarray:
        state, delta_arr = build(unknowns)
        command = mixer_commands(vehicle, delta_arr[None, :])
        dot, _ = vehicle_derivative(
            vehicle, state[None, :], command, wind[None, :], np.array([vehicle.mass_kg]), conditions
        )
        return np.concatenate([dot[0, 3:6], dot[0, 10:13], [dot[0, -1]]])

    solution = optimize.root(residual, np.zeros(7), method="hybr", options={"xtol": 1e-13})
    # judged by the residual: at the tight xtol the solver may call a converged root "not making good progress"
    if np.max(np.abs(residual(solution.x))) > 1e-8:
        raise RuntimeError(f"no hover trim for {vehicle.name} in wind {wind.tolist()} m/s: {solution.message}")
    state, delta_arr = build(solution.x)
    thrust = vehicle.thrust_curve(state[13 : 13 + vehicle.n_rotors])
    return Trim(state=state, mixer_input=delta_arr, wind_ned=wind, total_thrust_n=float(np.sum(thrust)))


def _air_body(phi: float, theta: float, psi: float, air_ned: np.ndarray) -> np.ndarray:
    """Rotate an NED vector into body axes."""
    quat = quaternion_from_euler(np.array([phi]), np.array([theta]), np.array([psi]))[0]
    w, x, y, z = quat
    ned_to_body = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)],
            [2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)],
            [2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)],
        ]
    )
    return cast(np.ndarray, ned_to_body @ air_ned)


def linearize_hover(
    vehicle: Vehicle,
    *,
    trim: Trim | None = None,
    step: float = 1e-6,
    conditions: Conditions | None = None,
    height_m: float = 10.0,
) -> LinearModel:
    """Numerical Jacobians of the bare airframe at hover, in the order of eq. 3.3.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle.
    trim : Trim, optional
        Operating point; default :func:`trim_hover` in still air.
    step : float, optional
        Central-difference step (states in SI, inputs in %).
    conditions : Conditions, optional
        Switches for one trial; default :meth:`Conditions.nominal`.
    height_m : float, optional
        Height of the CG above ground, m (matters only with ground effect).

    Returns
    -------
    LinearModel
        States :data:`EQ33_STATES`, inputs :data:`MIXER_INPUTS`, the vehicle's delays.

    Notes
    -----
    The battery is frozen at its trim (its voltage changes over minutes).
    """
    conditions = conditions or Conditions.nominal(1)
    trim = trim or trim_hover(vehicle, conditions=conditions, height_m=height_m)
    n_r = vehicle.n_rotors
    phi, theta, psi = trim.euler
    air_body = _air_body(phi, theta, psi, trim.state[3:6] - trim.wind_ned)
    rigid0 = np.concatenate([air_body, trim.state[10:13], trim.euler])
    x0 = np.concatenate([rigid0, trim.state[13 : 13 + n_r]])
    sag = float(trim.state[-1])

    def f(x: np.ndarray, u: np.ndarray) -> np.ndarray:
        return _reduced_derivative(vehicle, x[:9], x[9:], u, trim.wind_ned, sag, conditions, height_m)

    a = np.column_stack(
        [
            (f(x0 + step * e, trim.mixer_input) - f(x0 - step * e, trim.mixer_input)) / (2 * step)
            for e in np.eye(x0.size)
        ]
    )
    b = np.column_stack(
        [(f(x0, trim.mixer_input + step * e) - f(x0, trim.mixer_input - step * e)) / (2 * step) for e in np.eye(4)]
    )
    # rotor states onto mixer axes: s = M d + N eta
    mixer = vehicle.mixer
    basis = np.column_stack([mixer, linalg.null_space(mixer.T)])
    to_new = linalg.block_diag(np.eye(9), np.linalg.inv(basis))
    from_new = linalg.block_diag(np.eye(9), basis)
    a_new, b_new = to_new @ a @ from_new, to_new @ b
    keep = list(range(9)) + [9, 10, 12]  # d_lat, d_lon, d_thr
    dropped = [i for i in range(a_new.shape[0]) if i not in keep]
    coupling = float(np.max(np.abs(a_new[np.ix_(keep, dropped)]))) if dropped else 0.0
    delays = dict(zip(MIXER_INPUTS, vehicle.delays_s.tolist()))
    return LinearModel(
        a=a_new[np.ix_(keep, keep)],
        b=b_new[keep],
        states=EQ33_STATES,
        inputs=MIXER_INPUTS,
        delays_s=delays,
        dropped_coupling=coupling,
    )


def reference_model(parameters: Mapping[str, float] = CALM_HOVER, *, gravity_m_s2: float = 9.81) -> LinearModel:
    """The identified hover model of eqs. 3.10-3.13 with the actuator lag of eq. 3.2, in eq. 3.3 order.

    Parameters
    ----------
    parameters : Mapping[str, float], optional
        Table 3.3 names; default the calm column. Optional ``N_r`` adds yaw damping.
    gravity_m_s2 : float, optional
        Gravity, m/s^2 (9.81: the SI eigenvalues).

    Returns
    -------
    LinearModel

    Examples
    --------
    >>> lon = reference_model().a[np.ix_([0, 4, 7], [0, 4, 7])]
    >>> np.round(np.sort_complex(np.linalg.eigvals(lon)), 3)
    array([-2.073+0.j   ,  0.878-1.694j,  0.878+1.694j])
    """
    p, g = parameters, gravity_m_s2
    idx = {name: k for k, name in enumerate(EQ33_STATES)}
    a = np.zeros((12, 12))
    b = np.zeros((12, 4))
    a[idx["u"], [idx["u"], idx["theta"], idx["d_lon"]]] = p["X_u"], -g, p["X_lon"]
    a[idx["q"], [idx["u"], idx["d_lon"]]] = p["M_u"], p["M_lon"]
    a[idx["v"], [idx["v"], idx["phi"], idx["d_lat"]]] = p["Y_v"], g, p["Y_lat"]
    a[idx["p"], [idx["v"], idx["d_lat"]]] = p["L_v"], p["L_lat"]
    a[idx["w"], idx["d_thr"]] = p["Z_thr"]
    a[idx["r"], idx["r"]] = p.get("N_r", 0.0)
    b[idx["r"], 2] = p["N_yaw"]
    for angle, rate in (("phi", "p"), ("theta", "q"), ("psi", "r")):
        a[idx[angle], idx[rate]] = 1.0
    for k, state in ((0, "d_lat"), (1, "d_lon"), (3, "d_thr")):
        a[idx[state], idx[state]] = -1.0 / p["T_a"]
        b[idx[state], k] = 1.0 / p["T_a"]
    delays = {name: float(p.get(f"tau_{name.split('_')[1]}", 0.0)) for name in MIXER_INPUTS}
    return LinearModel(a=a, b=b, states=EQ33_STATES, inputs=MIXER_INPUTS, delays_s=delays)


def hover_derivatives(model: LinearModel) -> dict[str, float]:
    """Read the Table 3.3 parameters off an eq. 3.3 model.

    Parameters
    ----------
    model : LinearModel
        States :data:`EQ33_STATES`, inputs :data:`MIXER_INPUTS`.

    Returns
    -------
    dict of str to float
        ``X_u M_u X_lon M_lon Y_v L_v Y_lat L_lat N_r N_yaw Z_w Z_thr T_a tau_*``.
    """
    i = {name: k for k, name in enumerate(model.states)}
    a, b = model.a, model.b
    values = {
        "X_u": a[i["u"], i["u"]],
        "M_u": a[i["q"], i["u"]],
        "X_lon": a[i["u"], i["d_lon"]],
        "M_lon": a[i["q"], i["d_lon"]],
        "Y_v": a[i["v"], i["v"]],
        "L_v": a[i["p"], i["v"]],
        "Y_lat": a[i["v"], i["d_lat"]],
        "L_lat": a[i["p"], i["d_lat"]],
        "N_r": a[i["r"], i["r"]],
        "N_yaw": b[i["r"], 2],
        "Z_w": a[i["w"], i["w"]],
        "Z_thr": a[i["w"], i["d_thr"]],
        "T_a": -1.0 / a[i["d_lat"], i["d_lat"]],
    }
    values |= {f"tau_{name.split('_')[1]}": model.delays_s.get(name, 0.0) for name in MIXER_INPUTS}
    return {key: float(value) for key, value in values.items()}


def compare_eigenvalues(reference: LinearModel, other: LinearModel, *, zero_tol: float = 1e-9) -> EigenComparison:
    """Pair each reference eigenvalue with one of `other`'s (least total distance) and give the errors.

    Parameters
    ----------
    reference : LinearModel
        Reference model.
    other : LinearModel
        Model compared (at least as many states).
    zero_tol : float, optional
        Reference eigenvalues smaller than this (1/s) are compared absolutely.

    Returns
    -------
    EigenComparison
    """
    ref, oth = reference.eigenvalues, other.eigenvalues
    cost = np.abs(ref[:, None] - oth[None, :])
    rows, cols = optimize.linear_sum_assignment(cost)
    order = np.argsort(rows)
    ref_sorted, paired = ref[rows[order]], oth[cols[order]]
    scale = np.where(np.abs(ref_sorted) > zero_tol, np.abs(ref_sorted), 1.0)
    return EigenComparison(reference=ref_sorted, paired=paired, error=np.abs(paired - ref_sorted) / scale)
