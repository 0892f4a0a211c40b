"""More physics for the REAL vehicle of a discrepancy pair: worn rotors, drag, inflow, lift, a thrust ceiling, sensors.

Each is one of the search's newer catalogue entries by name, with a law and constants of this generator's own
(written without reading the search's terms). The laws act on the specific thrust of the linear plant,
``T = g - Z_thr d_thr`` (m/s², up; ``d_thr`` the lagged thrust input about trim), on the lagged mixer inputs
(what the rotors produce) and on the body air-relative velocity ``V = (U0 + u, v, W0 + w)`` (m/s, FRD: the
wind is in it when the case has one):

=================  =====================================================================================
effect             law (added acceleration; ``δ`` a mixer input with its trim, as the rotors produce it)
=================  =====================================================================================
MotorWear          thrust ``(1 - f_T) T``; moments ``(1 - f_i) L_lat δ_lat`` ... (worn motors or props)
AirframeDrag       ``a = -k |V| V`` on u and v (``k_v`` on w): drag of the airframe, quadratic
ClimbInflow        thrust ``T (1 - c (V_c + v_i(V_c) - v_h) / v_h)``, ``v_i`` the momentum-theory inflow
TranslationalLift  thrust ``T (1 + c V_h² / (V_h² + V_ref²))``, ``V_h`` the horizontal airspeed
ThrustCeiling      each motor's output stops at a ceiling command: the thrust and moments it would add are lost
GyroScale          logged ``p q r`` times ``1 + e`` per axis (at measurement; the loop's gyro is calibrated)
AccelScale         logged ``ax ay az`` times ``1 + e`` per axis (at measurement)
=================  =====================================================================================

A law is ``effect.law(context)``: a function of one :class:`~independent_sim.step.Step` returning the
accelerations ``(dist_u, dist_v, dist_w, dist_p, dist_q, dist_r)`` (m/s², rad/s²; w is down, so more thrust
is a negative ``dist_w``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from independent_sim._mixer import MOTOR_MIX, UNMIX
from independent_sim.step import PlantContext, Step

__all__ = [
    "MotorWear",
    "AirframeDrag",
    "ClimbInflow",
    "TranslationalLift",
    "ThrustCeiling",
    "GyroScale",
    "AccelScale",
]

Law = Callable[[Step], np.ndarray]


def _thrust_change(ratio_minus_one: float, thrust: float) -> np.ndarray:
    """Accelerations of a thrust ``T (1 + x)``: ``dist_w = -x T`` (w is down)."""
    return np.array([0.0, 0.0, -ratio_minus_one * thrust, 0.0, 0.0, 0.0])


@dataclass(frozen=True, slots=True, kw_only=True)
class MotorWear:
    """Worn motors or props: thrust and moments per unit command ``1 - fraction`` of the simulation's.

    ``T_real = (1 - thrust_fraction) T``, ``L_real = (1 - roll_fraction) L_lat δ_lat``, and the same for
    pitch (M_lon) and yaw (N_yaw, the yaw input after its delay). The closed loop compensates: at hover
    ``(1 - f) (g - Z_thr d_thr) = g`` gives a thrust input higher by ``g f / ((1 - f) |Z_thr|)``.

    Parameters
    ----------
    thrust_fraction : float
        Share of the thrust per unit command lost, 0 ≤ f < 1.
    roll_fraction, pitch_fraction, yaw_fraction : float
        Share of each moment per unit command lost, 0 ≤ f < 1.
    """

    thrust_fraction: float = 0.30
    roll_fraction: float = 0.0
    pitch_fraction: float = 0.0
    yaw_fraction: float = 0.0

    def __post_init__(self) -> None:
        for name in ("thrust_fraction", "roll_fraction", "pitch_fraction", "yaw_fraction"):
            if not 0.0 <= getattr(self, name) < 0.8:
                raise ValueError(f"{name}={getattr(self, name)} must be within [0, 0.8)")

    def law(self, context: PlantContext) -> Law:
        """The accelerations of the wear at one step (see the class)."""
        moments = np.array([self.roll_fraction * context.l_lat, self.pitch_fraction * context.m_lon])
        yaw = self.yaw_fraction * context.n_yaw

        def accelerations(s: Step) -> np.ndarray:
            lat, lon, yaw_input, _ = s.commands
            roll, pitch = -moments * (lat, lon)
            return np.array([0.0, 0.0, self.thrust_fraction * s.thrust, roll, pitch, -yaw * yaw_input])

        return accelerations


@dataclass(frozen=True, slots=True, kw_only=True)
class AirframeDrag:
    """Parasitic drag of the airframe, quadratic in the air-relative speed: ``a = -k |V| V``.

    The linear plant's X_u and Y_v stay; this is the drag they leave out. At 5 m/s the default adds
    0.75 m/s² against the motion (the plant's own X_u u: 1.6 m/s²).

    Parameters
    ----------
    horizontal_per_m : float
        k on u and v, 1/m (``ρ C_D A / 2 m``).
    vertical_per_m : float
        k on w, 1/m.
    """

    horizontal_per_m: float = 0.03
    vertical_per_m: float = 0.0

    def __post_init__(self) -> None:
        if self.horizontal_per_m < 0.0 or self.vertical_per_m < 0.0:
            raise ValueError("drag coefficients must be ≥ 0")

    def law(self, context: PlantContext) -> Law:
        """The drag's accelerations at one step (see the class)."""
        k = np.array([self.horizontal_per_m, self.horizontal_per_m, self.vertical_per_m])

        def accelerations(s: Step) -> np.ndarray:
            velocity = s.air_m_s
            drag = -k * float(np.linalg.norm(velocity)) * velocity
            return np.array([drag[0], drag[1], drag[2], 0.0, 0.0, 0.0])

        return accelerations


@dataclass(frozen=True, slots=True, kw_only=True)
class ClimbInflow:
    """Thrust that falls in a climb and rises in a descent: more air through the disc, less blade angle.

    ``T_real = T (1 - gain (V_c + v_i - v_h) / v_h)`` with ``V_c = -(W0 + w)`` the axial climb speed (m/s,
    up through the disc) and ``v_i = -V_c / 2 + sqrt(V_c² / 4 + v_h²)`` the induced velocity of momentum
    theory. At 2 m/s the default loses 9.9 % of the thrust; at 2 m/s down it gains 7.9 %.

    Parameters
    ----------
    gain : float
        Thrust ratio lost per unit of extra flow through the disc (over v_h).
    hover_inflow_m_s : float
        Induced velocity in hover, v_h, m/s.
    """

    gain: float = 0.4
    hover_inflow_m_s: float = 4.5

    def __post_init__(self) -> None:
        if not 0.0 <= self.gain < 2.0 or self.hover_inflow_m_s <= 0.0:
            raise ValueError(f"{self.gain=} must be within [0, 2) and {self.hover_inflow_m_s=} m/s > 0")

    def ratio(self, climb_m_s: float) -> float:
        """Thrust over the simulation's at an axial climb speed (m/s, up)."""
        v_h = self.hover_inflow_m_s
        induced = -0.5 * climb_m_s + math.sqrt(0.25 * climb_m_s**2 + v_h**2)
        return 1.0 - self.gain * (climb_m_s + induced - v_h) / v_h

    def law(self, context: PlantContext) -> Law:
        """The inflow's accelerations at one step (see the class)."""
        return lambda s: _thrust_change(self.ratio(-float(s.air_m_s[2])) - 1.0, s.thrust)


@dataclass(frozen=True, slots=True, kw_only=True)
class TranslationalLift:
    """Thrust that grows with the horizontal airspeed and levels off: ``T (1 + gain V_h² / (V_h² + V_ref²))``.

    ``V_h = sqrt((U0 + u)² + v²)`` (m/s). At 5 m/s the default adds 7.3 % of thrust, at 3 m/s 4.3 %.

    Parameters
    ----------
    gain : float
        Thrust ratio gained at high speed, minus one.
    speed_m_s : float
        Airspeed of half the gain, V_ref, m/s.
    """

    gain: float = 0.12
    speed_m_s: float = 4.0

    def __post_init__(self) -> None:
        if not 0.0 <= self.gain < 1.0 or self.speed_m_s <= 0.0:
            raise ValueError(f"{self.gain=} must be within [0, 1) and {self.speed_m_s=} m/s > 0")

    def ratio(self, speed_m_s: float) -> float:
        """Thrust over the simulation's at a horizontal airspeed (m/s)."""
        return 1.0 + self.gain * speed_m_s**2 / (speed_m_s**2 + self.speed_m_s**2)

    def law(self, context: PlantContext) -> Law:
        """The lift's accelerations at one step (see the class)."""
        return lambda s: _thrust_change(self.ratio(math.hypot(s.air_m_s[0], s.air_m_s[1])) - 1.0, s.thrust)


@dataclass(frozen=True, slots=True, kw_only=True)
class ThrustCeiling:
    """Commands above a ceiling produce no more thrust or moment (motors at full speed, or an ESC limit).

    Per motor (default): each of the eight motor commands of the X mixer
    (:data:`~independent_sim._mixer.MOTOR_MIX`) stops at `ceiling`; the mixer inputs the clipped motors amount
    to (least squares) replace the commanded ones, so a roll or pitch sweep near the ceiling loses moment
    and thrust at its peaks. Collective: only the thrust input stops at `ceiling`.

    Parameters
    ----------
    ceiling : float
        Highest command that still adds thrust, normalised (0.48: a little over the 0.45 hover; the open
        plan's sweeps and repositions drive a motor over it 10 % of the flight).
    per_motor : bool
        Motor by motor (True) or the collective thrust input only.
    """

    ceiling: float = 0.48
    per_motor: bool = True

    def __post_init__(self) -> None:
        if not 0.0 < self.ceiling <= 1.0:
            raise ValueError(f"{self.ceiling=} must be within (0, 1]")

    def lost_inputs(self, commands: np.ndarray) -> np.ndarray:
        """Change of the mixer inputs ``(lat, lon, yaw, thr)`` the ceiling makes (≤ 0 in thrust), shape (4,)."""
        if not self.per_motor:
            return np.array([0.0, 0.0, 0.0, -max(commands[3] - self.ceiling, 0.0)])
        motors = MOTOR_MIX @ commands
        over = motors - self.ceiling
        if over.max() <= 0.0:
            return np.zeros(4)
        return UNMIX @ -np.maximum(over, 0.0)

    def law(self, context: PlantContext) -> Law:
        """The accelerations the ceiling takes away at one step (see the class)."""
        gains = np.array([context.l_lat, context.m_lon, context.n_yaw])

        def accelerations(s: Step) -> np.ndarray:
            lost = self.lost_inputs(s.commands)
            moments = gains * lost[:3]
            return np.array([0.0, 0.0, context.z_thr * lost[3], moments[0], moments[1], moments[2]])

        return accelerations


@dataclass(frozen=True, slots=True, kw_only=True)
class GyroScale:
    """A gyro scale-factor error: logged ``p q r`` are ``(1 + error)`` times the true rates.

    It acts at measurement time only: the rate loop flies on a calibrated gyro (as an estimator fusing other
    sensors keeps the attitude true), so the vehicle flies as the simulation's.

    Parameters
    ----------
    p_error, q_error, r_error : float
        Scale error of each axis (0.04: reads 4 % high).
    """

    p_error: float = 0.04
    q_error: float = -0.03
    r_error: float = 0.05

    def __post_init__(self) -> None:
        for name in ("p_error", "q_error", "r_error"):
            if abs(getattr(self, name)) >= 0.5:
                raise ValueError(f"{name}={getattr(self, name)} must be within (-0.5, 0.5)")

    @property
    def scales(self) -> dict[str, float]:
        """Logged over true, by signal name."""
        return {"p": 1.0 + self.p_error, "q": 1.0 + self.q_error, "r": 1.0 + self.r_error}


@dataclass(frozen=True, slots=True, kw_only=True)
class AccelScale:
    """An accelerometer scale-factor error: logged ``ax ay az`` are ``(1 + error)`` times the true ones.

    At measurement time only (the velocity and attitude estimates stay true).

    Parameters
    ----------
    ax_error, ay_error, az_error : float
        Scale error of each axis (on ``az`` 0.03 reads hover as -10.1 m/s²).
    """

    ax_error: float = 0.03
    ay_error: float = -0.04
    az_error: float = 0.03

    def __post_init__(self) -> None:
        for name in ("ax_error", "ay_error", "az_error"):
            if abs(getattr(self, name)) >= 0.5:
                raise ValueError(f"{name}={getattr(self, name)} must be within (-0.5, 0.5)")

    @property
    def scales(self) -> dict[str, float]:
        """Logged over true, by signal name."""
        return {"ax": 1.0 + self.ax_error, "ay": 1.0 + self.ay_error, "az": 1.0 + self.az_error}
