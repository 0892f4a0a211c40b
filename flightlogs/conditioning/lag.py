"""Time shifts between streams: lag by cross-correlation, and the wind's transport delay."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, cast

import numpy as np

from flightlogs._moving import fast_fft_length
from flightlogs.errors import DataError

__all__ = [
    "LagEstimate",
    "estimate_lag",
    "TransportDelay",
    "transport_delay",
    "FROZEN_TURBULENCE_LIMIT",
]

#: Taylor's frozen-turbulence condition: sigma_M / M must stay below this (section 3.3.2).
FROZEN_TURBULENCE_LIMIT = 0.5


@dataclass(frozen=True, slots=True, kw_only=True)
class LagEstimate:
    """How far one stream lags another.

    Parameters
    ----------
    lag_s : float
        Delay of the second stream against the first, s (positive: it lags).
    correlation : float
        Normalised cross-correlation at the peak, -1..1 (its sign tells
        whether the two move together or against each other).
    time_constant_s : float, optional
        First-order lag the first stream was passed through before the
        delay was measured (an estimator's smoothing, modelled), s; 0 when none.
    """

    lag_s: float
    correlation: float
    time_constant_s: float = 0.0


def estimate_lag(
    reference: np.ndarray,
    delayed: np.ndarray,
    rate_hz: float,
    *,
    max_lag_s: float,
    prewhiten: bool = True,
) -> LagEstimate:
    """Estimate the delay of `delayed` against `reference` by cross-correlation.

    Parameters
    ----------
    reference, delayed : ndarray, shape (n_samples,)
        Two streams on the same uniform time base.
    rate_hz : float
        Sample rate of both, Hz.
    max_lag_s : float
        Largest delay searched, either way, s.
    prewhiten : bool, optional
        Correlate first differences instead of the signals. Wind and vehicle
        motion have red spectra whose correlation peaks are broad; differencing
        sharpens the peak. Default True.

    Returns
    -------
    LagEstimate
        The lag of the strongest correlation (by magnitude), refined below one
        sample by a parabola through the peak and its two neighbours.

    Raises
    ------
    DataError
        If the streams differ in length, are too short or carry no variation.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> x = np.cumsum(rng.normal(size=4000))
    >>> round(estimate_lag(x[50:], x[:-50], 100.0, max_lag_s=2.0).lag_s, 3)
    0.5
    """
    reference = np.asarray(reference, dtype=np.float64)
    delayed = np.asarray(delayed, dtype=np.float64)
    if reference.shape != delayed.shape or reference.ndim != 1:
        raise DataError(f"streams to correlate must be 1-D of equal length, got {reference.shape} and {delayed.shape}")
    max_lag = int(round(max_lag_s * rate_hz))
    if reference.size < 2 * max_lag + 8:
        raise DataError(f"{reference.size} samples are too few to search lags of ±{max_lag_s:g} s at {rate_hz:g} Hz")
    a, b = (np.diff(reference), np.diff(delayed)) if prewhiten else (reference, delayed)
    a = _detrended(a)
    b = _detrended(b)
    norm = np.sqrt(np.dot(a, a) * np.dot(b, b))
    if norm == 0.0:
        raise DataError("a stream to correlate is constant: no lag can be estimated")
    full, lags = _correlation(b, a, max_lag)
    full /= norm
    peak = int(np.argmax(np.abs(full)))
    shift = 0.0
    if 0 < peak < full.size - 1:
        left, centre, right = np.abs(full[peak - 1 : peak + 2])
        curvature = left - 2.0 * centre + right
        if curvature < 0.0:
            shift = 0.5 * (left - right) / curvature
    return LagEstimate(lag_s=float((lags[peak] + shift) / rate_hz), correlation=float(full[peak]))


def _detrended(x: np.ndarray) -> np.ndarray:
    """`x` less its least-squares straight line: ``scipy.signal.detrend(x)`` (to rounding)."""
    t = np.arange(x.size, dtype=np.float64) / x.size
    basis = np.column_stack([t, np.ones(x.size)])
    coefficients, *_ = np.linalg.lstsq(basis, x, rcond=None)
    return cast(np.ndarray, x - basis @ coefficients)


def _correlation(b: np.ndarray, a: np.ndarray, max_lag: int) -> tuple[np.ndarray, np.ndarray]:
    """``sum_n b[n + k] a[n]`` for lags ``k`` from ``-max_lag`` to ``max_lag``, and the lags, by FFT.

    ``scipy.signal.correlate(b, a, "full", method="fft")`` at those lags (to rounding), without
    importing scipy.signal, which takes longer to load than a log to read.
    """
    size = fast_fft_length(a.size + b.size - 1)
    circular = np.fft.irfft(np.fft.rfft(b, size) * np.conj(np.fft.rfft(a, size)), size)
    positive = circular[: min(max_lag, b.size - 1) + 1]
    negative = circular[size - min(max_lag, a.size - 1) :]  # lags -max_lag..-1 wrap to the end
    lags = np.arange(-negative.size, positive.size)
    return np.concatenate([negative, positive]), lags


@dataclass(frozen=True, slots=True, kw_only=True)
class TransportDelay:
    """Time the air takes from the anemometer to the vehicle (Taylor's hypothesis).

    Parameters
    ----------
    delay_s : float
        Delay applied to the anemometer record, s.
    source : {"geometry", "gps", "user", "correlation"}
        How `delay_s` was found: ``"geometry"`` from a distance (and bearing)
        the user gave, ``"gps"`` from the anemometer's position and the
        vehicle's mean GNSS position, ``"user"`` given outright,
        ``"correlation"`` from a cross-correlation.
    distance_m : float or None
        Anemometer-to-vehicle distance, m.
    along_line_speed_m_s : float or None
        Mean wind velocity along the anemometer-to-vehicle line, m/s.
    mean_speed_m_s : float
        Mean horizontal wind speed M, m/s.
    speed_std_m_s : float
        Standard deviation of the speed, sigma_M, m/s.
    bearing_rad : float or None
        Direction from the anemometer to the vehicle, rad clockwise from
        north; None when the anemometer was taken to be straight upstream.
    """

    delay_s: float
    source: Literal["geometry", "gps", "user", "correlation"]
    distance_m: float | None
    along_line_speed_m_s: float | None
    mean_speed_m_s: float
    speed_std_m_s: float
    bearing_rad: float | None = None

    @property
    def turbulence_ratio(self) -> float:
        """sigma_M / M (inf in a calm)."""
        return self.speed_std_m_s / self.mean_speed_m_s if self.mean_speed_m_s > 0 else float("inf")

    @property
    def frozen_turbulence_holds(self) -> bool:
        """True when sigma_M < 0.5 M, the condition for Taylor's hypothesis."""
        return self.turbulence_ratio < FROZEN_TURBULENCE_LIMIT


def transport_delay(
    wind_ne: np.ndarray,
    *,
    distance_m: float | None = None,
    bearing_rad: float | None = None,
    delay_s: float | None = None,
) -> TransportDelay:
    """Transport delay from the anemometer to the vehicle: distance / mean wind speed.

    Parameters
    ----------
    wind_ne : ndarray, shape (n_samples, 2)
        Measured wind ``wind_n, wind_e`` over the flight, m/s (velocity of the air).
    distance_m : float, optional
        Anemometer-to-vehicle distance, m. Needed unless `delay_s` is given.
    bearing_rad : float, optional
        Direction from the anemometer to the vehicle, rad clockwise from north.
        Without it the anemometer is taken to be straight upstream (the
        dissertation's set-up) and the full mean speed carries the air.
    delay_s : float, optional
        A delay chosen by the user, s; the statistics are still reported.

    Returns
    -------
    TransportDelay

    Raises
    ------
    DataError
        If neither a distance nor a delay is given, or the wind does not blow
        from the anemometer towards the vehicle.

    Examples
    --------
    The dissertation's strong-wind case: 4.6 m upstream at 5.4 m/s.

    >>> wind = np.column_stack([np.full(100, -5.4), np.zeros(100)])
    >>> round(transport_delay(wind, distance_m=4.6).delay_s, 4)
    0.8519
    """
    wind_ne = np.asarray(wind_ne, dtype=np.float64)
    speed = np.hypot(wind_ne[:, 0], wind_ne[:, 1])
    mean_speed, speed_std = float(speed.mean()), float(speed.std())
    if delay_s is not None:
        return TransportDelay(
            delay_s=float(delay_s),
            source="user",
            distance_m=distance_m,
            along_line_speed_m_s=None,
            mean_speed_m_s=mean_speed,
            speed_std_m_s=speed_std,
        )
    if distance_m is None:
        raise DataError(
            "the transport delay needs the anemometer-to-vehicle distance (`wind_distance_m`) or a delay (`transport_delay_s`)"
        )
    mean_vector = wind_ne.mean(axis=0)
    if bearing_rad is None:
        along = float(np.hypot(*mean_vector))
    else:
        along = float(mean_vector[0] * np.cos(bearing_rad) + mean_vector[1] * np.sin(bearing_rad))
    if along <= 0.1:
        raise DataError(
            f"the mean wind along the anemometer-to-vehicle line is {along:.2f} m/s: the anemometer "
            "is not upstream of the vehicle, so no transport delay follows; give the delay explicitly"
        )
    bearing = None if bearing_rad is None else float(bearing_rad)
    return TransportDelay(
        delay_s=distance_m / along,
        source="geometry",
        distance_m=float(distance_m),
        along_line_speed_m_s=along,
        mean_speed_m_s=mean_speed,
        speed_std_m_s=speed_std,
        bearing_rad=bearing,
    )
