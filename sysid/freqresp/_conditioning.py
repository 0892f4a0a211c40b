"""Conditioned (partial) spectra of multi-input, single-output systems (Bendat & Piersol, ch. 7).

For an output ``y`` and inputs ``x_1 .. x_q`` with spectral matrix ``G``,
the response of ``y`` to ``x_j`` with the other inputs' correlated part
removed follows from the spectra conditioned on the others ``r``, a Schur
complement:

    G_{aa.r} = G_aa - G_ar G_rr^{-1} G_ra,   a = (x_j, y)

and ``H_j = G_{jy.r} / G_{jj.r}`` (the ``j``-th element of ``G_xx^{-1} G_xy``),
partial coherence ``|G_{jy.r}|^2 / (G_{jj.r} G_{yy.r})``. With one input,
nothing is conditioned and these are the ordinary spectra.

With a reference (instrument) ``z`` standing in for the first input (the
excitation injected in closed loop, uncorrelated with the noise), the
responses are the instrumental-variable solution ``H = G_zx^{-1} G_zy``, the
other inputs being their own instruments; with one input ``H = G_ry / G_rx``.
Its random error follows from the residual ``n = y - H x``:
``cov(H) = G_nn G_zx^{-1} G_zz G_zx^{-H} / n_d``, and the coherence reported
is the one that gives that error in Bendat & Piersol's formula,
``gamma^2 = 1 / (1 + rho)`` with ``rho = G_nn [G_zx^{-1} G_zz G_zx^{-H}]_jj / |H_j|^2``.
Without a reference (``z = x``) this is the partial coherence above; in open
loop (``x`` a noise-free image of ``r``) it is the ordinary ``gamma^2_xy``.
It is neither the product nor the minimum of ``gamma^2_rx`` and
``gamma^2_ry`` (CIFER reports the latter's kind, y against r): the product
is its first-order approximation when the errors of ``G_rx`` and ``G_ry``
are small and independent, which in closed loop they are not (both carry the
fed-back noise); the minimum ignores one channel's error and, with sensor
noise fed back, understates the scatter by 40 % (tests/sysid/freqresp/test_estimate.py).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple, cast

import numpy as np

__all__: list[str] = []


class Estimate(NamedTuple):
    """One input/output pair from a spectral matrix, each array (n_freq,): see :func:`pair_estimate`."""

    response: np.ndarray
    coherence: np.ndarray
    g_jj: np.ndarray
    g_yy: np.ndarray
    g_jy: np.ndarray


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


def coherence(
    g_xx: np.ndarray,
    g_yy: np.ndarray,
    g_xy: np.ndarray,
    *,
    g_xx_total: np.ndarray | None = None,
    g_yy_total: np.ndarray | None = None,
) -> np.ndarray:
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
    return cast(np.ndarray, g_xy / np.maximum(g_xx, floor))


def random_error(gamma2: np.ndarray, n_effective: float | np.ndarray) -> np.ndarray:
    """Normalised random error of the magnitude, ``sqrt(1 - g2) / (|g| sqrt(2 n_d))`` (inf where g2 = 0)."""
    n_d = np.maximum(np.asarray(n_effective, dtype=float), 1.0)
    g2 = np.clip(gamma2, 0.0, 1.0)
    with np.errstate(divide="ignore"):
        return np.where(g2 > 0, np.sqrt(1.0 - g2) / np.sqrt(np.where(g2 > 0, g2, 1.0) * 2.0 * n_d), np.inf)


def pair_estimate(
    spectra: np.ndarray, inputs: Sequence[int], j: int, y: int, instrument: int | None = None
) -> Estimate:
    """Response of channel `y` to input channel ``inputs[j]`` from a spectral matrix, shape (n_freq, n_ch, n_ch).

    Returns an :class:`Estimate` of ``response``, ``coherence``, ``g_jj``,
    ``g_yy`` and ``g_jy``, each (n_freq,): the spectra conditioned on the other inputs; with an `instrument` (the
    channel standing in for ``inputs[0]``) the instrumental-variable response
    and its coherence (module notes), and ``g_jy = response g_jj``.
    """
    others = [k for n, k in enumerate(inputs) if n != j]
    g_jj, g_yy, g_jy = conditioned_spectra(spectra, inputs[j], others, y)
    g_xx_total = np.real(spectra[..., inputs[j], inputs[j]])
    if instrument is None:
        gamma2 = coherence(g_jj, g_yy, g_jy, g_xx_total=g_xx_total, g_yy_total=np.real(spectra[..., y, y]))
        return Estimate(response=response(g_jj, g_jy, g_xx_total), coherence=gamma2, g_jj=g_jj, g_yy=g_yy, g_jy=g_jy)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # a reference without power: gamma^2 = 0
        h, noise, spread = _instrumental(spectra, list(inputs), y, instrument)
        h_j = h[..., j]
        signal = np.abs(h_j) ** 2
        usable = (signal > 0) & (spread[..., j] > 0) & np.isfinite(spread[..., j]) & (g_jj > 1e-9 * g_xx_total)
        rho = np.maximum(noise, 0.0) * spread[..., j] / np.where(usable, signal, 1.0)
        gamma2 = np.where(usable & np.isfinite(rho), 1.0 / (1.0 + rho), 0.0)
        h_j = np.where(np.isfinite(h_j), h_j, 0.0)
    return Estimate(response=h_j, coherence=gamma2, g_jj=g_jj, g_yy=g_yy, g_jy=h_j * g_jj)


def residual_noise(spectra: np.ndarray, inputs: Sequence[int], y: int, instrument: int | None = None) -> np.ndarray:
    """Autospectrum of ``n = y - sum_a H_a x_a``, the output unexplained by all inputs, shape (n_freq,).

    ``H`` is the least-squares (no `instrument`) or instrumental-variable solution.
    """
    if instrument is None:
        g_jj, g_yy, g_jy = conditioned_spectra(spectra, inputs[0], list(inputs[1:]), y)
        return cast(np.ndarray, np.maximum(g_yy - np.abs(g_jy) ** 2 / np.maximum(g_jj, np.finfo(float).tiny), 0.0))
    with np.errstate(over="ignore", invalid="ignore"):
        noise = _instrumental(spectra, list(inputs), y, instrument)[1]
    return np.where(np.isfinite(noise), np.maximum(noise, 0.0), 0.0)


def _instrumental(
    spectra: np.ndarray, inputs: list[int], y: int, instrument: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``H`` (n_freq, q), residual autospectrum (n_freq,) and ``diag(G_zx^-1 G_zz G_zx^-H)`` (n_freq, q)."""
    z = [instrument, *inputs[1:]]
    g_zx = spectra[..., z, :][..., :, inputs]
    g_zz = spectra[..., z, :][..., :, z]
    g_xx = spectra[..., inputs, :][..., :, inputs]
    g_xy = spectra[..., inputs, y]
    scale = np.sqrt(np.abs(np.trace(g_zz, axis1=-2, axis2=-1) * np.trace(g_xx, axis1=-2, axis2=-1))) / len(z)
    loaded = g_zx + (_RIDGE * np.maximum(scale, np.finfo(float).tiny))[..., None, None] * np.eye(len(z))
    inverse = np.linalg.inv(loaded)
    h = np.einsum("...ab,...b->...a", inverse, spectra[..., z, y])
    noise = (
        np.real(spectra[..., y, y])
        - 2.0 * np.real(np.einsum("...a,...a->...", np.conj(h), g_xy))
        + np.real(np.einsum("...a,...ab,...b->...", np.conj(h), g_xx, h))
    )
    spread = np.real(np.einsum("...ab,...bc,...ac->...a", inverse, g_zz, np.conj(inverse)))
    return h, noise, spread
