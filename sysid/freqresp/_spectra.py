"""Windowed auto and cross spectra of several channels on an arbitrary frequency grid.

All windows of one length, from every record, are stacked into one array and
transformed at once: a matrix product with the (tapered) Fourier kernel for
an arbitrary (log-spaced) grid, or :class:`scipy.signal.CZT` for an evenly
spaced one. Windows never straddle two records; the spectra are averaged over
all windows of all records (Welch's method).

Scaling: one-sided spectral densities per rad/s, ``G_ab(omega) =
E[conj(X_a) X_b] / (pi dt sum(w^2))`` with ``X = sum_n w_n x_n
exp(-j omega n dt)``, so that the integral of ``G_aa`` from 0 to the Nyquist
frequency is the variance of ``a``.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from sysid.freqresp._tapers import taper as taper_window

__all__: list[str] = []


@dataclass(frozen=True, slots=True, kw_only=True)
class WindowSpectra:
    """Spectral matrix of all channels for one window length.

    Parameters
    ----------
    window_s : float
        Window length, s.
    spectra : ndarray of complex, shape (n_freq, n_channels, n_channels)
        ``spectra[f, a, b] = G_ab``, one-sided, unit_a unit_b / (rad/s); zero
        below `omega_low`, where the window is not used.
    n_windows : int
        Windows averaged.
    n_effective : float
        Equivalent number of independent averages (overlap-corrected).
    omega_low : float
        Lowest frequency the window resolves, rad/s.
    noise_dof : ndarray, shape (n_freq,), or None
        Degrees of freedom of the smoothed noise autospectra the whole-record
        member (:mod:`sysid.freqresp._whole`) carries; None for a window.
    """

    window_s: float
    spectra: np.ndarray
    n_windows: int
    n_effective: float
    omega_low: float
    noise_dof: np.ndarray | None = None


def window_spectra(
    data: Sequence[np.ndarray],
    dt: float,
    n_window: int,
    omega: np.ndarray,
    *,
    overlap: float,
    taper: str,
    min_cycles: float,
    spacing: str = "log",
) -> WindowSpectra | None:
    """Spectral matrix of the channels of every record for windows of `n_window` samples.

    `data` holds one array per record, shape (n_channels, n_samples), C order.
    Returns None when no record holds a whole window.
    """
    found = window_transforms(
        data, dt, n_window, omega, overlap=overlap, taper=taper, min_cycles=min_cycles, spacing=spacing
    )
    return None if found is None else found.spectra(omega)


@dataclass(frozen=True, slots=True, kw_only=True)
class WindowTransforms:
    """Every window's Fourier transform of the channels of every record, for windows of one length.

    Parameters
    ----------
    x : ndarray of complex, shape (n_used, n_channels, n_windows)
        Transforms of the mean-removed, tapered windows at the grid frequencies the window reaches.
    window_s : float
        Window length, s.
    n_windows : int
        Windows of each channel.
    n_effective : float
        Equivalent number of independent averages (overlap-corrected).
    omega_low : float
        Lowest frequency the window resolves, rad/s.
    scale : float
        ``dt / (pi sum(w^2) n_windows)``: what the windows' summed products are multiplied by.
    """

    x: np.ndarray
    window_s: float
    n_windows: int
    n_effective: float
    omega_low: float
    scale: float

    def spectra(self, omega: np.ndarray) -> WindowSpectra:
        """The spectral matrix on the grid `omega` (n_freq,), rad/s, whose frequencies from `omega_low` up are
        those transformed; zero below."""
        used = omega >= self.omega_low * (1.0 - 1e-12)
        spectra = np.zeros((omega.size, self.x.shape[1], self.x.shape[1]), dtype=complex)
        spectra[used] = np.conj(self.x) @ self.x.transpose(0, 2, 1)
        spectra *= self.scale
        return WindowSpectra(
            window_s=self.window_s,
            spectra=spectra,
            n_windows=self.n_windows,
            n_effective=self.n_effective,
            omega_low=self.omega_low,
        )


def window_transforms(
    data: Sequence[np.ndarray],
    dt: float,
    n_window: int,
    omega: np.ndarray,
    *,
    overlap: float,
    taper: str,
    min_cycles: float,
    spacing: str = "log",
) -> WindowTransforms | None:
    """The windows' transforms behind :func:`window_spectra` (same arguments), None when no record holds a window."""
    hop = max(1, int(round(n_window * (1.0 - overlap))))
    taper_values = taper_window(taper, n_window)  # periodic: the spectral-analysis form
    pieces = []
    n_effective = 0.0
    for channels in data:
        if channels.shape[1] < n_window:
            continue
        segments = sliding_window_view(channels, n_window, axis=1)[:, ::hop]  # (n_channels, n_win, n_window)
        pieces.append(segments)
        n_effective += effective_averages(segments.shape[1], hop, taper_values)
    if not pieces:
        return None
    stacked = np.ascontiguousarray(np.concatenate(pieces, axis=1))  # (n_channels, n_windows, n_window)
    n_channels, n_windows, _ = stacked.shape
    flat = stacked.reshape(n_channels * n_windows, n_window)
    window_s = n_window * dt
    omega_low = 2.0 * np.pi * min_cycles / window_s
    used = omega >= omega_low * (1.0 - 1e-12)  # below, the window's estimate is never used: not computed
    if spacing == "linear":
        transform = _czt(flat, dt, taper_values, omega[used])
    else:
        transform = _matrix_dft(flat, dt, taper_values, omega[used])
    x = np.ascontiguousarray(transform.reshape(n_channels, n_windows, -1).transpose(2, 0, 1))  # (n_used, ch, win)
    return WindowTransforms(
        x=x,
        window_s=window_s,
        n_windows=n_windows,
        n_effective=n_effective,
        omega_low=omega_low,
        scale=dt / (np.pi * float(np.sum(taper_values**2)) * n_windows),
    )


def _matrix_dft(flat: np.ndarray, dt: float, taper: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Fourier transform of each mean-removed, tapered row at `omega`: one real matrix product.

    The mean is removed after the product, ``sum w (x - m) e = sum w x e - m sum w e``,
    so the windows are never copied.
    """
    as_bytes = [np.ascontiguousarray(a, dtype=np.float64).tobytes() for a in (taper, omega)]
    kernel, kernel_sum = _kernel(flat.shape[1], float(dt), *as_bytes)
    product = flat @ kernel.T
    product -= flat.mean(axis=1)[:, None] * kernel_sum[None, :]
    n_freq = omega.size
    return cast(np.ndarray, product[:, :n_freq] - 1j * product[:, n_freq:])


def _kernel(n_window: int, dt: float, taper: bytes, omega: bytes) -> tuple[np.ndarray, np.ndarray]:
    """The tapered Fourier kernel, shape (2 n_freq, n_window), and its row sums (2 n_freq,), read-only.

    Kept for the next call, within :data:`_KERNEL_BYTES`: one identification asks for the same window on
    the same grid for its records, the quiet flight's floor and each group of outputs (15 kernels for 152
    transforms on the chapter 3 campaign), and the cosines and sines cost about a third of the products.
    Under a lock: a Dask worker of the user's may run fits on several threads.
    """
    key = (n_window, dt, taper, omega)
    with _KERNELS_LOCK:
        found = _KERNELS.get(key)
    if found is not None:
        return found
    phase = np.outer(np.frombuffer(omega) * dt, np.arange(n_window))
    kernel = np.concatenate([np.cos(phase), np.sin(phase)]) * np.frombuffer(taper)
    kernel_sum = kernel.sum(axis=1)
    kernel.flags.writeable = kernel_sum.flags.writeable = False
    with _KERNELS_LOCK:
        while _KERNELS and sum(k.nbytes for k, _ in _KERNELS.values()) + kernel.nbytes > _KERNEL_BYTES:
            del _KERNELS[next(iter(_KERNELS))]  # the oldest first
        _KERNELS[key] = (kernel, kernel_sum)
    return kernel, kernel_sum


#: Bytes of kernels kept (the campaign's 15 take 21 MB; a 400 Hz log's longest window alone may take 17).
_KERNEL_BYTES = 64 * 2**20
_KERNELS: dict[tuple[int, float, bytes, bytes], tuple[np.ndarray, np.ndarray]] = {}
_KERNELS_LOCK = threading.Lock()


def _czt(flat: np.ndarray, dt: float, taper: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """The same transform on an evenly spaced grid by the chirp-z transform."""
    step = float(omega[1] - omega[0])
    if not np.allclose(np.diff(omega), step, rtol=1e-9, atol=0.0):
        raise ValueError("the chirp-z transform needs an evenly spaced grid")
    from scipy import signal as sps  # here: scipy.signal takes 0.75 s to load, an even grid is rare

    transform = sps.CZT(flat.shape[1], m=omega.size, w=np.exp(-1j * step * dt), a=np.exp(1j * omega[0] * dt))
    tapered = (flat - flat.mean(axis=1, keepdims=True)) * taper
    return np.asarray(transform(tapered, axis=-1))


def effective_averages(n_windows: int, hop: int, taper: np.ndarray) -> float:
    """Number of independent averages equivalent to `n_windows` overlapping windows (Welch 1967).

    ``K / (1 + 2 sum_{j=1}^{K-1} (1 - j/K) rho(j hop)^2)`` with ``rho`` the
    normalised autocorrelation of the taper; exact for Gaussian noise with a
    flat spectrum over the taper's bandwidth.
    """
    if n_windows <= 1:
        return float(n_windows)
    energy = float(np.sum(taper**2))
    lags = hop * np.arange(1, n_windows)
    lags = lags[lags < taper.size]
    rho = np.array([np.dot(taper[: taper.size - lag], taper[lag:]) / energy for lag in lags])
    j = np.arange(1, rho.size + 1)
    return n_windows / (1.0 + 2.0 * float(np.sum((1.0 - j / n_windows) * rho**2)))
