"""SIM / REAL pairs with a concealed effect, written as PX4 logs: for ``sysid demo --discrepancy``, tests, benchmarks.

A pair is two flights of one mission (hover at 3 m, lon, lat and yaw sweeps, height steps down to
0.3 m and back), the REAL one with an effect the SIM one lacks, its timing stretched by a few
percent, another noise seed. Nothing in the files says which effect is there.
"""

from __future__ import annotations

import dataclasses
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, Literal

from simulator.autopilot.control import HeightSteps
from simulator.autopilot.excitation import Maneuver
from simulator.flights.nonlinear import simulate_flights
from simulator.flights.trial import Trial
from simulator.output.px4 import write_px4_log
from simulator.vehicle.presets import OCTO_S1000
from simulator.world.environment import Environment, GroundEffect, PayloadChange

__all__ = ["DURATION_S", "EFFECTS", "MODERATE", "mission", "write_pairs", "write_pair_set"]

DURATION_S = 160.0
#: Effect name -> (environment changes, vehicle changes) at the "strong" strength.
EFFECTS: dict[str, tuple[dict[str, Any], dict[str, Any]]] = {
    "none": ({}, {}),
    "ground_effect": ({"ground_effect": GroundEffect(model="exponential")}, {}),
    "battery_sag": ({"thrust_sag": True}, {}),
    "mass_change": ({"payload": PayloadChange(time_s=70.0, delta_mass_kg=0.4)}, {}),
    "cg_offset": ({"cg_offset_m": (0.02, 0.0, 0.0)}, {}),
    "time_delay": ({}, {"delays_s": OCTO_S1000.delays_s + 0.03}),
    "actuator_lag": ({}, {"motor_time_constant_s": OCTO_S1000.motor_time_constant_s * 1.6}),
}
_BASE: dict[str, Any] = {"ground_effect": GroundEffect(model="none"), "rotor_drag": True, "thrust_sag": False}


_SWEEPS: tuple[tuple[Literal["lat", "lon", "yaw", "thr"], float, float, float, float], ...] = (
    ("lon", 8.0, 6.0, 30.0, 6.0),  # axis, start s, amplitude %, length s, top frequency Hz
    ("lat", 42.0, 6.0, 30.0, 6.0),
    ("yaw", 76.0, 8.0, 20.0, 4.0),
)


def mission(environment: Environment, seed: int, stretch: float = 0.0) -> Trial:
    """The mission, its events moved by ``1 + stretch``.

    Parameters
    ----------
    environment : Environment
        Wind, ground effect, payload, CG, battery sag of the flight.
    seed : int
        Noise seed.
    stretch : float, optional
        Relative change of the events' times (0.02: 2 % later).
    """
    s = 1.0 + stretch
    sweeps = tuple(
        Maneuver(
            axis=axis,
            kind="sweep",
            start_s=start * s,
            amplitude=amplitude,
            duration_s=length,
            f_start_hz=0.3,
            f_stop_hz=f_stop,
            fade_in_s=2.0,
        )
        for axis, start, amplitude, length, f_stop in _SWEEPS
    )
    steps = HeightSteps(
        times_s=(0.0, 100 * s, 112 * s, 124 * s, 136 * s, 148 * s), heights_m=(3.0, 1.2, 0.5, 0.3, 0.6, 2.0)
    )
    return Trial(
        duration_s=DURATION_S,
        maneuvers=sweeps,
        environment=environment,
        seed=seed,
        hover_height_m=3.0,
        height_steps=steps,
        battery_used_ah=6.0,
    )


def write_pairs(effects: list[str], folder: Path, seed: int = 1) -> tuple[Path, dict[str, Path]]:
    """One SIM ULog and a REAL ULog per effect ("none": a null pair), written into `folder`.

    The flights of one vehicle fly as one batch; an effect of the vehicle itself (delay, lag) flies alone.
    Each REAL flight has its own noise seed and its events moved by 2 %.

    Parameters
    ----------
    effects : list of str
        Keys of :data:`EFFECTS`.
    folder : Path
        Where to write.
    seed : int, optional
        Noise seed of SIM (each REAL flight another).

    Returns
    -------
    sim : Path
        The simulated flight's log.
    reals : dict of str to Path
        Each effect's real flight log.
    """
    start = datetime(2024, 6, 1, 10, 0, tzinfo=UTC)
    same = [e for e in effects if not EFFECTS[e][1]]
    trials = [mission(Environment(**_BASE), seed)] + [
        mission(Environment(**{**_BASE, **EFFECTS[e][0]}), seed + 1000 + k, 0.02) for k, e in enumerate(same)
    ]
    flown = dict(zip(["sim", *same], simulate_flights(trials, OCTO_S1000, method="euler")))
    for k, effect in enumerate(e for e in effects if EFFECTS[e][1]):
        vehicle = dataclasses.replace(OCTO_S1000, **EFFECTS[effect][1])
        trial = mission(Environment(**_BASE), seed + 2000 + k, 0.02)
        (flown[effect],) = simulate_flights([trial], vehicle, method="euler")
    sim = write_px4_log(flown.pop("sim"), folder / f"sim-{seed}.ulg", utc_start=start)
    return sim, {e: write_px4_log(f, folder / f"real-{e}-{seed}.ulg", utc_start=start) for e, f in flown.items()}


#: The same effects at half strength ("moderate"; battery sag has one strength: the pack's own).
MODERATE: dict[str, tuple[dict[str, Any], dict[str, Any]]] = {
    "ground_effect": ({"ground_effect": GroundEffect(model="exponential", a=0.1372)}, {}),
    "battery_sag": EFFECTS["battery_sag"],
    "mass_change": ({"payload": PayloadChange(time_s=70.0, delta_mass_kg=0.2)}, {}),
    "cg_offset": ({"cg_offset_m": (0.01, 0.0, 0.0)}, {}),
    "time_delay": ({}, {"delays_s": OCTO_S1000.delays_s + 0.015}),
    "actuator_lag": ({}, {"motor_time_constant_s": OCTO_S1000.motor_time_constant_s * 1.3}),
}


def write_pair_set(
    pairs: dict[str, list[tuple[dict[str, Any], dict[str, Any]]]], folder: Path, seed: int
) -> tuple[Path, dict[str, Path]]:
    """One SIM ULog and a REAL ULog per named pair, each pair a list of (environment, vehicle) changes combined.

    The REAL flights with the simulated vehicle fly as one batch with SIM; the others one by one.

    Parameters
    ----------
    pairs : dict of str to list of (dict, dict)
        Name -> the (environment changes, vehicle changes) combined in its REAL flight.
    folder : Path
        Where to write.
    seed : int
        Noise seed of SIM.

    Returns
    -------
    sim : Path
        The simulated flight's log.
    reals : dict of str to Path
        Each pair's real flight log.
    """
    start = datetime(2024, 6, 1, 10, 0, tzinfo=UTC)
    combined = {}
    for name, parts in pairs.items():
        environment: dict[str, Any] = {}
        vehicle: dict[str, Any] = {}
        for env_part, vehicle_part in parts:
            environment.update(env_part)
            vehicle.update(vehicle_part)
        combined[name] = (environment, vehicle)
    same = [n for n, (_, v) in combined.items() if not v]
    trials = [mission(Environment(**_BASE), seed)] + [
        mission(Environment(**{**_BASE, **combined[n][0]}), seed + 1000 + k, 0.02) for k, n in enumerate(same)
    ]
    flown = dict(zip(["sim", *same], simulate_flights(trials, OCTO_S1000, method="euler")))
    for k, name in enumerate(n for n, (_, v) in combined.items() if v):
        environment, vehicle = combined[name]
        trial = mission(Environment(**{**_BASE, **environment}), seed + 2000 + k, 0.02)
        (flown[name],) = simulate_flights([trial], dataclasses.replace(OCTO_S1000, **vehicle), method="euler")
    sim = write_px4_log(flown.pop("sim"), folder / f"sim-{seed}.ulg", utc_start=start)
    return sim, {n: write_px4_log(f, folder / f"real-{n}-{seed}.ulg", utc_start=start) for n, f in flown.items()}
