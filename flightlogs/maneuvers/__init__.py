"""Maneuvers: find the sweeps, doublets, 3211s, multisines and hover in a flight, and recover the excitation.

The public names of :mod:`~flightlogs.maneuvers.excitation_recovery` and
:mod:`~flightlogs.maneuvers.segments` are re-exported here: write ``from flightlogs.maneuvers import
name``. Modules with a leading underscore are private.
"""

from flightlogs.maneuvers.excitation_recovery import FEEDBACK_STATES, ExcitationRecovery, estimate_excitation
from flightlogs.maneuvers.segments import (
    AXES,
    SID_AXES,
    Axis,
    DetectionOptions,
    Kind,
    Segment,
    SegmentDetector,
    SegmentSource,
    detect_segments,
    segments_from_sid,
)

__all__ = [
    "FEEDBACK_STATES",
    "ExcitationRecovery",
    "estimate_excitation",
    "Axis",
    "Kind",
    "SegmentSource",
    "AXES",
    "SID_AXES",
    "Segment",
    "DetectionOptions",
    "SegmentDetector",
    "detect_segments",
    "segments_from_sid",
]
