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

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from sysid.discrepancy._folds import blocks, folds
from sysid.discrepancy.catalogue import Candidate

__all__ = [
    "TermFit",
    "blocks",
    "folds",
    "combined",
    "cross_validated",
    "held_out_share",
    "narrowed",
    "fit_term",
    "joined",
    "split_joined",
    "effective_samples",
]

_CHUNK = 64  # grid values of a linear term whose regressors are held at once (a mass step's 640 times: 64 at a time)


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

    def coefficient_values(self) -> list[tuple[str, float, float]]:
        """Each coefficient as (key, value, standard deviation), in the candidate's column order over its outputs."""
        keys = iter(self.candidate.coefficients)
        out = []
        for o in self.candidate.outputs:
            if o not in self.coefficients:
                continue
            sigma = np.sqrt(np.maximum(np.diag(self.covariance[o]), 0.0))
            out += [(next(keys), float(v), float(e)) for v, e in zip(self.coefficients[o], sigma)]
        return out

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
    build = _Builds(candidate.build)  # one build per value for the whole flight's fit and every fold's
    value = _fit_term(candidate, y, base, additions, scale, None, build, uncertainties=False).value
    built = build(value)
    if candidate.kind == "transform":  # nothing is fitted per fold: every block's prediction is the transform's
        for o in candidate.outputs:
            predicted[o] = built[o] + additions[o]
    else:
        fixed = replace(candidate, grid=(value,))
        held = np.zeros(n, dtype=bool)
        for test in folds(n):
            held[:] = False
            held[test] = True
            fit = _fit_term(fixed, y, base, additions, scale, np.flatnonzero(~held), build, uncertainties=False)
            for o, coefficients in fit.coefficients.items():  # the prediction with the term, as TermFit.prediction
                predicted[o][test] = ((base[o] + additions[o]) + built[o] @ coefficients)[test]
    return held_out_share(y, predicted, current, scale, judged if judged is not None else candidate.outputs), predicted


def held_out_share(
    y: Mapping[str, np.ndarray],
    predicted: Mapping[str, np.ndarray],
    current: Mapping[str, np.ndarray],
    scale: Mapping[str, float],
    outputs: Sequence[str],
) -> float:
    """``1 - SSE_with / SSE_without`` of `outputs`, each weighted by its noise floor's inverse.

    Parameters
    ----------
    y : Mapping[str, ndarray]
        Each output as flown, shape (n,).
    predicted : Mapping[str, ndarray]
        Each output as predicted with the term (held out), shape (n,).
    current : Mapping[str, ndarray]
        Each output as predicted without it, shape (n,).
    scale : Mapping[str, float]
        Each output's noise-floor variance.
    outputs : sequence of str
        The outputs summed over.

    Examples
    --------
    >>> import numpy as np
    >>> y, without = {"ax": np.ones(4)}, {"ax": np.zeros(4)}
    >>> held_out_share(y, {"ax": np.full(4, 0.5)}, without, {"ax": 1.0}, ["ax"])
    0.75
    """
    before = sum(float(np.sum((y[o] - current[o]) ** 2)) / scale[o] for o in outputs)
    after = sum(float(np.sum((y[o] - predicted[o]) ** 2)) / scale[o] for o in outputs)
    return 1.0 - after / before if before > 0 else 0.0


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


def narrowed(candidate: Candidate, outputs: tuple[str, ...]) -> Candidate:
    """A linear `candidate` on `outputs` only (a subset of its own), its coefficients' keys kept in order.

    Parameters
    ----------
    candidate : Candidate
        A linear term.
    outputs : tuple of str
        The outputs it keeps.
    """
    built = candidate.build(candidate.grid[0])
    keys: list[str] = []
    first = 0
    for o in candidate.outputs:
        width = built[o].shape[1]
        if o in outputs:
            keys.extend(candidate.coefficients[first : first + width])
        first += width
    build = candidate.build

    def narrow(value: float) -> dict[str, np.ndarray]:
        whole = build(value)
        return {o: whole[o] for o in outputs}

    return replace(candidate, outputs=outputs, build=narrow, coefficients=tuple(keys))


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
    return _fit_term(candidate, y, base, additions, scale, rows, _Builds(candidate.build))


class _Builds:
    """A candidate's ``build`` that keeps the last value's regressors (NaN included): a fit reads them often.

    Only the last: a grid of 640 step times would otherwise hold 640 copies of its regressors.
    """

    def __init__(self, build: Callable[[float], Mapping[str, np.ndarray]]) -> None:
        self._build = build
        self._key: object = None
        self._made: Mapping[str, np.ndarray] = {}

    def __call__(self, value: float) -> Mapping[str, np.ndarray]:
        key = "nan" if value != value else value
        if key != self._key:
            self._key, self._made = key, self._build(value)
        return self._made


def _fit_term(
    candidate: Candidate,
    y: Mapping[str, np.ndarray],
    base: Mapping[str, np.ndarray],
    additions: Mapping[str, np.ndarray],
    scale: Mapping[str, float],
    rows: np.ndarray | None,
    build: _Builds,
    *,
    uncertainties: bool = True,
) -> TermFit:
    """:func:`fit_term` with the candidate's regressors from `build`; without `uncertainties`, none are computed.

    `rows` None: all samples, read in place (the same numbers as ``arange(n)`` gives, without the copies).
    """
    n = next(iter(y.values())).size
    count = n if rows is None else rows.size

    def take(a: np.ndarray) -> np.ndarray:
        return a if rows is None else a[rows]

    costs: list[float] = []
    fits: list[tuple[float, dict[str, np.ndarray]]] = []
    kept = {o: take(y[o]) - take(additions[o]) for o in candidate.outputs}  # what the term and the base must explain
    targets = {o: kept[o] - take(base[o]) for o in candidate.outputs}
    if candidate.kind == "transform":
        for value in candidate.grid:
            built = build(value)
            cost = 0.0
            for o in candidate.outputs:
                cost += float(np.sum((kept[o] - take(built[o])) ** 2)) / scale[o]
            costs.append(cost)
            fits.append((value, {}))
    else:
        for first in range(0, len(candidate.grid), _CHUNK):
            for value, coefficients, cost in _linear_fits(
                candidate.grid[first : first + _CHUNK], build, take, targets, scale, candidate.outputs
            ):
                costs.append(cost)
                fits.append((value, coefficients))
    best = int(np.argmin(costs))
    value, coefficients = fits[best]
    covariance: dict[str, np.ndarray] = {}
    spread = float("nan")
    if uncertainties:
        if candidate.kind == "linear":  # the covariance of the chosen grid value's coefficients only
            built = build(value)
            for o in candidate.outputs:
                z = np.ascontiguousarray(take(built[o]))
                covariance[o] = _covariance(z, targets[o] - z @ coefficients[o])
        spread = _grid_spread(
            np.asarray(candidate.grid), np.asarray(costs), best, count, candidate, y, base, scale, build
        )
        if np.isfinite(spread) and len(candidate.grid) > 1:  # never finer than the grid can tell
            spread = max(spread, float(np.median(np.diff(candidate.grid))) / np.sqrt(12.0))
    return TermFit(
        candidate=candidate, value=value, coefficients=coefficients, covariance=covariance, value_uncertainty=spread
    )


def _linear_fits(
    values: Sequence[float],
    build: _Builds,
    take: Callable[[np.ndarray], np.ndarray],
    targets: Mapping[str, np.ndarray],
    scale: Mapping[str, float],
    outputs: tuple[str, ...],
) -> list[tuple[float, dict[str, np.ndarray], float]]:
    """Per grid value of a linear term: its value, coefficients per output and weighted cost.

    The small normal equations of all `values` are judged and solved as stacks (numpy's linear algebra solves each
    matrix of a stack as it solves one alone: the same numbers, without a call per value).
    """
    columns: dict[str, list[np.ndarray]] = {o: [] for o in outputs}
    for value in values:
        built = build(value)
        for o in outputs:
            columns[o].append(np.ascontiguousarray(take(built[o])))
    solved = {o: _least_squares_each(columns[o], targets[o]) for o in outputs}
    out = []
    for j, value in enumerate(values):
        cost = 0.0
        for o in outputs:
            residual = targets[o] - columns[o][j] @ solved[o][j]
            cost += float(np.sum(residual**2)) / scale[o]
        out.append((value, {o: solved[o][j] for o in outputs}, cost))
    return out


def _least_squares_each(zs: list[np.ndarray], target: np.ndarray) -> list[np.ndarray]:
    """Coefficients minimising ``|target - z c|`` for every `z` of `zs` (each shape (n, k), one k).

    The normal equations where well conditioned (a few columns), else SVD.
    """
    grams = np.stack([z.T @ z for z in zs])
    rhs = np.stack([z.T @ target for z in zs])
    well = np.linalg.cond(grams) < 1e10
    out: list[np.ndarray] = [np.empty(0)] * len(zs)
    if well.any():
        for j, c in zip(np.flatnonzero(well), np.linalg.solve(grams[well], rhs[well][..., None])[..., 0]):
            out[j] = c
    for j in np.flatnonzero(~well):
        out[j] = np.asarray(np.linalg.lstsq(zs[j], target, rcond=None)[0])
    return out


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
    build: _Builds,
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
    built = build(float(grid[best]))
    residual = (y[first] - (built[first] if candidate.kind == "transform" else base[first])) / np.sqrt(scale[first])
    inflation = residual.size / max(effective_samples(residual), 1.0)
    return float(np.sqrt(2.0 * max(per_sample, 1e-12) * inflation / curvature))
