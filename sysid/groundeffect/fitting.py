"""Fit the ground-effect families of eqs. 2.1-2.5 to F/F0 against Z/R, and pick one.

Families and their free parameters:

===================== ============================ ===========================================
name                  law                          free parameters
===================== ============================ ===========================================
``cheeseman_bennett`` eq. 2.1                      none
``corrected``         eq. 2.2                      rho
``exponential``       eq. 2.3                      a, b
``piecewise_linear``  eq. 2.5's form, continuous   slope, breakpoint (intercept = 1 - slope bp)
===================== ============================ ===========================================

The piecewise-linear law is constrained, as eq. 2.5 is (to 2e-4), to be
continuous and equal to 1 from the breakpoint on: F/F0 = 1 + slope (Z/R - bp)
below bp. Its intercept is reported with its confidence interval by the delta
method. The cost is not smooth in the breakpoint (it kinks at every data
point), so the breakpoint is profiled: for each breakpoint the slope is a
linear least-squares solution; a grid from the smallest Z/R of the data to
one data span past the largest is searched and the best cell refined by
bounded scalar minimisation.

Other families are fitted by nonlinear least squares
(:func:`scipy.optimize.least_squares`, trust-region reflective, with bounds
that keep eq. 2.2 finite over the data). Confidence intervals come from the
covariance s^2 (J^T J)^-1 at the optimum with Student's t on n - p degrees of
freedom. RMSE is sqrt(RSS / (n - p)), the residual standard error as curve
fitting tools report it (Tables 2.2-2.3). Selection uses AICc (default) or
BIC, with k = p + 1 (the noise variance counted).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import cast

import numpy as np
from scipy import optimize, stats

from flightlogs.errors import FitError, FitWarning, collected_warnings
from sysid.groundeffect import formulas
from sysid.groundeffect.models import (
    MODEL_NAMES,
    PARAMETER_NAMES,
    Criterion,
    GroundEffectFit,
    ModelFit,
    ModelName,
    evaluate_model,
)
from sysid.groundeffect.records import ThrustRatioData

__all__ = ["FitConfig", "fit_ground_effect", "fit_model"]

_GRID = 400


@dataclass(frozen=True, slots=True, kw_only=True)
class FitConfig:
    """Which families to fit and how to choose among them.

    Parameters
    ----------
    models : tuple of str
        Families to fit (default all four).
    criterion : {"aicc", "bic"}
        Selection criterion: corrected Akaike or Bayesian information.
    confidence : float
        Level of the parameter confidence intervals (0 < level < 1).
    """

    models: tuple[ModelName, ...] = MODEL_NAMES
    criterion: Criterion = "aicc"
    confidence: float = 0.95

    def __post_init__(self) -> None:
        unknown = [m for m in self.models if m not in MODEL_NAMES]
        if unknown or not self.models:
            raise ValueError(f"models={self.models} must be a non-empty subset of {MODEL_NAMES}")
        if self.criterion not in ("aicc", "bic"):
            raise ValueError(f"criterion={self.criterion!r} must be 'aicc' or 'bic'")
        if not 0 < self.confidence < 1:
            raise ValueError(f"confidence={self.confidence} must lie in (0, 1)")


def fit_ground_effect(data: ThrustRatioData, config: FitConfig | None = None) -> GroundEffectFit:
    """Fit each family to F/F0 against Z/R and choose by information criterion.

    Parameters
    ----------
    data : ThrustRatioData
        The points.
    config : FitConfig, optional
        Families, criterion, confidence level.

    Returns
    -------
    GroundEffectFit

    Raises
    ------
    FitError
        If there are fewer than three points or no family can be chosen.

    Warns
    -----
    FitWarning
        For each note on the family chosen, named (``"piecewise_linear:
        breakpoint ... extrapolated"``). The notes on the other families stay
        in their :class:`ModelFit` only: a family not chosen is no caveat on
        the result.

    Examples
    --------
    >>> x = np.linspace(1.2, 9.0, 30)
    >>> y = formulas.piecewise_linear(x, -0.0373, 1.1651, 4.42) + 0.002 * np.sin(7 * x)
    >>> fit = fit_ground_effect(ThrustRatioData(height_ratio=x, thrust_ratio=y, rotor_radius_m=0.0225))
    >>> fit.best, round(fit.model("piecewise_linear").params["slope"], 3)
    ('piecewise_linear', -0.037)
    """
    config = config or FitConfig()
    if data.n_points < 3:
        what = "hover steps near the ground were found" if data.steps is not None else "points were given"
        if data.n_points == 1:
            what = what.replace("steps", "step").replace("points", "point").replace("were", "was")
        raise FitError(f"{data.source or 'data'}: {data.n_points} {what}; at least 3 are needed to fit")
    with collected_warnings() as caught:
        fits = tuple(
            fit_model(name, data.height_ratio, data.thrust_ratio, confidence=config.confidence)
            for name in config.models
        )
        caught.discard()  # kept in each family's notes; those of the family chosen are raised below
    scores = np.array([f.criterion(config.criterion) for f in fits])
    scores = np.where(np.isnan(scores), np.inf, scores)  # -inf (an exact fit) stays the best
    if np.all(scores == np.inf):
        raise FitError(
            f"{data.source or 'data'}: {data.n_points} points are too few for {config.criterion} "
            f"to compare {', '.join(config.models)}"
        )
    best = fits[int(np.argmin(scores))]
    for note in best.notes:
        warnings.warn(FitWarning(f"{best.name}: {note}"), stacklevel=2)
    return GroundEffectFit(
        data=data, models=fits, best=best.name, criterion=config.criterion, confidence=config.confidence
    )


def fit_model(name: str, height_ratio: np.ndarray, thrust_ratio: np.ndarray, *, confidence: float = 0.95) -> ModelFit:
    """Fit one family by least squares, with confidence intervals and goodness of fit.

    Parameters
    ----------
    name : {"cheeseman_bennett", "corrected", "exponential", "piecewise_linear"}
        The family.
    height_ratio : ndarray, shape (n_points,)
        Z/R.
    thrust_ratio : ndarray, shape (n_points,)
        F/F0.
    confidence : float, optional
        Level of the intervals.

    Returns
    -------
    ModelFit
        With ``notes``: the messages of the warnings below.

    Warns
    -----
    FitWarning
        When the optimiser does not converge, a parameter ends at a bound of
        its range, the breakpoint is not identified or extrapolated, or the
        covariance is singular.

    Examples
    --------
    >>> x = np.linspace(1.1, 9.0, 20)
    >>> round(fit_model("corrected", x, formulas.corrected(x, 3.315)).params["rho"], 6)
    3.315
    """
    x = np.asarray(height_ratio, dtype=np.float64)
    y = np.asarray(thrust_ratio, dtype=np.float64)
    if name not in _FITTERS:
        raise ValueError(f"unknown ground-effect model {name!r}; choose from {MODEL_NAMES}")
    with collected_warnings() as caught:
        free, jacobian = _FITTERS[name](x, y)
        fit = _summarise(name, x, y, free, jacobian, confidence)
    return replace(fit, notes=caught.messages)


# --------------------------------------------------------------------------- the families

_Fitted = tuple[np.ndarray, np.ndarray]  # free parameters, Jacobian (n, p)


def _fit_cheeseman_bennett(x: np.ndarray, y: np.ndarray) -> _Fitted:
    return np.zeros(0), np.zeros((x.size, 0))


def _fit_corrected(x: np.ndarray, y: np.ndarray) -> _Fitted:
    u = 1.0 / (16.0 * x * x)
    upper = float(np.min(1.0 / u)) * (1.0 - 1e-6)  # keeps 1 - rho u > 0 at every point
    start = float(np.clip(np.dot(u, 1.0 - 1.0 / y) / np.dot(u, u), -upper, upper * 0.999))  # linearised

    def residual(p: np.ndarray) -> np.ndarray:
        return cast(np.ndarray, formulas.corrected(x, p[0]) - y)

    def jac(p: np.ndarray) -> np.ndarray:
        return cast(np.ndarray, (u * formulas.corrected(x, p[0]) ** 2)[:, None])

    result = optimize.least_squares(residual, [start], jac=jac, bounds=([-np.inf], [upper]), method="trf")
    _warn_unconverged(result)
    if result.x[0] > upper * 0.999:
        warnings.warn(FitWarning("rho at the bound where eq. 2.2 diverges at the lowest point"), stacklevel=2)
    return result.x, jac(result.x)


def _fit_exponential(x: np.ndarray, y: np.ndarray) -> _Fitted:
    """Eq. 2.3: for a fixed decay length b, a is linear; b is profiled on a log grid, then both polished."""
    r = y - 1.0
    span = float(np.ptp(x)) or 1.0
    bounds = ([-np.inf, 1e-3 * span], [np.inf, 100.0 * span])

    def linear_fit(b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        e = np.exp(-x[None, :] / np.atleast_1d(b)[:, None])
        ee, er = np.einsum("gn,gn->g", e, e), e @ r
        safe = np.where(ee > 0, ee, 1.0)
        return np.where(ee > 0, er / safe, 0.0), float(r @ r) - np.where(ee > 0, er * er / safe, 0.0)

    b0 = _profile(
        lambda b: float(linear_fit(np.array(b))[1][0]),
        lambda g: linear_fit(g)[1],
        np.geomspace(bounds[0][1], bounds[1][1], 120),
    )
    a0 = float(linear_fit(np.array(b0))[0][0])

    def residual(p: np.ndarray) -> np.ndarray:
        return cast(np.ndarray, formulas.exponential(x, p[0], p[1]) - y)

    def jac(p: np.ndarray) -> np.ndarray:
        e = np.exp(-x / p[1])
        return np.column_stack([e, p[0] * e * x / p[1] ** 2])

    result = optimize.least_squares(residual, [a0, b0], jac=jac, bounds=bounds, method="trf")
    _warn_unconverged(result)
    if result.x[1] >= bounds[1][1] * 0.999 or result.x[1] <= bounds[0][1] * 1.001:
        warnings.warn(FitWarning("decay length b at a bound of its search range"), stacklevel=2)
    return result.x, jac(result.x)


def _fit_piecewise_linear(x: np.ndarray, y: np.ndarray) -> _Fitted:
    """Continuous piecewise linear: for a fixed breakpoint the slope is linear; the breakpoint is profiled."""
    r = y - 1.0
    lo, hi = float(x.min()), float(x.max())
    hi_bp = hi + (hi - lo)  # a breakpoint past the data is an extrapolation of the line to F/F0 = 1

    def linear_fit(bp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d = np.minimum(x[None, :] - np.atleast_1d(bp)[:, None], 0.0)
        dd, dr = np.einsum("gn,gn->g", d, d), d @ r
        safe = np.where(dd > 0, dd, 1.0)
        return np.where(dd > 0, dr / safe, 0.0), float(r @ r) - np.where(dd > 0, dr * dr / safe, 0.0)

    bp = _profile(
        lambda b: float(linear_fit(np.array(b))[1][0]),
        lambda g: linear_fit(g)[1],
        np.union1d(np.linspace(lo, hi_bp, _GRID), x),
    )
    slope = float(linear_fit(np.array(bp))[0][0])
    below = int(np.sum(x < bp))
    if below < 2:
        message = f"breakpoint {bp:.3g} leaves {below} of {x.size} points below it: not identified by the data"
        warnings.warn(FitWarning(message), stacklevel=2)
    elif bp >= hi:
        message = f"breakpoint {bp:.3g} lies past the largest Z/R {hi:.3g}: extrapolated, the data show no plateau"
        warnings.warn(FitWarning(message), stacklevel=2)
    jacobian = np.column_stack([np.minimum(x - bp, 0.0), np.where(x < bp, -slope, 0.0)])
    return np.array([slope, bp]), jacobian


def _warn_unconverged(result: optimize.OptimizeResult) -> None:
    if not result.success:
        warnings.warn(FitWarning(f"optimiser: {result.message}"), stacklevel=2)


def _profile(cost: Callable[[float], float], costs: Callable[[np.ndarray], np.ndarray], grid: np.ndarray) -> float:
    """The grid point of least cost, refined by bounded scalar minimisation between its neighbours."""
    values = costs(grid)
    i = int(np.argmin(values))
    left, right = float(grid[max(i - 1, 0)]), float(grid[min(i + 1, grid.size - 1)])
    best, best_cost = float(grid[i]), float(values[i])
    if right > left:
        refined = optimize.minimize_scalar(
            cost, bounds=(left, right), method="bounded", options={"xatol": 1e-10 * max(1.0, abs(right))}
        )
        if refined.fun < best_cost:
            best = float(refined.x)
    return best


_FITTERS: dict[str, Callable[[np.ndarray, np.ndarray], _Fitted]] = {
    "cheeseman_bennett": _fit_cheeseman_bennett,
    "corrected": _fit_corrected,
    "exponential": _fit_exponential,
    "piecewise_linear": _fit_piecewise_linear,
}


# --------------------------------------------------------------------------- statistics


def _summarise(
    name: str, x: np.ndarray, y: np.ndarray, free: np.ndarray, jacobian: np.ndarray, confidence: float
) -> ModelFit:
    """Values, covariance, intervals and goodness of fit of a fitted family (its notes left empty)."""
    n, p = x.size, free.size
    values = free if name != "piecewise_linear" else np.array([free[0], 1.0 - free[0] * free[1], free[1]])
    residuals = y - evaluate_model(name, values, x)
    rss = float(np.dot(residuals, residuals))
    dof = n - p
    covariance = _covariance(jacobian, rss / dof if dof > 0 else math.nan)
    if name == "piecewise_linear":  # intercept = 1 - slope bp, by the delta method
        gradient = np.array([[1.0, 0.0], [-free[1], -free[0]], [0.0, 1.0]])
        finite = bool(np.all(np.isfinite(covariance)))
        covariance = gradient @ covariance @ gradient.T if finite else np.full((3, 3), np.inf)
    stderr = np.sqrt(np.clip(np.diag(covariance), 0.0, None)) if p else np.zeros(0)
    t = float(stats.t.ppf(0.5 + confidence / 2, dof)) if dof > 0 else math.inf
    half = t * stderr
    tss = float(np.sum((y - y.mean()) ** 2))
    k = p + 1
    log_term = n * math.log(rss / n) if rss > 0 else -math.inf
    aicc = log_term + 2 * k + (2 * k * (k + 1) / (n - k - 1) if n - k - 1 > 0 else math.inf)
    bic = log_term + k * math.log(n)
    return ModelFit(
        name=name,
        param_names=PARAMETER_NAMES[name],
        values=values,
        stderr=stderr,
        ci_low=values - half,
        ci_high=values + half,
        n_free=p,
        residuals=residuals,
        rss=rss,
        rmse=math.sqrt(rss / dof) if dof > 0 else math.nan,
        r2=1.0 - rss / tss if tss > 0 else math.nan,
        aicc=aicc,
        bic=bic,
    )


def _covariance(jacobian: np.ndarray, variance: float) -> np.ndarray:
    """s^2 (J^T J)^-1; infinite where J^T J is singular."""
    p = jacobian.shape[1]
    if p == 0:
        return np.zeros((0, 0))
    information = jacobian.T @ jacobian
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        condition = np.linalg.cond(information)
    if not np.isfinite(condition) or condition > 1e14 or not np.isfinite(variance):
        warnings.warn(FitWarning("covariance singular: parameters not identified by the data"), stacklevel=2)
        return np.full((p, p), np.inf)
    return variance * np.linalg.inv(information)
