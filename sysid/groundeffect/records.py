"""Thrust-ratio data, F/F0 against Z/R, and how to read it: the containers the readers and the fits share.

:mod:`sysid.groundeffect.data` (rig CSV, dispatch on file content) and
:mod:`sysid.groundeffect.flight` (hover steps of a flight log) both produce
:class:`ThrustRatioData`; the fits and the spacing study consume it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flightlogs.errors import DataError

__all__ = ["HoverStep", "HoverSteps", "ThrustRatioData", "GroundEffectDataConfig"]


@dataclass(frozen=True, slots=True, kw_only=True)
class HoverStep:
    """One hover step of a flight log, and F/F0 over its steady (second) half.

    Parameters
    ----------
    start_s, end_s : float
        The step (a height plateau), s on the log clock.
    steady_start_s : float
        Start of the steady half used, s (the mid-point of the step).
    height_m : float
        Mean rotor-plane height above ground over the steady half, m.
    height_std_m : float
        Standard deviation of the height samples over the steady half, m.
    climb_rate_m_s : float
        Least-squares slope of the height over the steady half, m/s.
    f0_n : float
        Mean of eq. 2.6, sum of k_f PWM_i, over the steady half, N.
    thrust_ratio : float
        F/F0 with F the weight (or the out-of-ground-effect reference).
    samples : int
        Height samples in the steady half.
    """

    start_s: float
    end_s: float
    steady_start_s: float
    height_m: float
    height_std_m: float
    climb_rate_m_s: float
    f0_n: float
    thrust_ratio: float
    samples: int

    def __post_init__(self) -> None:
        if not self.start_s <= self.steady_start_s < self.end_s:
            raise ValueError(f"step times {self.start_s} <= {self.steady_start_s} < {self.end_s} violated")


@dataclass(frozen=True, slots=True, kw_only=True)
class HoverSteps:
    """Hover steps found in a flight log, with the height trace they were found on.

    Parameters
    ----------
    time_s : ndarray, shape (n_blocks,)
        Centres of the averaging blocks, s (log clock).
    height_m : ndarray, shape (n_blocks,)
        Block-mean rotor-plane height, m.
    steps : tuple of HoverStep
        The steps kept, in time order.
    dropped : tuple of str
        Why other plateaus were not used (on the ground, implausible F/F0).
    """

    time_s: np.ndarray
    height_m: np.ndarray
    steps: tuple[HoverStep, ...]
    dropped: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        time_s = np.asarray(self.time_s, dtype=np.float64)
        height = np.asarray(self.height_m, dtype=np.float64)
        if time_s.ndim != 1 or height.shape != time_s.shape:
            raise ValueError(f"time_s {time_s.shape} and height_m {height.shape} must be 1-D of equal length")
        object.__setattr__(self, "time_s", time_s)
        object.__setattr__(self, "height_m", height)
        object.__setattr__(self, "steps", tuple(self.steps))
        object.__setattr__(self, "dropped", tuple(self.dropped))


@dataclass(frozen=True, slots=True, kw_only=True)
class ThrustRatioData:
    """Points of thrust ratio F/F0 against height ratio Z/R, ready to fit.

    Parameters
    ----------
    height_ratio : ndarray, shape (n_points,)
        Z/R, rotor-plane height over propeller radius (> 0).
    thrust_ratio : ndarray, shape (n_points,)
        F/F0, thrust in ground effect over thrust out of it (> 0).
    rotor_radius_m : float
        Propeller radius R, m.
    source : str
        Where the points came from (file name or a description).
    f0_source : str
        How F0 was obtained (given, rows with Z/R > 8, eq. 2.6).
    f0_n : float or None
        The F0 used for rig data, N; None for flight data (one F0 per step).
    steps : HoverSteps or None
        The hover steps, for flight-log data.
    """

    height_ratio: np.ndarray
    thrust_ratio: np.ndarray
    rotor_radius_m: float
    source: str = ""
    f0_source: str = ""
    f0_n: float | None = None
    steps: HoverSteps | None = None

    def __post_init__(self) -> None:
        x = np.ascontiguousarray(self.height_ratio, dtype=np.float64)
        y = np.ascontiguousarray(self.thrust_ratio, dtype=np.float64)
        if x.ndim != 1 or y.shape != x.shape or x.size == 0:
            raise ValueError(f"height_ratio {x.shape} and thrust_ratio {y.shape} must be 1-D, non-empty, equal")
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y)) and np.all(x > 0) and np.all(y > 0)):
            raise DataError(f"{self.source or 'thrust-ratio data'}: Z/R and F/F0 must be finite and > 0")
        if not self.rotor_radius_m > 0:
            raise ValueError(f"rotor_radius_m={self.rotor_radius_m} must be > 0")
        for array in (x, y):
            array.setflags(write=False)
        object.__setattr__(self, "height_ratio", x)
        object.__setattr__(self, "thrust_ratio", y)

    @property
    def n_points(self) -> int:
        """Number of points."""
        return int(self.height_ratio.size)


@dataclass(frozen=True, slots=True, kw_only=True)
class GroundEffectDataConfig:
    """How to turn a rig CSV or a flight log into F/F0 against Z/R.

    Parameters
    ----------
    rotor_radius_m : float
        Propeller radius R, m.
    f0_n : float or None
        Rig: thrust out of ground effect, N; None takes the mean thrust of
        the rows with Z/R > `reference_height_ratio`.
    reference_height_ratio : float
        Z/R above which ground effect is taken as nil (chapter 2: 8).
    height_column, thrust_column : str
        Rig CSV column names.
    height_unit, thrust_unit : str or None
        Rig CSV units (default from the column names; see :func:`flightlogs.readers.rig.read_rig_csv`).
    kf_n_per_count : float
        Flight: motor force constant k_f of eq. 2.6, N per PWM count (Table 2.1: 2.083e-6).
    mass_kg : float or None
        Flight: vehicle mass, kg (F = m g). None: F is the mean eq. 2.6
        thrust of the steps above `reference_height_ratio`.
    pwm_full_scale : float
        Flight: PWM counts of a full motor command, for motors logged
        normalised to 0..1 (PX4 ``actuator_motors``); the Crazyflie's 16-bit
        PWM is 65535. Motors logged in any other unit are taken as counts.
    rotor_offset_m : float
        Flight: rotor plane above the height sensor's reference point, m.
    min_hold_s : float
        Flight: shortest hover step, s (chapter 2 holds each for 10 s; the second half of each is used). A
        commanded step during which the height keeps creeping (as it does in
        ground effect) may be found as two plateaus, each a valid point.
    gravity_m_s2 : float
        Gravity, m/s^2.
    """

    rotor_radius_m: float
    f0_n: float | None = None
    reference_height_ratio: float = 8.0
    height_column: str = "height_m"
    thrust_column: str = "thrust_n"
    height_unit: str | None = None
    thrust_unit: str | None = None
    kf_n_per_count: float = 2.083e-6
    mass_kg: float | None = None
    pwm_full_scale: float = 65535.0
    rotor_offset_m: float = 0.0
    min_hold_s: float = 6.0
    gravity_m_s2: float = 9.81

    def __post_init__(self) -> None:
        for name in (
            "rotor_radius_m",
            "reference_height_ratio",
            "kf_n_per_count",
            "pwm_full_scale",
            "min_hold_s",
            "gravity_m_s2",
        ):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"{name}={value} must be finite and > 0")
        for name in ("f0_n", "mass_kg"):
            value = getattr(self, name)
            if value is not None and not (np.isfinite(value) and value > 0):
                raise ValueError(f"{name}={value} must be finite and > 0")
