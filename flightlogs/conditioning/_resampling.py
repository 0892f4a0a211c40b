"""Numerics behind :mod:`flightlogs.conditioning.resample`: time checks, gaps, anti-alias filter, interpolants, spans.

Times are s; a piece is an index range ``[i0, i1)`` of samples between gaps;
spans are ordered lists of disjoint closed ``(start_s, end_s)`` intervals.
"""

from __future__ import annotations

from typing import cast

import numpy as np

from flightlogs._moving import fast_fft_length
from flightlogs.conditioning._splines import Located, SplineSystem, hermite, pchip_slopes
from flightlogs.errors import DataError

__all__: list[str] = []  # private to flightlogs.conditioning

TIME_TOL_S = 1e-7  # below the 1 µs resolution of log timestamps
_STOPBAND_DB = 60.0  # anti-alias attenuation from 0.6 × the target rate
_PASS_EDGE = 0.4  # anti-alias pass-band edge, × target rate
_STOP_EDGE = 0.6  # anti-alias stop-band edge, × target rate


def check_times(time_s: np.ndarray, name: str) -> np.ndarray:
    """Return `time_s` as float64 after checking it is 1-D, finite and strictly increasing."""
    t = np.asarray(time_s, dtype=np.float64)
    if t.ndim != 1 or t.size == 0:
        raise DataError(f"{name}: times must be a non-empty 1-D array, got shape {t.shape}")
    if not np.isfinite(t).all():
        raise DataError(f"{name}: times hold non-finite values")
    steps = np.diff(t)
    if (steps <= 0).any():
        at = int(np.argmax(steps <= 0))
        raise DataError(f"{name}: time does not increase at sample {at + 1} ({t[at]:.6f} → {t[at + 1]:.6f} s)")
    return t


def check_time_base(time_base: np.ndarray) -> tuple[np.ndarray, float]:
    """Validate a uniform time base; return it with its sample interval, s."""
    tb = check_times(time_base, "time_base")
    if tb.size < 2:
        raise DataError("time_base must hold at least 2 samples")
    steps = np.diff(tb)
    dt = float(np.median(steps))
    if np.max(np.abs(steps - dt)) > 1e-3 * dt + TIME_TOL_S:
        raise DataError(f"time_base is not uniform (steps from {steps.min():.6g} to {steps.max():.6g} s)")
    return tb, float((tb[-1] - tb[0]) / (tb.size - 1))


def nominal_interval(t: np.ndarray) -> float:
    """Median sample interval, s (inf for a single sample)."""
    return float(np.median(np.diff(t))) if t.size > 1 else np.inf


def piece_bounds(t: np.ndarray, dt: float, max_gap_samples: float) -> list[tuple[int, int]]:
    """Index ranges [i0, i1) of the pieces between gaps longer than `max_gap_samples` × `dt`."""
    if not (np.isfinite(max_gap_samples) and max_gap_samples >= 1):
        raise DataError(f"{max_gap_samples=} must be a finite number ≥ 1")
    cuts = np.flatnonzero(np.diff(t) > max_gap_samples * dt + TIME_TOL_S) + 1
    edges = np.r_[0, cuts, t.size]
    return [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]


class AntiAlias:
    """The anti-alias low-pass of one contiguous piece, for any columns sampled at its times `t` (n,).

    Each column is splined onto a uniform grid at the source rate (`grid`; the times themselves when
    already uniform), then convolved with a zero-phase Kaiser FIR (:func:`kaiser_lowpass`), the ends
    padded by odd reflection. The grid's spline system and the filter's spectrum are made once.
    """

    def __init__(self, t: np.ndarray, dt_src: float, target_rate_hz: float) -> None:
        n_fine = max(int(round((t[-1] - t[0]) / dt_src)) + 1, 2)
        grid = np.linspace(t[0], t[-1], n_fine)
        same = grid.size == t.size and np.allclose(grid, t, rtol=0.0, atol=TIME_TOL_S)
        self.grid = t if same else grid
        self._to_grid = None if same else Interpolant(t, grid, "spline")
        fs = (n_fine - 1) / (grid[-1] - grid[0])
        self._taps = kaiser_lowpass(fs, target_rate_hz)
        self._kernel = np.fft.rfft(
            self._taps, fast_fft_length(n_fine + 2 * (self._taps.size // 2) + self._taps.size - 1)
        )

    def __call__(self, v: np.ndarray) -> np.ndarray:
        """Column `v` (n,) low-passed, on :attr:`grid`: shape (grid.size,)."""
        values = v if self._to_grid is None else self._to_grid(v)
        half = self._taps.size // 2
        return convolve_valid(
            np.pad(values, (half, half), mode="reflect", reflect_type="odd"), self._taps, self._kernel
        )


def kaiser_lowpass(fs_hz: float, target_rate_hz: float) -> np.ndarray:
    """Odd-length, unit-DC-gain Kaiser FIR: pass to 0.4, stop from 0.6 × the target rate; shape (n_taps,).

    ``scipy.signal.firwin(n, cutoff, window=("kaiser", beta), fs=fs_hz)`` with ``n, beta`` from
    ``scipy.signal.kaiserord``, written out in numpy: scipy.signal takes longer to import (0.35 s)
    than a log takes to read. The test compares the two.
    """
    nyquist = fs_hz / 2.0
    width = min((_STOP_EDGE - _PASS_EDGE) * target_rate_hz / nyquist, 1.0)
    attenuation = abs(_STOPBAND_DB)  # kaiserord: Kaiser's formulas for the order and the window's beta
    beta = 0.1102 * (attenuation - 8.7)  # (the > 50 dB branch)
    numtaps = int(np.ceil((attenuation - 7.95) / 2.285 / (np.pi * width) + 1)) | 1
    cutoff = min(0.5 * (_PASS_EDGE + _STOP_EDGE) * target_rate_hz, 0.999 * nyquist) / nyquist
    m = np.arange(numtaps) - 0.5 * (numtaps - 1)
    taps = cutoff * np.sinc(cutoff * m) * np.kaiser(numtaps, beta)  # firwin: ideal low-pass times the window
    return cast(np.ndarray, taps / taps.sum())  # unit gain at DC


def convolve_valid(x: np.ndarray, taps: np.ndarray, kernel: np.ndarray | None = None) -> np.ndarray:
    """``x`` (shape (n,) or (n, k)) convolved with ``taps`` along axis 0, the fully overlapped part: (n - len + 1, ...).

    By FFT, as ``scipy.signal.fftconvolve(x, taps, mode="valid")`` (to rounding) without importing SciPy.
    `kernel`, when given, is ``rfft(taps, fast_fft_length(n + len - 1))`` made beforehand.
    """
    n, m = x.shape[0], taps.size
    size = fast_fft_length(n + m - 1)
    kernel = np.fft.rfft(taps, size) if kernel is None else kernel
    kernel = kernel.reshape((-1,) + (1,) * (x.ndim - 1))
    full = np.fft.irfft(np.fft.rfft(x, size, axis=0) * kernel, size, axis=0)
    return cast(np.ndarray, full[m - 1 : n])


class Interpolant:
    """One interpolant on knots `t` (n,) evaluated at points `at` (m,) inside [t[0], t[-1]], for any columns.

    The columns of one log message share their times: the spline's system is factored and the points
    located once, and the columns are then solved and evaluated a block at a time.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Strictly increasing knots, s.
    at : ndarray, shape (m,)
        Where to evaluate, s.
    method : {"spline", "pchip", "linear"}
        Not-a-knot cubic spline, shape-preserving PCHIP, or straight lines (also for fewer than 3 knots).
    """

    def __init__(self, t: np.ndarray, at: np.ndarray, method: str) -> None:
        if method not in ("spline", "pchip", "linear"):
            raise DataError(f"{method=} must be 'spline', 'pchip' or 'linear'")
        self.t, self.at = t, at
        self._linear = method == "linear" or t.size < 3
        self._system = SplineSystem(t) if method == "spline" and not self._linear else None
        self._where = None if self._linear else Located(t, at)

    def __call__(self, v: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """Column `v` (n,), or columns (n, k), at the points: shape (m,) or (m, k), written into `out` when given.

        Each column's values are those it has alone: the arithmetic is column by column, in the same order.
        """
        if v.ndim == 1:
            return self(v[:, None], None if out is None else out[:, None])[:, 0]
        if self._where is None:
            out = np.empty((self.at.size, v.shape[1])) if out is None else out
            for k in range(v.shape[1]):
                out[:, k] = np.interp(self.at, self.t, v[:, k])
            return out
        slopes = self._system.slopes(v) if self._system is not None else pchip_slopes(self.t, v)
        return hermite(self.t, v, slopes, self._where, out)


def complement(pieces: list[tuple[float, float]], lo: float, hi: float) -> list[tuple[float, float]]:
    """Parts of [lo, hi] not covered by the ordered, disjoint `pieces`."""
    holes, cursor = [], lo
    for a, b in pieces:
        if a > cursor + TIME_TOL_S and cursor < hi:
            holes.append((cursor, min(a, hi)))
        cursor = max(cursor, b)
    if cursor < hi - TIME_TOL_S:
        holes.append((cursor, hi))
    return holes


def intersect(left: list[tuple[float, float]], right: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """Intersection of two ordered lists of disjoint closed intervals."""
    out, i, j = [], 0, 0
    while i < len(left) and j < len(right):
        a, b = max(left[i][0], right[j][0]), min(left[i][1], right[j][1])
        if b >= a - TIME_TOL_S:
            out.append((a, max(a, b)))
        if left[i][1] < right[j][1]:
            i += 1
        else:
            j += 1
    return out


def snap(intervals: list[tuple[float, float]], grid: np.ndarray) -> list[tuple[float, float]]:
    """Shrink each interval to the grid samples inside it; drop those holding none."""
    out = []
    for a, b in intervals:
        i0 = int(np.searchsorted(grid, a - TIME_TOL_S, side="left"))
        i1 = int(np.searchsorted(grid, b + TIME_TOL_S, side="right")) - 1
        if i1 >= i0:
            out.append((float(grid[i0]), float(grid[i1])))
    return out
