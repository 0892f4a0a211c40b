"""Parameter accuracy from the cost Hessian: Cramér–Rao bounds, insensitivities, correlations.

Following Tischler & Remple (ch. 11), the Hessian of the frequency-response
cost is approximated from first derivatives (Gauss–Newton) and taken as the
Fisher information matrix::

    H = sum_l 20/n_omega sum_omega W_gamma [W_g (d|T|/dtheta)^T (d|T|/dtheta)
                                          + W_p (d<T/dtheta)^T (d<T/dtheta)]

(magnitude in dB, phase in deg), i.e. ``H = J_r^T J_r`` for the weighted
residual vector ``r`` whose sum of squares is the cost J of eq. 3.9. Then::

    CR_i = sqrt((H^-1)_ii)          Cramér–Rao bound (all other parameters free)
    I_i  = 1 / sqrt(H_ii)           insensitivity (all other parameters held)

each reported as a percentage of ``|theta_i|`` and judged against the CR%
and I% limits of :class:`~sysid.fit.guidelines.Guidelines`. ``H`` is
written as Tischler & Remple write it, without the factor 2 of the exact
Gauss–Newton Hessian of J (``2 J_r^T J_r``); with that factor every CR and
I would be smaller by sqrt(2). The choice is ours
where the book's normalisation could not be checked, and it is the more
conservative one.

That bound carries random error only. :func:`robust_bounds` raises it to the
residual's own sandwich bound where that is larger (a residual bigger than
the weights assume, or one that runs over neighbouring frequencies), and
:func:`with_spread` adds a further standard deviation in quadrature (the
fit range's spread, step 1's uncertainty carried into the wind step); see
:mod:`sysid.fit.bias`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import cast

import numpy as np
from scipy.fft import next_fast_len

__all__ = ["Accuracy", "accuracy", "correlated_lags", "robust_bounds", "with_spread"]

_NULL = 1e-12  # eigenvalues of H below this fraction of the largest are taken as unidentifiable directions


@dataclass(frozen=True, slots=True, kw_only=True)
class Accuracy:
    """Accuracy metrics of a set of estimated parameters.

    Parameters
    ----------
    names : tuple of str
        Parameter names, in order.
    values : ndarray, shape (n_par,)
        Estimates.
    hessian : ndarray, shape (n_par, n_par)
        ``J_r^T J_r``.
    cramer_rao : ndarray, shape (n_par,)
        CR bounds, in the parameters' units (``inf`` when not identifiable).
    insensitivity : ndarray, shape (n_par,)
        Insensitivities, in the parameters' units.
    correlation : ndarray, shape (n_par, n_par)
        Correlation matrix from ``H^-1`` (NaN rows for unidentifiable parameters).
    """

    names: tuple[str, ...]
    values: np.ndarray
    hessian: np.ndarray
    cramer_rao: np.ndarray
    insensitivity: np.ndarray
    correlation: np.ndarray

    def __post_init__(self) -> None:
        n = len(self.names)
        for name, shape in (
            ("values", (n,)),
            ("hessian", (n, n)),
            ("cramer_rao", (n,)),
            ("insensitivity", (n,)),
            ("correlation", (n, n)),
        ):
            if np.shape(getattr(self, name)) != shape:
                raise ValueError(f"{name} has shape {np.shape(getattr(self, name))}, expected {shape}")

    @property
    def cramer_rao_percent(self) -> np.ndarray:
        """CR bounds as % of ``|value|`` (``inf`` for a zero value), shape (n_par,)."""
        return _percent(self.cramer_rao, self.values)

    @property
    def insensitivity_percent(self) -> np.ndarray:
        """Insensitivities as % of ``|value|``, shape (n_par,)."""
        return _percent(self.insensitivity, self.values)


def _percent(spread: np.ndarray, values: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        out = 100.0 * spread / np.abs(values)
    return np.where(np.isnan(out), np.inf, out)


def accuracy(jacobian: np.ndarray, values: np.ndarray, names: tuple[str, ...]) -> Accuracy:
    """CR bounds, insensitivities and correlations from the residual Jacobian.

    Parameters
    ----------
    jacobian : ndarray, shape (n_residuals, n_par)
        Derivatives of the weighted residual vector of eq. 3.9.
    values : ndarray, shape (n_par,)
        Parameter estimates.
    names : tuple of str
        Parameter names.

    Returns
    -------
    Accuracy

    Examples
    --------
    >>> acc = accuracy(np.array([[2.0, 0.0], [0.0, 0.5]]), np.array([1.0, 10.0]), ("a", "b"))
    >>> acc.cramer_rao_percent.tolist(), acc.insensitivity_percent.tolist()
    ([50.0, 20.0], [50.0, 20.0])
    """
    jacobian = np.asarray(jacobian, dtype=float)
    values = np.asarray(values, dtype=float)
    hessian = jacobian.T @ jacobian
    n = values.size
    diagonal = np.diag(hessian).copy()
    with np.errstate(divide="ignore"):
        insensitivity = np.where(diagonal > 0, 1.0 / np.sqrt(np.maximum(diagonal, 1e-300)), np.inf)
    if n == 0:
        return Accuracy(
            names=names,
            values=values,
            hessian=hessian,
            cramer_rao=np.zeros(0),
            insensitivity=np.zeros(0),
            correlation=np.zeros((0, 0)),
        )
    covariance, null = _inverse(hessian)
    cramer_rao = np.where(null, np.inf, np.sqrt(np.maximum(np.diag(covariance), 0.0)))
    with np.errstate(divide="ignore", invalid="ignore"):
        sd = np.sqrt(np.diag(covariance))
        correlation = covariance / sd[:, None] / sd[None, :]
    correlation[null, :] = np.nan
    correlation[:, null] = np.nan
    return Accuracy(
        names=names,
        values=values,
        hessian=hessian,
        cramer_rao=cramer_rao,
        insensitivity=insensitivity,
        correlation=correlation,
    )


def robust_bounds(acc: Accuracy, jacobian: np.ndarray, residual: np.ndarray, series: Sequence[np.ndarray]) -> Accuracy:
    """`acc` with each Cramér–Rao bound raised to the residual's sandwich bound where that is the larger.

    Tischler's bound takes every weighted residual for an independent error
    of unit size. A fit whose residual is larger, or keeps one sign over
    many neighbouring frequencies (a model that cannot follow part of the
    band: in closed loop the position loop's pull at the bottom of the fit
    range), measures its parameters less well than that. The sandwich
    (Huber-White, with Newey-West's Bartlett weights between neighbouring
    points of one series)::

        C = H^-1 (sum_s sum_{k,l in s} (1 - |k - l| / (L_s + 1)) g_k g_l^T) H^-1,   g_k = r_k dr_k/dtheta

    measures it from the residual itself; ``L_s`` is the last lag at which the
    series' residual autocorrelation is still at or above 0.05
    (:func:`correlated_lags`, the wind step's rule in the time domain).

    Parameters
    ----------
    acc : Accuracy
        Tischler's accuracy of the fit (:func:`accuracy` of `jacobian`).
    jacobian : ndarray, shape (n_residuals, n_par)
        Derivatives of the weighted residual vector.
    residual : ndarray, shape (n_residuals,)
        The weighted residual at the estimate.
    series : sequence of ndarray of int
        Indices into `residual` of each series of neighbouring points, in
        frequency order (a response's magnitude, its phase).

    Returns
    -------
    Accuracy
        `acc` with ``cramer_rao = max(cramer_rao, sandwich)``; the Hessian,
        insensitivities and correlations unchanged.

    Examples
    --------
    A residual of twice the unit size doubles the bounds; one of half, none.

    >>> jac = np.array([[1.0], [1.0], [1.0], [1.0]])
    >>> base = accuracy(jac, np.array([1.0]), ("a",))
    >>> series = [np.arange(4)]
    >>> float(robust_bounds(base, jac, 2.0 * np.array([1.0, -1.0, 1.0, -1.0]), series).cramer_rao[0] / base.cramer_rao[0])
    2.0
    >>> float(robust_bounds(base, jac, 0.5 * np.array([1.0, -1.0, 1.0, -1.0]), series).cramer_rao[0] / base.cramer_rao[0])
    1.0
    """
    if acc.names == ():
        return acc
    covariance, null = _inverse(acc.hessian)
    scores = np.asarray(jacobian, dtype=float) * np.asarray(residual, dtype=float)[:, None]
    meat = np.zeros_like(covariance)
    for rows in series:
        g, n = scores[rows], len(rows)
        bandwidth = max(correlated_lags(np.asarray(residual, dtype=float)[rows]).size - 1, 0)
        for lag in range(min(bandwidth, n - 1) + 1):
            product = g[lag:].T @ g[: n - lag]
            meat += (1.0 - lag / (bandwidth + 1.0)) * (product if lag == 0 else product + product.T)
    sandwich = np.sqrt(np.maximum(np.diag(covariance @ meat @ covariance), 0.0))
    return replace(acc, cramer_rao=np.where(null, np.inf, np.maximum(acc.cramer_rao, sandwich)))


def with_spread(acc: Accuracy, spread: Mapping[str, float]) -> Accuracy:
    """`acc` with each parameter's Cramér–Rao bound and `spread` added in quadrature.

    Parameters
    ----------
    acc : Accuracy
        An accuracy.
    spread : Mapping[str, float]
        Further standard deviations, by name, in the parameters' units.

    Returns
    -------
    Accuracy
    """
    extra = np.array([spread.get(n, 0.0) for n in acc.names])
    return replace(acc, cramer_rao=np.sqrt(acc.cramer_rao**2 + extra**2))


def _inverse(hessian: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``H^-1`` (pseudo-inverse over the identifiable directions) and which parameters lie in a null direction."""
    diagonal = np.diag(hessian).copy()
    # scale to unit diagonal before inverting: parameters differ by orders of magnitude
    scale = np.where(diagonal > 0, 1.0 / np.sqrt(np.maximum(diagonal, 1e-300)), 0.0)
    scaled = hessian * scale[:, None] * scale[None, :]
    eigenvalues, vectors = np.linalg.eigh(scaled)
    keep = eigenvalues > _NULL * max(float(eigenvalues.max()), 1e-300)
    inverse = (vectors[:, keep] / eigenvalues[keep]) @ vectors[:, keep].T
    null = np.any(np.abs(vectors[:, ~keep]) > 1e-6, axis=1) | (diagonal <= 0)
    return inverse * scale[:, None] * scale[None, :], null


def correlated_lags(residual: np.ndarray) -> np.ndarray:
    """A residual series' normalised autocorrelation, from lag 0 while it stays at or above 0.05.

    The one rule for how far a residual's errors run together: the time-domain
    inflation of the wind step (:func:`sysid.fit.wind.residual_inflation`) and
    the sandwich's bandwidth (:func:`robust_bounds`).

    Parameters
    ----------
    residual : ndarray, shape (n,)
        The residual, in order (time or frequency).

    Returns
    -------
    ndarray, shape (n_lags,)
        ``rho_0 = 1, rho_1, ...`` up to the lag before the first below 0.05; empty for a constant residual.

    Examples
    --------
    >>> correlated_lags(np.array([1.0, -1.0, 1.0, -1.0])).tolist()
    [1.0]
    """
    centred = residual - residual.mean()
    size = next_fast_len(2 * centred.size - 1, real=True)  # a 5-smooth length: 2 n may be a large prime's multiple
    acf = np.fft.irfft(np.abs(np.fft.rfft(centred, size)) ** 2, size)[: centred.size]
    rho = acf / acf[0] if acf[0] > 0 else np.zeros(1)
    cut = int(np.argmax(rho < 0.05)) if np.any(rho < 0.05) else rho.size
    return cast(np.ndarray, rho[:cut])
