"""Structure reduction: which parameter to remove next, and the log of what was removed.

Tischler & Remple's procedure (ch. 11): after each fit, the worst parameter
beyond the guidelines leaves the model, and the model is refitted, until
every remaining parameter satisfies them. The worst is, in this order:

1. the largest insensitivity, if any I% exceeds the guideline's
   `max_insensitivity_percent` (the cost hardly depends on it);
2. the largest Cramér–Rao bound, if any CR% exceeds the guideline's
   `max_cr_percent` (it cannot be told apart from the others);
3. with `max_correlation` set, of the most correlated pair beyond it, the
   member with the larger CR%.

A parameter whose structure says ``reduce = "drop"`` is set to its
``drop_value`` (0: the term leaves the model); ``reduce = "fix"`` holds it
at its current estimate (a time constant such as T_a). A step is taken
only if the costs stay acceptable: when the refit without the parameter
raises J_ave, or the cost of any one response, beyond the margins of
:class:`~sysid.fit.guidelines.Guidelines` (Tischler & Remple, ch. 10:
J_ave by about 2 %, no response markedly), the removal is undone: the
parameter matters to the fit although its CR% or I% miss the guideline,
so it is kept (logged as ``kept``, with the costs that rose) and not
considered again.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Literal

import numpy as np

from sysid.fit.accuracy import Accuracy
from sysid.fit.guidelines import DEFAULT_GUIDELINES, Guidelines

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
        removing it raised the cost too much (`reason` says which).
    value : float
        Value it has from now on (for ``kept``: its estimate).
    estimate : float
        Its estimate in the fit that condemned it.
    cr_percent : float
        Its CR% in that fit.
    insensitivity_percent : float
        Its I% in that fit.
    reason : str
        Which guideline it failed, in words; for ``kept`` also which cost rose.
    cost_average : float
        J_ave of the fit that condemned it.
    cost_average_after : float
        J_ave after refitting without it (NaN if no refit followed).
    cost_responses : Mapping[str, float]
        J of each response in the fit that condemned it, by pair name.
    cost_responses_after : Mapping[str, float]
        J of each response after refitting without it (empty if no refit followed).
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
    cost_responses: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({}))
    cost_responses_after: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({}))

    def __post_init__(self) -> None:
        for name in ("cost_responses", "cost_responses_after"):
            table = getattr(self, name)
            object.__setattr__(self, name, MappingProxyType({str(k): float(v) for k, v in table.items()}))


def worst_parameter(
    acc: Accuracy,
    *,
    guidelines: Guidelines = DEFAULT_GUIDELINES,
    max_correlation: float | None = None,
    exclude: frozenset[str] = frozenset(),
) -> tuple[str, str] | None:
    """The parameter to remove next, and why; None when every parameter meets the guidelines.

    Parameters
    ----------
    acc : Accuracy
        Accuracy of the current fit.
    guidelines : Guidelines, optional
        The CR% and I% limits (`max_cr_percent`, `max_insensitivity_percent`); default Tischler's.
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
    >>> worst_parameter(acc, guidelines=Guidelines(max_insensitivity_percent=1e5))
    ('N_r', 'CR% = 1e+04 > 20')
    """
    allowed = np.array([name not in exclude for name in acc.names], dtype=bool)
    cr = np.where(allowed, acc.cramer_rao_percent, -np.inf)
    ins = np.where(allowed, acc.insensitivity_percent, -np.inf)
    if acc.names and guidelines.misses_insensitivity(float(np.max(ins))):
        k = int(np.argmax(ins))
        return acc.names[k], f"I% = {ins[k]:.3g} > {guidelines.max_insensitivity_percent:g}"
    if acc.names and guidelines.misses_cr(float(np.max(cr))):
        k = int(np.argmax(cr))
        return acc.names[k], f"CR% = {cr[k]:.3g} > {guidelines.max_cr_percent:g}"
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
