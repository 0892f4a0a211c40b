"""Thrust-ratio data, F/F0 against Z/R, from a test rig or from the hover steps of a flight log."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from flightlogs.errors import DataError

__all__ = [
    "HoverStep",
    "HoverSteps",
    "ThrustRatioData",
    "GroundEffectDataConfig",
    "rig_thrust_ratio",
    "load_thrust_ratio",
]

_PLAUSIBLE_MEDIAN = (0.5, 2.0)  # median F/F0 of rig readings: ground effect moves thrust by tens of percent at most
_LOG_SUFFIXES = (".ulg", ".bin", ".tlog")


@dataclass(frozen=True, slots=True)
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


@dataclass(frozen=True, slots=True)
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


@dataclass(frozen=True, slots=True)
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


@dataclass(frozen=True, slots=True)
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


def rig_thrust_ratio(
    height_m: np.ndarray,
    thrust_n: np.ndarray,
    *,
    rotor_radius_m: float,
    f0_n: float | None = None,
    reference_height_ratio: float = 8.0,
    source: str = "",
) -> ThrustRatioData:
    """F/F0 against Z/R from rig readings of thrust at known heights.

    Parameters
    ----------
    height_m : ndarray, shape (n_rows,)
        Rotor plane above the surface, m.
    thrust_n : ndarray, shape (n_rows,)
        Measured thrust, N.
    rotor_radius_m : float
        Propeller radius R, m.
    f0_n : float, optional
        Thrust out of ground effect, N. Default: the mean thrust of the rows
        with Z/R > `reference_height_ratio` (those rows stay in the data).
    reference_height_ratio : float, optional
        Z/R above which the rows give F0.
    source : str, optional
        Name of the data for messages.

    Returns
    -------
    ThrustRatioData

    Raises
    ------
    DataError
        If F0 is not given and no row lies above `reference_height_ratio`, or
        if the median F/F0 of the readings lies outside 0.5-2 (F0 or the
        thrust unit is wrong: ground effect changes thrust by tens of percent).

    Notes
    -----
    An F0 taken from rows at Z/R > 8 carries what ground effect remains
    there: 0.3 % for eq. 2.4 at Z/R = 8, none for eq. 2.5.

    Examples
    --------
    >>> data = rig_thrust_ratio(np.array([0.05, 0.2, 0.25]), np.array([0.42, 0.40, 0.40]), rotor_radius_m=0.0225)
    >>> data.height_ratio.round(2).tolist(), data.thrust_ratio.round(4).tolist(), data.f0_source
    ([2.22, 8.89, 11.11], [1.05, 1.0, 1.0], 'mean of 2 rows with Z/R > 8')
    """
    x = np.asarray(height_m, dtype=np.float64) / rotor_radius_m
    thrust = np.asarray(thrust_n, dtype=np.float64)
    if f0_n is None:
        reference = x > reference_height_ratio
        if not np.any(reference):
            raise DataError(
                f"{source or 'rig data'}: no reading above Z/R = {reference_height_ratio:g} "
                f"(height {reference_height_ratio * rotor_radius_m:.3f} m) to give F0; "
                "give F0 (--f0) or add readings out of ground effect"
            )
        f0 = float(np.mean(thrust[reference]))
        how = f"mean of {int(reference.sum())} row{'s' if reference.sum() > 1 else ''} with Z/R > {reference_height_ratio:g}"
    else:
        f0, how = float(f0_n), "given"
    ratio = thrust / f0
    median = float(np.median(ratio)) if ratio.size else 1.0
    if not _PLAUSIBLE_MEDIAN[0] <= median <= _PLAUSIBLE_MEDIAN[1]:
        raise DataError(
            f"{source or 'rig data'}: with F0 = {f0:.4g} N ({how}) the median F/F0 of the readings is "
            f"{median:.3g}, far from 1 out of ground effect; check F0 (--f0) and the thrust unit "
            f"(median thrust {float(np.median(thrust)):.4g} N)"
        )
    return ThrustRatioData(x, ratio, rotor_radius_m, source, how, f0)


def load_thrust_ratio(
    path: str | Path, config: GroundEffectDataConfig, *, progress: Callable[[int, int], None] | None = None
) -> ThrustRatioData:
    """F/F0 against Z/R from a rig CSV or a flight log, told apart by content.

    A file that reads as a PX4 ULog, ArduPilot DataFlash or MAVLink
    telemetry log is a flight log (:func:`sysid.groundeffect.flight.flight_thrust_ratio`);
    any other text file is a rig CSV (:func:`flightlogs.readers.rig.read_rig_csv`), unless
    it is named ``.ulg``, ``.bin`` or ``.tlog``: then the log reader's error stands.

    Parameters
    ----------
    path : str or Path
        The file.
    config : GroundEffectDataConfig
        Rotor radius, F0 or k_f and mass, columns.
    progress : callable, optional
        ``progress(done, total)`` in bytes while a flight log is read.

    Returns
    -------
    ThrustRatioData

    Raises
    ------
    DataError, LogFormatError, MissingSignalError
        If the file cannot be read or holds no usable points.
    """
    from flightlogs.errors import LogFormatError
    from flightlogs.readers.detect import detect_format

    path = Path(path)
    try:
        detect_format(path)
    except LogFormatError:
        if _is_text(path) and path.suffix.lower() not in _LOG_SUFFIXES:
            return _rig(path, config)
        raise
    from flightlogs.readers.dispatch import read_log
    from sysid.groundeffect.flight import flight_thrust_ratio

    return flight_thrust_ratio(read_log(path, progress=progress), config)


def _is_text(path: Path) -> bool:
    try:
        with path.open("rb") as stream:
            head = stream.read(4096)
    except OSError:
        return False
    return bool(head.strip()) and b"\x00" not in head


def _rig(path: Path, config: GroundEffectDataConfig) -> ThrustRatioData:
    from flightlogs.readers.rig import read_rig_csv

    rig = read_rig_csv(
        path,
        height_column=config.height_column,
        thrust_column=config.thrust_column,
        height_unit=config.height_unit,
        thrust_unit=config.thrust_unit,
    )
    return rig_thrust_ratio(
        rig.height_m,
        rig.thrust_n,
        rotor_radius_m=config.rotor_radius_m,
        f0_n=config.f0_n,
        reference_height_ratio=config.reference_height_ratio,
        source=path.name,
    )
