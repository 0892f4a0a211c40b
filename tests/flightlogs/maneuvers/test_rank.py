"""The rank statistics the detectors use equal scipy.stats.spearmanr (ties included) and numpy's median and quantile."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.stats import spearmanr

from flightlogs.maneuvers._rank import median, quantile, spearman

_VALUES = st.lists(st.integers(-5, 5) | st.floats(-1e6, 1e6, allow_nan=False), min_size=3, max_size=60)


@given(_VALUES)
def test_spearman_equals_scipys_with_ties(values: list[float]) -> None:
    x = np.asarray(values, dtype=float)
    y = x[::-1] + np.arange(x.size) % 3  # ties in both, some order shared
    if np.ptp(x) == 0 or np.ptp(y) == 0:
        assert np.isnan(spearman(x, y))  # scipy warns and gives NaN: no order to correlate
        return
    assert abs(spearman(x, y) - spearmanr(x, y).statistic) < 1e-12


def test_spearman_of_a_monotone_map_is_one_and_of_a_reversal_minus_one() -> None:
    t = np.linspace(0.1, 10.0, 200)
    assert spearman(t, np.log(t)) == 1.0
    assert spearman(t, -(t**3)) == -1.0
    assert np.isnan(spearman(t, np.ones_like(t)))


@pytest.mark.parametrize("n", [*range(1, 40), 101, 1000, 4097])
def test_median_and_quantile_equal_numpys_bit_for_bit(n: int) -> None:
    rng = np.random.default_rng(n)
    for trial in range(12):
        x = rng.standard_normal(n) * 10.0 ** rng.integers(-3, 4)
        if trial % 3 == 0:
            x = np.round(x, 1)  # ties
        assert median(x) == float(np.median(x))
        for q in (0.0, 0.1, 0.25, 0.5, 0.75, 0.9, 0.95, 1.0, float(rng.random())):
            assert quantile(x, q) == float(np.quantile(x, q)), (n, q)
