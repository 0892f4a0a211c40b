"""Altitude controllers of chapter 2 (section 2.5.3): PID (eq. 2.14) and PID + MRAC (eqs. 2.15-2.26).

Both follow :class:`~simulator.flights.altitude.AltitudeController`: ``reset`` once,
then ``step`` per control period with the measured height and climb rate,
returning the PWM per rotor. They work on a batch of trials at once.

The PID's output is the PWM of every rotor (Table 2.5's gains are in PWM
counts; the thrust feedforward gain k_T = 1 of Table 2.4 passes T_c to the
motors as PWM). Its integrator starts at the PWM that holds the vehicle where
the loop engages (Crazyflie's ROS controller sets it to the lift-off thrust)
and stops integrating while the PWM is saturated in the direction of the
error. The derivative acts on the measured climb rate (``de/dt = -v_z`` while
the command is held). Eq. 2.14 differentiates the error itself, which at a
step adds one control period of ``K_d dz_c/dt``: at 200 Hz that saturates the
PWM for 5 ms, lengthened every rise time in the simulator by 0.05-0.2 s and
moved no MRAC/PID rise-time ratio by more than one point, so the kick is
left out.

The MRAC adds ``u_adp = -Theta_hat^T Phi(z)`` (eq. 2.17, total thrust in N,
converted to PWM per rotor by ``n k_f``, eq. 2.6) with
``Theta_hat' = Gamma Phi e^T P B`` (eq. 2.19), ``B = [0, 1/m]`` from the heave
row of eq. 2.10 (T is the total thrust; with Theta_hat in PWM counts and
``Gamma = 1e-3`` the adaptive thrust would be ``n k_f`` = 8.3e-6 times weaker
and the MRAC would do nothing), and the tracking error of eq. A.4,
``e = x - x_ref`` with ``x = [z, v_z]`` and ``x_ref = [z_ref, v_z,ref]`` the
two states of the reference model eq. 2.20 ("x = [z, v_z] and u_cmd = [z_c]",
section 2.5.3). Eq. 2.20's second state is not the rate of its first (its
first row is ``z' = v_z - 0.1145 z_c``): with a held command ``v_z,ref`` settles
at ``0.1145 z_c``, so after a climb the law holds the vehicle about 2 % of
the step above the command, against the PID's integrator, and on it after a
descent to where the loop engaged, as the tables' take-off steady-state
errors, larger than the landing ones, suggest.
The reference model runs from the height at which the loop engages
(eq. 2.15 is linearised about hover).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from simulator.flights.altitude import CRAZYFLIE_ALTITUDE, AltitudeVehicle
from simulator.mrac.adaptive import Regressor, RegressorKind, adaptive_law
from simulator.mrac.reference import REFERENCE_EQ_2_20, ReferenceModel

__all__ = ["PidGains", "PidAltitude", "AdaptiveHistory", "MracAltitude"]


@dataclass(frozen=True, slots=True, kw_only=True)
class PidGains:
    """Gains of the z loop in PWM counts (Table 2.5).

    Parameters
    ----------
    kp_pwm_per_m : float
        Proportional gain, counts per m of height error.
    ki_pwm_per_m_s : float
        Integral gain, counts per (m s).
    kd_pwm_s_per_m : float
        Derivative gain, counts per (m/s).
    """

    kp_pwm_per_m: float = 42692.2
    ki_pwm_per_m_s: float = 8219.7
    kd_pwm_s_per_m: float = 55434.8

    def __post_init__(self) -> None:
        if min(self.kp_pwm_per_m, self.ki_pwm_per_m_s, self.kd_pwm_s_per_m) < 0:
            raise ValueError(f"{self} gains must be >= 0")


class PidAltitude:
    """PID height controller, eq. 2.14, output PWM per rotor.

    Parameters
    ----------
    gains : PidGains, optional
        Table 2.5's z gains by default.
    vehicle : AltitudeVehicle, optional
        Gives the PWM limits.

    Examples
    --------
    >>> pid = PidAltitude()
    >>> pid.reset(np.array([0.0]), np.array([40000.0]))
    >>> pid.step(np.array([0.0]), np.array([0.0]), 0.01, 0.005)  # 40000 + Kp * 0.01
    array([40426.922])
    """

    def __init__(self, gains: PidGains = PidGains(), *, vehicle: AltitudeVehicle = CRAZYFLIE_ALTITUDE) -> None:
        self.gains = gains
        self.vehicle = vehicle
        self._integral = np.zeros(0)

    @property
    def integral_pwm(self) -> np.ndarray:
        """Integrator state, counts, shape (n_trials,)."""
        return self._integral.copy()

    def reset(self, height_m: np.ndarray, trim_pwm: np.ndarray) -> None:
        """Engage at rest: the integrator holds `trim_pwm`.

        Parameters
        ----------
        height_m : ndarray, shape (n_trials,)
            Height, m (unused by the PID).
        trim_pwm : ndarray, shape (n_trials,)
            PWM per rotor that holds the vehicle, counts.
        """
        self._integral = np.array(trim_pwm, dtype=np.float64).reshape(-1).copy()

    def step(
        self,
        height_m: np.ndarray,
        climb_rate_m_s: np.ndarray,
        command_m: np.ndarray | float,
        dt_s: float,
        *,
        offset_pwm: np.ndarray | float = 0.0,
    ) -> np.ndarray:
        """PWM per rotor for the next period; advances the integrator.

        Parameters
        ----------
        height_m : ndarray, shape (n_trials,)
            Measured height, m.
        climb_rate_m_s : ndarray, shape (n_trials,)
            Measured climb rate, m/s.
        command_m : ndarray, shape (n_trials,), or float
            Commanded height, m.
        dt_s : float
            Control period, s.
        offset_pwm : ndarray or float, optional
            Added to the PID output before the limits (the MRAC's share), counts.

        Returns
        -------
        ndarray, shape (n_trials,)
            PWM, counts, within ``[idle, pwm_max]``.
        """
        g, vehicle = self.gains, self.vehicle
        error = command_m - np.asarray(height_m)
        raw = self._integral + g.kp_pwm_per_m * error - g.kd_pwm_s_per_m * np.asarray(climb_rate_m_s) + offset_pwm
        pwm = np.clip(raw, vehicle.idle_pwm, vehicle.pwm_max)
        winding = ((raw > vehicle.pwm_max) & (error > 0)) | ((raw < vehicle.idle_pwm) & (error < 0))
        self._integral = self._integral + np.where(winding, 0.0, g.ki_pwm_per_m_s * error * dt_s)
        return pwm


@dataclass(frozen=True, slots=True, kw_only=True)
class AdaptiveHistory:
    """What an MRAC did at each control step (values before that step's update).

    Parameters
    ----------
    theta : ndarray, shape (n_steps, n_trials, n_basis)
        Estimates Theta_hat, N per unit of each basis function.
    reference_height_m : ndarray, shape (n_steps, n_trials)
        Height of the reference model, m.
    adaptive_thrust_n : ndarray, shape (n_steps, n_trials)
        ``u_adp = -Theta_hat^T Phi``, total thrust, N.
    labels : tuple of str
        Name of each basis function.
    """

    theta: np.ndarray
    reference_height_m: np.ndarray
    adaptive_thrust_n: np.ndarray
    labels: tuple[str, ...] = field(default=())

    def __post_init__(self) -> None:
        shape = np.shape(self.theta)
        if len(shape) != 3 or shape[2] != len(self.labels):
            raise ValueError(f"theta has shape {shape}, expected (n_steps, n_trials, {len(self.labels)})")
        for name in ("reference_height_m", "adaptive_thrust_n"):
            if np.shape(getattr(self, name)) != shape[:2]:
                raise ValueError(f"{name} has shape {np.shape(getattr(self, name))}, expected {shape[:2]}")


class MracAltitude:
    """PID plus model reference adaptive control of the height (eq. 2.26), with the history of Theta_hat.

    Parameters
    ----------
    regressor : {"linear", "rbf"} or Regressor, optional
        Basis of the matched uncertainty (eqs. 2.21, 2.24).
    vehicle : AltitudeVehicle, optional
        Mass (for B) and thrust per PWM count.
    pid_gains : PidGains, optional
        The baseline loop (Table 2.5).
    reference : ReferenceModel, optional
        Eq. 2.20 by default.
    gamma : float, optional
        Adaptation rate, ``Gamma = gamma I`` (chapter 2: 1e-3).
    q_diag : tuple of float, optional
        Diagonal of Q in eq. A.8 (chapter 2: 100, 1).

    Examples
    --------
    >>> mrac = MracAltitude("rbf")
    >>> mrac.reset(np.array([0.0]), np.array([40000.0]))
    >>> _ = mrac.step(np.array([0.0]), np.array([0.0]), 0.05, 0.005)
    >>> mrac.history().theta.shape
    (1, 1, 7)
    """

    def __init__(
        self,
        regressor: RegressorKind | Regressor = "linear",
        *,
        vehicle: AltitudeVehicle = CRAZYFLIE_ALTITUDE,
        pid_gains: PidGains = PidGains(),
        reference: ReferenceModel = REFERENCE_EQ_2_20,
        gamma: float = 1e-3,
        q_diag: tuple[float, float] = (100.0, 1.0),
    ) -> None:
        if gamma <= 0:
            raise ValueError(f"{gamma=} must be > 0")
        self.regressor = regressor if isinstance(regressor, Regressor) else Regressor(regressor)
        self.vehicle = vehicle
        self.pid = PidAltitude(pid_gains, vehicle=vehicle)
        self.reference = reference
        self.gamma = float(gamma)
        self.p = reference.lyapunov(np.diag(np.asarray(q_diag, dtype=np.float64)))
        self.b = np.array([0.0, 1.0 / vehicle.mass_kg])
        self.p_b = self.p @ self.b
        self._dt = 0.0
        self._ad, self._bd = np.eye(2), np.zeros(2)
        self._theta = np.zeros((0, self.regressor.n_basis))
        self._origin = np.zeros(0)
        self._x_ref = np.zeros((0, 2))
        self._log: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []

    @property
    def theta(self) -> np.ndarray:
        """Current estimates, shape (n_trials, n_basis)."""
        return self._theta.copy()

    def reset(self, height_m: np.ndarray, trim_pwm: np.ndarray) -> None:
        """Engage at rest at `height_m`: Theta_hat = 0, the reference model at rest there, history cleared.

        Parameters
        ----------
        height_m : ndarray, shape (n_trials,)
            Height, m.
        trim_pwm : ndarray, shape (n_trials,)
            PWM per rotor that holds the vehicle, counts.
        """
        self.pid.reset(height_m, trim_pwm)
        self._origin = np.array(height_m, dtype=np.float64).reshape(-1).copy()
        self._theta = np.zeros((self._origin.size, self.regressor.n_basis))
        self._x_ref = np.zeros((self._origin.size, 2))
        self._log = []

    def step(
        self, height_m: np.ndarray, climb_rate_m_s: np.ndarray, command_m: np.ndarray | float, dt_s: float
    ) -> np.ndarray:
        """PWM per rotor for the next period; advances the reference model and Theta_hat.

        Parameters
        ----------
        height_m : ndarray, shape (n_trials,)
            Measured height, m.
        climb_rate_m_s : ndarray, shape (n_trials,)
            Measured climb rate, m/s.
        command_m : ndarray, shape (n_trials,), or float
            Commanded height, m.
        dt_s : float
            Control period, s.

        Returns
        -------
        ndarray, shape (n_trials,)
            PWM, counts.
        """
        if dt_s != self._dt:
            self._ad, self._bd = self.reference.discretize(dt_s)
            self._dt = dt_s
        height = np.asarray(height_m, dtype=np.float64)
        rate = np.asarray(climb_rate_m_s, dtype=np.float64)
        command = np.asarray(command_m, dtype=np.float64) - self._origin
        phi = self.regressor(height)
        error = np.column_stack([height - self._origin - self._x_ref[:, 0], rate - self._x_ref[:, 1]])  # eq. A.4
        adaptive = -np.einsum("nk,nk->n", self._theta, phi)
        pwm = self.pid.step(height, rate, command_m, dt_s, offset_pwm=adaptive / self.vehicle.thrust_per_pwm_n)
        self._log.append((self._theta, self._origin + self._x_ref[:, 0], adaptive))
        self._theta = self._theta + dt_s * adaptive_law(phi, error, self.p_b, self.gamma)
        self._x_ref = self._x_ref @ self._ad.T + command[:, None] * self._bd[None, :]
        return pwm

    def history(self) -> AdaptiveHistory:
        """Theta_hat, the reference height and the adaptive thrust at every step since `reset`.

        Returns
        -------
        AdaptiveHistory
        """
        n, k = self._origin.size, self.regressor.n_basis
        if not self._log:
            return AdaptiveHistory(
                theta=np.zeros((0, n, k)),
                reference_height_m=np.zeros((0, n)),
                adaptive_thrust_n=np.zeros((0, n)),
                labels=self.regressor.labels,
            )
        theta, reference, adaptive = zip(*self._log)
        return AdaptiveHistory(
            theta=np.stack(theta),
            reference_height_m=np.stack(reference),
            adaptive_thrust_n=np.stack(adaptive),
            labels=self.regressor.labels,
        )
