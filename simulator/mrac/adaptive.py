"""Regressors of the matched uncertainty (eqs. 2.21-2.25) and the adaptive law (eq. 2.19 = A.13)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, cast

import numpy as np

__all__ = ["Regressor", "adaptive_law", "lyapunov_function"]

RegressorKind = Literal["linear", "rbf"]


def _rbf_centres() -> tuple[float, ...]:
    return (0.0, 0.2, 0.4, 0.6, 0.8, 1.0)


@dataclass(frozen=True, slots=True)
class Regressor:
    """Basis functions Phi(z) of the height with which ``F(x) = Theta^T Phi(x)`` (eq. 2.16).

    Parameters
    ----------
    kind : {"linear", "rbf"}
        ``"linear"``: ``[z, 1]`` (eq. 2.21). ``"rbf"``: Gaussians
        ``exp(-eps^2 (z - c)^2)`` at each centre, then 1 (eqs. 2.23-2.24).
    centres_m : tuple of float
        RBF centres, heights above ground, m (chapter 2: 0, 0.2, ..., 1.0).
    epsilon_1_m : float
        RBF shape parameter eps, 1/m (chapter 2: 6.67).
    """

    kind: RegressorKind = "linear"
    centres_m: tuple[float, ...] = field(default_factory=_rbf_centres)
    epsilon_1_m: float = 6.67

    def __post_init__(self) -> None:
        if self.kind not in ("linear", "rbf"):
            raise ValueError(f"regressor kind {self.kind!r} must be 'linear' or 'rbf'")
        if self.kind == "rbf" and (not self.centres_m or self.epsilon_1_m <= 0):
            raise ValueError("an RBF regressor needs centres and epsilon_1_m > 0")
        object.__setattr__(self, "centres_m", tuple(float(c) for c in self.centres_m))

    @property
    def n_basis(self) -> int:
        """Number of basis functions (length of Theta)."""
        return 2 if self.kind == "linear" else len(self.centres_m) + 1

    @property
    def labels(self) -> tuple[str, ...]:
        """A name per basis function, for plots and tables."""
        if self.kind == "linear":
            return ("z", "1")
        return tuple(f"rbf({c:g} m)" for c in self.centres_m) + ("1",)

    def __call__(self, height_m: np.ndarray) -> np.ndarray:
        """Phi at each height.

        Parameters
        ----------
        height_m : ndarray, shape (n,)
            Height above ground, m.

        Returns
        -------
        ndarray, shape (n, n_basis)

        Examples
        --------
        >>> Regressor("linear")(np.array([0.05]))
        array([[0.05, 1.  ]])
        >>> np.round(Regressor("rbf")(np.array([0.2])), 3)
        array([[0.169, 1.   , 0.169, 0.001, 0.   , 0.   , 1.   ]])
        """
        z = np.asarray(height_m, dtype=np.float64).reshape(-1)
        ones = np.ones((z.size, 1))
        if self.kind == "linear":
            return np.column_stack([z, ones])
        centres = np.asarray(self.centres_m)
        return np.column_stack([np.exp(-(self.epsilon_1_m**2) * (z[:, None] - centres[None, :]) ** 2), ones])


def adaptive_law(phi: np.ndarray, error: np.ndarray, p_b: np.ndarray, gamma: np.ndarray | float) -> np.ndarray:
    """Rate of the estimates, ``Theta_hat' = Gamma Phi(x) e^T P B`` (eq. 2.19, eq. A.13), for a batch.

    Parameters
    ----------
    phi : ndarray, shape (n, n_basis)
        Regressor values.
    error : ndarray, shape (n, n_states)
        Tracking error ``e = x - x_ref``.
    p_b : ndarray, shape (n_states,)
        ``P B`` for a single input.
    gamma : ndarray, shape (n_basis, n_basis), or float
        Adaptation rate Gamma (a float means ``gamma * I``).

    Returns
    -------
    ndarray, shape (n, n_basis)

    Examples
    --------
    >>> adaptive_law(np.array([[0.5, 1.0]]), np.array([[0.1, 0.0]]), np.array([2.0, 0.0]), 1e-3)
    array([[0.0001, 0.0002]])
    """
    phi = np.atleast_2d(np.asarray(phi, dtype=np.float64))
    error = np.atleast_2d(np.asarray(error, dtype=np.float64))
    scale = error @ np.asarray(p_b, dtype=np.float64)
    weighted = phi * gamma if np.ndim(gamma) == 0 else phi @ np.asarray(gamma, dtype=np.float64).T
    return cast(np.ndarray, weighted * scale[:, None])


def lyapunov_function(
    error: np.ndarray, theta_error: np.ndarray, p: np.ndarray, gamma: np.ndarray | float
) -> np.ndarray:
    """``V = e^T P e + tr(dTheta^T Gamma^-1 dTheta)`` (eq. 2.18, eq. A.7), for a batch.

    Parameters
    ----------
    error : ndarray, shape (n, n_states)
        Tracking error.
    theta_error : ndarray, shape (n, n_basis)
        ``Theta_hat - Theta``.
    p : ndarray, shape (n_states, n_states)
        Solution of eq. A.8.
    gamma : ndarray, shape (n_basis, n_basis), or float
        Adaptation rate.

    Returns
    -------
    ndarray, shape (n,)
    """
    error = np.atleast_2d(np.asarray(error, dtype=np.float64))
    theta_error = np.atleast_2d(np.asarray(theta_error, dtype=np.float64))
    quadratic = np.einsum("ni,ij,nj->n", error, np.asarray(p, dtype=np.float64), error)
    if np.ndim(gamma) == 0:
        return quadratic + np.einsum("nk,nk->n", theta_error, theta_error) / float(gamma)  # type: ignore[no-any-return]
    inverse = np.linalg.inv(np.asarray(gamma, dtype=np.float64))
    return cast(np.ndarray, quadratic + np.einsum("ni,ij,nj->n", theta_error, inverse, theta_error))
