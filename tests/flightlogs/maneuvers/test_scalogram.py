"""The band envelopes' decimated inverse FFT against its definition: every `step`-th sample of the full inverse."""

from __future__ import annotations

import numpy as np
import pytest

from flightlogs.maneuvers._scalogram import _decimated_inverse, band_envelopes


@pytest.mark.parametrize(
    ("n_short", "step", "first", "size"), [(50, 4, 0, 30), (50, 4, 170, 30), (64, 10, 3, 600), (7, 3, 5, 16)]
)
def test_the_folded_inverse_is_the_full_inverse_decimated(n_short: int, step: int, first: int, size: int) -> None:
    """A band anywhere in the long spectrum, wrapping round the short one 0 to 9 times."""
    rng = np.random.default_rng(n_short + first)
    band = rng.normal(size=size) + 1j * rng.normal(size=size)
    full = np.zeros(n_short * step, dtype=np.complex128)
    full[first : first + size] = band
    np.testing.assert_allclose(_decimated_inverse(band, first, n_short, step), np.fft.ifft(full)[::step], atol=1e-14)


def test_two_tones_give_their_amplitudes_in_their_bands() -> None:
    """1.5 at 0.5 Hz and 0.25 at 6 Hz, 100 Hz sampling, 10 frames a second: each band reads its tone."""
    dt = 0.01
    t = np.arange(0.0, 200.0, dt)
    x = 1.5 * np.sin(2 * np.pi * 0.5 * t) + 0.25 * np.sin(2 * np.pi * 6.0 * t + 1.0)
    env = band_envelopes(x, dt, np.array([0.5, 6.0]), cycles=6.0, step=10)
    middle = env[500:1500]  # away from the ends, where the windows run off the record
    np.testing.assert_allclose(middle[:, 0], 1.5, rtol=2e-3)
    np.testing.assert_allclose(middle[:, 1], 0.25, rtol=2e-3)
