"""One maneuver, or one stretch of hover, in a flight: what detection, ArduPilot's SIDS runs or a user's file give.

Axes are the mixer inputs: ``lat`` (delta_lat, roll), ``lon`` (delta_lon, pitch), ``yaw`` (delta_yaw) and
``thr`` (delta_thr). Found by :mod:`flightlogs.maneuvers`, read from a file by
:func:`flightlogs.readers.segments_file.read_segments_file`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, get_args

import numpy as np

from flightlogs.errors import DataError

__all__ = ["Axis", "Kind", "SegmentSource", "AXES", "Segment"]

Axis = Literal["lat", "lon", "yaw", "thr"]
Kind = Literal["sweep", "doublet", "3211", "multisine", "broadband", "hover"]
SegmentSource = Literal["sids", "detected", "user"]

#: Mixer axes in canonical order (delta_lat, delta_lon, delta_yaw, delta_thr).
AXES: tuple[str, ...] = get_args(Axis)


@dataclass(frozen=True, slots=True, kw_only=True)
class Segment:
    """One maneuver, or one stretch of hover, in a flight.

    Parameters
    ----------
    axis : {"lat", "lon", "yaw", "thr"} or None
        Mixer axis excited; None exactly when `kind` is ``"hover"``.
    kind : {"sweep", "doublet", "3211", "multisine", "broadband", "hover"}
        What was flown. ``broadband`` is a pilot's frequency-rich input without
        a frequency trend: not a sweep (a sweep's frequency rises or falls), used
        for identification only when asked for.
    start_s, end_s : float
        Bounds on the log clock, s; a fade-in is inside.
    source : {"sids", "detected", "user"}
        Where the segment came from.
    f_min_hz, f_max_hz : float or None, optional
        Frequency range of a sweep (or multisine), Hz.
    detail : str, optional
        Free text, e.g. the ArduPilot axis that was excited.
    """

    axis: Axis | None
    kind: Kind
    start_s: float
    end_s: float
    source: SegmentSource
    f_min_hz: float | None = None
    f_max_hz: float | None = None
    detail: str = ""

    def __post_init__(self) -> None:
        if self.kind not in get_args(Kind):
            raise DataError(f"unknown kind {self.kind!r} (expected {', '.join(get_args(Kind))})")
        if self.kind == "hover" and self.axis is not None:
            raise DataError(f"a hover segment has no axis, got axis={self.axis!r}")
        if self.kind != "hover" and self.axis not in AXES:
            raise DataError(f"unknown axis {self.axis!r} for a {self.kind} (expected {', '.join(AXES)})")
        if self.source not in get_args(SegmentSource):
            raise DataError(f"unknown source {self.source!r}")
        start, end = float(self.start_s), float(self.end_s)
        if not (np.isfinite(start) and np.isfinite(end)) or end <= start:
            raise DataError(f"end_s={end:g} must be after start_s={start:g}")
        object.__setattr__(self, "start_s", start)
        object.__setattr__(self, "end_s", end)
        for name in ("f_min_hz", "f_max_hz"):
            value = getattr(self, name)
            if value is not None and not (np.isfinite(value) and value > 0):
                raise DataError(f"{name}={value} must be a positive frequency in Hz")
            object.__setattr__(self, name, None if value is None else float(value))
        if self.f_min_hz is not None and self.f_max_hz is not None and self.f_max_hz < self.f_min_hz:
            raise DataError(f"f_max_hz={self.f_max_hz:g} is below f_min_hz={self.f_min_hz:g}")

    @property
    def duration_s(self) -> float:
        """Length of the segment, s."""
        return self.end_s - self.start_s
