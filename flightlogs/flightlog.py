"""Containers for what a reader produces: time series and the flight log."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from types import MappingProxyType
from typing import Literal

import numpy as np

from .signals import LOGGED_SIGNALS, is_canonical

__all__ = ["Signal", "FlightLog", "Autopilot", "LogFormat"]

Autopilot = Literal["px4", "ardupilot"]
LogFormat = Literal["ulog", "dataflash", "tlog"]


@dataclass(frozen=True, slots=True)
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
        Sample values in `unit`.
    unit : str
        Unit of `values` (SI, or the autopilot's unit for mixer inputs).
    source : str
        Where the values came from, ``"topic[instance].field"`` or
        ``"MESSAGE[instance].Field"``, with the conversion applied if any.
    """

    name: str
    time_s: np.ndarray
    values: np.ndarray
    unit: str
    source: str

    def __post_init__(self) -> None:
        time_s = np.ascontiguousarray(self.time_s, dtype=np.float64)
        values = np.ascontiguousarray(self.values, dtype=np.float64)
        if time_s.ndim != 1 or values.shape != time_s.shape:
            raise ValueError(
                f"signal {self.name!r}: time_s {time_s.shape} and values {values.shape} "
                "must be 1-D of equal length"
            )
        if not is_canonical(self.name):
            raise ValueError(f"{self.name!r} is not a canonical signal name")
        time_s.setflags(write=False)
        values.setflags(write=False)
        object.__setattr__(self, "time_s", time_s)
        object.__setattr__(self, "values", values)

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
        """Mean sample rate, Hz (0 for fewer than two samples)."""
        span = self.duration_s
        return (self.samples - 1) / span if span > 0 else 0.0


@dataclass(frozen=True, slots=True)
class FlightLog:
    """Canonical signals read from one log file, with its metadata.

    Parameters
    ----------
    path : Path
        The file read.
    log_format : {"ulog", "dataflash", "tlog"}
        Format detected from the file content.
    autopilot : {"px4", "ardupilot"}
        Flight stack that wrote it.
    signals : Mapping[str, Signal]
        Canonical signals found, by name.
    vehicle : str
        Vehicle description (airframe, hardware) as far as the log tells.
    parameters : Mapping[str, float]
        Autopilot parameters at the start of the log.
    utc_offset_s : float or None
        Add to a log time (s) to get UTC as UNIX seconds; None when the log
        holds no GPS time.
    warnings : tuple of str
        Problems that were recovered from (skipped bytes, dropped samples).
    """

    path: Path
    log_format: LogFormat
    autopilot: Autopilot
    signals: Mapping[str, Signal]
    vehicle: str = ""
    parameters: Mapping[str, float] = field(default_factory=dict)
    utc_offset_s: float | None = None
    warnings: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        for name, signal in self.signals.items():
            if name != signal.name:
                raise ValueError(f"signal stored as {name!r} is named {signal.name!r}")
        object.__setattr__(self, "signals", MappingProxyType(dict(self.signals)))
        object.__setattr__(self, "parameters", MappingProxyType(dict(self.parameters)))
        object.__setattr__(self, "warnings", tuple(self.warnings))

    def __getitem__(self, name: str) -> Signal:
        from .errors import MissingSignalError

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
        """Earliest and latest sample time over all signals, s (log clock)."""
        starts = [s.time_s[0] for s in self.signals.values() if s.samples]
        ends = [s.time_s[-1] for s in self.signals.values() if s.samples]
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
        return datetime.fromtimestamp(self.time_range_s[0] + self.utc_offset_s, tz=timezone.utc)
