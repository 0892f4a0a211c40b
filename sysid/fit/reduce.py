"""Structure reduction: which parameter to remove next, and the log of what was removed.

Tischler & Remple's procedure (ch. 11): after each fit, the worst parameter
beyond the guidelines leaves the model, and the model is refitted, until
every remaining parameter satisfies them. The worst is, in this order:

1. the largest insensitivity, if any I% exceeds `max_insensitivity_percent`
   (the cost hardly depends on it);
2. the largest Cramér–Rao bound, if any CR% exceeds `max_cr_percent`
   (it cannot be told apart from the others);
3. with `max_correlation` set, of the most correlated pair beyond it, the
   member with the larger CR%.

A parameter whose structure says ``reduce = "drop"`` is set to its
``drop_value`` (0: the term leaves the model); ``reduce = "fix"`` holds it
at its current estimate (a time constant such as T_a). On request
(``FitOptions.max_cost_increase``), a removal that raises J_ave by more
than a tolerance is undone: the parameter matters to the fit although its
CR% or I% miss the guideline, so it is kept (logged as ``kept``) and not
considered again.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from sysid.fit.accuracy import Accuracy

__all__ = ["ReductionStep", "worst_parameter"]


@dataclass(frozen=True, slots=True, kw_only=True)
class ReductionStep:
    """One parameter removed by structure reduction.

    Parameters
    ----------
    step : int
        1 for the first removal.
    parameter : str
        Name of the parameter removed.
    action : {"dropped", "fixed", "kept"}
        Set to its drop value, held at its estimate, or restored because
        removing it raised the cost too much.
    value : float
        Value it has from now on (for ``kept``: its estimate).
    estimate : float
        Its estimate in the fit that condemned it.
    cr_percent : float
        Its CR% in that fit.
    insensitivity_percent : float
        Its I% in that fit.
    reason : str
        Which guideline it failed, in words.
    cost_average : float
        J_ave of the fit that condemned it.
    cost_average_after : float
        J_ave after refitting without it (NaN if no refit followed).
    """

    step: int
    parameter: str
    action: Literal["dropped", "fixed", "kept"]
    value: float
    estimate: float
    cr_percent: float
    insensitivity_percent: float
    reason: str
    cost_average: float
    cost_average_after: float = math.nan


def worst_parameter(
    acc: Accuracy,
    *,
    max_cr_percent: float = 20.0,
    max_insensitivity_percent: float = 10.0,
    max_correlation: float | None = None,
    exclude: frozenset[str] = frozenset(),
) -> tuple[str, str] | None:
    """The parameter to remove next, and why; None when every parameter meets the guidelines.

    Parameters
    ----------
    acc : Accuracy
        Accuracy of the current fit.
    max_cr_percent : float, optional
        CR% guideline.
    max_insensitivity_percent : float, optional
        I% guideline.
    max_correlation : float or None, optional
        Largest acceptable |correlation| between two parameters; None to
        ignore correlation.
    exclude : frozenset of str, optional
        Parameters not to propose (already kept on the cost criterion).

    Returns
    -------
    tuple of (str, str) or None
        Name and reason.

    Examples
    --------
    >>> from sysid.fit.accuracy import accuracy
    >>> acc = accuracy(np.array([[10.0, 0.0], [0.0, 10.0]]), np.array([1.0, 0.001]), ("X_u", "N_r"))
    >>> worst_parameter(acc)
    ('N_r', 'I% = 1e+04 > 10')
    """
    allowed = np.array([name not in exclude for name in acc.names], dtype=bool)
    cr = np.where(allowed, acc.cramer_rao_percent, -np.inf)
    ins = np.where(allowed, acc.insensitivity_percent, -np.inf)
    if acc.names and np.max(ins) > max_insensitivity_percent:
        k = int(np.argmax(ins))
        return acc.names[k], f"I% = {ins[k]:.3g} > {max_insensitivity_percent:g}"
    if acc.names and np.max(cr) > max_cr_percent:
        k = int(np.argmax(cr))
        return acc.names[k], f"CR% = {cr[k]:.3g} > {max_cr_percent:g}"
    if max_correlation is not None and len(acc.names) > 1:
        corr = np.abs(np.nan_to_num(acc.correlation, nan=0.0)) * np.outer(allowed, allowed)
        np.fill_diagonal(corr, 0.0)
        i, j = np.unravel_index(int(np.argmax(corr)), corr.shape)
        if corr[i, j] > max_correlation:
            k = int(i if cr[i] >= cr[j] else j)
            return acc.names[k], (
                f"|correlation| with {acc.names[int(j if k == i else i)]} = {corr[i, j]:.3f} > {max_correlation:g}"
            )
    return None
