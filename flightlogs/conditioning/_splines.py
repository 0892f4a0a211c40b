"""Piecewise-cubic interpolants in numpy: the not-a-knot cubic spline and PCHIP, as SciPy builds them.

``scipy.interpolate`` takes 0.35 s to import, longer than the rest of ingesting a log, and its
``CubicSpline`` keeps a (4, n, k) coefficient array. Here both interpolants are a slope per sample
(shape (n, k)) and a cubic Hermite evaluation; the spline's slopes solve SciPy's tridiagonal
system by cyclic reduction (log2(n) vectorised halvings). The tests compare both with SciPy.
"""

from __future__ import annotations

from typing import cast

import numpy as np

__all__: list[str] = []  # private to flightlogs.conditioning

_CHUNK = 1 << 15  # points evaluated at a time


def spline_slopes(t: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Slopes of the not-a-knot cubic spline through (t, v) at the knots: ``CubicSpline(t, v).derivative()(t)``.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Strictly increasing knots, s; n >= 3.
    v : ndarray, shape (n, k)
        Values at the knots.

    Returns
    -------
    ndarray, shape (n, k)
        d v / d t at the knots, in the unit of `v` per s.
    """
    dx = np.diff(t)[:, None]
    slope = np.diff(v, axis=0) / dx
    n = t.size
    if n == 3:  # not-a-knot on three points is the parabola through them
        c = (slope[1] - slope[0]) / (dx[0] + dx[1])
        return np.stack([slope[0] - c * dx[0], slope[0] + c * dx[0], slope[0] + c * (dx[0] + 2 * dx[1])])
    sub = np.empty(n)  # row i: sub[i] s[i-1] + diag[i] s[i] + sup[i] s[i+1] = rhs[i]
    diag = np.empty(n)
    sup = np.empty(n)
    rhs = np.empty_like(v, dtype=np.float64)
    sub[1:-1], diag[1:-1], sup[1:-1] = dx[1:, 0], 2 * (dx[:-1, 0] + dx[1:, 0]), dx[:-1, 0]
    rhs[1:-1] = 3 * (dx[1:] * slope[:-1] + dx[:-1] * slope[1:])
    span = t[2] - t[0]  # not-a-knot at the start, SciPy's row
    sub[0], diag[0], sup[0] = 0.0, dx[1, 0], span
    rhs[0] = ((dx[0] + 2 * span) * dx[1] * slope[0] + dx[0] ** 2 * slope[1]) / span
    span = t[-1] - t[-3]  # and at the end
    sub[-1], diag[-1], sup[-1] = span, dx[-2, 0], 0.0
    rhs[-1] = (dx[-1] ** 2 * slope[-2] + (2 * span + dx[-1]) * dx[-2] * slope[-1]) / span
    return _tridiagonal(sub, diag, sup, rhs)


def pchip_slopes(t: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Slopes of the shape-preserving PCHIP interpolant at the knots, as ``scipy.interpolate.PchipInterpolator``.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Strictly increasing knots, s; n >= 3.
    v : ndarray, shape (n, k)
        Values at the knots.

    Returns
    -------
    ndarray, shape (n, k)
        Slopes, unit of `v` per s: zero at local extrema, weighted harmonic means elsewhere.
    """
    h = np.diff(t)[:, None]
    m = np.diff(v, axis=0) / h
    sign = np.sign(m)
    flat = (sign[1:] != sign[:-1]) | (m[1:] == 0) | (m[:-1] == 0)
    w1, w2 = 2 * h[1:] + h[:-1], h[1:] + 2 * h[:-1]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # the flat knots are overwritten
        inner = (w1 + w2) / (w1 / m[:-1] + w2 / m[1:])
    d = np.empty_like(v, dtype=np.float64)
    d[1:-1] = np.where(flat, 0.0, inner)
    d[0] = _pchip_end(h[0], h[1], m[0], m[1])
    d[-1] = _pchip_end(h[-1], h[-2], m[-1], m[-2])
    return d


def hermite(
    t: np.ndarray, v: np.ndarray, slopes: np.ndarray, at: np.ndarray, out: np.ndarray | None = None
) -> np.ndarray:
    """The cubic Hermite interpolant of values `v` and `slopes` (shape (n, k)) on knots `t` (n,), at `at` (m,): (m, k).

    Points outside [t[0], t[-1]] extend the end pieces. Evaluated `_CHUNK`
    points at a time (the temporaries stay small), into `out` when given.
    """
    out = np.empty((at.size, v.shape[1])) if out is None else out
    for lo in range(0, at.size, _CHUNK):
        _hermite_into(t, v, slopes, at[lo : lo + _CHUNK], out[lo : lo + _CHUNK])
    return out


def _hermite_into(t: np.ndarray, v: np.ndarray, slopes: np.ndarray, at: np.ndarray, out: np.ndarray) -> None:
    j = np.clip(np.searchsorted(t, at, side="right") - 1, 0, t.size - 2)
    h = (t[j + 1] - t[j])[:, None]
    s = (at - t[j])[:, None] / h
    y0 = v.take(j, axis=0)
    rise = v.take(j + 1, axis=0) - y0
    d0 = slopes.take(j, axis=0) * h
    c3 = slopes.take(j + 1, axis=0) * h  # in Horner form: y0 + s (d0 + s (c2 + s c3))
    c3 += d0
    c3 -= 2 * rise  # c3 = d0 + d1 - 2 (y1 - y0)
    c2 = rise - d0 - c3  # = 3 (y1 - y0) - 2 d0 - d1
    out[...] = c3
    for term in (c2, d0, y0):
        out *= s
        out += term


def _pchip_end(h0: np.ndarray, h1: np.ndarray, m0: np.ndarray, m1: np.ndarray) -> np.ndarray:
    """End slope: the three-point formula, kept to the sign of the first secant and to 3 × its size."""
    d = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    d = np.where(np.sign(d) != np.sign(m0), 0.0, d)
    return np.where((np.sign(m0) != np.sign(m1)) & (np.abs(d) > 3 * np.abs(m0)), 3 * m0, d)


def _tridiagonal(sub: np.ndarray, diag: np.ndarray, sup: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve the tridiagonal system (rows (n,), right-hand sides (n, k)) by cyclic reduction.

    Each level eliminates the odd unknowns from the even rows, halving the
    system; the odd unknowns follow from their rows once the even ones are
    known. Without pivoting, as the Thomas algorithm: sound for the spline's
    diagonally dominant rows.
    """
    n = diag.size
    if n == 1:
        return cast(np.ndarray, rhs / diag[:, None])
    if n == 2:
        det = diag[0] * diag[1] - sup[0] * sub[1]
        first = (diag[1] * rhs[0] - sup[0] * rhs[1]) / det
        return np.stack([first, (rhs[1] - sub[1] * first) / diag[1]])
    even = slice(0, None, 2)
    n_odd = n // 2
    below = np.zeros(n - n_odd)  # for each even row: the factor on the odd row before it (none for row 0)
    above = np.zeros(n - n_odd)  # and on the odd row after it (none for a last even row)
    below[1:] = -sub[2::2] / diag[1::2][: n - n_odd - 1]
    above[:n_odd] = -sup[0::2][:n_odd] / diag[1::2]
    new_diag = diag[even].copy()
    new_rhs = rhs[even].copy()
    new_sub = np.zeros(n - n_odd)
    new_sup = np.zeros(n - n_odd)
    new_diag[1:] += below[1:] * sup[1::2][: n - n_odd - 1]
    new_rhs[1:] += below[1:, None] * rhs[1::2][: n - n_odd - 1]
    new_sub[1:] = below[1:] * sub[1::2][: n - n_odd - 1]
    new_diag[:n_odd] += above[:n_odd] * sub[1::2]
    new_rhs[:n_odd] += above[:n_odd, None] * rhs[1::2]
    new_sup[: n_odd - (n % 2 == 0)] = (above[:n_odd] * sup[1::2])[: n_odd - (n % 2 == 0)]
    x = np.empty_like(rhs)
    x[even] = _tridiagonal(new_sub, new_diag, new_sup, new_rhs)
    odd_rhs = rhs[1::2] - sub[1::2, None] * x[0:-1:2][:n_odd]
    has_next = np.arange(1, n, 2) + 1 < n
    odd_rhs[has_next] -= sup[1::2][has_next, None] * x[2::2]
    x[1::2] = odd_rhs / diag[1::2, None]
    return x
