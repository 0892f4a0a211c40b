"""Moving windows over 1-D traces in numpy: means, rank (median) filters, mask dilation and erosion, FFT lengths.

The ``scipy.ndimage`` and ``scipy.fft`` calls the ingest path used, written so that reading a log
does not import SciPy (0.17 s before anything else of it loads). Each matches its SciPy model with
the same window placement and edge mode; the tests compare them.
"""

from __future__ import annotations

from typing import cast

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

__all__ = ["dilate", "erode", "fast_fft_length", "moving_mean", "moving_rank"]


def moving_mean(x: np.ndarray, width: int) -> np.ndarray:
    """Mean over `width` samples around each one, the ends held: ``scipy.ndimage.uniform_filter1d(x, width, mode="nearest")``.

    Parameters
    ----------
    x : ndarray, shape (n,)
        Trace.
    width : int
        Window, samples (>= 1); an even window reaches one sample further back than forward.

    Returns
    -------
    ndarray, shape (n,)
    """
    x = np.asarray(x, dtype=np.float64)
    if x.size == 0:
        return x.copy()
    padded = np.pad(x, (width // 2, (width - 1) // 2), mode="edge")
    sums = np.concatenate(([0.0], np.cumsum(padded)))
    return cast(np.ndarray, (sums[width:] - sums[:-width]) / width)


def moving_rank(x: np.ndarray, width: int, *, mode: str = "reflect") -> np.ndarray:
    """The window's middle value (rank ``width // 2``): ``scipy.ndimage.median_filter(x, size=width, mode=mode)``.

    Parameters
    ----------
    x : ndarray, shape (n,)
        Trace.
    width : int
        Window, samples (>= 1).
    mode : {"reflect", "nearest"}
        Edges: mirrored about the end (d c b a | a b c d) or the end value held.

    Returns
    -------
    ndarray, shape (n,)

    Notes
    -----
    Sorts each window (memory n × width): meant for short traces or short windows.
    """
    x = np.asarray(x, dtype=np.float64)
    if x.size == 0:
        return x.copy()
    ends = (width // 2, width - 1 - width // 2)
    padded = np.pad(x, ends, mode="symmetric") if mode == "reflect" else np.pad(x, ends, mode="edge")
    return cast(np.ndarray, np.partition(sliding_window_view(padded, width), width // 2, axis=1)[:, width // 2])


def dilate(mask: np.ndarray, reach: int) -> np.ndarray:
    """True within `reach` samples of a True sample: ``scipy.ndimage.binary_dilation(mask, iterations=reach)``.

    Parameters
    ----------
    mask : ndarray of bool, shape (n,)
    reach : int
        Samples either side (>= 0).
    """
    return _any_within(np.asarray(mask, dtype=bool), reach)


def erode(mask: np.ndarray, reach: int) -> np.ndarray:
    """True where every sample within `reach` is, beyond the ends counted True: ``binary_erosion(mask, iterations=reach, border_value=1)``.

    Parameters
    ----------
    mask : ndarray of bool, shape (n,)
    reach : int
        Samples either side (>= 0).
    """
    return ~_any_within(~np.asarray(mask, dtype=bool), reach)


def fast_fft_length(n: int) -> int:
    """The smallest 5-smooth length (2^a 3^b 5^c) >= `n`: ``scipy.fft.next_fast_len(n, real=True)``.

    Parameters
    ----------
    n : int
        Samples to hold (>= 1).
    """
    best = 1 << max(int(n) - 1, 0).bit_length()
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            size = p35 << max(0, (-(-n // p35) - 1).bit_length())  # p35 times the power of two reaching n
            best = min(best, size)
            p35 *= 3
        p5 *= 5
    return best


def _any_within(mask: np.ndarray, reach: int) -> np.ndarray:
    """True where a True sample lies within `reach` samples (none beyond the ends)."""
    if reach <= 0:
        return mask.copy()
    padded = np.pad(mask, reach)
    counts = np.concatenate(([0], np.cumsum(padded, dtype=np.int64)))
    return cast(np.ndarray, counts[2 * reach + 1 :] - counts[: -2 * reach - 1] > 0)
