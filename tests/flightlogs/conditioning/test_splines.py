"""The numpy cubic spline and PCHIP equal SciPy's, on jittery knots, many columns and every small size."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import CubicSpline, PchipInterpolator

from flightlogs.conditioning._splines import Located, SplineSystem, hermite, pchip_slopes


def _knots(n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.2, 1.8, n))  # spacing varying ninefold
    v = rng.standard_normal((n, 3)) * [1.0, 1e3, 1e-3]
    at = np.sort(np.r_[t[0], t[-1], rng.uniform(t[0], t[-1], 3 * n)])
    return t, v, at


def _assert_close(ours: np.ndarray, expected: np.ndarray, v: np.ndarray) -> None:
    """Within 1e-11 of each column's largest value (the columns span six decades)."""
    scale = np.abs(v).max(axis=0)
    np.testing.assert_allclose(ours / scale, expected / scale, rtol=0, atol=1e-11)


@pytest.mark.parametrize("n", [3, 4, 5, 6, 7, 8, 9, 16, 17, 100, 1001, 20_000])
def test_the_not_a_knot_spline_is_scipys(n: int) -> None:
    t, v, at = _knots(n, n)
    expected = CubicSpline(t, v, bc_type="not-a-knot")(at)
    _assert_close(hermite(t, v, SplineSystem(t).slopes(v), at), expected, v)


@pytest.mark.parametrize("n", [3, 4, 5, 8, 100, 20_000])
def test_pchip_is_scipys(n: int) -> None:
    t, v, at = _knots(n, 7 * n)
    v[n // 3 : n // 2] = v[n // 3]  # a flat stretch: zero slopes there
    expected = PchipInterpolator(t, v)(at)
    _assert_close(hermite(t, v, pchip_slopes(t, v), at), expected, v)


def test_a_cubic_is_reproduced_exactly_with_its_slopes() -> None:
    t = np.cumsum(np.random.default_rng(3).uniform(0.5, 1.5, 50))
    v = (2 * t**3 - t**2 + 4)[:, None]
    slopes = SplineSystem(t).slopes(v)
    np.testing.assert_allclose(slopes[:, 0], 6 * t**2 - 2 * t, rtol=1e-9)
    at = np.linspace(t[0], t[-1], 777)
    np.testing.assert_allclose(hermite(t, v, slopes, at)[:, 0], 2 * at**3 - at**2 + 4, rtol=1e-11)


@pytest.mark.parametrize("n", [3, 4, 9, 1001, 70_000])
def test_one_factored_system_solves_each_column_alone_as_all_at_once(n: int) -> None:
    """The resampler solves a message's columns one at a time on one factored system, at points located once:
    bit for bit what solving them together gives (no (n, k) working arrays, same numbers)."""
    t, v, at = _knots(n, n + 1)
    system, where = SplineSystem(t), Located(t, at)
    together = hermite(t, v, system.slopes(v), at)
    for k in range(v.shape[1]):
        column = v[:, k : k + 1]
        alone = hermite(t, column, system.slopes(column), where)
        np.testing.assert_array_equal(alone[:, 0], together[:, k])
