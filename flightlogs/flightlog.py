"""Containers for what a reader produces: time series, logged maneuvers and the flight log."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from types import MappingProxyType
from typing import Literal

import numpy as np

from flightlogs.signals import LOGGED_SIGNALS, STATE_SIGNALS, is_canonical

__all__ = ["Signal", "SystemIdRun", "FlightLog", "WindMeasurement", "Autopilot", "LogFormat", "logged_rate_hz"]


def _held_dtype(dtype: np.dtype) -> type[np.floating]:
    """float32 for float32 and for integers of up to 16 bits (exact in it), float64 for anything else."""
    exact_in_single = dtype == np.float32 or (dtype.kind in "iub" and dtype.itemsize <= 2)
    return np.float32 if exact_in_single else np.float64


def logged_rate_hz(time_s: np.ndarray) -> float:
    """The rate a series was logged at, Hz: its mean interval within the pieces its gaps separate.

    An interval over five times the median is a gap (a logging pause, the
    space between two record pieces; as :class:`~flightlogs.conditioning.condition.ConditioningOptions`'
    ``max_gap_samples``) and is left out, so a 628 s pause does not read a 25
    Hz IMU as 2.6 Hz; the others are averaged, so a logger's jitter (20-24
    ms intervals of a 50 Hz topic) reads as the rate it keeps, not as its
    median interval.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Sample times, s, non-decreasing.

    Returns
    -------
    float
        0 for fewer than two distinct times.

    Examples
    --------
    >>> t = np.r_[np.arange(0.0, 10.0, 0.04), 638.0 + np.arange(0.0, 10.0, 0.04)]
    >>> round(logged_rate_hz(t), 6), round(float((t.size - 1) / (t[-1] - t[0])), 2)
    (25.0, 0.77)
    """
    steps = np.diff(np.asarray(time_s, dtype=np.float64))
    positive = steps[steps > 0]
    if not positive.size:
        return 0.0
    within = steps[steps <= _GAP_INTERVALS * float(np.median(positive))]
    return within.size / float(np.sum(within))


_GAP_INTERVALS = 5.0  # an interval this many times the median is a gap, not a sample interval


Autopilot = Literal["px4", "ardupilot", "unknown"]
LogFormat = Literal["ulog", "dataflash", "tlog", "table"]


@dataclass(frozen=True, slots=True, init=False)
class Signal:
    """One canonical signal as logged, on its own time base.

    Parameters
    ----------
    name : str
        Canonical name (see :mod:`flightlogs.signals`).
    time_s : ndarray, shape (n_samples,)
        Sample times, s, on the log's own clock (autopilot boot time).
        Non-decreasing.
    values : ndarray, shape (n_samples,)
        Sample values in `unit`. Held as given when float32 (a log's
        float32 field: half the memory) or as float32 when an integer type
        of up to 16 bits (a PWM, exactly); as float64 otherwise.
    unit : str
        Unit of `values` (SI, or the autopilot's unit for mixer inputs).
    source : str
        Where the values came from, ``"topic[instance].field"`` or
        ``"MESSAGE[instance].Field"``, with the conversion applied if any.
    derived : bool, optional
        True when the values were computed from other signals, not measured
        (a motion-capture table's specific forces from its velocities).

    Attributes
    ----------
    stored_values : ndarray, shape (n_samples,)
        The values as held, float32 or float64 (read-only); :attr:`values`
        gives them in float64.

    Notes
    -----
    A 400 Hz log keeps most of its signals as the float32 it logged them
    in; the resampler and the dataset take :attr:`stored_values` and widen
    a column at a time, so a log in memory is about its size in the file.
    """

    name: str
    time_s: np.ndarray
    stored_values: np.ndarray = field(init=False)  # so ``dataclasses.replace(signal, values=...)`` works
    unit: str
    source: str
    derived: bool = False

    def __init__(
        self, *, name: str, time_s: np.ndarray, values: np.ndarray, unit: str, source: str, derived: bool = False
    ) -> None:
        time_s = np.ascontiguousarray(time_s, dtype=np.float64)
        stored = np.ascontiguousarray(values, dtype=_held_dtype(np.asarray(values).dtype))
        if time_s.ndim != 1 or stored.shape != time_s.shape:
            raise ValueError(
                f"signal {name!r}: time_s {time_s.shape} and values {stored.shape} must be 1-D of equal length"
            )
        if not is_canonical(name):
            raise ValueError(f"{name!r} is not a canonical signal name")
        time_s.setflags(write=False)
        stored.setflags(write=False)
        for attribute, value in (
            ("name", name),
            ("time_s", time_s),
            ("stored_values", stored),
            ("unit", unit),
            ("source", source),
            ("derived", derived),
        ):
            object.__setattr__(self, attribute, value)

    @property
    def values(self) -> np.ndarray:
        """Sample values in `unit`, float64, shape (n_samples,), read-only (a new array when held as float32)."""
        if self.stored_values.dtype == np.float64:
            return self.stored_values
        widened = self.stored_values.astype(np.float64)
        widened.setflags(write=False)
        return widened

    @property
    def samples(self) -> int:
        """Number of samples."""
        return int(self.time_s.size)

    @property
    def duration_s(self) -> float:
        """Time between the first and last sample, s."""
        return float(self.time_s[-1] - self.time_s[0]) if self.samples > 1 else 0.0

    @property
    def rate_hz(self) -> float:
        """Sample rate, Hz, from the median interval (:func:`logged_rate_hz`; 0 for fewer than two samples)."""
        return logged_rate_hz(self.time_s)


@dataclass(frozen=True, slots=True, kw_only=True)
class SystemIdRun:
    """One ArduPilot System ID maneuver, from a SIDS message and the SIDD that follow it.

    Parameters
    ----------
    start_s : float
        Log time of the SIDS message, written on entering the mode, s.
    end_s : float
        Log time of the last SIDD sample before the next SIDS, s; the run
        ends there at the latest. NaN when unknown (no SIDD logged).
    axis : int
        ``SID_AXIS`` (1-3 input angle, 4-6 recovery, 7-9 rate, 10-13 mixer...).
    axis_name : str
        Its meaning, e.g. ``"rate roll"``.
    magnitude : float
        ``SID_MAGNITUDE`` (``Mag``), in the unit of the axis: deg, deg/s, or
        0-1 for mixer axes.
    f_start_hz, f_stop_hz : float
        Chirp start and stop frequency (``FSt``, ``FSp``), Hz.
    fade_in_s, const_s, record_s, fade_out_s : float
        Fade-in (``TFin``), dwell at the start frequency (``TC``), total
        record (``TR``) and fade-out (``TFout``) times, s.

    Notes
    -----
    Per ArduCopter's ``mode_systemid.cpp`` the chirp starts
    ``SYSTEM_ID_DELAY`` (1 s) after the SIDS message, and the fade-in, the
    dwell and the fade-out all lie inside ``TR`` (``AP_Math/chirp.cpp``).
    """

    start_s: float
    end_s: float
    axis: int
    axis_name: str
    magnitude: float
    f_start_hz: float
    f_stop_hz: float
    fade_in_s: float
    const_s: float
    record_s: float
    fade_out_s: float


@dataclass(frozen=True, slots=True, kw_only=True)
class FlightLog:
    """Canonical signals read from one log file, with its metadata.

    Parameters
    ----------
    path : Path
        The file read.
    log_format : {"ulog", "dataflash", "tlog", "table"}
        Format detected from the file content (``table``: a CSV or Parquet
        table read through a column map, :mod:`flightlogs.readers.table`).
    autopilot : {"px4", "ardupilot", "unknown"}
        Flight stack that wrote it (``unknown`` for a table).
    signals : Mapping[str, Signal]
        Canonical signals found, by name.
    vehicle : str
        Vehicle description (airframe, hardware) as far as the log tells.
    board_id : str
        The flight controller's unique id, which tells one vehicle from another: PX4's ``sys_uuid``,
        ArduPilot's board message (``"fmuv5 00290019 32375118 32363435"``); "" when the log has none.
    parameters : Mapping[str, float]
        Autopilot parameters at the start of the log.
    utc_offset_s : float or None
        Add to a log time (s) to get UTC as UNIX seconds; None when the log
        holds no GPS time.
    warnings : tuple of str
        Problems that were recovered from (skipped bytes, dropped samples).
    system_id_runs : tuple of SystemIdRun
        ArduPilot System ID maneuvers logged (SIDS messages), in time order;
        empty when the log holds none (and for other autopilots).
    vehicle_type : str
        ``"multirotor"``, the kind of vehicle the log says it is otherwise
        (``"fixed wing (MAV_TYPE 1)"``, ``"rover (ArduRover)"``), or ``""``
        when it does not say (a table, a generic MAV_TYPE 0).
    """

    path: Path
    log_format: LogFormat
    autopilot: Autopilot
    signals: Mapping[str, Signal]
    vehicle: str = ""
    board_id: str = ""
    parameters: Mapping[str, float] = field(default_factory=dict)
    utc_offset_s: float | None = None
    warnings: tuple[str, ...] = ()
    system_id_runs: tuple[SystemIdRun, ...] = ()
    vehicle_type: str = ""

    def __post_init__(self) -> None:
        for name, signal in self.signals.items():
            if name != signal.name:
                raise ValueError(f"signal stored as {name!r} is named {signal.name!r}")
        object.__setattr__(self, "signals", MappingProxyType(dict(self.signals)))
        object.__setattr__(self, "parameters", MappingProxyType(dict(self.parameters)))
        object.__setattr__(self, "warnings", tuple(self.warnings))
        object.__setattr__(self, "system_id_runs", tuple(self.system_id_runs))

    def __getitem__(self, name: str) -> Signal:
        from flightlogs.errors import MissingSignalError

        try:
            return self.signals[name]
        except KeyError:
            raise MissingSignalError(f"{self.path.name}: no signal {name!r} in this log") from None

    @property
    def missing(self) -> tuple[str, ...]:
        """Expected canonical signals the log does not provide, in canonical order."""
        missing = [name for name in LOGGED_SIGNALS if name not in self.signals]
        if not any(name.startswith("motor_") for name in self.signals):
            missing.append("motor_1..n")
        return tuple(missing)

    @property
    def time_range_s(self) -> tuple[float, float]:
        """Earliest and latest sample time over all signals, s (log clock).

        The flight states (``armed``, ``landed``: :data:`~flightlogs.signals.STATE_SIGNALS`) are left out: an
        autopilot logs them from boot and at each change, so they would stretch the span to the ground time
        before the first measurement (and with it the wind the transport delay is averaged over).
        """
        timed = [s for name, s in self.signals.items() if s.samples and name not in STATE_SIGNALS]
        starts = [s.time_s[0] for s in timed]
        ends = [s.time_s[-1] for s in timed]
        if not starts:
            return (0.0, 0.0)
        return (float(min(starts)), float(max(ends)))

    @property
    def duration_s(self) -> float:
        """Span of the canonical signals, s."""
        start, end = self.time_range_s
        return end - start

    @property
    def utc_start(self) -> datetime | None:
        """UTC of the first sample, or None without GPS time."""
        if self.utc_offset_s is None or not self.signals:
            return None
        return datetime.fromtimestamp(self.time_range_s[0] + self.utc_offset_s, tz=UTC)


@dataclass(frozen=True, slots=True, kw_only=True)
class WindMeasurement:
    """Horizontal wind recorded by a ground anemometer, in NED earth axes (:func:`~flightlogs.readers.read_anemometer_csv`).

    Parameters
    ----------
    path : Path
        The file read.
    utc_s : ndarray, shape (n_samples,)
        Sample times, UNIX seconds UTC, strictly increasing.
    wind_n, wind_e : ndarray, shape (n_samples,)
        North and east components of the velocity the air moves WITH
        (towards), m/s: ``wind_n = -speed cos(dir_from)``,
        ``wind_e = -speed sin(dir_from)``.
    speed_m_s : ndarray, shape (n_samples,)
        Horizontal wind speed, m/s, ≥ 0.
    direction_from_rad : ndarray, shape (n_samples,)
        Meteorological direction the wind comes FROM, rad, in [0, 2π),
        clockwise from north.
    wind_d : ndarray, shape (n_samples,), optional
        Down component of the air velocity, m/s (``-w``), when the file has
        a vertical component.
    columns : Mapping[str, str]
        Which CSV column fed which quantity (``"time"``, ``"speed"``, ...).
    unit : str
        Speed unit found in the file (key of :data:`flightlogs.readers.anemometer.SPEED_UNITS`).
    layout : {"columns", "responseone"}
        The layout recognised.
    warnings : tuple of str
        Assumptions made and lines dropped (the messages of the warnings
        raised while reading).
    """

    path: Path
    utc_s: np.ndarray
    wind_n: np.ndarray
    wind_e: np.ndarray
    speed_m_s: np.ndarray
    direction_from_rad: np.ndarray
    wind_d: np.ndarray | None = None
    columns: Mapping[str, str] = field(default_factory=dict)
    unit: str = "m/s"
    layout: str = "columns"
    warnings: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        n_samples = np.shape(self.utc_s)[0] if np.ndim(self.utc_s) == 1 else -1
        for name in ("utc_s", "wind_n", "wind_e", "speed_m_s", "direction_from_rad", "wind_d"):
            value = getattr(self, name)
            if value is None:
                continue
            array = np.array(value, dtype=np.float64)
            if array.shape != (n_samples,):
                raise ValueError(f"{name} has shape {array.shape}; expected ({n_samples},) like utc_s (1-D)")
            array.setflags(write=False)
            object.__setattr__(self, name, array)
        object.__setattr__(self, "columns", MappingProxyType(dict(self.columns)))
        object.__setattr__(self, "warnings", tuple(self.warnings))

    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.utc_s.size)

    @property
    def duration_s(self) -> float:
        """Time between the first and last sample, s."""
        return float(self.utc_s[-1] - self.utc_s[0]) if self.n_samples > 1 else 0.0

    @property
    def rate_hz(self) -> float:
        """Mean sample rate, Hz (0 for fewer than two samples)."""
        span = self.duration_s
        return (self.n_samples - 1) / span if span > 0 else 0.0

    @property
    def utc_start(self) -> datetime:
        """UTC of the first sample."""
        return datetime.fromtimestamp(float(self.utc_s[0]), tz=UTC)
