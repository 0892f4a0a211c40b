"""The residual clock offset against a wind estimate that lags the air (issue 31): the lag is modelled, not read as offset."""

from __future__ import annotations

import math

import numpy as np
import pytest

from flightlogs.conditioning import estimate_residual_offset

RATE_HZ = 20.0


def _air(seed: int, n: int) -> np.ndarray:
    """Gusts, north and east, m/s: white noise through a 1.5 s first-order filter, shape (n, 2)."""
    rng = np.random.default_rng(seed)
    keep = math.exp(-1.0 / (1.5 * RATE_HZ))
    out = np.zeros((n, 2))
    noise = rng.standard_normal((n, 2))
    for k in range(1, n):
        out[k] = keep * out[k - 1] + (1 - keep) * noise[k]
    return out / out.std(axis=0)


def _smoothed(wind: np.ndarray, tau_s: float) -> np.ndarray:
    """An EKF-like wind state: the air through a first-order lag of `tau_s`, by its own recursion."""
    keep, out = math.exp(-1.0 / (tau_s * RATE_HZ)), wind.copy()
    for k in range(1, wind.shape[0]):
        out[k] = keep * out[k - 1] + (1 - keep) * wind[k]
    return out


@pytest.mark.parametrize(("offset_s", "tau_s"), [(1.2, 2.5), (-0.8, 3.7), (0.6, 0.0)])
def test_the_offset_is_measured_through_the_estimators_lag(offset_s: float, tau_s: float) -> None:
    """3.7 s lies between the lags tried; 0 is a plain delay."""
    n, shift = 6000, int(round(offset_s * RATE_HZ))
    air = _air(1, n + 400)
    anemometer = air[200 : 200 + n]
    seen = air[200 - shift : 200 - shift + n]  # the vehicle meets the air `offset_s` later than assumed
    estimate = _smoothed(seen, tau_s) if tau_s > 0 else seen
    estimate = estimate + 0.05 * np.random.default_rng(2).standard_normal(estimate.shape)
    table = {"est_wind_n": estimate[:, 0], "est_wind_e": estimate[:, 1]}
    found, against = estimate_residual_offset(np.arange(n) / RATE_HZ, anemometer, table, RATE_HZ)
    assert found is not None and against == "autopilot wind estimate"
    assert abs(found.lag_s - offset_s) <= 0.1, found
    assert abs(found.time_constant_s - tau_s) <= 0.6, found


def test_the_lag_is_scipys_first_order_filter() -> None:
    """The bidiagonal solve that models the lag equals ``scipy.signal.lfilter`` started at rest on the first value."""
    from scipy.signal import lfilter

    from flightlogs.conditioning.align import _first_order_lag

    signal = np.random.default_rng(3).standard_normal((800, 2)).cumsum(axis=0)
    keep = math.exp(-1.0 / (2.5 * RATE_HZ))
    expected = np.vstack([signal[:1], lfilter([1 - keep], [1, -keep], signal[1:], axis=0, zi=keep * signal[:1])[0]])
    np.testing.assert_allclose(_first_order_lag(signal, 2.5, RATE_HZ), expected, rtol=1e-12, atol=1e-12)
