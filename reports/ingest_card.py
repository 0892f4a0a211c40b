"""The report's summary card of a flight: vehicle, flight and wind alignment, from an ingest's summary."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from flightlogs.errors import DataError

__all__ = ["ingest_card"]


def ingest_card(doc: Any, *, source: str = "ingest summary") -> dict[str, str]:
    """Summary-card lines (vehicle, flight, wind alignment) from what ``sysid ingest --json`` wrote.

    Parameters
    ----------
    doc : Mapping[str, Any]
        The ingest summary (anything else is refused).
    source : str, optional
        Its file name, for the error message.

    Returns
    -------
    dict of str to str
        Label to text.

    Raises
    ------
    DataError
        If `doc` is not an ingest summary.
    """
    if not isinstance(doc, Mapping):
        raise DataError(f"{source}: not a summary written by 'sysid ingest --json' (not a JSON object)")
    logs = doc.get("logs") if isinstance(doc.get("logs"), list) else [doc] if "vehicle" in doc else None
    if not logs or not all(isinstance(log, Mapping) for log in logs):
        raise DataError(f"{source}: not a summary written by 'sysid ingest --json' (no 'logs' or 'vehicle')")
    card = {"vehicle": "; ".join(dict.fromkeys(str(log.get("vehicle") or "not named in the log") for log in logs))}
    card["flight"] = "; ".join(
        f"{Path(str(log.get('path', '?'))).name}: {log.get('autopilot', '?')} {log.get('log_format', '')} log, "
        f"{float(log.get('duration_s') or 0.0):.0f} s from {log.get('utc_start') or 'unknown UTC'}"
        for log in logs
    )
    alignment = doc.get("wind_alignment")
    if isinstance(alignment, Mapping) and alignment:
        parts = [
            f"anemometer clock offset {float(alignment['clock_offset_s']):+.2f} s "
            f"({alignment.get('clock_offset_source', '?')})"
            if "clock_offset_s" in alignment
            else "",
            f"transport delay {float(alignment['transport_delay_s']):.2f} s "
            f"({alignment.get('transport_delay_source', '?')})"
            if "transport_delay_s" in alignment
            else "",
            f"turbulence {100 * float(alignment['turbulence_ratio']):.0f} %"
            if alignment.get("turbulence_ratio") is not None
            else "",
        ]
        card["wind alignment"] = ", ".join(p for p in parts if p)
    return card
