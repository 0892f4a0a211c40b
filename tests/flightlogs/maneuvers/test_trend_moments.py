"""The robust trend's window moments, summed block by block, equal the windows summed one by one."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.lib.stride_tricks import sliding_window_view

from flightlogs.maneuvers._detection import _window_moments


@pytest.mark.parametrize(
    ("n", "width"), [(1000, 101), (5000, 1001), (12_345, 999), (50, 101), (7, 31), (301, 17), (300, 3), (1, 3)]
)
def test_block_moments_equal_each_window_summed(n: int, width: int) -> None:
    half, stride = width // 2, max(1, width // 8)
    x = np.random.default_rng(n + width).standard_normal(n) + 5.0
    centres = np.unique(np.r_[np.arange(0, n, stride), n - 1])
    local_time = (np.arange(-half, half + 1) / half)[:, None] ** np.arange(5)
    expected = sliding_window_view(np.pad(x, half), width)[centres] @ local_time
    np.testing.assert_allclose(
        _window_moments(x, half, stride, 5), expected, rtol=0, atol=1e-12 * np.abs(expected).max()
    )
