"""Fitting a candidate term and judging it on time blocks it was not fitted on.

The flight is cut into blocks of 4 s dealt in turn to six folds; a term's coefficients are fitted
on all folds but one and scored on that one, in turn. The one parameter
inside a term's shape (a delay, a lag, a mass step's time) is chosen once on
the whole flight: a step's time cannot be found from blocks that do not hold
it, and one value chosen from thousands of samples costs next to nothing in
honesty (the null score of every term is measured the same way). Its score is the share of the held-out residual it
removes, each output's residual weighted by the inverse of its noise floor
(the simulation model's residual on held-out simulation data), so outputs
in different units count alike and an output the model already fits to its
noise weighs little.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from sysid.discrepancy.catalogue import Candidate

__all__ = [
    "TermFit",
    "blocks",
    "folds",
    "combined",
    "cross_validated",
    "fit_term",
    "joined",
    "split_joined",
    "effective_samples",
]

_N_BLOCKS = 6
_FOLD_BLOCK = 200  # samples per interleaved block of a fold (4 s at 50 Hz)


@dataclass(frozen=True, slots=True, kw_only=True)
class TermFit:
    """A term fitted on some samples.

    Parameters
    ----------
    candidate : Candidate
        The term.
    value : float
        Its grid value (NaN if it has none).
    coefficients : Mapping[str, ndarray]
        Per output, the coefficients of its regressors (linear terms; empty for transforms).
    covariance : Mapping[str, ndarray]
        Per output, their covariance, residual correlation accounted for.
    value_uncertainty : float
        Standard deviation of the grid value, from the curvature of the cost over the grid (NaN if none).
    """

    candidate: Candidate
    value: float
    coefficients: Mapping[str, np.ndarray]
    covariance: Mapping[str, np.ndarray]
    value_uncertainty: float

    def prediction(self, base: Mapping[str, np.ndarray], additions: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """The model's prediction with this term: `base` (the simulation model's) plus `additions` plus its own."""
        built = self.candidate.build(self.value)
        if self.candidate.kind == "transform":
            return {o: built[o] + additions[o] for o in base}
        out = combined(base, additions)
        for o, coefficients in self.coefficients.items():
            out[o] = out[o] + built[o] @ coefficients
        return out


def combined(base: Mapping[str, np.ndarray], additions: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The model's prediction: the simulation model's `base` plus the kept terms' `additions`, per output.

    Parameters
    ----------
    base, additions : Mapping[str, ndarray]
        Per output, shape (n,) each.
    """
    return {o: base[o] + additions[o] for o in base}


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


def cross_validated(
    candidate: Candidate,
    y: Mapping[str, np.ndarray],
    base: Mapping[str, np.ndarray],
    additions: Mapping[str, np.ndarray],
    scale: Mapping[str, float],
    reference: Mapping[str, np.ndarray] | None = None,
    judged: tuple[str, ...] | None = None,
) -> tuple[float, dict[str, np.ndarray]]:
    """Held-out share of the weighted residual of the term's outputs that the term removes, and its predictions.

    Parameters
    ----------
    candidate : Candidate
        The term.
    y : Mapping[str, ndarray]
        Each output as flown, shape (n,).
    base : Mapping[str, ndarray]
        The simulation model's prediction of each output, shape (n,) (a transform term replaces it).
    additions : Mapping[str, ndarray]
        Contributions of the terms already kept, shape (n,) each.
    scale : Mapping[str, float]
        Each output's noise-floor variance (the weights are its inverse).
    reference : Mapping[str, ndarray], optional
        The prediction the term is judged against, shape (n,) each (default ``base + additions``): the
        held-out prediction of the terms already kept when a :func:`joined` term refits them.
    judged : tuple of str, optional
        Outputs the score sums over (default the term's).

    Returns
    -------
    improvement : float
        ``1 - SSE_with / SSE_without`` over the held-out blocks (can be negative).
    predicted : dict of str to ndarray
        Each output as predicted on every block by the term fitted on the other blocks, shape (n,).
    """
    n = next(iter(y.values())).size
    current = dict(reference) if reference is not None else combined(base, additions)
    predicted = {o: current[o].copy() for o in current}
    fixed = replace(candidate, grid=(fit_term(candidate, y, base, additions, scale).value,))
    for test in folds(n):
        train = np.setdiff1d(np.arange(n), test)
        fit = fit_term(fixed, y, base, additions, scale, train)
        with_term = fit.prediction(base, additions)
        for o in candidate.outputs:
            predicted[o][test] = with_term[o][test]
    outputs = judged if judged is not None else candidate.outputs
    before = sum(np.sum((y[o] - current[o]) ** 2) / scale[o] for o in outputs)
    after = sum(np.sum((y[o] - predicted[o]) ** 2) / scale[o] for o in outputs)
    return float(1.0 - after / before) if before > 0 else 0.0, predicted


def joined(candidate: Candidate, kept: Sequence[TermFit]) -> Candidate:
    """`candidate` with the regressors of the linear terms already `kept` beside its own, to be fitted together.

    Two effects whose regressors overlap are told apart only when fitted jointly (a CG offset's constant
    moment and the hub moment of a steady wind): a kept term's coefficients, fitted alone, have taken up
    part of the newcomer's. Per output the columns are the candidate's, then each kept term's, in order.

    Parameters
    ----------
    candidate : Candidate
        A linear term.
    kept : sequence of TermFit
        Linear terms already kept (their grid values stay).

    Returns
    -------
    Candidate
        Named, gridded and located as `candidate`.
    """
    parts = [(candidate, None), *((k.candidate, k.value) for k in kept)]
    outputs = tuple(dict.fromkeys(o for c, _ in parts for o in c.outputs))

    def build(value: float) -> dict[str, np.ndarray]:
        built = [c.build(value if v is None else v) for c, v in parts]
        return {o: np.column_stack([b[o] for (c, _), b in zip(parts, built) if o in c.outputs]) for o in outputs}

    names = candidate.coefficients + tuple(n for k in kept for n in k.candidate.coefficients)
    return replace(candidate, outputs=outputs, build=build, coefficients=names)


def split_joined(fit: TermFit, candidate: Candidate, kept: Sequence[TermFit]) -> list[TermFit]:
    """A :func:`joined` fit back into one fit per term: the candidate's, then each kept term's.

    Parameters
    ----------
    fit : TermFit
        The joined term's fit.
    candidate : Candidate
        The candidate it was joined from.
    kept : sequence of TermFit
        The kept terms it holds, in the order given to :func:`joined`.
    """
    parts = [
        (candidate, fit.value, fit.value_uncertainty),
        *((k.candidate, k.value, k.value_uncertainty) for k in kept),
    ]
    first = dict.fromkeys(fit.coefficients, 0)
    out = []
    for term, value, spread in parts:
        built = term.build(value)
        coefficients, covariance = {}, {}
        for o in term.outputs:
            if o not in fit.coefficients:
                continue
            width = built[o].shape[1]
            span = slice(first[o], first[o] + width)
            coefficients[o], covariance[o] = fit.coefficients[o][span], fit.covariance[o][span, span]
            first[o] += width
        out.append(
            TermFit(
                candidate=term,
                value=value,
                coefficients=coefficients,
                covariance=covariance,
                value_uncertainty=spread,
            )
        )
    return out


def fit_term(
    candidate: Candidate,
    y: Mapping[str, np.ndarray],
    base: Mapping[str, np.ndarray],
    additions: Mapping[str, np.ndarray],
    scale: Mapping[str, float],
    rows: np.ndarray | None = None,
) -> TermFit:
    """The term fitted on samples `rows` (default all): grid value by least weighted SSE, then coefficients.

    Parameters
    ----------
    candidate, y, base, additions, scale
        As :func:`cross_validated`.
    rows : ndarray of int, optional
        Samples to fit on.

    Returns
    -------
    TermFit
    """
    n = next(iter(y.values())).size
    rows = np.arange(n) if rows is None else rows
    costs, fits = [], []
    kept = {o: y[o][rows] - additions[o][rows] for o in candidate.outputs}  # what the term and the base must explain
    targets = {o: kept[o] - base[o][rows] for o in candidate.outputs}
    for value in candidate.grid:
        built = candidate.build(value)
        coefficients, cost = {}, 0.0
        for o in candidate.outputs:
            if candidate.kind == "transform":
                residual = kept[o] - built[o][rows]
            else:
                target = targets[o]
                z = built[o][rows]
                coefficients[o] = _least_squares(z, target)
                residual = target - z @ coefficients[o]
            cost += float(np.sum(residual**2)) / scale[o]
        costs.append(cost)
        fits.append((value, coefficients))
    best = int(np.argmin(costs))
    value, coefficients = fits[best]
    covariance = {}
    if candidate.kind == "linear":  # the covariance of the chosen grid value's coefficients only
        built = candidate.build(value)
        for o in candidate.outputs:
            z = built[o][rows]
            covariance[o] = _covariance(z, targets[o] - z @ coefficients[o])
    spread = _grid_spread(np.asarray(candidate.grid), np.asarray(costs), best, rows.size, candidate, y, base, scale)
    if np.isfinite(spread) and len(candidate.grid) > 1:  # never finer than the grid can tell
        spread = max(spread, float(np.median(np.diff(candidate.grid))) / np.sqrt(12.0))
    return TermFit(
        candidate=candidate, value=value, coefficients=coefficients, covariance=covariance, value_uncertainty=spread
    )


def _least_squares(z: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Coefficients minimising ``|target - z c|``: the normal equations when well conditioned (a few columns), else SVD."""
    gram = z.T @ z
    if np.linalg.cond(gram) < 1e10:
        return np.asarray(np.linalg.solve(gram, z.T @ target))
    return np.asarray(np.linalg.lstsq(z, target, rcond=None)[0])


def effective_samples(residual: np.ndarray) -> float:
    """Samples worth of independent information in a correlated residual (lag-1 autocorrelation, AR(1)).

    Parameters
    ----------
    residual : ndarray, shape (n,)
        A residual time series.
    """
    r = residual - residual.mean()
    denominator = float(np.dot(r, r))
    rho = float(np.dot(r[1:], r[:-1]) / denominator) if denominator > 0 else 0.0
    rho = min(max(rho, 0.0), 0.999)
    return float(residual.size * (1.0 - rho) / (1.0 + rho))


def _covariance(z: np.ndarray, residual: np.ndarray) -> np.ndarray:
    """Coefficient covariance, the residual variance inflated by its correlation (``n / n_effective``)."""
    inflation = residual.size / max(effective_samples(residual), 1.0)
    variance = float(np.mean(residual**2)) * inflation
    return np.asarray(variance * np.linalg.pinv(z.T @ z))


def _grid_spread(
    grid: np.ndarray,
    costs: np.ndarray,
    best: int,
    n: int,
    candidate: Candidate,
    y: Mapping[str, np.ndarray],
    base: Mapping[str, np.ndarray],
    scale: Mapping[str, float],
) -> float:
    """Standard deviation of the grid value: the cost's curvature at its minimum, residual correlation counted.

    The weighted cost is a sum of squares whose noise variance is one per effective sample, so
    ``sigma² = 2 / (d²cost/dvalue²)`` scaled by ``n / n_effective`` (taken from the first output's residual).
    """
    if grid.size < 3 or not np.isfinite(grid).all():
        return float("nan")
    k = min(max(best, 1), grid.size - 2)
    h1, h2 = grid[k] - grid[k - 1], grid[k + 1] - grid[k]
    curvature = 2.0 * (h1 * costs[k + 1] - (h1 + h2) * costs[k] + h2 * costs[k - 1]) / (h1 * h2 * (h1 + h2))
    if curvature <= 0:
        return float(h1 + h2)
    per_sample = costs[best] / max(n * len(candidate.outputs), 1)  # about 1 when the floor is right
    first = candidate.outputs[0]
    built = candidate.build(float(grid[best]))
    residual = (y[first] - (built[first] if candidate.kind == "transform" else base[first])) / np.sqrt(scale[first])
    inflation = residual.size / max(effective_samples(residual), 1.0)
    return float(np.sqrt(2.0 * max(per_sample, 1e-12) * inflation / curvature))
