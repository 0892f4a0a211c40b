"""SIM / REAL pairs with a concealed effect, written as PX4 logs: for ``sysid demo --discrepancy``, tests, benchmarks.

A pair is two flights of one mission (hover at 3 m, lon, lat and yaw sweeps, legs north and east at
the speed limit, height steps down to 0.3 m and back; 4 minutes), the REAL one with an effect the SIM
one lacks, its timing stretched by a few percent, another noise seed. Nothing in the files says which
effect is there. Each effect has two strengths, scaled to the vehicle (a mass step of 5.7 % of its
mass, a CG offset of 3.8 % of its arm): ``strong`` and ``moderate`` (about half).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, Literal

import numpy as np

from simulator.autopilot.control import HeightSteps, Legs
from simulator.autopilot.excitation import Axis, Maneuver
from simulator.flights.nonlinear import simulate_flights
from simulator.flights.trial import Trial
from simulator.output.px4 import write_px4_log
from simulator.vehicle.multirotor import Vehicle
from simulator.vehicle.presets import OCTO_S1000, QUAD_X500
from simulator.world.environment import Environment, GroundEffect, PayloadChange
from simulator.world.wind_field import Wind

__all__ = [
    "DURATION_S",
    "EFFECTS",
    "STRENGTHS",
    "VEHICLES",
    "Strength",
    "changes",
    "mission",
    "write_pairs",
    "write_pair_set",
    "write_sweep_flight",
]

DURATION_S = 240.0
#: The vehicles a matrix flies.
VEHICLES: Mapping[str, Vehicle] = {"octo": OCTO_S1000, "quad": QUAD_X500}
Strength = Literal["strong", "moderate"]
STRENGTHS: tuple[Strength, ...] = ("strong", "moderate")
_SCALE: Mapping[Strength, float] = {"strong": 1.0, "moderate": 0.5}
#: (environment changes, vehicle changes) of a REAL flight.
Changes = tuple[dict[str, Any], dict[str, Any]]


def _arm_m(vehicle: Vehicle) -> float:
    return float(np.max(np.hypot(vehicle.rotor_positions_m[:, 0], vehicle.rotor_positions_m[:, 1])))


_CHANGES: Mapping[str, Callable[[Vehicle, float], Changes]] = {
    "none": lambda v, k: ({}, {}),
    # eq. 2.3 (exponential) at full strength; its constant a halved at moderate
    "ground_effect": lambda v, k: ({"ground_effect": GroundEffect(model="exponential", a=0.2744 * k)}, {}),
    # the real rotors drag 2x (1.5x) what the simulation's do
    "rotor_drag": lambda v, k: ({}, {"drag_s_m": v.drag_s_m * (1.0 + k)}),
    # the real flight in the chapter 3 strong (light) wind from 30 deg, with turbulence; the simulation in a calm
    "wind": lambda v, k: (
        {"wind": Wind.dissertation("strong" if k == 1.0 else "light", direction_from_deg=30.0, height_m=3.0)},
        {},
    ),
    "time_delay": lambda v, k: ({}, {"delays_s": v.delays_s + 0.030 * k}),
    "actuator_lag": lambda v, k: ({}, {"motor_time_constant_s": v.motor_time_constant_s * (1.0 + 0.6 * k)}),
    # the thrust follows the pack's voltage; at moderate a pack of twice the charge and half the resistance
    # (about half the sag over the mission)
    "battery_sag": lambda v, k: (
        {"thrust_sag": True},
        {}
        if k == 1.0
        else {
            "battery": replace(
                v.battery, capacity_ah=2 * v.battery.capacity_ah, resistance_ohm=v.battery.resistance_ohm / 2
            )
        },
    ),
    "mass_change": lambda v, k: ({"payload": PayloadChange(time_s=70.0, delta_mass_kg=0.057 * k * v.mass_kg)}, {}),
    "cg_offset": lambda v, k: ({"cg_offset_m": (0.038 * k * _arm_m(v), 0.0, 0.0)}, {}),
}
#: The effects a REAL flight may conceal ("none": a null pair).
EFFECTS: tuple[str, ...] = tuple(_CHANGES)
_BASE: dict[str, Any] = {"ground_effect": GroundEffect(model="none"), "rotor_drag": True, "thrust_sag": False}


def changes(effect: str, vehicle: Vehicle, strength: Strength = "strong") -> Changes:
    """The environment and vehicle changes that conceal `effect` in a REAL flight of `vehicle`.

    Parameters
    ----------
    effect : str
        One of :data:`EFFECTS`.
    vehicle : Vehicle
        The simulated vehicle.
    strength : {"strong", "moderate"}, optional
        Strength.

    Returns
    -------
    environment : dict
        :class:`~simulator.world.environment.Environment` fields.
    vehicle : dict
        :class:`~simulator.vehicle.multirotor.Vehicle` fields.
    """
    return _CHANGES[effect](vehicle, _SCALE[strength])


_SWEEPS: tuple[tuple[Axis, float, float, float, float], ...] = (
    ("lon", 8.0, 6.0, 30.0, 6.0),  # axis, start s, amplitude %, length s, top frequency Hz
    ("lat", 42.0, 6.0, 30.0, 6.0),
    ("yaw", 76.0, 8.0, 20.0, 4.0),
)
#: The sweeps a model of the simulation is fitted from: every axis, the throttle's too.
_MODEL_SWEEPS: tuple[tuple[Axis, float, float, float, float], ...] = (
    ("lon", 6.0, 6.0, 40.0, 6.0),
    ("lat", 52.0, 6.0, 40.0, 6.0),
    ("yaw", 98.0, 8.0, 30.0, 4.0),
    ("thr", 134.0, 4.0, 30.0, 4.0),
)
_LEGS = ((0.0, 0.0, 0.0), (102.0, 20.0, 0.0), (117.0, 0.0, 0.0), (132.0, 0.0, 20.0), (147.0, 0.0, 0.0))
_USED = 0.375  # share of the pack drawn before the mission
#: Height steps: (time s, CG height m) or, for the low ones, (time s, rotor-plane height over rotor radius Z/R);
#: the octocopter's 1.2, 0.5, 0.3 and 0.6 m.
_HEIGHTS: tuple[tuple[float, float, Literal["m", "Z/R"]], ...] = (
    (0.0, 3.0, "m"),
    (162.0, 6.7, "Z/R"),
    (174.0, 3.05, "Z/R"),
    (186.0, 2.0, "Z/R"),
    (198.0, 3.6, "Z/R"),
    (210.0, 2.0, "m"),
    (222.0, 3.0, "m"),
)


def mission(
    environment: Environment,
    seed: int,
    stretch: float = 0.0,
    battery_used_ah: float = 6.0,
    vehicle: Vehicle = OCTO_S1000,
) -> Trial:
    """The mission, its events moved by ``1 + stretch``, its lowest heights scaled to `vehicle`'s rotors.

    Parameters
    ----------
    environment : Environment
        Wind, ground effect, payload, CG, battery sag of the flight.
    seed : int
        Noise seed.
    stretch : float, optional
        Relative change of the events' times (0.05: 5 % later).
    battery_used_ah : float, optional
        Charge drawn before the mission, Ah.
    vehicle : Vehicle, optional
        The vehicle (its rotor radius and the rotors' height above the CG set the low steps).
    """
    s = 1.0 + stretch
    return Trial(
        duration_s=DURATION_S,
        maneuvers=_sweeps(_SWEEPS, s),
        environment=environment,
        seed=seed,
        hover_height_m=3.0,
        heading_deg=0.0,
        height_steps=HeightSteps(
            tuple(t * s for t, _, _ in _HEIGHTS), tuple(_height(h, u, vehicle) for _, h, u in _HEIGHTS)
        ),
        legs=Legs(tuple(t * s for t, _, _ in _LEGS), tuple(n for _, n, _ in _LEGS), tuple(e for _, _, e in _LEGS)),
        battery_used_ah=battery_used_ah,
    )


def _sweeps(plan: Sequence[tuple[Axis, float, float, float, float]], stretch: float = 1.0) -> tuple[Maneuver, ...]:
    """Log chirps from 0.3 Hz with a 2 s fade-in: (axis, start s, amplitude %, length s, top frequency Hz)."""
    return tuple(
        Maneuver(
            axis=axis,
            kind="sweep",
            start_s=start * stretch,
            amplitude=amplitude,
            duration_s=length,
            f_start_hz=0.3,
            f_stop_hz=f_stop,
            fade_in_s=2.0,
        )
        for axis, start, amplitude, length, f_stop in plan
    )


def write_sweep_flight(folder: Path, seed: int = 1, vehicle: Vehicle = OCTO_S1000) -> Path:
    """SIM's vehicle, in SIM's air, sweeping each axis in turn at 3 m: what a model of the simulation is fitted from.

    Parameters
    ----------
    folder : Path
        Where to write ``sweeps-{seed}.ulg``.
    seed : int, optional
        Noise seed.
    vehicle : Vehicle, optional
        The vehicle.

    Returns
    -------
    Path
        The log (for ``sysid fit --model hover``).
    """
    trial = Trial(
        duration_s=_MODEL_SWEEPS[-1][1] + _MODEL_SWEEPS[-1][3] + 8.0,
        maneuvers=_sweeps(_MODEL_SWEEPS),
        environment=Environment(**_BASE),
        seed=seed,
        hover_height_m=3.0,
        heading_deg=0.0,
        battery_used_ah=_USED * vehicle.battery.capacity_ah,
    )
    (flight,) = simulate_flights([trial], vehicle, method="euler")
    return write_px4_log(flight, folder / f"sweeps-{seed}.ulg", utc_start=datetime(2024, 6, 1, 9, 0, tzinfo=UTC))


def _height(value: float, unit: Literal["m", "Z/R"], vehicle: Vehicle) -> float:
    """CG height above ground, m, of a height given in m or as the rotor plane's Z/R."""
    if unit == "m":
        return value
    return value * vehicle.rotor_radius_m + float(np.mean(vehicle.rotor_positions_m[:, 2]))  # FRD: rotors above: z < 0


def write_pairs(
    effects: Sequence[str], folder: Path, seed: int = 1, vehicle: Vehicle = OCTO_S1000
) -> tuple[Path, dict[str, Path]]:
    """One SIM ULog and a strong REAL ULog per effect ("none": a null pair), written into `folder`.

    Parameters
    ----------
    effects : sequence of str
        Names from :data:`EFFECTS`.
    folder : Path
        Where to write.
    seed : int, optional
        Noise seed of SIM (each REAL flight another).
    vehicle : Vehicle, optional
        The vehicle both fly.

    Returns
    -------
    sim : Path
        The simulated flight's log.
    reals : dict of str to Path
        Each effect's real flight log.
    """
    return write_pair_set({e: [(e, "strong")] for e in effects}, folder, seed, vehicle)


def write_pair_set(
    pairs: Mapping[str, Sequence[tuple[str, Strength]]],
    folder: Path,
    seed: int,
    vehicle: Vehicle = OCTO_S1000,
    stretch: float = 0.02,
) -> tuple[Path, dict[str, Path]]:
    """One SIM ULog and a REAL ULog per named pair, each pair's effects combined.

    The REAL flights with the simulated vehicle fly as one batch with SIM; the others one by one.
    Each REAL flight has its own noise seed and its events moved by `stretch`, alternately later
    and earlier.

    Parameters
    ----------
    pairs : Mapping of str to sequence of (str, str)
        Name -> the (effect, strength) combined in its REAL flight.
    folder : Path
        Where to write.
    seed : int
        Noise seed of SIM.
    vehicle : Vehicle, optional
        The vehicle.
    stretch : float, optional
        Relative change of the REAL flights' event times.

    Returns
    -------
    sim : Path
        The simulated flight's log.
    reals : dict of str to Path
        Each pair's real flight log.
    """
    start = datetime(2024, 6, 1, 10, 0, tzinfo=UTC)
    combined: dict[str, Changes] = {}
    for name, parts in pairs.items():
        environment: dict[str, Any] = {}
        own: dict[str, Any] = {}
        for effect, strength in parts:
            env_part, vehicle_part = changes(effect, vehicle, strength)
            environment.update(env_part)
            own.update(vehicle_part)
        combined[name] = (environment, own)
    used_ah = _USED * vehicle.battery.capacity_ah
    trials = {"sim": mission(Environment(**_BASE), seed, 0.0, used_ah, vehicle)}
    for k, (name, (environment, _)) in enumerate(combined.items()):
        shift = stretch if k % 2 == 0 else -stretch
        trials[name] = mission(Environment(**{**_BASE, **environment}), seed + 1000 + k, shift, used_ah, vehicle)
    same = ["sim", *(n for n, (_, v) in combined.items() if not v)]
    flown = dict(zip(same, simulate_flights([trials[n] for n in same], vehicle, method="euler")))
    for name, (_, own) in combined.items():
        if own:
            (flown[name],) = simulate_flights([trials[name]], replace(vehicle, **own), method="euler")
    sim = write_px4_log(flown.pop("sim"), folder / f"sim-{seed}.ulg", utc_start=start)
    return sim, {n: write_px4_log(f, folder / f"real-{n}-{seed}.ulg", utc_start=start) for n, f in flown.items()}
