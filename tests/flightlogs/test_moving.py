"""The numpy moving windows equal the SciPy calls they replace on the ingest path."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage
from scipy.fft import next_fast_len

from flightlogs._moving import dilate, erode, fast_fft_length, moving_mean, moving_rank

_SIZES = (1, 2, 5, 50, 1001)
_WIDTHS = (1, 2, 3, 4, 7, 20)


@pytest.mark.parametrize("n", _SIZES)
@pytest.mark.parametrize("width", _WIDTHS)
def test_moving_mean_is_uniform_filter1d_with_held_ends(n: int, width: int) -> None:
    x = np.random.default_rng(n * 31 + width).standard_normal(n)
    np.testing.assert_allclose(
        moving_mean(x, width), ndimage.uniform_filter1d(x, width, mode="nearest"), rtol=0, atol=1e-12
    )


@pytest.mark.parametrize(
    ("n", "width", "mode"),
    [(n, w, m) for n in _SIZES for w in _WIDTHS for m in ("reflect", "nearest") if m == "nearest" or w <= n],
)  # a window wider than the trace mirrors it repeatedly, where SciPy extends it otherwise
def test_moving_rank_is_median_filter_with_its_window_and_edges(n: int, width: int, mode: str) -> None:
    x = np.random.default_rng(n * 17 + width).standard_normal(n)
    assert np.array_equal(moving_rank(x, width, mode=mode), ndimage.median_filter(x, size=width, mode=mode))


@pytest.mark.parametrize("n", _SIZES)
@pytest.mark.parametrize("reach", (0, 1, 2, 7, 20))
def test_dilation_and_erosion_are_scipys_with_its_borders(n: int, reach: int) -> None:
    mask = np.random.default_rng(n + reach).random(n) > 0.8
    expected_dilated = ndimage.binary_dilation(mask, iterations=reach) if reach else mask
    expected_eroded = ndimage.binary_erosion(mask, iterations=reach, border_value=1) if reach else mask
    assert np.array_equal(dilate(mask, reach), expected_dilated)
    assert np.array_equal(erode(mask, reach), expected_eroded)


def test_empty_traces_stay_empty() -> None:
    assert moving_mean(np.array([]), 5).size == moving_rank(np.array([]), 3).size == 0
    assert dilate(np.array([], bool), 2).size == erode(np.array([], bool), 2).size == 0


def test_fast_fft_length_is_next_fast_len() -> None:
    for n in [*range(1, 3000), 400_017, 1_234_567, 10**8 + 7]:
        assert fast_fft_length(n) == next_fast_len(n, real=True), n
