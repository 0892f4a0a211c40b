"""What the PID gains imply near the ground: stiffnesses, the integrator's time constant, closed-loop poles.

In ground effect the thrust at a fixed PWM falls as the vehicle climbs, a
spring of stiffness ``k_ge = -dT/dz`` that resists any change of height. The
proportional term moves the vehicle only ``k_p / (k_p + k_ge)`` of a step;
the rest waits for the integrator, whose closed-loop time constant is
``(k_p + k_ge) / k_i``. The MRAC's bias estimate adds an integral action of
``Gamma (P B)_z = Gamma p_12 / m`` per unit ``|Phi|^2`` on the height error.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simulator.flights.altitude import CRAZYFLIE_ALTITUDE, AltitudeVehicle, ThrustRatioModel
from simulator.mrac.controllers import PidGains
from simulator.mrac.reference import REFERENCE_EQ_2_20, ReferenceModel
from simulator.world.environment import GroundEffect

__all__ = ["LoopAnalysis", "loop_analysis"]


@dataclass(frozen=True, slots=True, kw_only=True)
class LoopAnalysis:
    """The PID z loop linearised at one height (thrust in N, heights in m).

    Parameters
    ----------
    height_m : float
        Height above the resting position, m.
    height_ratio : float
        Z/R there.
    proportional_stiffness_n_m : float
        ``Kp n k_f``, N/m.
    ground_stiffness_n_m : float
        ``-dT/dz`` at the PWM that holds the weight there, N/m.
    integral_gain_n_m_s : float
        ``Ki n k_f``, N/(m s).
    derivative_gain_n_s_m : float
        ``Kd n k_f``, N s/m.
    adaptive_integral_gain_n_m_s : float
        ``Gamma p_12 / m``: the MRAC's integral action on the height error per unit ``|Phi|^2``, N/(m s).
    integrator_time_constant_s : float
        ``(k_p + k_ge) / k_i``, s.
    pid_poles : ndarray, shape (3,), complex
        Roots of ``m s^3 + k_d s^2 + (k_p + k_ge) s + k_i`` (no motor lag), rad/s.
    reference_poles : ndarray, shape (2,), complex
        Poles of the reference model, rad/s.
    """

    height_m: float
    height_ratio: float
    proportional_stiffness_n_m: float
    ground_stiffness_n_m: float
    integral_gain_n_m_s: float
    derivative_gain_n_s_m: float
    adaptive_integral_gain_n_m_s: float
    integrator_time_constant_s: float
    pid_poles: np.ndarray
    reference_poles: np.ndarray

    def __post_init__(self) -> None:
        if np.shape(self.pid_poles) != (3,) or np.shape(self.reference_poles) != (2,):
            raise ValueError("pid_poles must have shape (3,) and reference_poles (2,)")

    @property
    def proportional_share(self) -> float:
        """Fraction of a step the proportional term closes alone, ``k_p / (k_p + k_ge)``."""
        return self.proportional_stiffness_n_m / (self.proportional_stiffness_n_m + self.ground_stiffness_n_m)

    @property
    def integrator_rise_time_s(self) -> float:
        """10-90 % rise time, s, if the P share is immediate and the rest ``exp(-t/tau)`` (0: P reaches 90 %)."""
        rest = 1.0 - self.proportional_share
        if rest <= 0.1:
            return 0.0
        return self.integrator_time_constant_s * float(np.log(rest / 0.1))


def loop_analysis(
    height_m: float,
    *,
    vehicle: AltitudeVehicle = CRAZYFLIE_ALTITUDE,
    ground_effect: ThrustRatioModel | None = None,
    gains: PidGains = PidGains(),
    gamma: float = 1e-3,
    q_diag: tuple[float, float] = (100.0, 1.0),
    reference: ReferenceModel = REFERENCE_EQ_2_20,
) -> LoopAnalysis:
    """Linearise the PID z loop with ground effect at `height_m`.

    Parameters
    ----------
    height_m : float
        Height above the resting position, m.
    vehicle : AltitudeVehicle, optional
        Heave parameters.
    ground_effect : ThrustRatioModel or None, optional
        F/F0 against Z/R; default eq. 2.5.
    gains : PidGains, optional
        Table 2.5 by default.
    gamma : float, optional
        MRAC adaptation rate.
    q_diag : tuple of float, optional
        Diagonal of Q (eq. A.8).
    reference : ReferenceModel, optional
        Eq. 2.20 by default.

    Returns
    -------
    LoopAnalysis

    Examples
    --------
    >>> out = loop_analysis(CRAZYFLIE_ALTITUDE.height_for_ratio(4.0))
    >>> round(out.proportional_stiffness_n_m, 3), round(out.ground_stiffness_n_m, 2)
    (0.356, 0.61)
    >>> round(out.integrator_time_constant_s, 1)
    14.1
    """
    law: ThrustRatioModel = ground_effect if ground_effect is not None else GroundEffect(model="fitted_4rotor")
    weight = vehicle.mass_kg * vehicle.gravity_m_s2
    dz = 1e-4
    heights = np.array([max(height_m - dz, 0.0), height_m, height_m + dz])
    ratio = np.asarray(law.ratio(vehicle.height_ratio(heights)), dtype=np.float64)
    slope = (ratio[2] - ratio[0]) / (heights[2] - heights[0])
    k_ge = float(-weight * slope / ratio[1]) + 0.0  # no "-0" out of ground effect
    per_pwm = vehicle.thrust_per_pwm_n
    k_p, k_i, k_d = gains.kp_pwm_per_m * per_pwm, gains.ki_pwm_per_m_s * per_pwm, gains.kd_pwm_s_per_m * per_pwm
    p = reference.lyapunov(np.diag(np.asarray(q_diag, dtype=np.float64)))
    poles = np.roots([vehicle.mass_kg, k_d, k_p + k_ge, k_i])
    return LoopAnalysis(
        height_m=float(height_m),
        height_ratio=float(vehicle.height_ratio(np.array(height_m))),
        proportional_stiffness_n_m=k_p,
        ground_stiffness_n_m=k_ge,
        integral_gain_n_m_s=k_i,
        derivative_gain_n_s_m=k_d,
        adaptive_integral_gain_n_m_s=float(gamma * p[0, 1] / vehicle.mass_kg),
        integrator_time_constant_s=(k_p + k_ge) / k_i if k_i > 0 else float("inf"),
        pid_poles=poles[np.argsort(-poles.real)],
        reference_poles=reference.poles(),
    )
