"""The part of a model of several decoupled axes that one excited input drives."""

from __future__ import annotations

import numpy as np

from flightlogs.errors import ModelError

from ..statespace import DelayedStateSpace

__all__ = ["driven_part"]


def driven_part(model: DelayedStateSpace, excited: str) -> DelayedStateSpace:
    """The part of a decoupled model that input `excited` drives.

    States reachable from `excited` through B and A, the outputs that read
    them (or `excited` directly), and every input that drives those states
    (the wind as well as the mixer input). For a model of one axis this is
    the model itself.

    Parameters
    ----------
    model : DelayedStateSpace
        Model, possibly of several decoupled axes.
    excited : str
        The input excited in a record (for example ``"delta_lon"``).

    Returns
    -------
    DelayedStateSpace

    Raises
    ------
    ModelError
        If `excited` is not a model input.
    """
    if excited not in model.inputs:
        raise ModelError(f"{excited!r} is not an input of the model ({', '.join(model.inputs)})")
    a, b, c, d = (np.asarray(m, dtype=float) for m in (model.a, model.b, model.c, model.d))
    columns = [j for j, name in enumerate(model.inputs) if name == excited]
    reached = np.any(b[:, columns] != 0, axis=1)
    while True:
        grown = reached | np.any(a[:, reached] != 0, axis=1)
        if np.array_equal(grown, reached):
            break
        reached = grown
    rows = np.any(c[:, reached] != 0, axis=1) | np.any(d[:, columns] != 0, axis=1)
    keep_inputs = np.any(b[reached] != 0, axis=0) | np.any(d[rows] != 0, axis=0)
    x, u, y = np.flatnonzero(reached), np.flatnonzero(keep_inputs), np.flatnonzero(rows)
    return DelayedStateSpace(
        a[np.ix_(x, x)], b[np.ix_(x, u)], c[np.ix_(y, x)], d[np.ix_(y, u)],
        tuple(model.states[i] for i in x), tuple(model.inputs[j] for j in u), tuple(model.outputs[i] for i in y),
        np.asarray(model.input_delays_s, dtype=float)[u], model.trim)
