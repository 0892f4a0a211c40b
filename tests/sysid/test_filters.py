"""The numpy filters of the discrepancy search and the wind step equal the SciPy calls they replace, to rounding.

SciPy is the reference (cross-implementation). What is compared: the whole output, sample by sample,
``max |ours - scipy| <= 1e-9 * scale`` with `scale` the largest magnitude of SciPy's output (the
signal's scale: an offset included, as the search's signals carry one; exact equality where that is
zero). Rounding alone leaves 1e-17 to 1e-12 of it (the lowest Butterworth cutoffs the most, where
SciPy's own direct-form sections round the most); an edge sample, a window's origin or a filter
state wrong by one sample shows as 1e-3 or more. Signals: white noise, and realistic ones (an
accelerometer's hover with rotor vibration and manoeuvres, a rate's doublets, a command's steps),
with lengths from one sample to 60 000 and SciPy's padding limit.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy import ndimage, signal

from flightlogs._moving import moving_mean  # the search's moving mean is ingest's: held to SciPy here too
from sysid._filters import (
    _butterworth_fractions,
    butterworth_zero_phase,
    one_pole,
    savgol_slope,
    welch_density,
)
from sysid.discrepancy.series import _FILTER_PAD, _anti_aliased
from sysid.fit.wind_offset import SMOOTHING_HZ, smoothed

_RTOL = 1e-9  # of the signal's scale: rounding is 1e-12 at most


def _assert_same(ours: np.ndarray, scipys: np.ndarray) -> None:
    """Equal sample by sample within 1e-9 of the reference's largest magnitude (exactly where that is 0)."""
    assert ours.shape == scipys.shape
    scale = float(np.max(np.abs(scipys))) if scipys.size else 0.0
    error = float(np.max(np.abs(ours - scipys))) if scipys.size else 0.0
    assert error <= _RTOL * scale, f"max |difference| {error:.3g} against a scale of {scale:.3g}"


def _signal(kind: str, n: int, rate_hz: float, seed: int) -> np.ndarray:
    """A test signal of `n` samples at `rate_hz`: white noise or a realistic flight signal with its offset."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / rate_hz
    if kind == "noise":
        return rng.standard_normal(n)
    if kind == "accelerometer":  # hover (-9.81 m/s²), rotor vibration at 170 Hz, manoeuvres, sensor noise
        return (
            -9.81
            + 3.0 * np.sin(2 * np.pi * 170.0 * t + 0.3)
            + 2.0 * np.sin(2 * np.pi * 0.4 * t) * (t > 1.0)
            + 0.05 * rng.standard_normal(n)
        )
    if kind == "rate":  # doublets of ±0.5 rad/s averaged over 5 samples, gyro noise
        doublet = 0.5 * (((t % 4.0) < 1.0).astype(float) - (((t % 4.0) >= 1.0) & ((t % 4.0) < 2.0)))
        return np.convolve(doublet, np.full(5, 0.2))[:n] + 0.01 * rng.standard_normal(n) + 0.02
    if kind == "command":  # steps of a mixer input about its hover value
        return 0.45 + 0.1 * np.sign(np.sin(2 * np.pi * 0.7 * t + 0.1)) + 0.002 * rng.standard_normal(n)
    raise ValueError(kind)


_KINDS = ("noise", "accelerometer", "rate", "command")


# ---------------------------------------------------------------------- first-order recursion


@pytest.mark.parametrize("n", [1, 2, 3, 255, 256, 257, 1000, 12_000])
@pytest.mark.parametrize("time_constant_s", [1e-9, 1e-3, 0.0025, 0.03, 0.15, 2.0, 1e6, 1e18])
def test_the_lag_is_lfilter_of_a_first_order_lag(n: int, time_constant_s: float) -> None:
    """first_order's ``lfilter([1 - a], [1, -a], u)``, ``a = exp(-1 / (rate tau))``: a = 0 (tiny τ) to a = 1.0 (huge τ)."""
    a = float(np.exp(-1.0 / (50.0 * time_constant_s)))
    for seed, kind in enumerate(_KINDS):
        u = _signal(kind, n, 50.0, seed)
        u = u - u[0]  # as first_order starts each piece at rest
        _assert_same(one_pole(a, (1.0 - a) * u), signal.lfilter([1.0 - a], [1.0, -a], u))


@pytest.mark.parametrize("n", [1, 5, 300, 5000])
@pytest.mark.parametrize(
    "pole", [0.5 + 0.3j, 0.99 * np.exp(0.1j), 0.9999 * np.exp(0.001j), 1e-3j, -0.9 + 0j, np.exp(0.3j), 1.0 + 0j]
)
def test_a_complex_mode_from_any_state_is_lfilter_with_its_initial_condition(n: int, pole: complex) -> None:
    """``v[k] = p v[k-1] + u[k]`` from ``v[-1] = s``: lfilter's direct form starts from ``zi = p s``."""
    u = _signal("noise", n, 1.0, n) + 1j * _signal("noise", n, 1.0, n + 1)
    state = 1.5 - 2.0j
    expected, _ = signal.lfilter([1.0], [1.0, -pole], u, zi=[pole * state])
    _assert_same(one_pole(complex(pole), u, state), expected)


def test_a_pole_outside_the_unit_circle_is_refused() -> None:
    with pytest.raises(ValueError, match="unit circle"):
        one_pole(1.01, np.ones(4))
    assert one_pole(0.5, np.array([])).size == 0


# ---------------------------------------------------------------------- moving mean


@pytest.mark.parametrize("n", [1, 2, 5, 50, 1001, 60_000])
@pytest.mark.parametrize("width", [1, 2, 3, 4, 5, 10, 11, 100])
def test_the_moving_mean_is_uniform_filter1d_with_held_ends(n: int, width: int) -> None:
    """Even and odd windows (an even one reaches one sample further back), wider than the signal too."""
    for seed, kind in enumerate(_KINDS):
        x = _signal(kind, n, 50.0, seed) + (1000.0 if kind == "noise" else 0.0)  # an offset far above the spread
        _assert_same(moving_mean(x, width), ndimage.uniform_filter1d(x, width, mode="nearest"))


# ---------------------------------------------------------------------- Savitzky-Golay derivative


@pytest.mark.parametrize(("n", "window"), [(5, 5), (7, 5), (30, 7), (25, 25), (26, 25), (5000, 25), (5000, 101)])
@pytest.mark.parametrize("polyorder", [1, 2, 3, 4])
@pytest.mark.parametrize("rate_hz", [50.0, 250.0, 1000.0])
def test_the_slope_is_savgol_filters_first_derivative_with_its_interp_edges(
    n: int, window: int, polyorder: int, rate_hz: float
) -> None:
    """Windows down to 5 and equal to the signal (the edge fits then cover it all but the middle)."""
    if polyorder >= window:
        pytest.skip("no such filter")
    for seed, kind in enumerate(_KINDS):
        x = _signal(kind, n, rate_hz, seed)
        expected = signal.savgol_filter(x, window, polyorder, deriv=1, delta=1.0 / rate_hz)
        _assert_same(savgol_slope(x, window, polyorder, 1.0 / rate_hz), expected)


def test_the_slope_of_a_parabola_is_exact_to_its_ends() -> None:
    """Analytic: a quadratic's Savitzky-Golay slope (polyorder 2) is its derivative everywhere, edges included."""
    t = np.arange(200) / 250.0
    np.testing.assert_allclose(savgol_slope(3.0 * t**2 - t + 2.0, 25, 2, 1.0 / 250.0), 6.0 * t - 1.0, atol=1e-9)


def test_windows_savgol_filter_refuses_are_refused() -> None:
    with pytest.raises(ValueError, match="window=6 must be odd"):
        savgol_slope(np.ones(10), 6, 2, 0.02)
    with pytest.raises(ValueError, match="at most the 4 samples"):
        savgol_slope(np.ones(4), 5, 2, 0.02)


# ---------------------------------------------------------------------- Welch


@pytest.mark.parametrize("n", [1, 2, 7, 64, 1000, 5000, 60_000])
@pytest.mark.parametrize("rate_hz", [10.0, 50.0, 250.0])
def test_the_density_is_welchs_as_the_band_asks_for_it(n: int, rate_hz: float) -> None:
    """``_band``'s call: segments of 64 s or the whole signal (odd lengths too), not detrended."""
    nperseg = min(n, int(64 * rate_hz))
    for seed, kind in enumerate(_KINDS):
        x = _signal(kind, n, rate_hz, seed)
        freq, density = signal.welch(x, fs=rate_hz, nperseg=nperseg, detrend=False)
        ours_freq, ours = welch_density(x, rate_hz, nperseg)
        _assert_same(ours_freq, freq)
        _assert_same(ours, density)


def test_a_segment_longer_than_the_signal_is_the_signal_as_in_scipy() -> None:
    x = _signal("rate", 100, 50.0, 0)
    with pytest.warns(UserWarning, match="nperseg"):
        _, density = signal.welch(x, fs=50.0, nperseg=256, detrend=False)
    _assert_same(welch_density(x, 50.0, 256)[1], density)


# ---------------------------------------------------------------------- zero-phase Butterworth


@pytest.mark.parametrize("order", [2, 4, 6])
@pytest.mark.parametrize("wn", [0.001, 0.005, 0.04, 0.16, 0.32, 0.9])
def test_the_design_has_butters_poles_and_unit_gain_at_dc(order: int, wn: float) -> None:
    _, poles, _ = signal.butter(order, wn, output="zpk")
    upper, residues, direct = _butterworth_fractions(order, wn)
    ours = np.concatenate([upper, upper.conj()])
    np.testing.assert_allclose(np.sort_complex(ours), np.sort_complex(poles), rtol=0, atol=1e-13)
    assert direct + 2.0 * np.sum(np.real(residues / (1.0 - upper))) == pytest.approx(1.0, abs=1e-12)


_RATES = [(250.0, 50.0), (125.0, 50.0), (1000.0, 50.0), (8000.0, 50.0), (250.0, 20.0), (400.0, 100.0)]


@pytest.mark.parametrize("n", [61, 62, 63, 100, 1000, 20_000])
@pytest.mark.parametrize(("from_hz", "to_hz"), _RATES)
def test_the_anti_alias_filter_is_sosfiltfilt_of_butter(n: int, from_hz: float, to_hz: float) -> None:
    """The search's call (4th order at 40 % of the search's rate, 60 samples of padding, n > 60) on each signal."""
    sos = signal.butter(4, 0.4 * to_hz, fs=from_hz, output="sos")
    for seed, kind in enumerate(_KINDS):
        x = _signal(kind, n, from_hz, seed)
        expected = signal.sosfiltfilt(sos, x, padlen=min(_FILTER_PAD, n - 1))
        _assert_same(_anti_aliased(x, from_hz, to_hz), expected)


@pytest.mark.parametrize("order", [2, 4, 6])
@pytest.mark.parametrize("pad", [0, 1, 60, "n - 1"])
@pytest.mark.parametrize(("from_hz", "to_hz"), _RATES)
def test_any_even_order_and_padding_is_sosfiltfilt(order: int, pad: int | str, from_hz: float, to_hz: float) -> None:
    """No padding, one sample, and the longest SciPy takes (n - 1)."""
    n = 500
    x = _signal("accelerometer", n, from_hz, order)
    padlen = n - 1 if pad == "n - 1" else int(pad)
    sos = signal.butter(order, 0.4 * to_hz, fs=from_hz, output="sos")
    expected = signal.sosfiltfilt(sos, x, padlen=padlen)
    _assert_same(butterworth_zero_phase(x, 0.4 * to_hz, from_hz, order=order, pad=padlen), expected)


def test_a_long_log_is_filtered_as_scipy_filters_it() -> None:
    """60 000 samples at 250 Hz (4 min): no drift of the carried state."""
    x = _signal("accelerometer", 60_000, 250.0, 7)
    expected = signal.sosfiltfilt(signal.butter(4, 20.0, fs=250.0, output="sos"), x, padlen=60)
    _assert_same(butterworth_zero_phase(x, 20.0, 250.0, order=4, pad=60), expected)


@pytest.mark.parametrize("n", [32, 33, 1000, 20_000])
@pytest.mark.parametrize("rate_hz", [8.5, 10.0, 50.0, 100.0, 400.0])
def test_the_wind_steps_smoothing_is_sosfiltfilt_of_butter_with_its_default_padding(n: int, rate_hz: float) -> None:
    """The anemometer's wind (north, east) low-passed at 2 Hz as SciPy's call with its defaults, column by column."""
    wind = np.column_stack([_signal("command", n, rate_hz, 3) + 4.0, _signal("rate", n, rate_hz, 4) - 1.5])
    expected = signal.sosfiltfilt(signal.butter(4, SMOOTHING_HZ, fs=rate_hz, output="sos"), wind, axis=0)
    ours = smoothed(wind, rate_hz)
    for column in range(2):
        _assert_same(ours[:, column], expected[:, column])


def test_what_sosfiltfilt_refuses_is_refused() -> None:
    x = np.ones(60)
    with pytest.raises(ValueError, match="below the 60 samples"):
        butterworth_zero_phase(x, 20.0, 250.0, order=4, pad=60)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError):
            signal.sosfiltfilt(signal.butter(4, 20.0, fs=250.0, output="sos"), x, padlen=60)
    with pytest.raises(ValueError, match="order=3 must be even"):
        butterworth_zero_phase(np.ones(100), 20.0, 250.0, order=3, pad=0)
    with pytest.raises(ValueError, match="cutoff_hz=125.0"):
        butterworth_zero_phase(np.ones(100), 125.0, 250.0, order=4, pad=0)
