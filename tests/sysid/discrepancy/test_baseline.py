"""The simulation's model: its lagged inputs, taken as strided views, against a column at a time."""

from __future__ import annotations

import numpy as np
import pytest

from sysid.discrepancy.baseline import _lagged


def _column_at_a_time(spans: list[slice], x: np.ndarray, lags: np.ndarray) -> np.ndarray:
    """x(t - lag) per lag, each piece padded with its first value: the definition, one slice per column."""
    out = np.empty((x.size, lags.size))
    longest = int(lags[-1])
    for rows in spans:
        piece = x[rows]
        padded = np.concatenate([np.full(longest, piece[0]), piece])
        for j, lag in enumerate(lags.tolist()):
            out[rows, j] = padded[longest - lag : longest - lag + piece.size]
    return out


@pytest.mark.parametrize(
    "lags",
    [np.arange(16), np.arange(0, 16, 5), np.arange(0, 13, 4), np.array([0]), np.array([0, 1, 4, 9])],
    ids=["every-sample", "step-5", "step-4", "none", "uneven"],
)
@pytest.mark.parametrize(
    "spans", [[slice(0, 600)], [slice(0, 2), slice(2, 300), slice(300, 600)]], ids=["one-piece", "short-first-piece"]
)
def test_the_lagged_inputs_are_the_definitions_columns(lags: np.ndarray, spans: list[slice]) -> None:
    """Equal, bit for bit: no lag reaches across a gap, a piece shorter than the lags holds its first value."""
    x = np.random.default_rng(7).normal(size=600)
    assert np.array_equal(_lagged(spans, x, lags), _column_at_a_time(spans, x, lags))
