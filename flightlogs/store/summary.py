"""Plain, JSON-ready summaries of what was ingested (for scripts and the CLI)."""

from __future__ import annotations

from datetime import UTC
from pathlib import Path
from typing import TYPE_CHECKING, Any

from flightlogs.flightlog import FlightLog, WindMeasurement

if TYPE_CHECKING:
    from flightlogs.store.campaign import Campaign

__all__ = ["log_summary", "wind_summary", "conditioned_summary", "campaign_summary"]


def log_summary(log: FlightLog) -> dict[str, Any]:
    """Summarise a flight log as JSON-ready data.

    Parameters
    ----------
    log : FlightLog
        The log read.

    Returns
    -------
    dict
        ``path``, ``log_format``, ``autopilot``, ``vehicle``, ``vehicle_type``, ``duration_s``,
        ``utc_start`` (ISO-8601 or None), ``signals.NAME.{samples, rate_hz,
        unit, source}``, ``missing`` (names) and ``warnings`` (sentences).
    """
    utc_start = log.utc_start
    return {
        "path": str(log.path),
        "log_format": log.log_format,
        "autopilot": log.autopilot,
        "vehicle": log.vehicle,
        "vehicle_type": log.vehicle_type,
        "duration_s": round(log.duration_s, 6),
        "utc_start": utc_start.isoformat() if utc_start else None,
        "signals": {
            name: {
                "samples": signal.samples,
                "rate_hz": round(signal.rate_hz, 3),
                "unit": signal.unit,
                "source": signal.source,
            }
            for name, signal in log.signals.items()
        },
        "missing": list(log.missing),
        "warnings": list(log.warnings),
    }


def wind_summary(wind: WindMeasurement) -> dict[str, Any]:
    """Summarise an anemometer measurement as JSON-ready data.

    Parameters
    ----------
    wind : WindMeasurement
        The anemometer file read.
    """
    from datetime import datetime

    import numpy as np

    def _iso(seconds: float) -> str:
        return datetime.fromtimestamp(float(seconds), tz=UTC).isoformat()

    return {
        "path": str(wind.path),
        "samples": int(wind.utc_s.size),
        "rate_hz": round(float(wind.rate_hz), 3),
        "utc_start": _iso(wind.utc_s[0]),
        "utc_end": _iso(wind.utc_s[-1]),
        "mean_speed_m_s": round(float(np.mean(wind.speed_m_s)), 4),
        "columns": dict(wind.columns),
        "warnings": list(wind.warnings),
    }


def conditioned_summary(flight: Any) -> dict[str, Any]:
    """Summarise a conditioned flight as JSON-ready data.

    Parameters
    ----------
    flight : ConditionedFlight
        The conditioned flight.

    Returns
    -------
    dict
        ``rate_hz``, ``records[]`` (``start_s, end_s, samples, signals``),
        ``segments[]`` (``axis, kind, start_s, end_s, source, f_min_hz,
        f_max_hz``), ``wind_alignment`` (offsets and delays used, or None) and
        ``warnings``.
    """
    alignment = None
    if flight.wind is not None:
        wind = flight.wind
        transport = wind.transport
        alignment = {
            "wind_file": str(wind.wind_path),
            "reference_clock": wind.reference,
            "clock_offset_s": round(wind.clock_offset_s, 4),
            "clock_offset_source": wind.clock_offset_source,
            "transport_delay_s": round(transport.delay_s, 4),
            "transport_delay_source": transport.source,
            "distance_m": transport.distance_m,
            "mean_speed_m_s": round(transport.mean_speed_m_s, 4),
            "turbulence_ratio": round(transport.turbulence_ratio, 4),
            "frozen_turbulence_holds": transport.frozen_turbulence_holds,
            "overlap_s": round(wind.overlap_s, 3),
            "residual_offset_s": None if wind.residual is None else round(wind.residual.lag_s, 4),
            "residual_correlation": None if wind.residual is None else round(wind.residual.correlation, 4),
            "residual_against": wind.residual_against,
            "residual_lag_modelled_s": None if wind.residual is None else round(wind.residual.time_constant_s, 4),
        }
    return {
        "rate_hz": round(flight.rate_hz, 6),
        "records": [
            {
                "label": r.label,
                "start_s": round(r.start_s, 4),
                "end_s": round(r.end_s, 4),
                "samples": int(r.time_s.size),
                "signals": list(r.signals),
            }
            for r in flight.records
        ],
        "segments": [
            {
                "axis": s.axis,
                "kind": s.kind,
                "start_s": round(s.start_s, 3),
                "end_s": round(s.end_s, 3),
                "source": s.source,
                "f_min_hz": s.f_min_hz,
                "f_max_hz": s.f_max_hz,
            }
            for s in flight.segments
        ],
        "wind_alignment": alignment,
        "warnings": list(flight.warnings),
    }


def campaign_summary(campaign: Campaign, out: str | Path | None = None) -> dict[str, Any]:
    """What an ingest found, as ``sysid ingest --json`` gives it and ``sysid report --ingest-summary`` reads it.

    Parameters
    ----------
    campaign : Campaign
        The logs read and conditioned.
    out : str or Path, optional
        The dataset written, if any.

    Returns
    -------
    dict
        ``logs``: for each log its :func:`log_summary`, with its :func:`conditioned_summary` where it was
        conditioned and every warning; ``wind``: each anemometer file's :func:`wind_summary`; ``output``.
        With one log, its entry's keys also at the top level.
    """
    entries = []
    for log, flight, notes in zip(campaign.logs, campaign.conditioned, campaign.notes):
        entry = log_summary(log)
        if flight is not None:
            conditioned = conditioned_summary(flight)
            entry.update({k: v for k, v in conditioned.items() if k != "warnings"})
            entry["warnings"] += conditioned["warnings"]
        entry["warnings"] += list(notes)
        entries.append(entry)
    summary: dict[str, Any] = dict(entries[0]) if len(entries) == 1 else {}
    summary["logs"] = entries
    summary["wind"] = [wind_summary(wind) for wind in campaign.winds]
    summary["output"] = str(out) if out is not None else None
    return summary
