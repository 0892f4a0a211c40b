"""Physics OUTSIDE the discrepancy search's catalogue, for a REAL vehicle whose right answer is ``unexplained``.

None of these is a ground effect, rotor drag, wind, delay, actuator lag, battery sag, mass change, CG offset,
control effectiveness (per axis), parasitic drag, inflow, translational lift, thrust saturation or sensor
scale, nor a sum of them. Each names the outputs it primarily acts on (:attr:`primary_outputs`, in
``ax ay az p_dot q_dot r_dot``), where a correct search must leave the gap unexplained:

=================  ==================================================================================
effect             law (added accelerations)
=================  ==================================================================================
SwingingPayload    a load of share ``r`` of the all-up mass on a cable of length ``l`` below the CG
                   swings (its own pendulum, damped); the cable's pull moves the lighter body:
                   ``u' += r (u'_sim + g sin β) / (1 - r)``, ``q' += r g h sin(β - θ) / k²`` (and v, p)
MixerCrossCoupling a share of the roll input acts as pitch input (a twisted motor mount):
                   ``q' += s_rp M_lon δ_lat``, ``p' += s_pr L_lat δ_lon``
SpeedPitchMoment   a hub moment growing with the airspeed (rotor flapping): ``q' += k_u (U0 + u)``,
                   ``p' += k_v v`` (rad/s² per m/s)
=================  ==================================================================================

The simulation's all-up mass is kept by the swinging payload (the simulated vehicle carries the same load
bolted on): its hover thrust is the simulation's, only the swing differs.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from independent_sim.step import PlantContext, Step

__all__ = ["OUTPUTS", "SwingingPayload", "MixerCrossCoupling", "SpeedPitchMoment"]

#: Names of the outputs an outside effect may primarily act on (specific forces m/s², angular accelerations rad/s²).
OUTPUTS = ("ax", "ay", "az", "p_dot", "q_dot", "r_dot")

Law = Callable[[Step], np.ndarray]


@dataclass(frozen=True, slots=True, kw_only=True)
class SwingingPayload:
    """A load on a cable under the vehicle, swinging as its own damped pendulum.

    The body carries ``1 - r`` of the all-up mass M (the simulation's, load included). The load hangs at
    angles ``β`` (forward) and ``γ`` (right) from the vertical, its cable fixed `attach_below_m` under the
    CG. With ``a_x`` the plant's own ``u'`` (the thrust's and drag's pull on the whole mass)::

        body:  x'' = (a_x + r g sin β) / (1 - r)                 (so u' += r (a_x + g sin β) / (1 - r))
        load:  β'' = -(g sin β + x'' cos β) / l - 2 ζ sqrt(g / l) β'
        pitch: q' += r g h sin(β - θ) / k²      roll: p' += -r g h sin(γ + φ) / k²

    and the same across (γ, v, φ). The cable's pull below the CG also adds an attitude stiffness
    (the ``-θ`` and ``+φ`` terms) that no catalogue entry has. Quasi-static, the load trails and the body
    moves as the whole mass would; the swing (``sqrt(g / ((1 - r) l))``, 0.52 Hz at the defaults) is what
    differs.

    Parameters
    ----------
    length_m : float
        Cable length to the load's centre, m.
    mass_ratio : float
        Load over the all-up mass, r.
    attach_below_m : float
        Cable's hook under the CG, h, m.
    gyration_m : float
        Radius of gyration of the vehicle about roll and pitch (over the all-up mass), k, m.
    damping_ratio : float
        Damping of the swing (air on the load), ζ.
    """

    length_m: float = 1.2
    mass_ratio: float = 0.25
    attach_below_m: float = 0.25
    gyration_m: float = 0.35
    damping_ratio: float = 0.02

    def __post_init__(self) -> None:
        if self.length_m <= 0.0 or self.gyration_m <= 0.0 or self.attach_below_m < 0.0:
            raise ValueError("length_m and gyration_m must be > 0, attach_below_m ≥ 0")
        if not 0.0 < self.mass_ratio < 0.5 or not 0.0 <= self.damping_ratio < 1.0:
            raise ValueError(f"{self.mass_ratio=} must be within (0, 0.5) and {self.damping_ratio=} within [0, 1)")

    @property
    def primary_outputs(self) -> tuple[str, ...]:
        """Outputs the swing acts on: the horizontal specific forces and the roll and pitch accelerations."""
        return ("ax", "ay", "p_dot", "q_dot")

    def law(self, context: PlantContext) -> Law:
        """The swing's accelerations, step by step (the load starts hanging still)."""
        return _Pendulum(self, context)


class _Pendulum:
    """The load's two swing angles and rates, advanced one control period per call (semi-implicit Euler)."""

    def __init__(self, load: SwingingPayload, context: PlantContext) -> None:
        self.load, self.context = load, context
        self.angles = np.zeros(2)  # β forward, γ right, rad
        self.rates = np.zeros(2)  # rad/s

    def __call__(self, s: Step) -> np.ndarray:
        load, g, dt = self.load, self.context.gravity, self.context.period_s
        r, length = load.mass_ratio, load.length_m
        sines = np.sin(self.angles)
        body = (s.accel_sim + r * g * sines) / (1.0 - r)  # the body's horizontal accelerations, m/s²
        omega = math.sqrt(g / length)
        swing = -(g * sines + body * np.cos(self.angles)) / length - 2.0 * load.damping_ratio * omega * self.rates
        self.rates = self.rates + dt * swing
        self.angles = self.angles + dt * self.rates
        stiffness = r * g * load.attach_below_m / load.gyration_m**2  # rad/s² per rad of cable off the body axis
        pitch = stiffness * math.sin(self.angles[0] - (self.context.trim_theta_rad + s.theta))
        roll = -stiffness * math.sin(self.angles[1] + s.phi)
        extra = body - s.accel_sim
        return np.array([extra[0], extra[1], 0.0, roll, pitch, 0.0])


@dataclass(frozen=True, slots=True, kw_only=True)
class MixerCrossCoupling:
    """Off-diagonal control effectiveness: a share of one axis's input acts on another (a twisted mount).

    ``q' += roll_to_pitch M_lon δ_lat`` and ``p' += pitch_to_roll L_lat δ_lon``, ``δ`` the lagged inputs as
    the rotors produce them (trim included).

    Parameters
    ----------
    roll_to_pitch : float
        Share of the roll input that acts as pitch input.
    pitch_to_roll : float
        Share of the pitch input that acts as roll input.
    """

    roll_to_pitch: float = 0.15
    pitch_to_roll: float = 0.0

    def __post_init__(self) -> None:
        if max(abs(self.roll_to_pitch), abs(self.pitch_to_roll)) >= 0.5:
            raise ValueError("cross-coupling shares must be within (-0.5, 0.5)")

    @property
    def primary_outputs(self) -> tuple[str, ...]:
        """``q_dot`` for a roll-to-pitch share, ``p_dot`` for a pitch-to-roll share."""
        return tuple(name for name, share in (("p_dot", self.pitch_to_roll), ("q_dot", self.roll_to_pitch)) if share)

    def law(self, context: PlantContext) -> Law:
        """The coupled moments at one step (see the class)."""

        def accelerations(s: Step) -> np.ndarray:
            lat, lon = s.commands[0], s.commands[1]
            roll = self.pitch_to_roll * context.l_lat * lon
            pitch = self.roll_to_pitch * context.m_lon * lat
            return np.array([0.0, 0.0, 0.0, roll, pitch, 0.0])

        return accelerations


@dataclass(frozen=True, slots=True, kw_only=True)
class SpeedPitchMoment:
    """A hub moment proportional to the airspeed (rotor flapping back from the relative wind).

    ``q' += pitch_per_m_s (U0 + u)`` and ``p' += roll_per_m_s v``: a changed speed stability (M_u, L_v) that the
    simulation's airframe lacks. At 5 m/s the default adds 1.5 rad/s² (the plant's own M_u u: 3.8).

    Parameters
    ----------
    pitch_per_m_s : float
        Pitch acceleration per m/s of forward airspeed, rad/(m s) (nose up for positive).
    roll_per_m_s : float
        Roll acceleration per m/s of rightward airspeed, rad/(m s) (negative: rolls away, left).
    """

    pitch_per_m_s: float = 0.3
    roll_per_m_s: float = -0.3

    @property
    def primary_outputs(self) -> tuple[str, ...]:
        """``p_dot`` and ``q_dot`` (those of a nonzero coefficient)."""
        return tuple(name for name, k in (("p_dot", self.roll_per_m_s), ("q_dot", self.pitch_per_m_s)) if k)

    def law(self, context: PlantContext) -> Law:
        """The hub moments at one step (see the class)."""

        def accelerations(s: Step) -> np.ndarray:
            roll = self.roll_per_m_s * s.air_m_s[1]
            pitch = self.pitch_per_m_s * s.air_m_s[0]
            return np.array([0.0, 0.0, 0.0, roll, pitch, 0.0])

        return accelerations
