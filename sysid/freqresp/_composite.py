"""Multi-window composite: at each frequency, the windows that measure it best count most.

CIFER's COMPOSITE finds, per frequency, the spectra that best fit all
windows' spectra in a weighted least-squares sense. With a diagonal weighting
that solution is the weighted mean, which is what is computed here: the
spectral matrices of the window lengths are averaged per frequency with
weights ``1 / eps_r^2 = 2 n_d gamma^2 / (1 - gamma^2)``, eps_r being each
window's normalised random error (from its own, partial, coherence and its
effective number of averages), and zero below the lowest frequency the window
resolves. The response, coherence and random error then follow from the
composite spectra; the random error uses the same weighted mean of ``n_d``
(the windows reuse the same data, so their errors are not independent and
the composite is credited no more averages than its windows had).

Both the weights and the random error use the coherence with the bias of a
finite number of averages removed, ``(n_d g^2 - 1) / (n_d - 1)``: unrelated
signals give ``E[g^2] = 1 / n_d``, and a long window with few averages would
otherwise look coherent in noise and claim too small an error. The coherence
reported is the usual estimate, the one thresholds (eq. 3.8) refer to.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ._conditioning import coherence, conditioned_spectra, random_error, response
from ._spectra import WindowSpectra

__all__: list[str] = []


@dataclass(frozen=True, slots=True)
class PairEstimate:
    """Composite estimate of one output's response to one input, arrays of shape (n_freq,)."""

    response: np.ndarray
    coherence: np.ndarray
    random_error: np.ndarray
    input_autospectrum: np.ndarray
    output_autospectrum: np.ndarray
    cross_spectrum: np.ndarray
    windows_s: tuple[float, ...]


def composite_pair(
    windows: Sequence[WindowSpectra], omega: np.ndarray, inputs: Sequence[int], j: int, y: int
) -> PairEstimate:
    """Composite conditioned estimate of channel `y` against input channel ``inputs[j]``."""
    others = [k for n, k in enumerate(inputs) if n != j]
    n_conditioned = len(others)
    weights = np.zeros((len(windows), omega.size))
    valid = np.zeros((len(windows), omega.size), dtype=bool)
    for i, window in enumerate(windows):
        valid[i] = omega >= window.omega_low * (1.0 - 1e-12)
        spectra_i = window.spectra[valid[i]]
        g_jj, g_yy, g_jy = conditioned_spectra(spectra_i, inputs[j], others, y)
        gamma2 = coherence(g_jj, g_yy, g_jy, g_xx_total=np.real(spectra_i[:, inputs[j], inputs[j]]),
                           g_yy_total=np.real(spectra_i[:, y, y]))
        n_d = max(window.n_effective - n_conditioned, 1.0)
        unbiased = _unbiased_coherence(gamma2, n_d)
        weights[i, valid[i]] = 2.0 * n_d * unbiased / np.maximum(1.0 - unbiased, 1e-12)
    total = weights.sum(axis=0)
    weights = np.where(total > 0, weights, valid.astype(float))  # no coherence anywhere: plain mean of valid windows
    weights /= np.maximum(weights.sum(axis=0), np.finfo(float).tiny)
    stacked = np.stack([window.spectra for window in windows])  # (n_windows, n_freq, n_ch, n_ch)
    spectra = np.einsum("if,ifab->fab", weights, stacked)
    g_jj, g_yy, g_jy = conditioned_spectra(spectra, inputs[j], others, y)
    gamma2 = coherence(g_jj, g_yy, g_jy, g_xx_total=np.real(spectra[:, inputs[j], inputs[j]]),
                       g_yy_total=np.real(spectra[:, y, y]))
    n_d = weights.T @ np.array([max(w.n_effective - n_conditioned, 1.0) for w in windows])
    contributes = np.any(weights > 0, axis=1)
    used = tuple(float(w.window_s) for k, w in enumerate(windows) if contributes[k])
    return PairEstimate(
        response=response(g_jj, g_jy, np.real(spectra[:, inputs[j], inputs[j]])),
        coherence=gamma2,
        random_error=random_error(_unbiased_coherence(gamma2, n_d), n_d),
        input_autospectrum=g_jj,
        output_autospectrum=g_yy,
        cross_spectrum=g_jy,
        windows_s=used,
    )


def _unbiased_coherence(gamma2: np.ndarray, n_d: float | np.ndarray) -> np.ndarray:
    """Coherence with the bias of few averages removed: ``(n_d g^2 - 1) / (n_d - 1)``, clipped to [0, 1].

    Unrelated signals give ``E[g^2] = 1 / n_d``, not 0; without the correction a
    long window with a handful of averages would look coherent in noise and
    be trusted over a short one with hundreds. One average carries no weight.
    """
    n = np.asarray(n_d, dtype=float)
    corrected = (n * gamma2 - 1.0) / np.maximum(n - 1.0, 1e-12)
    return np.where(n > 1.0, np.clip(corrected, 0.0, 1.0), 0.0)
