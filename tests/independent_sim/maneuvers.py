"""Maneuver designs and the :class:`Maneuver` that places one on an axis, at an injection point and a time.

Each design (:class:`Chirp`, :class:`PilotedSweep`, :class:`Doublet`,
:class:`ThreeTwoOneOne`, :class:`Multisine`) holds the shape of one of the
signals of :mod:`.excitation` and renders it on a time grid.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from independent_sim.excitation import (
    Excitation,
    chirp,
    doublet,
    multisine,
    piloted_sweep,
    three_two_one_one,
)

__all__ = [
    "Axis",
    "Injection",
    "Chirp",
    "PilotedSweep",
    "Doublet",
    "ThreeTwoOneOne",
    "Multisine",
    "Design",
    "Maneuver",
]

Axis = Literal["lat", "lon", "yaw", "thr"]
#: Where a maneuver enters the loop: the mixer (normalised, PX4 torque/thrust
#: setpoint), the rate setpoint (rad/s), the attitude setpoint (rad) or the
#: climb-rate setpoint (m/s, up; thr only).
Injection = Literal["mixer", "rate", "attitude", "climb"]


@dataclass(frozen=True, slots=True, kw_only=True)
class Chirp:
    """Design of a :func:`chirp` (parameters as there)."""

    duration_s: float = 34.0
    f_min_hz: float = 0.1
    f_max_hz: float = 10.0
    law: Literal["linear", "log"] = "log"
    direction: Literal["up", "down"] = "up"
    fade_in_s: float = 3.0
    fade_out_s: float = 1.0
    dwell_periods: float = 0.0  # periods of f_min_hz flown before the sweep rises
    kind = "sweep"

    def render(self, time_s: np.ndarray, start_s: float, amplitude: float, rng: np.random.Generator) -> Excitation:
        """The signal on `time_s` (see :func:`chirp`; `rng` unused)."""
        return chirp(
            time_s,
            start_s=start_s,
            amplitude=amplitude,
            duration_s=self.duration_s,
            f_min_hz=self.f_min_hz,
            f_max_hz=self.f_max_hz,
            law=self.law,
            direction=self.direction,
            fade_in_s=self.fade_in_s,
            fade_out_s=self.fade_out_s,
            dwell_s=self.dwell_periods / self.f_min_hz,
        )

    @property
    def band_hz(self) -> tuple[float, float] | None:
        """``(f_min_hz, f_max_hz)``."""
        return (self.f_min_hz, self.f_max_hz)

    @property
    def label(self) -> str:
        """Short description, e.g. ``"log chirp up 0.1-10 Hz"``."""
        return f"{self.law} chirp {self.direction} {self.f_min_hz:g}-{self.f_max_hz:g} Hz"


@dataclass(frozen=True, slots=True, kw_only=True)
class PilotedSweep:
    """Design of a :func:`piloted_sweep` (parameters as there)."""

    duration_s: float = 45.0
    f_min_hz: float = 0.2
    f_max_hz: float = 3.0
    irregularity: float = 0.25
    kind = "sweep"

    def render(self, time_s: np.ndarray, start_s: float, amplitude: float, rng: np.random.Generator) -> Excitation:
        """The signal on `time_s` (see :func:`piloted_sweep`)."""
        return piloted_sweep(
            time_s,
            start_s=start_s,
            amplitude=amplitude,
            rng=rng,
            duration_s=self.duration_s,
            f_min_hz=self.f_min_hz,
            f_max_hz=self.f_max_hz,
            irregularity=self.irregularity,
        )

    @property
    def band_hz(self) -> tuple[float, float] | None:
        """``(f_min_hz, f_max_hz)`` on average."""
        return (self.f_min_hz, self.f_max_hz)

    @property
    def label(self) -> str:
        """Short description."""
        return f"piloted sweep {self.f_min_hz:g}-{self.f_max_hz:g} Hz"


@dataclass(frozen=True, slots=True, kw_only=True)
class Doublet:
    """Design of a :func:`doublet`."""

    width_s: float = 1.0
    kind = "doublet"

    @property
    def duration_s(self) -> float:
        """Length of the two pulses, s."""
        return 2 * self.width_s

    def render(self, time_s: np.ndarray, start_s: float, amplitude: float, rng: np.random.Generator) -> Excitation:
        """The signal on `time_s` (see :func:`doublet`; `rng` unused)."""
        return doublet(time_s, start_s=start_s, amplitude=amplitude, width_s=self.width_s)

    band_hz = None

    @property
    def label(self) -> str:
        """Short description."""
        return f"doublet {self.width_s:g} s pulses"


@dataclass(frozen=True, slots=True, kw_only=True)
class ThreeTwoOneOne:
    """Design of a :func:`three_two_one_one`."""

    unit_s: float = 0.4
    kind = "3211"

    @property
    def duration_s(self) -> float:
        """Length, s."""
        return 7 * self.unit_s

    def render(self, time_s: np.ndarray, start_s: float, amplitude: float, rng: np.random.Generator) -> Excitation:
        """The signal on `time_s` (see :func:`three_two_one_one`; `rng` unused)."""
        return three_two_one_one(time_s, start_s=start_s, amplitude=amplitude, unit_s=self.unit_s)

    band_hz = None

    @property
    def label(self) -> str:
        """Short description."""
        return f"3-2-1-1 unit {self.unit_s:g} s"


@dataclass(frozen=True, slots=True, kw_only=True)
class Multisine:
    """Design of a :func:`multisine` (parameters as there)."""

    duration_s: float = 30.0
    f_min_hz: float = 0.2
    f_max_hz: float = 8.0
    period_s: float = 10.0
    kind = "multisine"

    def render(self, time_s: np.ndarray, start_s: float, amplitude: float, rng: np.random.Generator) -> Excitation:
        """The signal on `time_s` (see :func:`multisine`; `rng` unused)."""
        return multisine(
            time_s,
            start_s=start_s,
            amplitude=amplitude,
            duration_s=self.duration_s,
            f_min_hz=self.f_min_hz,
            f_max_hz=self.f_max_hz,
            period_s=self.period_s,
        )

    @property
    def band_hz(self) -> tuple[float, float] | None:
        """``(f_min_hz, f_max_hz)``."""
        return (self.f_min_hz, self.f_max_hz)

    @property
    def label(self) -> str:
        """Short description."""
        return f"multisine {self.f_min_hz:g}-{self.f_max_hz:g} Hz"


Design = Chirp | PilotedSweep | Doublet | ThreeTwoOneOne | Multisine
_INJECTIONS: dict[str, tuple[str, ...]] = {
    "lat": ("mixer", "rate", "attitude"),
    "lon": ("mixer", "rate", "attitude"),
    "yaw": ("mixer", "rate"),
    "thr": ("mixer", "climb"),
}
_UNITS = {"mixer": "normalised", "rate": "rad/s", "attitude": "rad", "climb": "m/s"}


@dataclass(frozen=True, slots=True, kw_only=True)
class Maneuver:
    """One maneuver of a flight.

    Parameters
    ----------
    axis : {"lat", "lon", "yaw", "thr"}
        Mixer axis excited.
    design : Chirp, PilotedSweep, Doublet, ThreeTwoOneOne or Multisine
        The signal's shape.
    start_s : float
        Start, s after take-off.
    amplitude : float
        Peak, in the units of `injection` (normalised at the mixer: 0.06 is
        6 % of full scale).
    injection : {"mixer", "rate", "attitude", "climb"}
        Where the signal enters: added to the torque/thrust setpoint after
        the rate controller, or (a pilot's stick) to the rate, attitude or
        climb-rate setpoint.
    """

    axis: Axis
    design: Design
    start_s: float
    amplitude: float
    injection: Injection = "mixer"

    def __post_init__(self) -> None:
        if self.injection not in _INJECTIONS.get(self.axis, ()):
            raise ValueError(f"{self.axis=} cannot take {self.injection=}; use one of {_INJECTIONS.get(self.axis)}")
        if self.start_s < 0.0:
            raise ValueError(f"{self.start_s=} s must be ≥ 0 (after take-off)")

    @property
    def end_s(self) -> float:
        """End, s after take-off."""
        return self.start_s + self.design.duration_s

    @property
    def channel(self) -> str:
        """Name of the closed-loop input it drives, e.g. ``"exc_mixer_lon"``."""
        return f"exc_{self.injection}_{self.axis}"

    @property
    def amplitude_unit(self) -> str:
        """Unit of `amplitude`."""
        return _UNITS[self.injection]
