"""Exact zero-order-hold discretisation with fractional input delays.

An input held constant over each control period ``T`` and delayed by
``tau = n T + r`` (``0 <= r < T``) is, within period ``k``, the sample
``u[k-n-1]`` on ``[kT, kT + r)`` and ``u[k-n]`` on ``[kT + r, (k+1)T)``. The
state at ``kT + s`` (``0 < s <= T``) is therefore exactly::

    x(kT + s) = e^{As} x[k] + Pa(s) u[k-n-1] + Pb(s) u[k-n]
    Pa(s) = e^{A (s - min(s, r))} Gamma(min(s, r)) b,   Pb(s) = Gamma(max(s - r, 0)) b
    Gamma(t) = integral_0^t e^{A sigma} d sigma

(the modified z-transform), from the matrix exponential of the augmented
matrix ``[[A, b], [0, 0]]``. No numerical integration is involved. The
exponential is our own scaling-and-squaring Taylor series (:func:`expm`), exact
to rounding: :func:`scipy.linalg.expm` is equivalent but can take 10 ms per
call when OpenBLAS threads contend for a busy machine.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["DelayedInputMap", "expm", "propagator", "delayed_input_map"]

_TAYLOR_ORDER = 14  # with the scaled norm at most 1/4, the remainder is below 1e-19 of the result


def expm(M: np.ndarray) -> np.ndarray:
    """Matrix exponential by scaling and squaring of a Taylor series.

    Parameters
    ----------
    M : ndarray, shape (n, n)
        Square matrix.

    Returns
    -------
    ndarray, shape (n, n)
        ``e^M``.

    Examples
    --------
    >>> rotation = expm(np.array([[0.0, -np.pi / 2], [np.pi / 2, 0.0]]))
    >>> np.round(rotation, 12) + 0.0
    array([[ 0., -1.],
           [ 1.,  0.]])
    """
    norm = float(np.abs(M).sum(axis=0).max()) if M.size else 0.0
    squarings = max(0, int(np.ceil(np.log2(norm / 0.25)))) if norm > 0.25 else 0
    scaled = M / 2.0**squarings
    result = np.eye(M.shape[0]) + scaled
    term = scaled
    for k in range(2, _TAYLOR_ORDER + 1):
        term = term @ scaled / k
        result += term
    for _ in range(squarings):
        result = result @ result
    return result


def propagator(A: np.ndarray, B: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
    """``e^{At}`` and ``Gamma(t) B`` for a hold of length `t`.

    Parameters
    ----------
    A : ndarray, shape (n, n)
        State matrix, 1/s.
    B : ndarray, shape (n, m)
        Input matrix.
    t : float
        Hold length, s (≥ 0).

    Returns
    -------
    tuple of ndarray
        ``e^{At}`` of shape (n, n) and ``Gamma(t) B`` of shape (n, m).

    Examples
    --------
    >>> phi, gamma = propagator(np.array([[0.0]]), np.array([[1.0]]), 0.5)
    >>> float(phi[0, 0]), float(gamma[0, 0])
    (1.0, 0.5)
    """
    if t < 0.0:
        raise ValueError(f"{t=} s must be ≥ 0")
    n, m = A.shape[0], B.shape[1]
    block = np.zeros((n + m, n + m))
    block[:n, :n], block[:n, n:] = A, B
    full = expm(block * t)
    return full[:n, :n], full[:n, n:]


@dataclass(frozen=True, slots=True)
class DelayedInputMap:
    """How one delayed, held input enters the state over sub-steps of a control period.

    Parameters
    ----------
    n_periods : int
        Whole control periods in the delay, ``n``.
    remainder_s : float
        ``r = tau - n T``, s, in ``[0, T)``.
    before : ndarray, shape (n_sub, n_states)
        ``Pa(s_m)`` for each sub-step end ``s_m = (m + 1) T / n_sub``: weight of ``u[k-n-1]``.
    after : ndarray, shape (n_sub, n_states)
        ``Pb(s_m)``: weight of ``u[k-n]``.
    active_after : ndarray of bool, shape (n_sub + 1,)
        Whether ``u[k-n]`` (True) or ``u[k-n-1]`` is the input acting at
        ``s = m T / n_sub``, m = 0..n_sub (for state derivatives).
    """

    n_periods: int
    remainder_s: float
    before: np.ndarray
    after: np.ndarray
    active_after: np.ndarray


def delayed_input_map(A: np.ndarray, b: np.ndarray, delay_s: float, period_s: float, n_sub: int) -> DelayedInputMap:
    """The exact sub-step maps of one input column with a delay.

    Parameters
    ----------
    A : ndarray, shape (n, n)
        State matrix, 1/s.
    b : ndarray, shape (n,)
        Input column.
    delay_s : float
        Transport delay, s (≥ 0).
    period_s : float
        Control period T over which the input is held, s.
    n_sub : int
        Sub-steps per period at which states are wanted (≥ 1); the last is the period's end.

    Returns
    -------
    DelayedInputMap

    Examples
    --------
    An integrator fed a unit step delayed by 0.25 of a period gains 0.75 T in that period:

    >>> m = delayed_input_map(np.zeros((1, 1)), np.ones(1), 0.25, 1.0, 1)
    >>> m.n_periods, float(m.after[-1, 0]), float(m.before[-1, 0])
    (0, 0.75, 0.25)
    """
    if delay_s < 0.0 or period_s <= 0.0 or n_sub < 1:
        raise ValueError(f"need {delay_s=} ≥ 0, {period_s=} > 0 and {n_sub=} ≥ 1")
    n_periods = int(np.floor(delay_s / period_s + 1e-9))
    remainder = max(delay_s - n_periods * period_s, 0.0)
    if remainder < 1e-12:
        remainder = 0.0
    column = b.reshape(-1, 1)
    before, after = [], []
    for m in range(1, n_sub + 1):
        s = m * period_s / n_sub
        head = min(s, remainder)
        _, gamma_head = propagator(A, column, head)
        phi_rest, _ = propagator(A, column, s - head)
        before.append((phi_rest @ gamma_head)[:, 0])
        after.append(propagator(A, column, max(s - remainder, 0.0))[1][:, 0])
    sub_times = np.arange(n_sub + 1) * period_s / n_sub
    return DelayedInputMap(
        n_periods=n_periods,
        remainder_s=remainder,
        before=np.array(before),
        after=np.array(after),
        active_after=sub_times >= remainder - 1e-12,
    )
