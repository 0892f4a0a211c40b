"""The residual's sandwich bound against Monte Carlo truth: a straight line fitted through AR(1) errors.

``y_k = a x_k + e_k`` over 40 points, ``e`` of unit variance with lag-one correlation ``rho``; the least-squares
``a`` and its bounds, 400 draws. With ``rho = 0`` Tischler's bound is the estimate's standard deviation and the
truth lies inside 2 bounds 95 % of the time; with correlated errors it is too small by ``sqrt((1 + rho) / (1 -
rho))`` at most, and the truth falls outside it more often.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sysid.fit.accuracy import accuracy, robust_bounds, with_spread

N_POINTS, N_DRAWS = 40, 400


def _coverage(rho: float, seed: int) -> tuple[float, float, float]:
    """Share of draws with the truth inside 2 bounds, Tischler's and the sandwich's; the median ratio of the two."""
    rng = np.random.default_rng(seed)
    x = np.linspace(1.0, 2.0, N_POINTS)
    inside_cr = inside_robust = 0
    ratios = []
    for _ in range(N_DRAWS):
        innovation = rng.normal(size=N_POINTS)
        error = np.empty(N_POINTS)
        error[0] = innovation[0]
        for k in range(1, N_POINTS):
            error[k] = rho * error[k - 1] + np.sqrt(1.0 - rho**2) * innovation[k]
        y = x + error  # truth a = 1
        a = float(x @ y / (x @ x))
        jacobian = x[:, None]
        tischler = accuracy(jacobian, np.array([a]), ("a",))
        robust = robust_bounds(tischler, jacobian, a * x - y, [np.arange(N_POINTS)])
        inside_cr += abs(a - 1.0) <= 2.0 * tischler.cramer_rao[0]
        inside_robust += abs(a - 1.0) <= 2.0 * robust.cramer_rao[0]
        ratios.append(robust.cramer_rao[0] / tischler.cramer_rao[0])
    return inside_cr / N_DRAWS, inside_robust / N_DRAWS, float(np.median(ratios))


def test_on_independent_unit_errors_the_sandwich_keeps_tischlers_bound() -> None:
    """Measured: 94.0 and 94.5 % inside, median ratio 1.00. Binomial 3 sigma about 95.4 %: 92-98.5 %."""
    tischler, robust, ratio = _coverage(0.0, seed=0)
    assert 0.92 <= tischler <= 0.985 and 0.92 <= robust <= 0.985, (tischler, robust)
    assert ratio <= 1.05, ratio


def test_where_errors_run_over_neighbouring_points_the_sandwich_widens_the_bound() -> None:
    """rho = 0.8: Tischler's bound is 2.9 times too small (the truth inside 2 of it on 54 % of the draws); the
    sandwich, its bandwidth read off 40 points, recovers part of that (73 %, median 1.5 times Tischler's)."""
    tischler, robust, ratio = _coverage(0.8, seed=1)
    assert tischler < 0.65, tischler
    assert robust >= tischler + 0.1, (tischler, robust)
    assert ratio >= 1.3, ratio


def test_series_are_summed_apart() -> None:
    """Two series of four residuals, +2 then -2 (a magnitude and a phase, say), scores ``g = r``, H = 8.

    Apart, each series is constant: bandwidth 0, meat ``sum g^2 = 32``, bound sqrt(32) / 8. As one series its
    autocorrelation stays above 0.05 for two lags (bandwidth 2, Bartlett weights 2/3 and 1/3): the lag-one
    products sum to 20 and the lag-two ones to 8 (those across the join negative), meat 32 + 2 (2/3) 20 +
    2 (1/3) 8 = 64, bound 1.
    """
    jacobian = np.ones((8, 1))
    residual = np.repeat([2.0, -2.0], 4)
    tischler = accuracy(jacobian, np.array([1.0]), ("a",))
    apart = robust_bounds(tischler, jacobian, residual, [np.arange(4), np.arange(4, 8)])
    joined = robust_bounds(tischler, jacobian, residual, [np.arange(8)])
    assert apart.cramer_rao[0] == pytest.approx(np.sqrt(32.0) / 8.0, rel=1e-12)
    assert joined.cramer_rao[0] == pytest.approx(1.0, rel=1e-12)


def test_a_spread_adds_in_quadrature() -> None:
    tischler = accuracy(np.full((4, 1), 2.0), np.array([1.0]), ("a",))  # bound 0.25
    assert with_spread(tischler, {"a": 0.75 / 1.0}).cramer_rao[0] == np.hypot(0.25, 0.75)
    assert with_spread(tischler, {"b": 3.0}).cramer_rao[0] == 0.25


def test_a_range_too_narrow_or_empty_to_raise_is_kept() -> None:
    """The fit range's spread refits with the bottom raised only where a range gating accepts (0.3 decade) and a
    frequency of the response are left."""
    from sysid.fit.bias import raised
    from sysid.fit.synthetic import synthetic_responses
    from sysid.model import load_structure, structure_model

    model, _ = structure_model(load_structure("hover"), load_structure("hover").values())
    omega = np.array([0.5, 1.0, 2.0, 30.0])
    (response,) = synthetic_responses(model, ["p/delta_lat"], omega=omega, fit_range=(0.5, 30.0))
    assert raised(response, 1.6) is not None and raised(response, 1.6).fit_range == (0.8, 30.0)  # type: ignore[union-attr]
    narrow = dataclasses.replace(response, fit_range=(10.0, 20.0))
    assert raised(narrow, 1.25) is None  # 12.5-20 rad/s: 0.2 decade
    empty = dataclasses.replace(response, fit_range=(2.5, 29.0))
    assert raised(empty, 1.6) is None  # 4-29 rad/s holds none of 0.5, 1, 2, 30
