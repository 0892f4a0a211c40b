"""The runs of True in a mask: edge cases by hand, and the half-open convention as an invariant."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from flightlogs.errors import DataError
from flightlogs.masks import true_runs

T, F = True, False


@pytest.mark.parametrize(
    ("mask", "runs"),
    [
        ([], []),
        ([F], []),
        ([T], [(0, 1)]),
        ([F, F, F], []),
        ([T, T, T], [(0, 3)]),
        ([T, F, F, T], [(0, 1), (3, 4)]),
        ([T, T, F, T, T], [(0, 2), (3, 5)]),
        ([F, T, F, T, F], [(1, 2), (3, 4)]),
        ([F, T, T, T, F], [(1, 4)]),
    ],
    ids=[
        "empty",
        "one False",
        "one True",
        "all False",
        "all True",
        "single at both ends",
        "at both ends",
        "single samples",
        "inside",
    ],
)
def test_true_runs(mask: list[bool], runs: list[tuple[int, int]]) -> None:
    assert true_runs(np.array(mask, dtype=bool)) == runs
    assert true_runs(mask) == runs  # a list works as well


def test_true_runs_are_python_ints() -> None:
    (run,) = true_runs(np.ones(4, dtype=bool))
    assert all(type(bound) is int for bound in run)


def test_a_mask_of_more_than_one_dimension_is_refused() -> None:
    with pytest.raises(DataError, match=r"one-dimensional, not of shape \(2, 2\)"):
        true_runs(np.ones((2, 2), dtype=bool))


@given(st.lists(st.booleans(), max_size=60))
def test_the_runs_rebuild_the_mask(mask: list[bool]) -> None:
    """Half-open and maximal: the slices set back every True, and no two runs touch."""
    runs = true_runs(mask)
    rebuilt = np.zeros(len(mask), dtype=bool)
    for start, stop in runs:
        assert start < stop
        rebuilt[start:stop] = True
    np.testing.assert_array_equal(rebuilt, np.array(mask, dtype=bool))
    assert all(stop < next_start for (_, stop), (next_start, _) in zip(runs, runs[1:]))
