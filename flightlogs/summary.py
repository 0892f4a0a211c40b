"""Plain, JSON-ready summaries of what was ingested (for scripts and the CLI)."""

from __future__ import annotations

from typing import Any

from .flightlog import FlightLog

__all__ = ["log_summary", "wind_summary"]


def log_summary(log: FlightLog) -> dict[str, Any]:
    """Summarise a flight log as JSON-ready data.

    Parameters
    ----------
    log : FlightLog
        The log read.

    Returns
    -------
    dict
        ``path``, ``log_format``, ``autopilot``, ``vehicle``, ``duration_s``,
        ``utc_start`` (ISO-8601 or None), ``signals.NAME.{samples, rate_hz,
        unit, source}``, ``missing`` (names) and ``warnings`` (sentences).
    """
    utc_start = log.utc_start
    return {
        "path": str(log.path),
        "log_format": log.log_format,
        "autopilot": log.autopilot,
        "vehicle": log.vehicle,
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


def wind_summary(wind: Any) -> dict[str, Any]:
    """Summarise an anemometer measurement as JSON-ready data.

    Parameters
    ----------
    wind : WindMeasurement
        The anemometer file read.
    """
    import numpy as np

    from datetime import datetime, timezone

    def _iso(seconds: float) -> str:
        return datetime.fromtimestamp(float(seconds), tz=timezone.utc).isoformat()

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
