"""Hover autopilot for the nonlinear simulator: cascaded PID loops, excitation at the mixer input.

Loops, outer to inner (all vectorised over a batch of trials):

- horizontal position (P) -> ground velocity (PI) -> acceleration -> roll and pitch set-points;
- height (P) -> climb rate (PI) -> vertical acceleration -> ``delta_thr`` with tilt compensation;
- angles (P) -> body rates (PI) -> ``delta_lat, delta_lon, delta_yaw``.

The computer-generated excitation is added to the controller's output, at
the mixer input, where PX4 and ArduPilot inject System ID signals; the
logged mixer input is that sum. Gains come from the hover model (Table 3.3
names) by loop shaping (:func:`design_gains`).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Literal, cast

import numpy as np

from simulator.autopilot.excitation import Axis, Maneuver, excitation_signal, multisine, three_two_one_one

__all__ = [
    "ControllerGains",
    "design_gains",
    "Injection",
    "HeightSteps",
    "Legs",
    "excitation_table",
    "initial_controller_state",
    "controller_step",
    "N_CONTROLLER_STATES",
]

#: Integrators: rate p, q, r (%), acceleration north, east (m/s^2), climb (m/s^2).
N_CONTROLLER_STATES = 6
_AXES: tuple[Axis, ...] = ("lat", "lon", "yaw", "thr")


@dataclass(frozen=True, slots=True, kw_only=True)
class ControllerGains:
    """Gains and limits of the cascaded hover controller.

    Parameters
    ----------
    rate_kp : tuple of float
        Roll, pitch, yaw rate proportional gains, % per rad/s.
    rate_ki : tuple of float
        Rate integral gains, % per rad.
    angle_kp : tuple of float
        Roll, pitch, heading gains, 1/s.
    velocity_kp : float
        Horizontal velocity gain, m/s^2 per m/s.
    velocity_ki : float
        Horizontal velocity integral gain, m/s^2 per m.
    position_kp : float
        Horizontal position gain, 1/s.
    height_kp : float
        Height gain, 1/s.
    climb_kp : float
        Climb-rate gain, m/s^2 per m/s.
    climb_ki : float
        Climb-rate integral gain, m/s^2 per m.
    thrust_pct_per_m_s2 : float
        ``delta_thr`` per upward acceleration, % per m/s^2 (-1/Z_thr).
    max_rate_rad_s : float
        Rate set-point limit, rad/s.
    max_tilt_rad : float
        Roll and pitch set-point limit, rad.
    max_speed_m_s : float
        Horizontal speed set-point limit, m/s.
    max_climb_m_s : float
        Climb-rate set-point limit, m/s.
    """

    rate_kp: tuple[float, float, float]
    rate_ki: tuple[float, float, float]
    angle_kp: tuple[float, float, float]
    velocity_kp: float
    velocity_ki: float
    position_kp: float
    height_kp: float
    climb_kp: float
    climb_ki: float
    thrust_pct_per_m_s2: float
    max_rate_rad_s: float = 2.5
    max_tilt_rad: float = 0.6
    max_speed_m_s: float = 3.0
    max_climb_m_s: float = 1.5

    def __post_init__(self) -> None:
        values = (
            *self.rate_kp,
            *self.rate_ki,
            *self.angle_kp,
            self.velocity_kp,
            self.velocity_ki,
            self.position_kp,
            self.height_kp,
            self.climb_kp,
            self.climb_ki,
            self.thrust_pct_per_m_s2,
        )
        if len(values) != 16 or min(values) < 0:
            raise ValueError("gains must be three per attitude axis and all >= 0")


def _per_axis(values: Iterable[float]) -> tuple[float, float, float]:
    """Roll, pitch and yaw values as a triple."""
    roll, pitch, yaw = values
    return (roll, pitch, yaw)


def design_gains(
    derivatives: Mapping[str, float],
    *,
    rate_crossover_rad_s: tuple[float, float, float] = (10.0, 10.0, 4.0),
    angle_ratio: float = 0.4,
    velocity_crossover_rad_s: float = 1.0,
    height_crossover_rad_s: float = 1.0,
) -> ControllerGains:
    """Loop-shaped gains from a hover model.

    Parameters
    ----------
    derivatives : Mapping[str, float]
        ``L_lat M_lon N_yaw Z_thr`` (per % of mixer input).
    rate_crossover_rad_s : tuple of float, optional
        Rate-loop crossover of roll, pitch, yaw, rad/s. With T_a = 0.046 s
        and 20 ms delay, 10 rad/s keeps about 40 deg of phase margin.
    angle_ratio : float, optional
        Angle-loop bandwidth over the rate loop's.
    velocity_crossover_rad_s : float, optional
        Velocity loop crossover, rad/s (position loop at 0.4 of it).
    height_crossover_rad_s : float, optional
        Height loop crossover, rad/s (climb loop at 3 times it).

    Returns
    -------
    ControllerGains

    Notes
    -----
    The rate plant is ``L_lat / s`` (roll), so ``K_p = omega_c / L_lat``;
    the integrator corner is a fifth of the crossover.
    """
    effectiveness = (abs(derivatives["L_lat"]), abs(derivatives["M_lon"]), abs(derivatives["N_yaw"]))
    rate_kp = _per_axis(w / e for w, e in zip(rate_crossover_rad_s, effectiveness))
    rate_ki = _per_axis(k * w / 5.0 for k, w in zip(rate_kp, rate_crossover_rad_s))
    angle_kp = _per_axis(angle_ratio * w for w in rate_crossover_rad_s)
    climb = 3.0 * height_crossover_rad_s
    return ControllerGains(
        rate_kp=rate_kp,
        rate_ki=rate_ki,
        angle_kp=angle_kp,
        velocity_kp=velocity_crossover_rad_s,
        velocity_ki=0.2 * velocity_crossover_rad_s**2,
        position_kp=0.4 * velocity_crossover_rad_s,
        height_kp=height_crossover_rad_s,
        climb_kp=climb,
        climb_ki=0.2 * climb**2,
        thrust_pct_per_m_s2=1.0 / abs(derivatives["Z_thr"]),
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class Injection:
    """A 3-2-1-1 or multisine excitation on one mixer axis (sweeps and doublets are :class:`Maneuver`).

    Parameters
    ----------
    axis : {"lat", "lon", "yaw", "thr"}
        Mixer input it is summed into.
    kind : {"3211", "multisine"}
        Signal.
    start_s : float
        Start, s.
    amplitude : float
        Peak, %.
    duration_s : float
        Length, s (a 3-2-1-1's shortest pulse is a seventh of it).
    f_min_hz, f_max_hz : float
        Multisine band, Hz.
    n_tones : int
        Multisine tones.
    """

    axis: Axis
    kind: Literal["3211", "multisine"]
    start_s: float
    amplitude: float
    duration_s: float
    f_min_hz: float = 0.1
    f_max_hz: float = 10.0
    n_tones: int = 30

    def __post_init__(self) -> None:
        if self.axis not in _AXES or self.kind not in ("3211", "multisine") or self.duration_s <= 0:
            raise ValueError(f"bad injection: axis={self.axis!r}, kind={self.kind!r}, duration_s={self.duration_s}")

    @property
    def end_s(self) -> float:
        """End time, s."""
        return self.start_s + self.duration_s

    def signal(self, time_s: np.ndarray) -> np.ndarray:
        """The excitation, %, shape (n_samples,).

        Parameters
        ----------
        time_s : ndarray, shape (n_samples,)
            Times, s.

        Returns
        -------
        ndarray, shape (n_samples,)
        """
        if self.kind == "3211":
            return three_two_one_one(time_s, self.start_s, self.amplitude, self.duration_s / 7.0)
        return multisine(
            time_s,
            self.start_s,
            self.duration_s,
            self.amplitude,
            f_min_hz=self.f_min_hz,
            f_max_hz=self.f_max_hz,
            n_tones=self.n_tones,
        )


@dataclass(frozen=True, slots=True)
class HeightSteps:
    """A piecewise-constant height reference (chapter 2's hover steps near the ground).

    Parameters
    ----------
    times_s : tuple of float
        Start of each step, s (increasing; the first applies from time 0).
    heights_m : tuple of float
        Height of the CG above ground held from each time, m.
    """

    times_s: tuple[float, ...]
    heights_m: tuple[float, ...]

    def __post_init__(self) -> None:
        if len(self.times_s) != len(self.heights_m) or not self.times_s or np.any(np.diff(self.times_s) <= 0):
            raise ValueError("times_s and heights_m must be non-empty, of equal length, times increasing")

    def reference(self, time_s: np.ndarray) -> np.ndarray:
        """Height reference, m, shape (n_samples,).

        Parameters
        ----------
        time_s : ndarray, shape (n_samples,)
            Times, s.

        Returns
        -------
        ndarray, shape (n_samples,)
        """
        return _held(self.times_s, self.heights_m, time_s)

    @classmethod
    def ground_effect_descent(
        cls,
        rotor_radius_m: float,
        *,
        ratios: tuple[float, ...] = (10, 4, 3, 2),
        hold_s: float = 10.0,
        rotor_height_m: float = 0.0,
    ) -> HeightSteps:
        """Chapter 2's flight test: start at Z/R = 10 and step down, holding each height.

        Parameters
        ----------
        rotor_radius_m : float
            Propeller radius R, m.
        ratios : tuple of float, optional
            Rotor-plane height over R at each step.
        hold_s : float, optional
            Hold per step, s (chapter 2: 10 s).
        rotor_height_m : float, optional
            Rotor plane above the CG, m (subtracted to get the CG height).

        Returns
        -------
        HeightSteps
        """
        return cls(
            tuple(hold_s * k for k in range(len(ratios))), tuple(r * rotor_radius_m - rotor_height_m for r in ratios)
        )


@dataclass(frozen=True, slots=True)
class Legs:
    """A piecewise-constant horizontal position reference: legs flown between hover points.

    Parameters
    ----------
    times_s : tuple of float
        Start of each hold, s (increasing; the first applies from time 0).
    north_m : tuple of float
        North position held from each time, m (from the take-off point).
    east_m : tuple of float
        East position held from each time, m.

    Notes
    -----
    The position loop flies each leg at up to its speed limit
    (:attr:`ControllerGains.max_speed_m_s`).
    """

    times_s: tuple[float, ...]
    north_m: tuple[float, ...]
    east_m: tuple[float, ...]

    def __post_init__(self) -> None:
        if not (len(self.times_s) == len(self.north_m) == len(self.east_m)) or not self.times_s:
            raise ValueError("times_s, north_m and east_m must be non-empty and of equal length")
        if np.any(np.diff(self.times_s) <= 0):
            raise ValueError("times_s must increase")

    def reference(self, time_s: np.ndarray) -> np.ndarray:
        """North and east position reference, m, shape (n_samples, 2).

        Parameters
        ----------
        time_s : ndarray, shape (n_samples,)
            Times, s.

        Returns
        -------
        ndarray, shape (n_samples, 2)
        """
        return np.column_stack([_held(self.times_s, self.north_m, time_s), _held(self.times_s, self.east_m, time_s)])


def _held(times_s: tuple[float, ...], values: tuple[float, ...], time_s: np.ndarray) -> np.ndarray:
    """Each value held from its time to the next (the first also before it), at `time_s`."""
    index = np.clip(np.searchsorted(times_s, time_s, side="right") - 1, 0, None)
    return np.asarray(values, dtype=np.float64)[index]


def excitation_table(
    time_s: np.ndarray, maneuvers: tuple[Maneuver, ...], injections: tuple[Injection, ...] = ()
) -> np.ndarray:
    """Excitation on the four mixer inputs, %, shape (n_samples, 4) (lat, lon, yaw, thr).

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Times, s.
    maneuvers : tuple of Maneuver
        Sweeps and doublets.
    injections : tuple of Injection, optional
        3-2-1-1s and multisines.

    Returns
    -------
    ndarray, shape (n_samples, 4)
    """
    table = np.column_stack([excitation_signal(time_s, maneuvers, axis) for axis in _AXES])
    for injection in injections:
        table[:, _AXES.index(injection.axis)] += injection.signal(time_s)
    return table


def initial_controller_state(
    gains: ControllerGains, euler: np.ndarray, mixer_trim: np.ndarray, gravity_m_s2: float = 9.81
) -> np.ndarray:
    """Integrator values that hold a trim without a transient.

    Parameters
    ----------
    gains : ControllerGains
        Gains.
    euler : ndarray, shape (n_trials, 3)
        Trim roll, pitch, yaw, rad.
    mixer_trim : ndarray, shape (n_trials, 4)
        Trim mixer inputs, %.
    gravity_m_s2 : float, optional
        Gravity, m/s^2.

    Returns
    -------
    ndarray, shape (n_trials, N_CONTROLLER_STATES)
    """
    phi, theta, psi = euler[:, 0], euler[:, 1], euler[:, 2]
    a_x = -gravity_m_s2 * np.tan(theta)
    a_y = gravity_m_s2 * np.tan(phi) / np.cos(theta)
    state = np.zeros((euler.shape[0], N_CONTROLLER_STATES))
    state[:, 0:3] = mixer_trim[:, 0:3]
    state[:, 3] = np.cos(psi) * a_x - np.sin(psi) * a_y
    state[:, 4] = np.sin(psi) * a_x + np.cos(psi) * a_y
    tilt = gravity_m_s2 * (1.0 / (np.cos(phi) * np.cos(theta)) - 1.0)
    state[:, 5] = mixer_trim[:, 3] / gains.thrust_pct_per_m_s2 - tilt
    return state


def _clip(value: np.ndarray, low: float, high: float) -> np.ndarray:
    return cast(np.ndarray, np.minimum(np.maximum(value, low), high))


def _euler(quaternion: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    w, x, y, z = quaternion[:, 0], quaternion[:, 1], quaternion[:, 2], quaternion[:, 3]
    phi = np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    theta = np.arcsin(np.clip(2.0 * (w * y - z * x), -1.0, 1.0))
    psi = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return phi, theta, psi


def controller_step(
    gains: ControllerGains,
    integrators: np.ndarray,
    state: np.ndarray,
    reference: np.ndarray,
    dt_s: float,
    gravity_m_s2: float = 9.81,
) -> tuple[np.ndarray, np.ndarray]:
    """One controller update for a batch: mixer inputs and the updated integrators.

    Parameters
    ----------
    gains : ControllerGains
        Gains.
    integrators : ndarray, shape (n_trials, N_CONTROLLER_STATES)
        Integrator values.
    state : ndarray, shape (n_trials, n_states)
        Vehicle states as the estimator reports them (the simulator adds estimation errors).
    reference : ndarray, shape (n_trials, 4)
        North, east (m), height above ground (m), heading (rad) to hold.
    dt_s : float
        Update interval, s.
    gravity_m_s2 : float, optional
        Gravity, m/s^2.

    Returns
    -------
    mixer_input : ndarray, shape (n_trials, 4)
        ``delta_lat, delta_lon, delta_yaw, delta_thr``, % (before excitation).
    integrators : ndarray, shape (n_trials, N_CONTROLLER_STATES)
    """
    g = gains
    phi, theta, psi = _euler(state[:, 6:10])
    out_i = integrators.copy()
    # horizontal: position -> velocity -> acceleration -> tilt
    v_n = _clip(g.position_kp * (reference[:, 0] - state[:, 0]), -g.max_speed_m_s, g.max_speed_m_s)
    v_e = _clip(g.position_kp * (reference[:, 1] - state[:, 1]), -g.max_speed_m_s, g.max_speed_m_s)
    e_n, e_e = v_n - state[:, 3], v_e - state[:, 4]
    out_i[:, 3] = _clip(integrators[:, 3] + g.velocity_ki * e_n * dt_s, -6.0, 6.0)
    out_i[:, 4] = _clip(integrators[:, 4] + g.velocity_ki * e_e * dt_s, -6.0, 6.0)
    a_n, a_e = g.velocity_kp * e_n + out_i[:, 3], g.velocity_kp * e_e + out_i[:, 4]
    cos_psi, sin_psi = np.cos(psi), np.sin(psi)
    a_x, a_y = cos_psi * a_n + sin_psi * a_e, -sin_psi * a_n + cos_psi * a_e
    theta_sp = _clip(np.arctan2(-a_x, gravity_m_s2), -g.max_tilt_rad, g.max_tilt_rad)
    phi_sp = _clip(np.arctan2(a_y * np.cos(theta_sp), gravity_m_s2), -g.max_tilt_rad, g.max_tilt_rad)
    # attitude: angle -> rate -> mixer
    heading_error = np.angle(np.exp(1j * (reference[:, 3] - psi)))
    errors = (phi_sp - phi, theta_sp - theta, heading_error)
    mixer = np.empty((state.shape[0], 4))
    for k in range(3):
        rate_sp = _clip(g.angle_kp[k] * errors[k], -g.max_rate_rad_s, g.max_rate_rad_s)
        e_rate = rate_sp - state[:, 10 + k]
        out_i[:, k] = _clip(integrators[:, k] + g.rate_ki[k] * e_rate * dt_s, -40.0, 40.0)
        mixer[:, k] = g.rate_kp[k] * e_rate + out_i[:, k]
    # height: height -> climb -> acceleration -> thrust
    climb_sp = _clip(g.height_kp * (reference[:, 2] + state[:, 2]), -g.max_climb_m_s, g.max_climb_m_s)
    e_climb = climb_sp + state[:, 5]
    out_i[:, 5] = _clip(integrators[:, 5] + g.climb_ki * e_climb * dt_s, -8.0, 8.0)
    tilt = gravity_m_s2 * (1.0 / np.maximum(np.cos(phi) * np.cos(theta), 0.5) - 1.0)
    mixer[:, 3] = (g.climb_kp * e_climb + out_i[:, 5] + tilt) * g.thrust_pct_per_m_s2
    return mixer, out_i
