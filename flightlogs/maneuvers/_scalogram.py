"""Constant-Q band envelopes of a trace: where in time and frequency it carries energy.

A Gabor (Gaussian-windowed) filter bank, applied in the frequency domain:
each band keeps the positive frequencies near its centre under a Gaussian
of relative width ``1 / cycles``, and the magnitude of the inverse transform
is the band's envelope (the modulus of an analytic, band-limited signal).
Constant Q gives long windows at low frequency, where a sweep lingers, and
short ones at high frequency, where it races, so one ridge follows a sweep
over decades. Helpers of :mod:`flightlogs.maneuvers._sweeps`.
"""

from __future__ import annotations

import numpy as np

from flightlogs._moving import fast_fft_length

__all__: list[str] = []


def band_frequencies(f_min_hz: float, f_max_hz: float, per_octave: int) -> np.ndarray:
    """Log-spaced band centres from `f_min_hz` to at most `f_max_hz`, Hz, shape (n_bands,)."""
    n = int(np.floor(np.log2(f_max_hz / f_min_hz) * per_octave)) + 1
    return np.asarray(f_min_hz * 2.0 ** (np.arange(n) / per_octave), dtype=np.float64)


def band_envelopes(x: np.ndarray, dt: float, freqs_hz: np.ndarray, *, cycles: float, step: int) -> np.ndarray:
    """Envelopes of `x` in constant-Q bands, sampled every `step` samples.

    Parameters
    ----------
    x : ndarray, shape (n_samples,)
        Uniformly sampled trace, any unit; its mean should be removed.
    dt : float
        Sample interval, s.
    freqs_hz : ndarray, shape (n_bands,)
        Band centres, Hz.
    cycles : float
        Band width: the Gaussian's standard deviation is ``f / cycles`` in
        frequency, ``cycles / (2 π f)`` s in time.
    step : int
        Decimation of the output in time (the envelopes are smooth).

    Returns
    -------
    ndarray, shape (ceil(n_samples / step), n_bands)
        Envelope amplitude, in the unit of `x`: a sinusoid of amplitude A at
        a band's centre frequency gives A there.

    Examples
    --------
    >>> t = np.arange(0, 60, 0.01)
    >>> env = band_envelopes(np.sin(2 * np.pi * 2.0 * t), 0.01, np.array([0.5, 2.0, 8.0]), cycles=6.0, step=100)
    >>> np.round(env[30], 2)
    array([0., 1., 0.])
    """
    n = x.size
    n_fft = fast_fft_length(n + int(4 * cycles / (2 * np.pi * freqs_hz.min() * dt)))  # room for the tails
    spectrum = np.fft.rfft(x, n_fft)
    f = np.fft.rfftfreq(n_fft, dt)
    out = np.empty(((n + step - 1) // step, freqs_hz.size))
    for k, centre in enumerate(freqs_hz):
        gain = np.exp(-0.5 * ((f - centre) * cycles / centre) ** 2)
        # analytic signal of the band: positive frequencies doubled; the complex inverse from the half spectrum
        band = _analytic_inverse(spectrum * gain, n_fft)[:n:step]
        out[:, k] = np.abs(band)
    return out


def _analytic_inverse(half_spectrum: np.ndarray, n_fft: int) -> np.ndarray:
    """Analytic signal whose positive-frequency spectrum is `half_spectrum` (real part: the band-passed trace)."""
    real = np.fft.irfft(half_spectrum, n_fft)
    imag = np.fft.irfft(-1j * half_spectrum, n_fft)  # Hilbert transform: -j on positive frequencies
    return np.asarray(real + 1j * imag)
