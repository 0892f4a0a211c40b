"""Boolean sample masks: where their runs of True start and stop.

One convention for every stretch of samples found from a mask (a maneuver
burst, a hover, a gap-free piece): half-open ``[start, stop)`` sample
indices, as Python slices are, so ``values[start:stop]`` is the run and
``stop - start`` its length.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from flightlogs.errors import DataError

__all__ = ["true_runs"]


def true_runs(mask: npt.ArrayLike) -> list[tuple[int, int]]:
    """Bounds ``[start, stop)`` of every run of True in `mask`, in order.

    Parameters
    ----------
    mask : array_like of bool, shape (n_samples,)
        One flag a sample.

    Returns
    -------
    list of (int, int)
        ``(start, stop)`` of each maximal run: ``mask[start:stop]`` is all
        True and the samples just outside it (if any) are False. Empty when
        no sample is True.

    Raises
    ------
    DataError
        If `mask` is not one-dimensional.

    Examples
    --------
    >>> true_runs([True, True, False, False, True])
    [(0, 2), (4, 5)]
    >>> true_runs(np.zeros(3, dtype=bool)), true_runs([])
    ([], [])
    """
    flags = np.asarray(mask, dtype=bool)
    if flags.ndim != 1:
        raise DataError(f"mask must be one-dimensional, not of shape {flags.shape}")
    edges = np.flatnonzero(np.diff(np.concatenate([[0], flags.astype(np.int8), [0]])))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2])]
