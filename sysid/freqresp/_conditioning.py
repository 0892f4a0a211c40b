"""Conditioned (partial) spectra of multi-input, single-output systems (Bendat & Piersol, ch. 7).

For an output ``y`` and inputs ``x_1 .. x_q`` with spectral matrix ``G``,
the response of ``y`` to ``x_j`` with the other inputs' correlated part
removed follows from the spectra conditioned on the others ``r``, a Schur
complement:

    G_{aa.r} = G_aa - G_ar G_rr^{-1} G_ra,   a = (x_j, y)

and ``H_j = G_{jy.r} / G_{jj.r}`` (the ``j``-th element of ``G_xx^{-1} G_xy``),
partial coherence ``|G_{jy.r}|^2 / (G_{jj.r} G_{yy.r})``. With one input,
nothing is conditioned and these are the ordinary spectra.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__: list[str] = []

_RIDGE = 1e-12  # relative diagonal loading of G_rr: inputs identical at a frequency give zero partial coherence there


def conditioned_spectra(
    spectra: np.ndarray, j: int, others: Sequence[int], y: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(G_jj.r, G_yy.r, G_jy.r)`` from a spectral matrix, shape (..., n_freq, n_ch, n_ch) -> (..., n_freq)."""
    a = [j, y]
    g_aa = spectra[..., a, :][..., :, a]
    if others:
        r = list(others)
        g_rr = spectra[..., r, :][..., :, r]
        g_ra = spectra[..., r, :][..., :, a]
        g_ar = spectra[..., a, :][..., :, r]
        scale = np.real(np.trace(g_rr, axis1=-2, axis2=-1)) / len(r)
        loaded = g_rr + (_RIDGE * np.maximum(scale, np.finfo(float).tiny))[..., None, None] * np.eye(len(r))
        g_aa = g_aa - g_ar @ np.linalg.solve(loaded, g_ra)
    g_jj = np.maximum(np.real(g_aa[..., 0, 0]), 0.0)
    g_yy = np.maximum(np.real(g_aa[..., 1, 1]), 0.0)
    return g_jj, g_yy, g_aa[..., 0, 1]


def coherence(g_xx: np.ndarray, g_yy: np.ndarray, g_xy: np.ndarray, *, g_xx_total: np.ndarray | None = None,
              g_yy_total: np.ndarray | None = None) -> np.ndarray:
    """``|G_xy|^2 / (G_xx G_yy)`` clipped to [0, 1].

    Zero where either autospectrum vanishes, or, given the unconditioned
    autospectra, where conditioning left less than 1e-9 of them: an input the
    others explain entirely carries no information of its own, and an output
    they explain entirely leaves nothing to relate (the ratio would be
    rounding noise over rounding noise).
    """
    tiny = np.finfo(float).tiny
    usable = g_xx * g_yy > tiny
    if g_xx_total is not None:
        usable &= g_xx > 1e-9 * g_xx_total
    if g_yy_total is not None:
        usable &= g_yy > 1e-9 * g_yy_total
    ratio = np.abs(g_xy) ** 2 / np.where(usable, g_xx * g_yy, 1.0)
    return np.clip(np.where(usable, ratio, 0.0), 0.0, 1.0)


def response(g_xx: np.ndarray, g_xy: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """``G_xy / G_xx``, with the conditioned input autospectrum floored at 1e-12 of `reference`.

    An input entirely explained by the others has ``G_xx.r`` near zero; the
    floor keeps the (meaningless, zero-coherence) response finite.
    """
    floor = 1e-12 * np.maximum(reference, np.finfo(float).tiny)
    return g_xy / np.maximum(g_xx, floor)


def random_error(gamma2: np.ndarray, n_effective: float | np.ndarray) -> np.ndarray:
    """Normalised random error of the magnitude, ``sqrt(1 - g2) / (|g| sqrt(2 n_d))`` (inf where g2 = 0)."""
    n_d = np.maximum(np.asarray(n_effective, dtype=float), 1.0)
    g2 = np.clip(gamma2, 0.0, 1.0)
    with np.errstate(divide="ignore"):
        return np.where(g2 > 0, np.sqrt(1.0 - g2) / np.sqrt(np.where(g2 > 0, g2, 1.0) * 2.0 * n_d), np.inf)
