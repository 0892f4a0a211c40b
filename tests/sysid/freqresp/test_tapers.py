"""The numpy tapers equal scipy.signal.get_window, and other names still reach SciPy."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal as sps

from sysid.freqresp._tapers import _COSINE_SUMS, taper


@pytest.mark.parametrize("name", sorted(_COSINE_SUMS))
@pytest.mark.parametrize("n", [1, 2, 7, 16, 1000])
def test_every_cosine_sum_window_is_scipys_periodic_one(name: str, n: int) -> None:
    np.testing.assert_allclose(taper(name, n), sps.get_window(name, n), rtol=0, atol=1e-15)


def test_other_windows_are_scipys_and_unknown_names_raise() -> None:
    np.testing.assert_array_equal(taper("tukey", 64), sps.get_window("tukey", 64))
    with pytest.raises(ValueError):
        taper("no-such-window", 16)
