"""The added excitation signals: 3-2-1-1 and multisine."""

from __future__ import annotations

import numpy as np
import pytest

from simulator.autopilot.excitation import multisine, three_two_one_one


def test_3211_has_its_pulse_pattern_and_zero_mean_area() -> None:
    t = np.arange(0.0, 12.0, 0.01)
    x = three_two_one_one(t, 1.0, 5.0, 0.5)
    assert np.all(x[t < 1.0] == 0) and np.all(x[t >= 4.5] == 0)
    assert set(np.unique(x)) == {-5.0, 0.0, 5.0}
    assert np.sum(x) * 0.01 == pytest.approx(5.0 * 0.5 * (3 - 2 + 1 - 1), abs=0.05)


def test_multisine_peak_band_and_fades() -> None:
    rate, duration = 200.0, 20.0
    t = np.arange(0.0, 30.0, 1 / rate)
    x = multisine(t, 5.0, duration, 8.0, f_min_hz=0.2, f_max_hz=5.0, n_tones=20)
    assert 7.9 <= np.max(np.abs(x)) <= 8.0 * 1.002
    assert np.all(x[(t < 5.0) | (t >= 25.0)] == 0)
    inside = x[(t >= 6.0) & (t < 24.0)]
    spectrum = np.abs(np.fft.rfft(x[(t >= 5.0) & (t < 25.0)])) ** 2
    freq = np.fft.rfftfreq(int(duration * rate), 1 / rate)
    in_band = spectrum[(freq >= 0.15) & (freq <= 5.5)].sum()
    assert in_band / spectrum.sum() > 0.97
    assert np.max(np.abs(inside)) / np.std(inside) < 4.0  # crest factor (a sine is 1.41, noise about 4)
    with pytest.raises(ValueError):
        multisine(t, 0.0, 1.0, 1.0, fade_s=1.0)
