"""Resampling onto a uniform time base: accuracy, anti-aliasing, gaps, invariants.

Reference values are analytic: a resampled sine must keep the amplitude and
phase of the sine it came from (measured by a least-squares fit at the known
frequency); a cubic spline reproduces polynomials up to degree 3 exactly.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from flightlogs.conditioning import resample
from flightlogs.conditioning.resample import (
    ContiguousSpans,
    Gap,
    contiguous_spans,
    find_gaps,
    resample_signal,
    resample_signals,
    uniform_time_base,
)
from flightlogs.errors import DataError
from flightlogs.flightlog import Signal

AMPLITUDE_TOL_DB = 0.1
PHASE_TOL_DEG = 1.0


def _sine_fit(time_s: np.ndarray, values: np.ndarray, freq_hz: float) -> complex:
    """Complex amplitude A·e^{jφ} of A·sin(2πft + φ) in `values` (least squares, with an offset)."""
    ok = np.isfinite(values)
    arg = 2 * np.pi * freq_hz * time_s[ok]
    design = np.column_stack([np.sin(arg), np.cos(arg), np.ones(arg.size)])
    (s, c, _), *_ = np.linalg.lstsq(design, values[ok], rcond=None)
    return complex(s, c)


def _errors(measured: complex, expected: complex) -> tuple[float, float]:
    """Amplitude error, dB, and phase error, deg."""
    ratio = measured / expected
    return 20 * np.log10(abs(ratio)), float(np.degrees(np.angle(ratio)))


def _jittered(rate_hz: float, duration_s: float, jitter_s: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    n = int(duration_s * rate_hz)
    return np.arange(n) / rate_hz + np.clip(rng.normal(0, jitter_s, n), -0.4 / rate_hz, 0.4 / rate_hz)


# ------------------------------------------------------------------ accuracy

UPSAMPLE_FREQS_HZ = [0.1, 0.25, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0]  # up to 0.4 × Nyquist of 20 Hz


@pytest.mark.parametrize("freq_hz", UPSAMPLE_FREQS_HZ)
def test_a_jittery_20_hz_stream_upsampled_to_100_hz_keeps_amplitude_and_phase(freq_hz: float) -> None:
    # anemometer-like: 20 Hz with 2 ms timing jitter (the logged times are the true sample times)
    t_src = _jittered(20.0, 60.0, 0.002, seed=1)
    phase = 0.7
    wind = (t_src, 1.5 * np.sin(2 * np.pi * freq_hz * t_src + phase))
    time_base = uniform_time_base([wind], rate_hz=100.0)
    out = resample_signal(wind, time_base)
    assert np.isfinite(out).all()
    amp_db, phase_deg = _errors(_sine_fit(time_base, out, freq_hz), 1.5 * np.exp(1j * phase))
    # cubic-spline theory at f/fs = 0.2: -0.042 dB, zero phase (symmetric kernel)
    assert abs(amp_db) < AMPLITUDE_TOL_DB
    assert abs(phase_deg) < PHASE_TOL_DEG


@pytest.mark.parametrize(("alias_src_hz", "alias_out_hz"), [(60.0, 40.0), (70.0, 30.0), (130.0, 30.0), (190.0, 10.0)])
def test_downsampling_1_khz_to_100_hz_suppresses_the_alias(alias_src_hz: float, alias_out_hz: float) -> None:
    t_src = _jittered(1000.0, 20.0, 5e-5, seed=2)
    values = 0.8 * np.sin(2 * np.pi * 5.0 * t_src + 0.3) + np.sin(2 * np.pi * alias_src_hz * t_src)
    time_base = uniform_time_base([(t_src, values)], rate_hz=100.0)
    out = resample_signal((t_src, values), time_base)
    inner = (time_base > time_base[0] + 0.5) & (time_base < time_base[-1] - 0.5)  # beyond the FIR's half-length
    alias_db = 20 * np.log10(abs(_sine_fit(time_base[inner], out[inner], alias_out_hz)))
    amp_db, phase_deg = _errors(_sine_fit(time_base[inner], out[inner], 5.0), 0.8 * np.exp(0.3j))
    assert alias_db < -40.0  # designed: ≥ 60 dB from 0.6 × the target rate
    assert abs(amp_db) < AMPLITUDE_TOL_DB
    assert abs(phase_deg) < PHASE_TOL_DEG
    # the measurement does see aliasing when the filter is off
    raw = resample_signal((t_src, values), time_base, anti_alias=False)
    assert 20 * np.log10(abs(_sine_fit(time_base[inner], raw[inner], alias_out_hz))) > -1.0


def test_in_band_content_up_to_0_35_of_the_target_rate_passes_downsampling_unchanged() -> None:
    t_src = np.arange(20000) / 1000.0
    values = np.sin(2 * np.pi * 35.0 * t_src)
    time_base = uniform_time_base([(t_src, values)], rate_hz=100.0)
    out = resample_signal((t_src, values), time_base)
    amp_db, phase_deg = _errors(_sine_fit(time_base[50:-50], out[50:-50], 35.0), 1.0 + 0j)
    assert abs(amp_db) < AMPLITUDE_TOL_DB and abs(phase_deg) < PHASE_TOL_DEG


# ------------------------------------------------------------------ gaps and spans


def _with_hole(start_s: float, end_s: float) -> np.ndarray:
    """100 Hz times over 0-30 s without the samples strictly between start_s and end_s."""
    t = np.arange(3000) / 100.0
    return t[(t <= start_s + 1e-9) | (t >= end_s - 1e-9)]


def test_a_long_gap_is_found_and_splits_the_record() -> None:
    t = np.arange(3000) / 100.0
    q_time = _with_hole(12.30, 13.14)
    signals = {
        "p": Signal(name="p", time_s=t, values=np.sin(t), unit="rad/s", source="test"),
        "q": Signal(name="q", time_s=q_time, values=np.cos(q_time), unit="rad/s", source="test"),
    }
    gaps = find_gaps(q_time, name="q")
    assert gaps == (Gap("q", 12.30, 13.14),)
    found = contiguous_spans(signals, t)
    assert isinstance(found, ContiguousSpans)
    assert found.spans == ((0.0, 12.30), (13.14, 29.99))
    assert found.messages() == ("q: 0.84 s gap at 12.30 s; record split",)
    q = resample_signal(signals["q"], t)
    inside = (t > 12.30 + 1e-9) & (t < 13.14 - 1e-9)
    assert np.isnan(q[inside]).all()
    assert np.allclose(q[~inside], np.cos(t[~inside]), atol=1e-9)


def test_short_dropouts_are_interpolated_not_gaps() -> None:
    # 5 intervals is the limit: 4 dropped samples are bridged, 5 are not
    t = np.arange(1000) / 100.0
    bridged, broken = np.delete(t, range(500, 504)), np.delete(t, range(500, 505))
    assert find_gaps(bridged) == ()
    assert len(find_gaps(broken)) == 1
    out = resample_signal((bridged, np.sin(bridged)), t)
    assert np.allclose(out, np.sin(t), atol=1e-6)


def test_a_signal_starting_late_trims_the_record() -> None:
    t = np.arange(1000) / 100.0
    late = t[t >= 2.0]
    found = contiguous_spans([(t, t), (late, late)], (0.0, 9.99), min_duration_s=1.0)
    assert found.spans == ((2.0, 9.99),)
    assert found.messages() == ("signal 1: 2.00 s gap at 0.00 s; record trimmed",)


def test_spans_shorter_than_asked_are_dropped() -> None:
    t = np.arange(2000) / 100.0
    q_time = np.r_[t[:50], t[200:]]
    assert contiguous_spans({"q": (q_time, q_time)}, t, min_duration_s=1.0).spans == ((2.0, 19.99),)


# ------------------------------------------------------------------ time base and API


def test_the_default_time_base_is_the_fastest_rate_over_the_common_span() -> None:
    fast = Signal(
        name="q",
        time_s=_jittered(100.0, 30.0, 0.0005, seed=3) + 0.002,
        values=np.zeros(3000),
        unit="rad/s",
        source="test",
    )
    slow = Signal(name="wind_n", time_s=np.arange(5.03, 25.0, 0.05), values=np.zeros(400), unit="m/s", source="test")
    time_base = uniform_time_base({"q": fast, "wind_n": slow})
    assert np.allclose(np.diff(time_base), 0.01)
    assert time_base[0] >= 5.03 and time_base[0] < 5.04
    assert time_base[-1] <= slow.time_s[-1] + 1e-7
    assert np.allclose(time_base * 100, np.round(time_base * 100))  # whole multiples of 10 ms


def test_signals_that_do_not_overlap_have_no_time_base() -> None:
    with pytest.raises(DataError, match="no common time span"):
        uniform_time_base([(np.arange(0, 10.0, 0.01), np.zeros(1000)), (np.arange(20, 30.0, 0.05), np.zeros(200))])


def test_resample_signals_resamples_each_signal_with_its_method() -> None:
    t = np.arange(0, 10.0, 0.05)
    step = (t >= 5.0).astype(float)
    signals = {
        "wind_n": Signal(name="wind_n", time_s=t, values=np.sin(t), unit="m/s", source="test"),
        "excitation": Signal(name="excitation", time_s=t, values=step, unit="1", source="test"),
    }
    time_base = np.arange(0, 995) / 100.0
    out = resample_signals(signals, time_base, method={"excitation": "pchip"})
    assert set(out) == {"wind_n", "excitation"}
    assert np.allclose(out["wind_n"], np.sin(time_base), atol=1e-4)
    assert out["excitation"].min() >= 0.0 and out["excitation"].max() <= 1.0  # no overshoot


def test_no_extrapolation_outside_the_source() -> None:
    t = np.arange(100, 900) / 100.0
    time_base = np.arange(0, 1000) / 100.0
    out = resample_signal((t, t), time_base)
    assert np.isnan(out[time_base < 1.0]).all() and np.isnan(out[time_base > 8.99 + 1e-9]).all()
    with pytest.raises(DataError, match="no data to interpolate at 0.000 s"):
        resample_signal((t, t), time_base, outside="raise")


@pytest.mark.parametrize(
    ("time_s", "values", "time_base", "kwargs", "fragment"),
    [
        ([0.0, 0.2, 0.1], [1.0, 2.0, 3.0], [0.0, 0.1], {}, "does not increase"),
        ([0.0, 0.1, 0.2], [1.0, np.nan, 3.0], [0.0, 0.1], {}, "non-finite values"),
        ([0.0, 0.1, 0.2], [1.0, 2.0], [0.0, 0.1], {}, "values of shape"),
        ([0.0, 0.1, 0.2], [1.0, 2.0, 3.0], [0.0, 0.05, 0.2], {}, "not uniform"),
        ([0.0, 0.1, 0.2], [1.0, 2.0, 3.0], [0.0, 0.1], {"method": "cubic"}, "method="),
        ([0.0, 0.1, 0.2], [1.0, 2.0, 3.0], [0.0, 0.1], {"max_gap_samples": 0.5}, "max_gap_samples="),
    ],
)
def test_malformed_input_is_a_data_error(time_s, values, time_base, kwargs, fragment) -> None:
    with pytest.raises(DataError, match=fragment):
        resample_signal((np.array(time_s), np.array(values)), np.array(time_base), **kwargs)


# ------------------------------------------------------------------ invariants


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    n=st.integers(4, 300),
    rate_hz=st.floats(5.0, 1000.0),
    jitter=st.floats(0.0, 0.4),
    target_hz=st.floats(1.0, 1000.0),
    offset=st.floats(-1e3, 1e3),
    slope=st.floats(-1e3, 1e3),
    method=st.sampled_from(["spline", "pchip", "linear"]),
    seed=st.integers(0, 2**16),
)
def test_a_ramp_is_resampled_exactly(n, rate_hz, jitter, target_hz, offset, slope, method, seed) -> None:
    rng = np.random.default_rng(seed)
    t = 100.0 + (np.arange(n) + rng.uniform(-jitter / 2, jitter / 2, n)) / rate_hz
    if (t[-1] - t[0]) * target_hz < 2:
        return  # fewer than 2 target samples: no time base to test
    time_base = uniform_time_base([(t, t)], rate_hz=target_hz)
    out = resample_signal((t, offset + slope * t), time_base, method=method)
    scale = abs(offset) + abs(slope) * t[-1] + 1.0
    assert np.allclose(out, offset + slope * time_base, rtol=0.0, atol=1e-9 * scale)


@settings(max_examples=60, deadline=None)
@given(
    values=st.lists(st.floats(-1e6, 1e6), min_size=2, max_size=200),
    rate_hz=st.floats(1.0, 1000.0),
    start_s=st.floats(-1e3, 1e4),
    method=st.sampled_from(["spline", "pchip", "linear"]),
)
def test_resampling_onto_the_own_time_base_returns_the_source(values, rate_hz, start_s, method) -> None:
    t = start_s + np.arange(len(values)) / rate_hz
    out = resample_signal((t, np.array(values)), t, method=method)
    assert np.allclose(out, values, rtol=1e-9, atol=1e-9 * (1.0 + np.max(np.abs(values))))


def test_a_cubic_is_reproduced_by_the_spline() -> None:
    t_src = _jittered(20.0, 10.0, 0.003, seed=4)
    cubic = lambda t: 0.3 * t**3 - 2.0 * t**2 + t - 4.0
    time_base = uniform_time_base([(t_src, t_src)], rate_hz=100.0)
    assert np.allclose(resample_signal((t_src, cubic(t_src)), time_base), cubic(time_base), rtol=1e-9, atol=1e-8)


@pytest.mark.parametrize("method", ["spline", "pchip", "linear"])
@pytest.mark.parametrize("rate_hz", [50.0, 400.0])  # downsampled through the anti-alias filter, and not
@pytest.mark.parametrize("block_values", [None, 2 * 2000, 1])  # all columns at once; two at a time; one
def test_signals_on_shared_times_resample_as_each_alone(
    method: str, rate_hz: float, block_values: int | None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """One spline (and one filter) for the columns of a message equals one per signal, gaps included, to the
    last bit, whether its columns are solved all at once or in blocks."""
    if block_values is not None:
        monkeypatch.setattr(resample, "_BLOCK_VALUES", block_values)
    rng = np.random.default_rng(5)
    t = np.cumsum(rng.uniform(0.0024, 0.0026, 4000))  # a jittery 400 Hz message
    t[2000:] += 0.5  # a gap
    signals = {
        name: Signal(name=name, time_s=t, values=rng.normal(0.0, 1.0, t.size), unit="-", source=name)
        for name in ("p", "q", "r")
    }
    signals["ax"] = Signal(name="ax", time_s=t.copy(), values=np.sin(t), unit="-", source="ax")  # equal times
    signals["ay"] = Signal(name="ay", time_s=t[::2], values=np.cos(t[::2]), unit="-", source="ay")  # other times
    base = uniform_time_base([(t, t)], rate_hz=rate_hz)
    together = resample_signals(signals, base, method=method)  # type: ignore[arg-type]
    assert list(together) == list(signals)
    for name, signal in signals.items():
        alone = resample_signal(signal, base, method=method)  # type: ignore[arg-type]
        np.testing.assert_array_equal(together[name], alone)  # NaN where NaN
        assert np.isnan(alone).any()  # the gap is left out in both


@pytest.mark.parametrize(("fs_hz", "target_hz"), [(1000.0, 100.0), (400.0, 50.0), (250.0, 200.0), (100.0, 99.0)])
def test_the_anti_alias_filter_is_scipys_kaiser_design_and_convolution(fs_hz: float, target_hz: float) -> None:
    """The numpy Kaiser FIR and FFT convolution (no scipy.signal on the ingest path) equal scipy.signal's."""
    from scipy.signal import fftconvolve, firwin, kaiserord

    from flightlogs.conditioning._resampling import convolve_valid, kaiser_lowpass

    nyquist = fs_hz / 2.0
    numtaps, beta = kaiserord(60.0, min(0.2 * target_hz / nyquist, 1.0))
    cutoff = min(0.5 * target_hz, 0.999 * nyquist)
    expected = firwin(numtaps | 1, cutoff, window=("kaiser", beta), fs=fs_hz)
    taps = kaiser_lowpass(fs_hz, target_hz)
    assert taps.size == expected.size and taps.size % 2 == 1
    np.testing.assert_allclose(taps, expected, rtol=0.0, atol=1e-14)
    x = np.random.default_rng(1).normal(size=(3000, 3))
    np.testing.assert_allclose(convolve_valid(x, taps), fftconvolve(x, taps[:, None], mode="valid"), atol=1e-12)
    np.testing.assert_allclose(convolve_valid(x[:, 0], taps), fftconvolve(x[:, 0], taps, mode="valid"), atol=1e-12)
