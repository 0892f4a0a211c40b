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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Accuracy", "accuracy"]

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
    # scale to unit diagonal before inverting: parameters differ by orders of magnitude
    scale = np.where(diagonal > 0, 1.0 / np.sqrt(np.maximum(diagonal, 1e-300)), 0.0)
    scaled = hessian * scale[:, None] * scale[None, :]
    eigenvalues, vectors = np.linalg.eigh(scaled)
    keep = eigenvalues > _NULL * max(float(eigenvalues.max()), 1e-300)
    inverse = (vectors[:, keep] / eigenvalues[keep]) @ vectors[:, keep].T
    covariance = inverse * scale[:, None] * scale[None, :]
    null = np.any(np.abs(vectors[:, ~keep]) > 1e-6, axis=1) | (diagonal <= 0)
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
