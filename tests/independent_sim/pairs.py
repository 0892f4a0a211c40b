"""Discrepancy pairs (issue 15): two flights of one plan, the REAL one with plant parameters changed.

The plan: lon, lat and yaw log chirps (0.1-6 Hz, 40 s, 6-8 % of the mixer range) in hover, then a
15 m reposition north and back; 200 s in all, as PX4 ULog. A pair's REAL flight has its own noise
seed and some :class:`~independent_sim.plant.HoverPlant` fields set to other values (a longer delay,
a slower actuator, more speed damping); nothing in the log says which.
"""

from __future__ import annotations

from independent_sim.maneuvers import Chirp, Maneuver
from independent_sim.plant import hover_plant
from independent_sim.scenario import Case, FlightPlan, Reposition

__all__ = ["PLANT", "Changes", "delayed", "scaled", "pair_case"]

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


def pair_case(name: str, seed: int, changes: Changes) -> Case:
    """One flight of the pair plan, with the plant `changes` (none for SIM)."""
    sweep = Chirp(duration_s=40.0, f_min_hz=0.1, f_max_hz=6.0)
    maneuvers = tuple(
        Maneuver(axis=axis, design=sweep, start_s=start, amplitude=amplitude)  # type: ignore[arg-type]
        for axis, start, amplitude in (("lon", 10.0, 0.06), ("lat", 56.0, 0.07), ("yaw", 102.0, 0.08))
    )
    plan = FlightPlan(
        duration_s=200.0,
        repositions=(Reposition(start_s=150.0, north_m=15.0), Reposition(start_s=170.0, north_m=-15.0)),
    )
    return Case(name=name, fmt="ulog", plan=plan, maneuvers=maneuvers, seed=seed, plant_changes=changes)
