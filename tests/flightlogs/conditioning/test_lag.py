"""Lag estimation and transport delay against known, synthetic truth."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal as sps

from flightlogs.conditioning.lag import estimate_lag, transport_delay
from flightlogs.errors import DataError

RATE_HZ = 100.0


def _turbulence(n: int, seed: int) -> np.ndarray:
    """Low-pass filtered noise, a stand-in for gusty wind (first-order, 1 Hz corner)."""
    rng = np.random.default_rng(seed)
    b, a = sps.butter(1, 1.0, fs=RATE_HZ)
    return sps.lfilter(b, a, rng.normal(size=n)) * 3.0 + 4.0


def _delayed(x: np.ndarray, delay_s: float) -> np.ndarray:
    """x delayed by a fractional number of samples (exact band-limited shift via FFT)."""
    n = x.size
    freq = np.fft.rfftfreq(n, d=1.0 / RATE_HZ)
    return np.fft.irfft(np.fft.rfft(x) * np.exp(-2j * np.pi * freq * delay_s), n)


@pytest.mark.parametrize("delay_s", [0.0, 0.01, 0.237, 0.8519, -1.234, 2.5])
def test_known_delay_is_recovered_within_one_sample(delay_s: float) -> None:
    wind = _turbulence(12_000, seed=3)
    rng = np.random.default_rng(4)
    measured = _delayed(wind, delay_s) + rng.normal(scale=0.05, size=wind.size)  # anemometer noise
    estimate = estimate_lag(wind[500:-500], measured[500:-500], RATE_HZ, max_lag_s=4.0)
    assert abs(estimate.lag_s - delay_s) < 1.0 / RATE_HZ
    assert estimate.correlation > 0.5


@settings(max_examples=25, deadline=None)
@given(lag_samples=st.integers(min_value=-300, max_value=300), seed=st.integers(0, 2**16))
def test_integer_shifts_are_exact(lag_samples: int, seed: int) -> None:
    x = _turbulence(5000, seed)
    reference = x[400:4600]
    delayed = x[400 - lag_samples : 4600 - lag_samples]
    assert estimate_lag(reference, delayed, RATE_HZ, max_lag_s=3.5).lag_s == pytest.approx(
        lag_samples / RATE_HZ, abs=1e-3
    )


def test_an_inverted_stream_gives_a_negative_correlation() -> None:
    x = _turbulence(4000, seed=9)
    estimate = estimate_lag(x, -_delayed(x, 0.3), RATE_HZ, max_lag_s=1.0)
    assert estimate.lag_s == pytest.approx(0.3, abs=0.01) and estimate.correlation < -0.5


@pytest.mark.parametrize(
    ("a", "b", "message"),
    [
        (np.zeros(100), np.zeros(99), "equal length"),
        (np.zeros(50), np.zeros(50), "too few"),
        (np.ones(1000), np.ones(1000), "constant"),
    ],
)
def test_bad_streams_are_refused(a: np.ndarray, b: np.ndarray, message: str) -> None:
    with pytest.raises(DataError, match=message):
        estimate_lag(a, b, RATE_HZ, max_lag_s=0.4)


def test_transport_delay_is_distance_over_mean_speed() -> None:
    # The dissertation's set-up: anemometer 4.6 m straight upstream; light wind 2.7 m/s from the west.
    wind = np.column_stack([np.zeros(2000), 2.7 + 0.3 * np.sin(np.linspace(0, 40, 2000))])
    delay = transport_delay(wind, distance_m=4.6)
    assert delay.delay_s == pytest.approx(4.6 / np.hypot(*wind.mean(axis=0)))
    assert delay.source == "geometry" and delay.frozen_turbulence_holds
    # with a bearing: the vehicle 4.6 m north-east of the sensor sees only the component along that line
    along = transport_delay(wind, distance_m=4.6, bearing_rad=np.radians(45.0))
    assert along.along_line_speed_m_s == pytest.approx(wind[:, 1].mean() * np.sin(np.radians(45.0)))
    assert along.delay_s == pytest.approx(4.6 / along.along_line_speed_m_s)


def test_gusty_calm_breaks_frozen_turbulence() -> None:
    rng = np.random.default_rng(1)
    speed = np.abs(0.9 + rng.normal(scale=0.8, size=5000))
    wind = np.column_stack([speed, np.zeros_like(speed)])
    delay = transport_delay(wind, distance_m=4.6)
    assert delay.turbulence_ratio == pytest.approx(speed.std() / speed.mean())
    assert not delay.frozen_turbulence_holds


def test_a_downstream_anemometer_is_refused() -> None:
    wind = np.column_stack([np.full(100, 3.0), np.zeros(100)])  # air moving north
    with pytest.raises(DataError, match="not upstream"):
        transport_delay(wind, distance_m=4.6, bearing_rad=np.pi)  # vehicle south of the sensor
    with pytest.raises(DataError, match="distance"):
        transport_delay(wind)
    assert transport_delay(wind, delay_s=0.4).delay_s == 0.4


def test_the_transport_delay_records_the_bearing_it_used() -> None:
    wind = np.column_stack([np.full(100, 3.0), np.full(100, 4.0)])
    assert transport_delay(wind, distance_m=4.6).bearing_rad is None
    delay = transport_delay(wind, distance_m=5.0, bearing_rad=np.arctan2(4.0, 3.0))
    assert delay.bearing_rad == pytest.approx(np.arctan2(4.0, 3.0))
    assert delay.delay_s == pytest.approx(1.0)  # straight downwind at 5 m/s


@pytest.mark.parametrize(("n_a", "n_b", "max_lag"), [(500, 500, 40), (300, 700, 250), (700, 300, 299), (64, 64, 63)])
def test_the_detrend_and_correlation_are_scipys(n_a: int, n_b: int, max_lag: int) -> None:
    from scipy import signal as sps

    from flightlogs.conditioning.lag import _correlation, _detrended

    rng = np.random.default_rng(n_a + n_b)
    a, b = rng.standard_normal(n_a) + 0.01 * np.arange(n_a), rng.standard_normal(n_b)
    np.testing.assert_allclose(_detrended(a), sps.detrend(a), rtol=0, atol=1e-12)
    full = sps.correlate(b, a, mode="full", method="fft")
    lags = sps.correlation_lags(b.size, a.size, mode="full")
    window = np.abs(lags) <= max_lag
    ours, our_lags = _correlation(b, a, max_lag)
    np.testing.assert_array_equal(our_lags, lags[window])
    np.testing.assert_allclose(ours, full[window], rtol=0, atol=1e-10)
