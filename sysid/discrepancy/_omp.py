"""Orthogonal matching pursuit on a Gram matrix, with its whole forward path: scikit-learn's, without its import.

A port of ``sklearn.linear_model.orthogonal_mp_gram(gram, xy, n_nonzero_coefs=k, return_path=True)`` for one
target vector (its ``_gram_omp``: the Cholesky factor of the active columns' Gram matrix grown one row a step, the
columns swapped to the front as they are chosen), so that the model of the unknown (:mod:`sysid.discrepancy.generic`)
does not import ``sklearn.linear_model``, a second and more beyond scipy for an algorithm of forty lines. The same
BLAS and LAPACK calls in the same order (``nrm2``, ``trtrs`` through :func:`scipy.linalg.solve_triangular`, ``potrs``,
the matrix-vector product on the Fortran-ordered Gram matrix), so the path is scikit-learn's bit for bit on the same
BLAS; the test (``tests/sysid/discrepancy/test_omp.py``) holds it to scikit-learn's to rounding.

Ported from scikit-learn 1.9 ``sklearn/linear_model/_omp.py`` (BSD-3-Clause, the scikit-learn developers).
"""

from __future__ import annotations

from math import sqrt

import numpy as np
from scipy.linalg import get_blas_funcs, get_lapack_funcs, solve_triangular

__all__ = ["omp_gram_path"]


def omp_gram_path(gram: np.ndarray, xy: np.ndarray, *, n_nonzero_coefs: int) -> np.ndarray:
    """The coefficients of orthogonal matching pursuit after each of its first `n_nonzero_coefs` steps.

    Each step chooses the column whose correlation with the residual is largest in magnitude and refits all the
    chosen columns by least squares (normal equations through the updated Cholesky factor); all from ``X'X`` and
    ``X'y`` alone.

    Parameters
    ----------
    gram : ndarray, shape (n_features, n_features)
        The Gram matrix ``X'X`` of the columns (symmetric, positive semi-definite); not modified.
    xy : ndarray, shape (n_features,)
        The columns' products with the target, ``X'y``; not modified.
    n_nonzero_coefs : int
        Most columns to choose, 1 to ``n_features``.

    Returns
    -------
    ndarray, shape (n_features, n_steps)
        Column ``k`` holds the coefficients of every column after step ``k + 1`` (zero for those not yet chosen).
        ``n_steps`` is `n_nonzero_coefs` unless the path ends early (see Notes). scikit-learn squeezes its
        ``(n_features, 1, n_steps)`` result; this is that result reshaped to ``(n_features, -1)``.

    Raises
    ------
    ValueError
        `gram` not square or not finite, `xy` of another length, `n_nonzero_coefs` outside
        ``1 .. n_features`` (as scikit-learn refuses them); a first chosen column of negative squared norm
        (``math.sqrt``'s domain error, as in scikit-learn).

    Notes
    -----
    The path ends early, with fewer steps than asked for, where scikit-learn warns "Orthogonal matching pursuit
    ended prematurely due to linear dependence in the dictionary": when the column chosen next is one already
    chosen, when its correlation's square is below the machine epsilon (the target is fitted), or when its
    squared distance from the span of those chosen, the new Cholesky pivot, is at most the machine epsilon
    (colinear columns). No warning is given here: the path's length says it.

    Computed in float64. Rubinstein, Zibulevsky and Elad, *Efficient implementation of the K-SVD algorithm using
    batch orthogonal matching pursuit*, Technion CS-2008-08 (2008).

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 1.0], [0.0, 0.0, 1.0], [1.0, 1.0, 0.0]])
    >>> y = x @ np.array([0.0, 2.0, 0.5])
    >>> omp_gram_path(x.T @ x, x.T @ y, n_nonzero_coefs=3).round(6)  # fitted after two steps: the path ends
    array([[0.  , 0.  ],
           [2.25, 2.  ],
           [0.  , 0.5 ]])
    """
    gram = np.array(gram, dtype=float, order="F")  # a copy: scikit-learn's copy_Gram=True
    xy = np.array(xy, dtype=float)  # a copy: its copy_Xy=True
    n_features = gram.shape[0] if gram.ndim == 2 else -1
    if gram.ndim != 2 or gram.shape[1] != n_features:
        raise ValueError(f"gram of shape {gram.shape} must be square")
    if not np.all(np.isfinite(gram)):
        raise ValueError("gram must be finite (it holds NaN or infinity)")
    if xy.shape != (n_features,):
        raise ValueError(f"xy of shape {xy.shape} must be ({n_features},), one value per column of gram")
    if not 1 <= n_nonzero_coefs <= n_features:
        raise ValueError(f"{n_nonzero_coefs=} must be 1 .. {n_features} (the number of columns)")
    steps, order = _gram_omp(gram, xy, n_nonzero_coefs)
    path = np.zeros((n_features, steps.shape[1]))
    for k in range(steps.shape[1]):  # the first k + 1 of `order` never move after step k
        path[order[: k + 1], k] = steps[: k + 1, k]
    return path


def _gram_omp(gram: np.ndarray, xy: np.ndarray, n_nonzero_coefs: int) -> tuple[np.ndarray, np.ndarray]:
    """scikit-learn's ``_gram_omp`` with ``tol=None`` and ``return_path=True``, on arrays it may overwrite.

    Parameters
    ----------
    gram : ndarray, shape (n_features, n_features)
        The Gram matrix, Fortran-ordered; its rows and columns are swapped as columns are chosen.
    xy : ndarray, shape (n_features,)
        ``X'y``, swapped with them.
    n_nonzero_coefs : int
        Most steps.

    Returns
    -------
    steps : ndarray, shape (n_nonzero_coefs, n_steps)
        The first ``k + 1`` rows of column ``k``: the coefficients of the chosen columns after step ``k + 1``, in
        the order chosen (the rest is garbage).
    order : ndarray of int, shape (n_features,)
        The original index of each column after the swaps; the first ``n_steps`` are the chosen ones, in order.
    """
    eps = np.finfo(gram.dtype).eps
    (nrm2,) = get_blas_funcs(("nrm2",), (gram,))
    (potrs,) = get_lapack_funcs(("potrs",), (gram,))
    order = np.arange(gram.shape[0])
    chol = np.empty((n_nonzero_coefs, n_nonzero_coefs))  # the lower Cholesky factor of the chosen columns' Gram
    steps = np.empty_like(chol)
    alpha = xy  # the columns' correlation with the residual
    n_active = 0
    while n_active < n_nonzero_coefs:
        lam = int(np.argmax(np.abs(alpha)))
        if lam < n_active or alpha[lam] ** 2 < eps:  # chosen twice, or the target fitted
            break
        if n_active > 0:
            row = solve_triangular(chol[:n_active, :n_active], gram[lam, :n_active], lower=True, check_finite=False)
            pivot = gram[lam, lam] - nrm2(row) ** 2
            if pivot <= eps:  # colinear with those chosen
                break
            chol[n_active, :n_active] = row
            chol[n_active, n_active] = sqrt(pivot)
        else:
            chol[0, 0] = sqrt(gram[lam, lam])
        swap = [lam, n_active]
        gram[[n_active, lam]] = gram[swap]
        gram[:, [n_active, lam]] = gram[:, swap]
        order[[n_active, lam]] = order[swap]
        xy[[n_active, lam]] = xy[swap]
        n_active += 1
        gamma, _ = potrs(chol[:n_active, :n_active], xy[:n_active], lower=True, overwrite_b=False)
        steps[:n_active, n_active - 1] = gamma
        alpha = xy - np.dot(gram[:, :n_active], gamma)
    return steps[:, :n_active], order
