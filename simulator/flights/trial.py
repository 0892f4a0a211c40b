"""One flight to simulate: its length, excitation, environment and seed."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from simulator.autopilot.control import HeightSteps, Injection, Legs
from simulator.autopilot.excitation import Maneuver
from simulator.world.environment import Environment

__all__ = ["Trial"]


@dataclass(frozen=True, slots=True, kw_only=True)
class Trial:
    """One flight to simulate.

    Parameters
    ----------
    duration_s : float
        Length, s.
    maneuvers : tuple of Maneuver
        Sweeps and doublets summed at the mixer input.
    injections : tuple of Injection
        3-2-1-1s and multisines summed at the mixer input.
    environment : Environment
        Wind, anemometer, ground effect, payload, CG, sensors.
    seed : int
        Seed of the turbulence and the sensor noise.
    hover_height_m : float
        Height of the CG above ground held, m (chapter 3: 4.6 m, the anemometer's height).
    heading_deg : float or None
        Heading held, deg; None: nose into the wind (chapter 3).
    height_steps : HeightSteps or None
        A height reference replacing `hover_height_m`.
    legs : Legs or None
        A horizontal position reference (default: hold the take-off point).
    battery_used_ah : float
        Charge drawn before the trial, Ah.
    label : str
        Free text carried to the flight.
    """

    duration_s: float
    maneuvers: tuple[Maneuver, ...] = ()
    injections: tuple[Injection, ...] = ()
    environment: Environment = field(default_factory=Environment)
    seed: int = 0
    hover_height_m: float = 4.6
    heading_deg: float | None = None
    height_steps: HeightSteps | None = None
    legs: Legs | None = None
    battery_used_ah: float = 0.0
    label: str = ""

    def __post_init__(self) -> None:
        if self.duration_s <= 0 or self.hover_height_m <= 0 or self.battery_used_ah < 0:
            raise ValueError("duration_s and hover_height_m must be > 0, battery_used_ah >= 0")

    @property
    def heading_rad(self) -> float:
        """Heading held, rad."""
        heading = self.environment.wind.direction_from_deg if self.heading_deg is None else self.heading_deg
        return float(np.radians(heading))
