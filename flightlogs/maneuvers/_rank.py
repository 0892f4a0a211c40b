"""Spearman's rank correlation without importing scipy.stats (which takes longer to load than a log to read).

Equal to ``scipy.stats.spearmanr(x, y).statistic`` for 1-D finite data, ties given their average rank
(tests/flightlogs/maneuvers/test_rank.py compares them).
"""

from __future__ import annotations

import numpy as np

__all__ = ["spearman"]


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
