"""The rank correlation the sweep tests use equals scipy.stats.spearmanr, ties included."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from scipy.stats import spearmanr

from flightlogs.maneuvers._rank import spearman

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
