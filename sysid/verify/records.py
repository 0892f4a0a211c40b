"""The records to verify on: each doublet of a conditioned flight, with a little quiet before and after."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from flightlogs.conditioning.condition import ConditionedFlight
from flightlogs.errors import DataError
from flightlogs.readers.segments_file import segment_line
from flightlogs.record import Record
from flightlogs.segment import Segment

__all__ = ["AFTER_S", "BEFORE_S", "DoubletRecords", "check_given_doublets", "doublet_records", "MIXER_INPUTS"]

#: Mixer input excited by a maneuver on each axis.
#: Quiet stretch kept before each doublet, and response after it, s (an unstable model diverges over long records).
BEFORE_S, AFTER_S = 0.5, 1.0
MIXER_INPUTS = {"lat": "delta_lat", "lon": "delta_lon", "yaw": "delta_yaw", "thr": "delta_thr"}


@dataclass(frozen=True, slots=True, kw_only=True)
class DoubletRecords:
    """Doublet records and the mixer input each excites.

    Parameters
    ----------
    records : tuple of Record
        One per doublet, cut from the flight's records.
    excited : tuple of str
        Per record, the mixer input of the doublet's axis (``"delta_lon"``).
    """

    records: tuple[Record, ...]
    excited: tuple[str, ...]

    def __post_init__(self) -> None:
        if len(self.records) != len(self.excited):
            raise ValueError(f"{len(self.records)} records but {len(self.excited)} excited inputs")


def doublet_records(
    flights: Sequence[ConditionedFlight],
    *,
    before_s: float = BEFORE_S,
    after_s: float = AFTER_S,
    kinds: tuple[str, ...] = ("doublet",),
) -> DoubletRecords:
    """Cut a record around every doublet of the flights.

    Parameters
    ----------
    flights : sequence of ConditionedFlight
        Conditioned flights with their segments.
    before_s : float, optional
        Quiet stretch kept before each doublet, s (the initial state is fitted there).
    after_s : float, optional
        Response kept after each doublet, s. Keep records short: an open-loop
        unstable model diverges over long ones.
    kinds : tuple of str, optional
        Segment kinds to take (``"3211"`` works as well).

    Returns
    -------
    DoubletRecords
        In flight and time order; doublets outside every record are skipped.
    """
    records: list[Record] = []
    excited: list[str] = []
    for flight in flights:
        for segment in flight.segments:
            if segment.kind not in kinds or segment.axis is None:
                continue
            for record in flight.records:
                if record.start_s <= segment.start_s <= record.end_s:
                    start = max(record.start_s, segment.start_s - before_s)
                    end = min(record.end_s, segment.end_s + after_s)
                    label = f"{flight.source.name} {segment.axis} {segment.kind} at {segment.start_s:.1f} s"
                    records.append(record.between(start, end, label=label))
                    excited.append(MIXER_INPUTS[segment.axis])
                    break
    return DoubletRecords(records=tuple(records), excited=tuple(excited))


def check_given_doublets(path: Path, segments: Sequence[Segment], flights: Sequence[ConditionedFlight]) -> None:
    """Check that every doublet a segments file gives starts inside some flight's records.

    Parameters
    ----------
    path : Path
        The segments file (its CSV line is named).
    segments : sequence of Segment
        The maneuvers it gives.
    flights : sequence of ConditionedFlight
        The flights they should lie in.

    Raises
    ------
    DataError
        Naming the first doublet of `path` that starts outside every flight's records, its line and the
        records' spans.
    """
    for segment in segments:
        if segment.kind != "doublet" or segment.axis is None:
            continue
        if any(r.start_s <= segment.start_s <= r.end_s for f in flights for r in f.records):
            continue
        spans = "; ".join(
            f"{f.source.name} {min(r.start_s for r in f.records):.1f}-{max(r.end_s for r in f.records):.1f} s"
            for f in flights
            if f.records
        )
        line = segment_line(path, segment)
        where = f"{path}" + (f" line {line}" if line else "")
        raise DataError(
            f"{where}: the {segment.axis} doublet at {segment.start_s:g}-{segment.end_s:g} s starts "
            f"outside every log's records ({spans})"
        )
