"""Rank statistics of 1-D samples: Spearman's correlation, the median and quantiles.

:func:`spearman` equals ``scipy.stats.spearmanr(x, y).statistic`` for 1-D finite data, ties given
their average rank, without importing scipy.stats (which takes longer to load than a log to read).
:func:`median` and :func:`quantile` equal ``np.median`` and ``np.quantile`` (linear) bit for bit on
1-D finite data, at a tenth of their cost on the short traces the edge search takes them of
hundreds of times (numpy's generic machinery costs more than the partition). The tests compare them.
"""

from __future__ import annotations

import numpy as np

__all__ = ["median", "quantile", "spearman"]


def spearman(x: np.ndarray, y: np.ndarray) -> float:
    """Spearman's rho of two equal-length 1-D samples; NaN if either is constant.

    Parameters
    ----------
    x, y : ndarray, shape (n,)
        Finite values.
    """
    a, b = _ranks(np.asarray(x, dtype=np.float64)), _ranks(np.asarray(y, dtype=np.float64))
    a -= a.mean()
    b -= b.mean()
    norm = float(np.sqrt(np.dot(a, a) * np.dot(b, b)))
    return float(np.dot(a, b) / norm) if norm > 0.0 else float("nan")


def _ranks(values: np.ndarray) -> np.ndarray:
    """Ranks 1..n, ties at their average (scipy.stats.rankdata's 'average')."""
    order = np.argsort(values, kind="mergesort")
    ordered = values[order]
    first = np.r_[True, ordered[1:] != ordered[:-1]]
    group = np.cumsum(first) - 1  # tie group of each sorted value
    starts = np.flatnonzero(first)
    ends = np.r_[starts[1:], values.size]
    average = 0.5 * (starts + ends - 1) + 1.0  # mean of the 1-based positions start..end-1
    ranks = np.empty(values.size)
    ranks[order] = average[group]
    return ranks


def median(x: np.ndarray) -> float:
    """``float(np.median(x))`` of a 1-D finite sample (n >= 1).

    Parameters
    ----------
    x : ndarray, shape (n,)
        Finite values.
    """
    n = x.size
    if n % 2:
        return float(np.partition(x, n // 2)[n // 2])
    low, high = np.partition(x, [n // 2 - 1, n // 2])[n // 2 - 1 : n // 2 + 1]
    return float((low + high) / 2)


def quantile(x: np.ndarray, q: float) -> float:
    """``float(np.quantile(x, q))`` (linear interpolation) of a 1-D finite sample (n >= 1).

    Parameters
    ----------
    x : ndarray, shape (n,)
        Finite values.
    q : float
        Quantile, 0 to 1.
    """
    n = x.size
    virtual = (n - 1) * q  # numpy's virtual index of the linear method
    if virtual >= n - 1:
        return float(np.max(x))
    below = int(np.floor(virtual))
    gamma = virtual - below
    low, high = np.partition(x, [below, below + 1])[below : below + 2]
    step = high - low
    return float(high - step * (1 - gamma) if gamma >= 0.5 else low + step * gamma)  # numpy's _lerp
