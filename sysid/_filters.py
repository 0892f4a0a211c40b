"""Filters in numpy for the discrepancy search and the wind step, without importing scipy.signal or scipy.ndimage.

``scipy.signal`` and ``scipy.ndimage`` take 0.5-0.9 s to import on top of what the search or a fit
imports anyway (scipy.signal pulls in scipy.stats, scipy.interpolate and array-API decorators that parse
docstrings), more than the filtering itself takes on a pair of flights or the 90 anemometer pieces of a
campaign. Four SciPy calls are written out here, each equal to SciPy's to rounding
(``tests/sysid/test_filters.py`` compares them); ``uniform_filter1d`` is ingest's
:func:`flightlogs._moving.moving_mean`:

=====================================  ================================================================
here                                   SciPy
=====================================  ================================================================
:func:`one_pole`                       ``lfilter([b], [1, -pole], x)`` (and complex poles, any state)
:func:`savgol_slope`                   ``savgol_filter(x, window, polyorder, deriv=1, delta=dt)``
:func:`welch_density`                  ``welch(x, fs=rate_hz, nperseg=n, detrend=False)``
:func:`butterworth_zero_phase`         ``sosfiltfilt(butter(order, cutoff_hz, fs=rate_hz, output="sos"), x, padlen=pad)``
=====================================  ================================================================

A recursive filter runs without a Python loop per sample: each pole of the Butterworth filter is a
complex first-order mode (its partial fraction), and a first-order mode is run in blocks, where
``v[s + k] = pole^k (pole v[s - 1] + sum_{j <= k} pole^-j u[s + j])`` is a cumulative sum; the state
carried from block to block is a first-order recursion over the blocks, run by doubling.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import cast

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

__all__: list[str] = []  # private to sysid (the discrepancy search, the wind step)

_EXPONENT = 200.0  # a block's pole^-k reaches at most e^200 (7e86): far from overflow
_BLOCK = 256  # samples per block at most: the cumulative sum's rounding grows with the block


def one_pole(pole: complex, u: np.ndarray, state: complex = 0.0) -> np.ndarray:
    """The first-order recursion ``v[k] = pole v[k-1] + u[k]`` from ``v[-1] = state``, shape (n,).

    ``scipy.signal.lfilter([1], [1, -pole], u, zi=[pole * state])`` for ``|pole| <= 1``, real or complex.

    Parameters
    ----------
    pole : complex
        The mode's pole, ``|pole| <= 1`` (a real float keeps the output real).
    u : ndarray, shape (n,)
        Input, any unit.
    state : complex, optional
        The value before the first sample, ``v[-1]``, in the input's unit.

    Returns
    -------
    ndarray, shape (n,)
        Real when `pole`, `u` and `state` are, else complex.

    Notes
    -----
    Blocks of ``L`` samples, with ``|pole|^-L <= e^200`` and ``L <= 256``: within one,
    ``v[s + k] = pole^k (pole v[s - 1] + sum_{j <= k} pole^-j u[s + j])``. The rounding of the sum is
    at most about ``L`` units of the last place of ``sum_j |pole|^(k - j) |u[s + j]|``, the size of
    the output itself. The states entering the blocks follow ``e[b + 1] = pole^L e[b] + z[b]`` (``z``
    a block's last value from rest), summed by doubling (``log2`` of the number of blocks steps).
    """
    u = np.asarray(u)
    n = u.size
    if not abs(pole) <= 1.0:
        raise ValueError(f"{pole=} must lie on or inside the unit circle")
    complex_valued = np.iscomplexobj(u) or isinstance(pole, complex) or isinstance(state, complex)
    dtype = np.dtype(np.complex128 if complex_valued else np.float64)
    if n == 0:
        return np.zeros(0, dtype=dtype)
    rising, falling, across = _powers(pole if complex_valued else float(pole.real), min(n, _block(pole)))
    length = rising.size
    if n == length:  # one block
        return rising * (np.cumsum(u * falling) + pole * state)
    blocks, tail = divmod(n, length)
    sums = np.empty((blocks + (tail > 0), length), dtype=dtype)
    np.multiply(u[: blocks * length].reshape(blocks, length), falling, out=sums[:blocks])
    if tail:
        np.multiply(u[blocks * length :], falling[:tail], out=sums[-1, :tail])
        sums[-1, tail:] = 0.0
    np.cumsum(sums, axis=1, out=sums)  # sum_{j <= k} pole^-j u[s + j] in each block
    entering = np.empty(sums.shape[0], dtype=dtype)  # v[s - 1] of each block
    entering[0] = state
    entering[1:] = sums[:-1, -1] * rising[-1]  # a block's last value from rest
    entering = _scan(across, entering)
    np.add(sums, (pole * entering)[:, None], out=sums)
    np.multiply(sums, rising, out=sums)
    return cast(np.ndarray, sums.reshape(-1)[:n])


def _block(pole: complex) -> int:
    """Samples per block: at most 256, and ``|pole|^-L <= e^200``."""
    decay = -math.log(abs(pole)) if pole != 0 else math.inf
    return int(min(_BLOCK, max(1.0, _EXPONENT / decay if decay > 0.0 else math.inf)))


@lru_cache(maxsize=256)
def _powers(pole: complex, length: int) -> tuple[np.ndarray, np.ndarray, complex]:
    """``pole^k`` and ``pole^-k`` for ``k < length`` (each shape (length,)) and ``pole^length``; read-only."""
    k = np.arange(length)
    base = np.asarray(pole)
    rising = np.power(base, k)
    falling = np.ones(1, dtype=rising.dtype) if length == 1 else np.power(base, -k)
    rising.flags.writeable = falling.flags.writeable = False
    return rising, falling, pole**length


def _scan(ratio: complex | float, c: np.ndarray) -> np.ndarray:
    """``s[m] = sum_{i <= m} ratio^(m - i) c[i]`` by doubling (``|ratio| <= 1``), shape (m,)."""
    s = c.copy()
    factor, shift = ratio, 1
    while shift < s.size and factor != 0:
        s[shift:] = s[shift:] + factor * s[:-shift]  # the right side is read whole before it is written
        factor, shift = factor * factor, 2 * shift
    return s


def savgol_slope(x: np.ndarray, window: int, polyorder: int, interval_s: float) -> np.ndarray:
    """The Savitzky-Golay first derivative: ``savgol_filter(x, window, polyorder, deriv=1, delta=interval_s)``.

    Parameters
    ----------
    x : ndarray, shape (n,)
        Signal sampled every `interval_s`, any unit.
    window : int
        Samples a polynomial is fitted over, odd, ``polyorder < window <= n``.
    polyorder : int
        Degree of the fitted polynomials (>= 1).
    interval_s : float
        Sample interval, s.

    Returns
    -------
    ndarray, shape (n,)
        The slope, the signal's unit per s.

    Notes
    -----
    Inside, the slope at the window's middle of the least-squares polynomial (SciPy's ``savgol_coeffs``,
    a minimum-norm solution of the normal equations, convolved). The first and last ``window // 2``
    samples take the derivative of the polynomial fitted to the first and last window (mode 'interp').
    """
    x = np.asarray(x, dtype=np.float64)
    if window % 2 != 1 or not polyorder < window <= x.size or polyorder < 1:
        raise ValueError(f"{window=} must be odd, above {polyorder=} (≥ 1) and at most the {x.size} samples")
    half = window // 2
    offsets = np.arange(half, -half - 1, -1, dtype=np.float64)  # reversed: a convolution's kernel
    design = offsets ** np.arange(polyorder + 1, dtype=np.float64)[:, None]  # (polyorder + 1, window)
    target = np.zeros(polyorder + 1)
    target[1] = 1.0 / interval_s
    kernel = np.linalg.lstsq(design, target, rcond=None)[0]
    y = np.convolve(x, kernel, mode="same")
    steps = np.arange(window, dtype=np.float64)
    for start, stop in ((0, half), (x.size - half, x.size)):
        first = 0 if start == 0 else x.size - window
        fitted = np.polyder(np.polyfit(steps, x[first : first + window], polyorder))
        y[start:stop] = np.polyval(fitted, np.arange(start - first, stop - first, dtype=np.float64)) / interval_s
    return cast(np.ndarray, y)


def welch_density(x: np.ndarray, rate_hz: float, nperseg: int) -> tuple[np.ndarray, np.ndarray]:
    """Welch's one-sided power spectral density: ``welch(x, fs=rate_hz, nperseg=nperseg, detrend=False)``.

    Periodic Hann segments of `nperseg` samples overlapping by half (``nperseg // 2``), not detrended,
    averaged (mean).

    Parameters
    ----------
    x : ndarray, shape (n,)
        Real signal sampled at `rate_hz`, any unit.
    rate_hz : float
        Sample rate, Hz.
    nperseg : int
        Samples per segment (>= 1; at most `n`, as SciPy makes it).

    Returns
    -------
    freq_hz : ndarray, shape (nperseg // 2 + 1,)
        Frequencies, Hz.
    density : ndarray, shape (nperseg // 2 + 1,)
        Power spectral density, the signal's unit squared per Hz.
    """
    x = np.asarray(x, dtype=np.float64)
    if nperseg < 1 or x.size == 0:
        raise ValueError(f"{nperseg=} must be ≥ 1 and the signal not empty")
    nperseg = min(nperseg, x.size)
    taper = np.ones(1) if nperseg == 1 else 0.5 - 0.5 * np.cos(2.0 * np.pi * np.arange(nperseg) / nperseg)
    hop = nperseg - nperseg // 2
    count = (x.size - nperseg // 2) // hop
    segments = sliding_window_view(x, nperseg)[::hop][:count]
    spectra = np.abs(np.fft.rfft(segments * taper, axis=1)) ** 2 / (rate_hz * float(np.sum(taper**2)))
    spectra[:, 1 : None if nperseg % 2 else -1] *= 2.0  # one-sided: the negative frequencies' power folded in
    return np.fft.rfftfreq(nperseg, 1.0 / rate_hz), cast(np.ndarray, spectra.mean(axis=0))


def butterworth_zero_phase(x: np.ndarray, cutoff_hz: float, rate_hz: float, *, order: int, pad: int) -> np.ndarray:
    """`x` through a Butterworth low-pass forward and backward, SciPy's ``sosfiltfilt`` of its ``butter``.

    ``sosfiltfilt(butter(order, cutoff_hz, fs=rate_hz, output="sos"), x, padlen=pad)``: the ends
    extended by `pad` samples of odd reflection (``2 x[0] - x[pad:0:-1]``), each pass started in the
    steady state of its first sample (SciPy's ``sosfilt_zi`` times that sample).

    Parameters
    ----------
    x : ndarray, shape (n,)
        Signal sampled at `rate_hz`, any unit; ``n > pad``.
    cutoff_hz : float
        The -3 dB frequency of one pass, Hz, below ``rate_hz / 2``.
    rate_hz : float
        Sample rate, Hz.
    order : int
        Order of the filter, even (>= 2).
    pad : int
        Samples of odd extension at each end (>= 0).

    Returns
    -------
    ndarray, shape (n,)

    Notes
    -----
    The digital filter is SciPy's design: the analog prototype's poles ``-exp(i pi m / 2N)``, ``m = -N+1,
    -N+3, .., N-1``, scaled to the pre-warped cutoff ``4 tan(pi Wn / 2)`` and mapped by the bilinear
    transform (``fs = 2``), its N zeros at ``z = -1``. It runs as its partial fractions,
    ``H(q) = c + sum_i r_i / (1 - p_i q)`` (``q = z^-1``): one complex :func:`one_pole` per conjugate
    pair of poles, the output ``c u + 2 Re(sum r_i v_i)``; the steady state of an input held at ``u0`` is
    ``v_i = u0 / (1 - p_i)``.
    """
    x = np.asarray(x, dtype=np.float64)
    if order < 2 or order % 2:
        raise ValueError(f"{order=} must be even and ≥ 2")
    if not 0.0 < cutoff_hz < rate_hz / 2.0:
        raise ValueError(f"{cutoff_hz=} must lie between 0 and half {rate_hz=}")
    if not 0 <= pad < x.size:
        raise ValueError(f"{pad=} must be ≥ 0 and below the {x.size} samples")
    poles, residues, direct = _butterworth_fractions(order, 2.0 * cutoff_hz / rate_hz)
    extended = np.concatenate([2.0 * x[0] - x[pad:0:-1], x, 2.0 * x[-1] - x[-2 : -pad - 2 : -1]]) if pad else x
    forward = _run_fractions(poles, residues, direct, extended)
    backward = _run_fractions(poles, residues, direct, forward[::-1])[::-1]
    return backward[pad : backward.size - pad]


def _butterworth_fractions(order: int, wn: float) -> tuple[np.ndarray, np.ndarray, float]:
    """The upper-half poles (order / 2,), their residues (order / 2,) and the direct term of the digital low-pass.

    `wn` is the cutoff over the Nyquist frequency. ``H(q) = gain (1 + q)^N / prod(1 - p q)`` over all N poles.
    """
    warped = 4.0 * math.tan(math.pi * wn / 2.0)  # scipy's iirfilter: 2 fs tan(pi Wn / fs), fs = 2
    m = np.arange(-order + 1, order, 2)
    analog = -np.exp(1j * np.pi * m / (2 * order)) * warped  # buttap's poles, lp2lp_zpk
    poles = (4.0 + analog) / (4.0 - analog)  # bilinear_zpk, fs2 = 4
    gain = warped**order * float(np.real(1.0 / np.prod(4.0 - analog)))
    upper = np.flatnonzero(m < 0)  # m < 0: Im(p) > 0; the other half are their conjugates
    residues = np.array(
        [gain * (1.0 + 1.0 / poles[i]) ** order / np.prod(1.0 - np.delete(poles, i) / poles[i]) for i in upper]
    )
    direct = gain / float(np.real(np.prod(-poles)))
    return poles[upper], residues, direct


def _run_fractions(poles: np.ndarray, residues: np.ndarray, direct: float, u: np.ndarray) -> np.ndarray:
    """``c u + 2 Re(sum_i r_i v_i)``, each mode started in the steady state of ``u[0]``, shape (n,)."""
    out = direct * u
    for pole, residue in zip(poles, residues):
        out = out + 2.0 * np.real(residue * one_pole(complex(pole), u, u[0] / (1.0 - pole)))
    return cast(np.ndarray, out)
