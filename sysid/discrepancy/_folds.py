"""Held-out blocks of a flight's samples: contiguous blocks, and folds of interleaved ones.

Below the catalogue and the selection alike (a sensor's jackknife and the terms' cross-validation
deal a flight's samples the same way).
"""

from __future__ import annotations

import numpy as np

__all__ = ["blocks", "folds"]

_N_BLOCKS = 6
_FOLD_BLOCK = 200  # samples per interleaved block of a fold (4 s at 50 Hz)


def blocks(n: int, k: int = _N_BLOCKS) -> list[np.ndarray]:
    """`k` contiguous blocks of sample indices covering ``range(n)``.

    Parameters
    ----------
    n : int
        Number of samples.
    k : int, optional
        Number of blocks.
    """
    edges = np.linspace(0, n, k + 1).astype(int)
    return [np.arange(edges[i], edges[i + 1]) for i in range(k)]


def folds(n: int, block: int = _FOLD_BLOCK, k: int = _N_BLOCKS) -> list[np.ndarray]:
    """`k` folds of sample indices, each the blocks of `block` samples ``j, j + k, j + 2k …``, covering ``range(n)``.

    A flight's manoeuvres are short: a reposition's speed lives in 10 s of 250. With `k` contiguous
    blocks the one that holds it is predicted from blocks that never saw that regime, and a coefficient
    fitted on noise elsewhere extrapolates there (a parasitic drag scored -14 on a flight whose drag it
    had right). Interleaved blocks of a few seconds (the residual's correlation is far shorter) let every
    fold see every regime and still hold out whole stretches of flight.

    Parameters
    ----------
    n : int
        Number of samples.
    block : int, optional
        Samples per block (200: 4 s at the search's 50 Hz).
    k : int, optional
        Number of folds.

    Examples
    --------
    >>> [f.tolist() for f in folds(7, block=2, k=2)]
    [[0, 1, 4, 5], [2, 3, 6]]
    """
    labels = (np.arange(n) // max(block, 1)) % k
    return [np.flatnonzero(labels == j) for j in range(k)]
