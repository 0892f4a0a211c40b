"""Piecewise-cubic interpolants in numpy: the not-a-knot cubic spline and PCHIP, as SciPy builds them.

``scipy.interpolate`` takes 0.35 s to import, longer than the rest of ingesting a log, and its
``CubicSpline`` keeps a (4, n, k) coefficient array. Here both interpolants are a slope per sample
(shape (n, k)) and a cubic Hermite evaluation; the spline's slopes solve SciPy's tridiagonal
system by cyclic reduction (log2(n) vectorised halvings). The tests compare both with SciPy.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import numpy as np

__all__: list[str] = []  # private to flightlogs.conditioning

_CHUNK = 1 << 15  # points evaluated at a time


class SplineSystem:
    """The not-a-knot cubic spline's slope equations on knots `t`, factored once for any number of value columns.

    The tridiagonal rows depend on the knots only; cyclic reduction's elimination factors of every level
    are computed here, so that signals sampled at the same times (one log message's fields) are solved
    one column at a time without repeating them, and without (n, k) working arrays.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Strictly increasing knots, s; n >= 3.
    """

    def __init__(self, t: np.ndarray) -> None:
        self.t = t
        self._dx = np.diff(t)[:, None]
        dx = self._dx[:, 0]
        n = t.size
        if n == 3:  # not-a-knot on three points is the parabola through them: no system
            self._levels: list[_Level] = []
            return
        sub = np.empty(n)  # row i: sub[i] s[i-1] + diag[i] s[i] + sup[i] s[i+1] = rhs[i]
        diag = np.empty(n)
        sup = np.empty(n)
        sub[1:-1], diag[1:-1], sup[1:-1] = dx[1:], 2 * (dx[:-1] + dx[1:]), dx[:-1]
        sub[0], diag[0], sup[0] = 0.0, dx[1], t[2] - t[0]  # not-a-knot at the start, SciPy's row
        sub[-1], diag[-1], sup[-1] = t[-1] - t[-3], dx[-2], 0.0  # and at the end
        self._levels = _factor(sub, diag, sup)

    def slopes(self, v: np.ndarray) -> np.ndarray:
        """Slopes of the spline through (t, v) at the knots: ``CubicSpline(t, v).derivative()(t)``.

        Parameters
        ----------
        v : ndarray, shape (n, k)
            Values at the knots.

        Returns
        -------
        ndarray, shape (n, k)
            d v / d t at the knots, in the unit of `v` per s.
        """
        t, dx = self.t, self._dx
        slope = np.diff(v, axis=0) / dx
        if t.size == 3:
            c = (slope[1] - slope[0]) / (dx[0] + dx[1])
            return np.stack([slope[0] - c * dx[0], slope[0] + c * dx[0], slope[0] + c * (dx[0] + 2 * dx[1])])
        rhs = np.empty_like(v, dtype=np.float64)
        rhs[1:-1] = 3 * (dx[1:] * slope[:-1] + dx[:-1] * slope[1:])
        span = t[2] - t[0]
        rhs[0] = ((dx[0] + 2 * span) * dx[1] * slope[0] + dx[0] ** 2 * slope[1]) / span
        span = t[-1] - t[-3]
        rhs[-1] = (dx[-1] ** 2 * slope[-2] + (2 * span + dx[-1]) * dx[-2] * slope[-1]) / span
        del slope
        return _solve(self._levels, rhs)


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


class Located:
    """Points `at` (m,) located among knots `t` (n,): the piece of each, for any columns of the same knots.

    Points outside [t[0], t[-1]] extend the end pieces. Only the pieces are kept (the search is the
    costly part; int32 below 2**31 knots): each piece's width and the point's place in it are worked
    out a chunk at a time when evaluated.
    """

    def __init__(self, t: np.ndarray, at: np.ndarray) -> None:
        self.t, self.at, self.size = t, at, at.size
        index = np.int32 if t.size < 2**31 else np.int64
        self.piece = np.clip(np.searchsorted(t, at, side="right") - 1, 0, t.size - 2).astype(index)

    def part(self, lo: int, hi: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Points ``lo:hi``: their pieces (m,), the pieces' widths (m, 1), s, and the places in them (m, 1), 0-1."""
        j = self.piece[lo:hi]
        start = self.t[j]
        width = (self.t[j + 1] - start)[:, None]
        return j, width, (self.at[lo:hi] - start)[:, None] / width


def hermite(
    t: np.ndarray,
    v: np.ndarray,
    slopes: np.ndarray,
    at: np.ndarray | Located,
    out: np.ndarray | None = None,
) -> np.ndarray:
    """The cubic Hermite interpolant of values `v` and `slopes` (shape (n, k)) on knots `t` (n,), at `at` (m,): (m, k).

    `at` may be the points already :class:`Located` (shared by columns of the same knots). Evaluated
    `_CHUNK` points at a time (the temporaries stay small), into `out` when given.
    """
    where = at if isinstance(at, Located) else Located(t, at)
    out = np.empty((where.size, v.shape[1])) if out is None else out
    for lo in range(0, where.size, _CHUNK):
        _hermite_into(v, slopes, *where.part(lo, lo + _CHUNK), out[lo : lo + _CHUNK])
    return out


def _hermite_into(
    v: np.ndarray, slopes: np.ndarray, j: np.ndarray, h: np.ndarray, s: np.ndarray, out: np.ndarray
) -> None:
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


@dataclass(frozen=True, slots=True)
class _Level:
    """One level of cyclic reduction of an n-row system: what eliminating its odd unknowns takes."""

    n: int
    below: np.ndarray  # (n_even,): each even row's factor on the odd row before it
    above: np.ndarray  # (n_even,): and on the odd row after it
    odd_sub: np.ndarray  # (n_odd,): the odd rows' coefficients
    odd_diag: np.ndarray
    odd_sup: np.ndarray
    with_next: int  # the odd rows followed by an even one: the first n_odd, or n_odd - 1 when n is even
    base: tuple[np.ndarray, np.ndarray, np.ndarray] | None  # the rows themselves when n <= 2 (solved directly)


def _factor(sub: np.ndarray, diag: np.ndarray, sup: np.ndarray) -> list[_Level]:
    """Cyclic reduction of the tridiagonal rows (sub, diag, sup; each (n,)), level by level, down to 1 or 2 rows.

    Each level eliminates the odd unknowns from the even rows, halving the system; the odd unknowns
    follow from their rows once the even ones are known. Without pivoting, as the Thomas algorithm:
    sound for the spline's diagonally dominant rows.
    """
    levels = []
    while True:
        n = diag.size
        empty = np.empty(0)
        if n <= 2:
            levels.append(_Level(n, empty, empty, empty, empty, empty, 0, (sub, diag, sup)))
            return levels
        even = slice(0, None, 2)
        n_odd = n // 2
        n_even = n - n_odd
        below = np.zeros(n_even)
        above = np.zeros(n_even)
        below[1:] = -sub[2::2] / diag[1::2][: n_even - 1]
        above[:n_odd] = -sup[0::2][:n_odd] / diag[1::2]
        new_diag = diag[even].copy()
        new_sub = np.zeros(n_even)
        new_sup = np.zeros(n_even)
        new_diag[1:] += below[1:] * sup[1::2][: n_even - 1]
        new_sub[1:] = below[1:] * sub[1::2][: n_even - 1]
        new_diag[:n_odd] += above[:n_odd] * sub[1::2]
        new_sup[: n_odd - (n % 2 == 0)] = (above[:n_odd] * sup[1::2])[: n_odd - (n % 2 == 0)]
        with_next = n_odd - (n % 2 == 0)
        odd_sub, odd_diag, odd_sup = (row[1::2].copy() for row in (sub, diag, sup))  # views would keep the rows
        levels.append(_Level(n, below, above, odd_sub, odd_diag, odd_sup, with_next, None))
        sub, diag, sup = new_sub, new_diag, new_sup


def _solve(levels: list[_Level], rhs: np.ndarray) -> np.ndarray:
    """The solution (n, k) of the factored system for right-hand sides `rhs` (n, k)."""
    level, rest = levels[0], levels[1:]
    if level.base is not None:
        sub, diag, sup = level.base
        if level.n == 1:
            return cast(np.ndarray, rhs / diag[:, None])
        det = diag[0] * diag[1] - sup[0] * sub[1]
        first = (diag[1] * rhs[0] - sup[0] * rhs[1]) / det
        return np.stack([first, (rhs[1] - sub[1] * first) / diag[1]])
    n, n_odd = level.n, level.n // 2
    n_even = n - n_odd
    new_rhs = rhs[0::2].copy()
    new_rhs[1:] += level.below[1:, None] * rhs[1::2][: n_even - 1]
    new_rhs[:n_odd] += level.above[:n_odd, None] * rhs[1::2]
    x = np.empty_like(rhs)
    x[0::2] = _solve(rest, new_rhs)
    del new_rhs
    odd_rhs = rhs[1::2] - level.odd_sub[:, None] * x[0:-1:2][:n_odd]
    odd_rhs[: level.with_next] -= level.odd_sup[: level.with_next, None] * x[2::2]
    x[1::2] = odd_rhs / level.odd_diag[:, None]
    return x
