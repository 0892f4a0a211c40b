"""Physics outside the plant as disturbance accelerations, computed step by step from the state reached.

Every effect of :mod:`.effects`, :mod:`.effects_more` and :mod:`.effects_outside` is a force or moment
that the closed loop feels at every control step. :class:`EffectForcing` turns the plant state the loop
has reached (a :class:`Step`) into accelerations added to the plant's unmeasured disturbance inputs
:data:`FORCED` (``dist_u dist_v dist_w`` m/s², ``dist_p dist_q dist_r`` rad/s²). The accelerometers read
the state derivative (eq. 3.7), so they feel these as a real force would be felt.

The effects of :mod:`.effects` keep their laws here (a ground cushion, a battery fade, a payload picked
up, a CG off the thrust axis); the newer effects carry their own law (``effect.law(context)``, which may
keep a state of its own, e.g. a swinging load). Sensor errors (:class:`~.effects_more.GyroScale`,
:class:`~.effects_more.AccelScale`) act at measurement time and force nothing.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from independent_sim.effects import BatteryFade, Effect, GroundCushion, OffsetCentre, PayloadPickUp, pack_voltage
from independent_sim.effects_more import (
    AccelScale,
    AirframeDrag,
    ClimbInflow,
    GyroScale,
    MotorWear,
    ThrustCeiling,
    TranslationalLift,
)
from independent_sim.effects_outside import MixerCrossCoupling, SpeedPitchMoment, SwingingPayload
from independent_sim.step import PlantContext, Step

__all__ = ["FORCED", "AnyEffect", "EffectForcing", "effect_forcing", "Step", "PlantContext"]

#: Effects act through these plant inputs (unmeasured disturbance accelerations), in this order.
FORCED = ("dist_u", "dist_v", "dist_w", "dist_p", "dist_q", "dist_r")

#: Every effect a REAL vehicle may carry.
AnyEffect = (
    Effect
    | MotorWear
    | AirframeDrag
    | ClimbInflow
    | TranslationalLift
    | ThrustCeiling
    | GyroScale
    | AccelScale
    | SwingingPayload
    | MixerCrossCoupling
    | SpeedPitchMoment
)
_SENSORS = (GyroScale, AccelScale)
_CLASSIC = (GroundCushion, BatteryFade, PayloadPickUp, OffsetCentre)
Law = Callable[[Step], np.ndarray]


@dataclass(frozen=True, slots=True)
class EffectForcing:
    """The effects of one flight as disturbance accelerations, step by step.

    Parameters
    ----------
    effects : tuple of AnyEffect
        What acts (sensor errors are skipped: they force nothing).
    context : PlantContext
        The plant's constants the laws need.
    """

    effects: tuple[AnyEffect, ...]
    context: PlantContext

    def laws(self) -> list[Law]:
        """A fresh law per effect for one flight (an effect with a state of its own starts at rest)."""
        out: list[Law] = []
        for effect in self.effects:
            if isinstance(effect, _SENSORS):
                continue
            if isinstance(effect, _CLASSIC):
                out.append(_classic_law(effect, self.context))
            else:
                out.append(effect.law(self.context))
        return out


def _classic_law(effect: Effect, c: PlantContext) -> Law:
    """The laws of :mod:`.effects` (thrust ``T = g - Z_thr d_thr``, m/s², up) as a 6-vector of accelerations."""

    def law(s: Step) -> np.ndarray:
        thrust = s.thrust
        force, roll, pitch = 0.0, 0.0, 0.0
        if isinstance(effect, GroundCushion):
            z = max(s.height_m, 0.0) + effect.rotor_above_m
            force = thrust * effect.gain * np.exp(-z / effect.decay_m)
        elif isinstance(effect, BatteryFade):
            volts = pack_voltage(np.array([s.thrust_command]), np.array([s.t_s]))[0]
            fade = (volts / effect.full_v) ** effect.exponent - 1.0
            force = thrust * fade
            roll = fade * c.l_lat * s.d_lat
            pitch = fade * c.m_lon * s.d_lon
        elif isinstance(effect, PayloadPickUp):
            if s.t_s >= effect.at_s:
                force = -thrust * effect.ratio / (1.0 + effect.ratio)
        else:
            roll = effect.roll_rad_m * thrust
            pitch = effect.pitch_rad_m * thrust
        return np.array([0.0, 0.0, -force, roll, pitch, 0.0])  # more thrust: w (down) decelerates

    return law


def effect_forcing(effects: Sequence[AnyEffect], context: PlantContext) -> EffectForcing | None:
    """The step-by-step forcing of `effects`, or None when none of them forces the plant.

    Parameters
    ----------
    effects : sequence of AnyEffect
        The vehicle's effects.
    context : PlantContext
        The plant's constants.

    Returns
    -------
    EffectForcing or None
    """
    if not any(not isinstance(e, _SENSORS) for e in effects):
        return None
    return EffectForcing(tuple(effects), context)
