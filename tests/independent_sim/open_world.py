"""The open world's discrepancy cases: what each REAL vehicle carries, and the answer a search owes it.

Read by the open-world tests (one seed per case, and the rates over many seeds). The order of
:func:`open_world_cases` is the order the REAL flights take their seeds in.
"""

from __future__ import annotations

from independent_sim.effects import GroundCushion, OffsetCentre
from independent_sim.effects_more import AirframeDrag, ClimbInflow, MotorWear, ThrustCeiling, TranslationalLift
from independent_sim.effects_more import GyroScale as _GyroScale  # a sensor: not physics
from independent_sim.effects_outside import MixerCrossCoupling, SpeedPitchMoment, SwingingPayload
from independent_sim.pairs import delayed, scaled

__all__ = ["NAMED", "SENSORS", "CATALOGUED", "OUTSIDE", "CEILING", "open_world_cases"]

#: Catalogue effects: name -> (the effect concealed, the REAL vehicle's effects, its plant changes).
NAMED = {
    "worn_motors_thrust": ("control_effectiveness", (MotorWear(thrust_fraction=0.30),), ()),
    "worn_motors_moments": (
        "control_effectiveness",
        (MotorWear(thrust_fraction=0.0, roll_fraction=0.20, pitch_fraction=0.20),),
        (),
    ),
    "parasitic_drag": ("parasitic_drag", (AirframeDrag(),), ()),
    "inflow": ("inflow", (ClimbInflow(),), ()),
    "translational_lift": ("translational_lift", (TranslationalLift(),), ()),
    "ground_effect": ("ground_effect", (GroundCushion(),), ()),
    "cg_offset": ("cg_offset", (OffsetCentre(),), ()),
    "time_delay": ("time_delay", (), delayed(0.015)),
    "actuator_lag": ("actuator_lag", (), scaled(1.6, "T_a")),
}
#: A sensor's error, flown after every other case (the earlier cases keep the seeds they were first read with).
SENSORS = {"gyro_scale": ("sensor_scale", (_GyroScale(),), ())}  # p +4 %, q -3 %, r +5 %
#: Every case the catalogue names: the physics, then the sensors.
CATALOGUED = NAMED | SENSORS
#: Effects outside the catalogue: the right answer is ``unexplained`` on one of their primary outputs.
OUTSIDE = {
    "swinging_payload": SwingingPayload(),
    "mixer_cross_coupling": MixerCrossCoupling(),
    "speed_pitch_moment": SpeedPitchMoment(),
}
#: A hard per-motor thrust ceiling: named first, not alone (the lost moments leave a second finding).
CEILING = ThrustCeiling()


def open_world_cases(
    nulls: int = 1, *, ceiling: bool = True
) -> dict[str, tuple[tuple[object, ...], tuple[tuple[str, float], ...]]]:
    """Case name -> (the REAL vehicle's effects, its plant changes): `nulls` nulls first, the named, the outside.

    Parameters
    ----------
    nulls : int, optional
        How many REAL flights of the same vehicle (``none``, ``none-1`` ...).
    ceiling : bool, optional
        Add the thrust ceiling after the outside effects.

    The sensors' cases come last (:data:`SENSORS`).
    """
    cases: dict[str, tuple[tuple[object, ...], tuple[tuple[str, float], ...]]] = {
        ("none" if j == 0 else f"none-{j}"): ((), ()) for j in range(nulls)
    }
    cases |= {name: (effects, changes) for name, (_, effects, changes) in NAMED.items()}
    cases |= {name: ((effect,), ()) for name, effect in OUTSIDE.items()}
    if ceiling:
        cases["thrust_ceiling"] = ((CEILING,), ())
    cases |= {name: (effects, changes) for name, (_, effects, changes) in SENSORS.items()}
    return cases
