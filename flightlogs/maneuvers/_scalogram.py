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

_SUPPORT_SIGMAS = 9.0  # a band's Gaussian is kept to 9 σ (gain 2.6e-18 there), zero beyond


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
    rows = (n + step - 1) // step
    n_short = fast_fft_length(-(-(n + int(4 * cycles / (2 * np.pi * freqs_hz.min() * dt))) // step))  # tails' room
    n_fft = n_short * step  # a multiple of the decimation: the decimated band is an inverse FFT of n_short points
    spectrum = np.fft.rfft(x, n_fft)
    f = np.fft.rfftfreq(n_fft, dt)
    weight = np.full(f.size, 2.0)  # analytic signal: positive frequencies doubled, DC and Nyquist once
    weight[0] = 1.0
    if n_fft % 2 == 0:
        weight[-1] = 1.0
    out = np.empty((rows, freqs_hz.size))
    for k, centre in enumerate(freqs_hz):
        lo, hi = np.searchsorted(f, centre * (1.0 + np.array([-1.0, 1.0]) * _SUPPORT_SIGMAS / cycles))
        lo, hi = int(lo), int(hi)
        gain = np.exp(-0.5 * ((f[lo:hi] - centre) * cycles / centre) ** 2)
        out[:, k] = np.abs(_decimated_inverse(spectrum[lo:hi] * gain * weight[lo:hi], lo, n_short, step)[:rows])
    return out


def _decimated_inverse(band: np.ndarray, first: int, n_short: int, step: int) -> np.ndarray:
    """Every `step`-th sample of the inverse FFT (length ``n_short * step``) of a spectrum holding `band` from bin `first`.

    Taking every step-th sample folds the spectrum onto ``n_short`` bins (bin
    ``i`` onto ``i mod n_short``); the inverse of the folded spectrum is the
    decimated signal, exactly, at ``1 / step`` of the cost.
    """
    folded = np.zeros(n_short, dtype=np.complex128)
    at, done = first % n_short, 0
    while done < band.size:  # each turn of the band round the short spectrum, added in bin order
        take = min(n_short - at, band.size - done)
        folded[at : at + take] += band[done : done + take]
        at, done = 0, done + take
    return np.asarray(np.fft.ifft(folded) / step)
