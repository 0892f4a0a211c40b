"""Put anemometer wind on a flight log's clock: UTC pairing, clock offset, transport delay.

Times are related by::

    anemometer time = reference time + clock_offset_s
    reference time  = UTC (log with GPS time) or the log's own clock (without)
    log time        = UTC - utc_offset_s
    wind at the vehicle at log time t = wind measured at the anemometer at t - transport_delay_s
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Literal

import numpy as np

from flightlogs.conditioning.lag import LagEstimate, TransportDelay, estimate_lag
from flightlogs.errors import DataError
from flightlogs.flightlog import FlightLog, WindMeasurement

__all__ = [
    "ESTIMATOR_LAGS_S",
    "WindAlignment",
    "pair_winds",
    "overlap_s",
    "wind_log_time",
    "estimate_residual_offset",
]


@dataclass(frozen=True, slots=True, kw_only=True)
class WindAlignment:
    """How an anemometer record was put on a log's clock.

    Parameters
    ----------
    wind_path : Path
        The anemometer file.
    reference : {"utc", "log"}
        Clock the offset is taken against: UTC when the log has GPS time,
        else the log's own clock.
    clock_offset_s : float
        Anemometer clock minus reference clock, s.
    clock_offset_source : {"gps", "user", "estimated"}
        Where the offset came from: GPS time alone, the user, or GPS time
        plus the residual found by cross-correlation.
    transport : TransportDelay
        Anemometer-to-vehicle delay applied.
    overlap_s : float
        Time the wind record overlaps the log, s.
    residual : LagEstimate or None
        Residual clock offset found by correlating the delayed wind with the
        autopilot's wind estimate or the vehicle's attitude, s (None when
        neither could be used).
    residual_against : str or None
        What the residual was estimated against.
    """

    wind_path: Path
    reference: Literal["utc", "log"]
    clock_offset_s: float
    clock_offset_source: Literal["gps", "user", "estimated"]
    transport: TransportDelay
    overlap_s: float
    residual: LagEstimate | None = None
    residual_against: str | None = None


def _log_span_utc(log: FlightLog) -> tuple[float, float]:
    start, end = log.time_range_s
    assert log.utc_offset_s is not None
    return start + log.utc_offset_s, end + log.utc_offset_s


def overlap_s(log: FlightLog, wind: WindMeasurement, *, clock_offset_s: float = 0.0) -> float:
    """Seconds during which `wind` covers `log` (0 if they do not meet).

    Parameters
    ----------
    log : FlightLog
        The flight; needs GPS time unless `clock_offset_s` maps its own clock.
    wind : WindMeasurement
        The anemometer record (``utc_s`` on the anemometer's clock).
    clock_offset_s : float, optional
        Anemometer clock minus reference clock, s.
    """
    return _overlap(_span(log), wind, clock_offset_s)


def _span(log: FlightLog) -> tuple[float, float]:
    """The log's first and last sample time, UTC s where it has GPS time, else on its own clock."""
    return log.time_range_s if log.utc_offset_s is None else _log_span_utc(log)


def _overlap(span: tuple[float, float], wind: WindMeasurement, clock_offset_s: float) -> float:
    w_start = float(wind.utc_s[0]) - clock_offset_s
    w_end = float(wind.utc_s[-1]) - clock_offset_s
    return max(0.0, min(span[1], w_end) - max(span[0], w_start))


def _iso(seconds: float) -> str:
    return datetime.fromtimestamp(seconds, tz=UTC).strftime("%Y-%m-%d %H:%M:%S UTC")


def pair_winds(
    logs: Sequence[FlightLog], winds: Sequence[WindMeasurement], *, clock_offset_s: float | None = None
) -> list[WindMeasurement | None]:
    """Pair each log with the anemometer record that overlaps it most in time.

    Parameters
    ----------
    logs : sequence of FlightLog
        Flights of a campaign.
    winds : sequence of WindMeasurement
        Anemometer records (any order).
    clock_offset_s : float, optional
        Anemometer clock minus reference clock, s, as given by the user. It is
        required for logs without GPS time.

    Returns
    -------
    list
        For each log, its WindMeasurement (None when `winds` is empty).

    Raises
    ------
    DataError
        If a log has no GPS time and no offset is given, or no record overlaps a log.
    """
    if not winds:
        return [None] * len(logs)
    paired: list[WindMeasurement | None] = []
    for log in logs:
        if log.utc_offset_s is None and clock_offset_s is None:
            raise DataError(
                f"{log.path}: the log has no GPS time, so the anemometer cannot be aligned by UTC; "
                "give `wind_offset_s` (anemometer time minus log time, s)"
            )
        offset, span = clock_offset_s or 0.0, _span(log)  # the span once: every record is tried against it
        overlaps = [_overlap(span, wind, offset) for wind in winds]
        best = int(np.argmax(overlaps))
        if overlaps[best] <= 0.0:
            raise DataError(_no_overlap_message(log, winds, offset))
        paired.append(winds[best])
    return paired


def _no_overlap_message(log: FlightLog, winds: Sequence[WindMeasurement], offset: float) -> str:
    spans = "; ".join(
        f"{Path(w.path).name} {_iso(float(w.utc_s[0]) - offset)} to {_iso(float(w.utc_s[-1]) - offset)}" for w in winds
    )
    if log.utc_offset_s is None:
        start, end = log.time_range_s
        where = f"log clock {start:.1f} to {end:.1f} s"
    else:
        start, end = _log_span_utc(log)
        where = f"{_iso(start)} to {_iso(end)}"
    return (
        f"{log.path}: no anemometer record overlaps the flight ({where}; {spans}); "
        "if the anemometer clock is off, give `wind_offset_s`"
    )


def wind_log_time(
    log: FlightLog, wind: WindMeasurement, *, clock_offset_s: float, transport_delay_s: float
) -> np.ndarray:
    """Times of the wind samples on the log's clock, as felt at the vehicle.

    Parameters
    ----------
    log : FlightLog
        The flight.
    wind : WindMeasurement
        The anemometer record.
    clock_offset_s : float
        Anemometer clock minus reference clock, s.
    transport_delay_s : float
        Anemometer-to-vehicle delay, s.

    Returns
    -------
    ndarray, shape (n_wind_samples,)
        Log time (s) at which each anemometer sample reaches the vehicle.
    """
    reference = np.asarray(wind.utc_s, dtype=np.float64) - clock_offset_s
    log_time = reference - (log.utc_offset_s or 0.0)
    return log_time + transport_delay_s


#: First-order lags tried for what the anemometer is correlated with, s: EKF wind states smooth over 1-5 s.
ESTIMATOR_LAGS_S = (0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0)
_SEARCH_RATE_HZ = 20.0


def _first_order_lag(signal: np.ndarray, time_constant_s: float, rate_hz: float) -> np.ndarray:
    """`signal` (n, m) through a causal first-order lag of `time_constant_s`, started at its first value.

    ``y[0] = x[0]``, ``y[n] = a y[n-1] + (1 - a) x[n]``: a lower bidiagonal system, solved by LAPACK
    (scipy.signal's ``lfilter`` gives the same and takes 0.75 s to load).
    """
    if time_constant_s <= 0.0 or signal.shape[0] < 2:
        return signal
    from scipy.linalg import solve_banded

    keep = math.exp(-1.0 / (time_constant_s * rate_hz))
    rhs = (1.0 - keep) * np.asarray(signal[1:], dtype=np.float64)
    rhs[0] += keep * signal[0]
    bands = np.vstack([np.ones(rhs.shape[0]), np.full(rhs.shape[0], -keep)])  # diagonal, then below it
    out: np.ndarray = np.vstack([signal[:1], solve_banded((1, 0), bands, rhs)])
    return out


def estimate_residual_offset(
    time_s: np.ndarray,
    wind_ne: np.ndarray,
    table: dict[str, np.ndarray],
    rate_hz: float,
    *,
    max_lag_s: float = 10.0,
) -> tuple[LagEstimate | None, str | None]:
    """Residual clock offset between the delayed anemometer wind and the vehicle.

    Correlates with the autopilot's own wind estimate where the log has one,
    else with the attitude a position-holding multirotor takes to lean into
    the wind (pitch against the wind along the nose, roll against the wind
    across it). Both lag the air: an EKF's wind is a smoothed state, the lean
    follows the position loop; correlated as they are, that lag reads as
    clock offset (2.5 s of estimator smoothing read 1.3 s of it on the
    independent generator's flights). So the anemometer's wind is first
    passed through a first-order lag of each time constant in
    :data:`ESTIMATOR_LAGS_S`, and the one that correlates best says the lag;
    the delay at it is the offset.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Uniform time base, s.
    wind_ne : ndarray, shape (n_samples, 2)
        Anemometer wind on that time base (transport delay applied), m/s.
    table : dict of ndarray
        Canonical signals on the same time base.
    rate_hz : float
        Sample rate, Hz.
    max_lag_s : float, optional
        Largest residual searched, s.

    Returns
    -------
    tuple
        The :class:`LagEstimate` (positive: the vehicle sees the wind later than
        assumed, so the anemometer clock is ahead by that much; its
        ``time_constant_s`` the lag modelled) and the name of what it was
        estimated against; ``(None, None)`` when no usable signal.
    """
    max_lag_s = min(max_lag_s, 0.2 * (time_s[-1] - time_s[0]))
    if "est_wind_n" in table and "est_wind_e" in table:
        wind, responses = wind_ne, [table["est_wind_n"], table["est_wind_e"]]
        against = "autopilot wind estimate"
    elif {"phi", "theta", "psi"} <= table.keys():
        from flightlogs.frames import wind_to_body_axes

        wind, responses = wind_to_body_axes(wind_ne, table["psi"]), [table["theta"], -table["phi"]]
        against = "attitude (leaning into the wind)"
    else:
        return None, None
    step = max(int(rate_hz // _SEARCH_RATE_HZ), 1)  # the lag is searched at about the anemometer's rate
    found: tuple[float, int, float] | None = None  # (|correlation|, component, time constant)
    for tau in ESTIMATOR_LAGS_S:
        lagged = _first_order_lag(wind[::step], tau, rate_hz / step)
        for k, response in enumerate(responses):
            try:
                estimate = estimate_lag(
                    lagged[:, k], response[::step], rate_hz / step, max_lag_s=max_lag_s, prewhiten=False
                )
            except DataError:
                continue
            if found is None or abs(estimate.correlation) > found[0]:
                found = (abs(estimate.correlation), k, tau)
    best: LagEstimate | None = None
    if found is not None:  # the delay at the lag found, at the full rate
        _, k, tau = found
        lagged = _first_order_lag(wind[:, k : k + 1], tau, rate_hz)[:, 0]
        best = replace(
            estimate_lag(lagged, responses[k], rate_hz, max_lag_s=max_lag_s, prewhiten=False), time_constant_s=tau
        )
    return (best, against) if best is not None else (None, None)
