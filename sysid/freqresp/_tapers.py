"""Spectral-analysis tapers (periodic windows) without importing scipy.signal, which takes 0.75 s to load.

:func:`taper` equals ``scipy.signal.get_window(name, n)`` (the periodic form) for the cosine-sum
windows written here, and hands any other name to SciPy. The tests compare them.
"""

from __future__ import annotations

from typing import cast

import numpy as np

__all__: list[str] = []  # private to sysid.freqresp

#: Cosine-sum coefficients a_k of ``sum_k (-1)^k a_k cos(2 pi k n / N)``, by every name SciPy takes.
_COSINE_SUMS = {
    **dict.fromkeys(("hann", "han"), (0.5, 0.5)),
    **dict.fromkeys(("hamming", "hamm", "ham"), (0.54, 0.46)),
    **dict.fromkeys(("blackman", "black", "blk"), (0.42, 0.50, 0.08)),
    **dict.fromkeys(("boxcar", "box", "ones", "rect", "rectangular"), (1.0,)),
}


def taper(name: str, n: int) -> np.ndarray:
    """The periodic window `name` of `n` samples, shape (n,): ``scipy.signal.get_window(name, n)``.

    Raises
    ------
    ValueError
        If SciPy does not know the window.
    """
    coefficients = _COSINE_SUMS.get(name) if isinstance(name, str) else None
    if coefficients is None:
        from scipy import signal as sps  # any other window: SciPy's

        return cast(np.ndarray, sps.get_window(name, n))
    if n == 1:
        return np.ones(1)  # SciPy's one-sample window, whatever its name
    phase = 2.0 * np.pi * np.arange(n) / n  # periodic: one sample of the next period left out
    values = np.zeros(n)
    for k, a in enumerate(coefficients):
        values += (-1) ** k * a * np.cos(k * phase)
    return values
