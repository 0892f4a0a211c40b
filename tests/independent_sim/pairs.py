"""Discrepancy pairs (issue 15): two flights of one plan, the REAL one with plant parameters changed.

The plan: lon, lat and yaw log chirps (0.1-6 Hz, 40 s, 6-8 % of the mixer range) in hover, then a
15 m reposition north and back; 200 s in all, as PX4 ULog. A pair's REAL flight has its own noise
seed and some :class:`~independent_sim.plant.HoverPlant` fields set to other values (a longer delay,
a slower actuator, more speed damping); nothing in the log says which.

:func:`physics_pair_case` flies a longer plan (240 s) that adds a low hover (0.35 m for 20 s) after
the repositions, for physics outside the plant (:mod:`independent_sim.effects`) or a wind.

:func:`open_pair_case` flies a 250 s plan that also shows the newer physics (:mod:`independent_sim.effects_more`,
:mod:`independent_sim.effects_outside`): faster repositions (20 m in 5 s, over 5 m/s), a climb and a descent of
4 m at 2 m/s, and the real sensors' nuisances (:mod:`independent_sim.nuisances`) on SIM and REAL alike.
"""

from __future__ import annotations

from independent_sim.effects import Effect
from independent_sim.forcing import AnyEffect
from independent_sim.maneuvers import Chirp, Maneuver
from independent_sim.nuisances import DEFAULT_NUISANCES, Nuisances
from independent_sim.plant import hover_plant
from independent_sim.scenario import Case, FlightPlan, HeightChange, Reposition
from independent_sim.wind import WindModel

__all__ = [
    "PLANT",
    "Changes",
    "delayed",
    "scaled",
    "pair_case",
    "physics_pair_case",
    "open_pair_case",
    "OPEN_PLAN",
    "LOW_HOVER_M",
]

#: The plant both flights start from (Table 3.3, calm).
PLANT = hover_plant("calm")
_AXES = ("lat", "lon", "yaw", "thr")

#: Plant fields and their new values.
Changes = tuple[tuple[str, float], ...]


def delayed(extra_s: float) -> Changes:
    """Every input's delay longer by `extra_s`, s."""
    return tuple((f"tau_{a}", getattr(PLANT, f"tau_{a}") + extra_s) for a in _AXES)


def scaled(factor: float, *fields: str) -> Changes:
    """The plant's `fields` times `factor`."""
    return tuple((f, factor * getattr(PLANT, f)) for f in fields)


#: Height of the low hover of :func:`physics_pair_case`, m.
LOW_HOVER_M = 0.35
_REPOSITIONS = (Reposition(start_s=150.0, north_m=15.0), Reposition(start_s=170.0, north_m=-15.0))


def _sweeps() -> tuple[Maneuver, ...]:
    sweep = Chirp(duration_s=40.0, f_min_hz=0.1, f_max_hz=6.0)
    return tuple(
        Maneuver(axis=axis, design=sweep, start_s=start, amplitude=amplitude)  # type: ignore[arg-type]
        for axis, start, amplitude in (("lon", 10.0, 0.06), ("lat", 56.0, 0.07), ("yaw", 102.0, 0.08))
    )


def pair_case(name: str, seed: int, changes: Changes) -> Case:
    """One flight of the pair plan, with the plant `changes` (none for SIM)."""
    plan = FlightPlan(duration_s=200.0, repositions=_REPOSITIONS)
    return Case(name=name, fmt="ulog", plan=plan, maneuvers=_sweeps(), seed=seed, plant_changes=changes)


def physics_pair_case(
    name: str,
    seed: int,
    *,
    changes: Changes = (),
    effects: tuple[Effect, ...] = (),
    wind: WindModel | None = None,
) -> Case:
    """One flight of the longer plan with a low hover: sweeps, repositions, 20 s at 0.35 m, landing.

    Parameters
    ----------
    name : str
        Case name.
    seed : int
        Noise seed.
    changes : Changes
        Plant fields set to other values (none for SIM).
    effects : tuple of Effect
        Physics outside the plant acting on this vehicle (none for SIM).
    wind : WindModel or None
        A wind for the calm airframe (the anemometer's CSV is written with the log).
    """
    down = 4.6 - LOW_HOVER_M
    plan = FlightPlan(
        duration_s=240.0,
        repositions=_REPOSITIONS,
        height_changes=(HeightChange(start_s=188.0, down_m=down), HeightChange(start_s=213.0, down_m=-down)),
    )
    return Case(
        name=name,
        fmt="ulog",
        plan=plan,
        maneuvers=_sweeps(),
        seed=seed,
        plant_changes=changes,
        wind=wind,
        effects=effects,
    )


_DOWN = 4.6 - LOW_HOVER_M
#: The plan of :func:`open_pair_case` (times after take-off): chirps on lon (10-50 s), lat (56-96 s) and yaw
#: (102-142 s); 20 m north in 5 s at 146 s and back at 160 s (peak 5.3 m/s); up 4 m in 3 s at 174 s and down
#: at 183 s (2 m/s); down to 0.35 m at 192 s, 20 s there, up at 217 s; landing from 243 s; 250 s in all.
OPEN_PLAN = FlightPlan(
    duration_s=250.0,
    repositions=(Reposition(start_s=146.0, north_m=20.0), Reposition(start_s=160.0, north_m=-20.0)),
    height_changes=(
        HeightChange(start_s=174.0, down_m=-4.0, duration_s=3.0),
        HeightChange(start_s=183.0, down_m=4.0, duration_s=3.0),
        HeightChange(start_s=192.0, down_m=_DOWN),
        HeightChange(start_s=217.0, down_m=-_DOWN),
    ),
)


def open_pair_case(
    name: str,
    seed: int,
    *,
    effects: tuple[AnyEffect, ...] = (),
    nuisances: Nuisances | None = DEFAULT_NUISANCES,
    changes: Changes = (),
    wind: WindModel | None = None,
) -> Case:
    """One flight of the open plan (:data:`OPEN_PLAN`): sweeps, fast repositions, a climb, a low hover; PX4 ULog.

    Parameters
    ----------
    name : str
        Case name.
    seed : int
        Noise seed (the nuisances draw from it too).
    effects : tuple of AnyEffect
        Physics acting on this vehicle, in or outside the search's catalogue (none for SIM).
    nuisances : Nuisances or None
        Vibration, gyro drift and logging gaps, on SIM and REAL alike; None switches them off.
    changes : Changes
        Plant fields set to other values (none for SIM).
    wind : WindModel or None
        A wind for the calm airframe (the anemometer's CSV is written with the log).

    Returns
    -------
    Case

    Examples
    --------
    >>> from independent_sim.effects_outside import MixerCrossCoupling
    >>> case = open_pair_case("real", 3, effects=(MixerCrossCoupling(),))
    >>> case.plan.duration_s, case.nuisances is not None
    (250.0, True)
    """
    return Case(
        name=name,
        fmt="ulog",
        plan=OPEN_PLAN,
        maneuvers=_sweeps(),
        seed=seed,
        plant_changes=changes,
        wind=wind,
        effects=effects,
        nuisances=nuisances,
    )
