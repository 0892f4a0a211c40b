"""The whole-record member from as many records as inputs or fewer: noise (and responses) from neighbouring bins.

With more records than inputs, :mod:`sysid.freqresp._whole` measures the
noise between the records at each frequency. Most logs hold one sweep per
axis, and conditioning on a measured wind makes two inputs of it; then the
noise, and with several inputs the responses themselves, come from the
record's own neighbouring DFT bins (Pintelon & Schoukens' local polynomial
method): around each grid frequency ``omega_g`` the bins within
``±max(3 bins, 10 %)`` (wider when the model needs more) obey

    Y_b = sum_a (H_a0 + H_a1 d_b + H_a2 d_b^2) X_ab + T_k + N_b,   d_b = (omega_b - omega_g) / half-width,

each response a parabola across the neighbourhood (a straight line leaves
the curvature of a lightly damped or unstable pair in the residual, and
takes the member's weight away exactly where the windows are biased) and
what is left of the transient of record ``k``'s ends after their taper a
constant. The residual measures the noise ``G_nn`` with ``2 (n_b - p)``
degrees of freedom, ``p`` the number of coefficients.

The member's coherence is unbiased (the signal is the fitted response's,
or ``|Y|^2`` less the noise), so the composite applies no further
correction to it and credits it one average (``sysid.freqresp._composite``):
a conservative weight for an estimate that pools several bins.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__: list[str] = []

SMOOTH_BINS = 3.0  # neighbourhood: at least ±3 bins of 2 pi / T ...
SMOOTH_FRACTION = 0.1  # ... or ±10 % of the frequency
_MIN_COHERENCE = 1e-6  # floor of the unbiased coherence where the noise explains the whole output
_SINGLE_TERMS = 4  # one input: the response a parabola across the neighbourhood, the transient a constant


def local_noise(
    spectra: np.ndarray,
    record: np.ndarray,
    omega: np.ndarray,
    valid: np.ndarray,
    x: int,
    outputs: Sequence[int],
    scale: float,
    dt: float,
) -> np.ndarray:
    """One record of one input: each output's noise from its neighbouring bins, put into `spectra` (in place).

    `record` is the tapered, levelled record, shape (n_channels, n_samples);
    `scale` turns a squared transform into a one-sided density. The spectra
    stay pointwise (``Y = H X`` holds at every frequency with ``H = Y / X``,
    so they alone would give a coherence of 1); the local regression (module
    notes, ``p = 4``) measures the noise. As ``|Y_g|^2`` holds the noise as
    well as the signal, the unbiased coherence is ``1 - G_nn / G_yy``; ``G_yy``
    is divided by it so that the spectra give that coherence (and, with a
    reference, the matching random error). Returns the degrees of freedom
    per grid frequency (0 where unused).
    """
    n_samples = record.shape[1]
    transform = np.fft.rfft(record, axis=1)  # (n_channels, n_bins), same sum as the grid's kernel at the bins
    bins = 2.0 * np.pi * np.arange(transform.shape[1]) / (n_samples * dt)
    half = np.maximum(SMOOTH_BINS * bins[1], SMOOTH_FRACTION * omega)
    dof = np.zeros(omega.size)
    for g in np.flatnonzero(valid):
        near = (np.abs(bins - omega[g]) <= half[g]) & (bins > 0)
        if near.sum() <= _SINGLE_TERMS:
            spectra[g] = 0.0
            continue
        d = (bins[near] - omega[g]) / half[g]
        xb = transform[x, near]
        design = np.stack([xb, xb * d, xb * d**2, np.ones_like(xb)], axis=1)
        targets = transform[list(outputs)][:, near].T  # (n_b, n_outputs)
        fitted = design @ np.linalg.lstsq(design, targets, rcond=None)[0]
        noise = np.sum(np.abs(targets - fitted) ** 2, axis=0) / (near.sum() - _SINGLE_TERMS) * scale
        for y, n_yy in zip(outputs, noise):
            g_yy = float(np.real(spectra[g, y, y]))
            unbiased = max(1.0 - n_yy / g_yy, _MIN_COHERENCE) if g_yy > 0 else _MIN_COHERENCE
            spectra[g, y, y] = g_yy / unbiased
        dof[g] = 2.0 * (near.sum() - _SINGLE_TERMS)
    return dof


def local_member(
    spectra: np.ndarray,
    records: Sequence[np.ndarray],
    omega: np.ndarray,
    valid: np.ndarray,
    inputs: Sequence[int],
    outputs: Sequence[int],
    scales: Sequence[float],
    dt: float,
) -> np.ndarray:
    """Several inputs from as many records or fewer: `spectra` (in place) rebuilt from the local responses.

    `records` are the tapered, levelled records, each (n_channels, n_samples),
    `scales` what turns each one's squared transform into a density. At each grid frequency the bins of all records are pooled in one local
    regression (above; ``p = 3 q + K``); the member's spectral matrix is then
    the one those estimates imply: ``G_xx`` the inputs' bins averaged,
    ``G_xy = G_xx H_0``, ``G_yy = H_0^H G_xx H_0 + G_nn``, so that conditioning
    returns ``H_0`` and the partial coherence follows from ``G_nn``.
    Returns the degrees of freedom per grid frequency (0 where unused).
    """
    inputs, outputs = list(inputs), list(outputs)
    n_terms = 3 * len(inputs) + len(records)
    transforms = [np.fft.rfft(block, axis=1) * np.sqrt(scale) for block, scale in zip(records, scales)]
    bins = [2.0 * np.pi * np.arange(f.shape[1]) / (block.shape[1] * dt) for f, block in zip(transforms, records)]
    spacing = max(b[1] for b in bins)
    needed = (n_terms + 3) / (2.0 * len(records))  # bins either side for at least 3 more than the coefficients
    half = np.maximum(max(SMOOTH_BINS, needed) * spacing, SMOOTH_FRACTION * omega)
    dof = np.zeros(omega.size)
    spectra[:] = 0.0
    for g in np.flatnonzero(valid):
        rows, targets, xs = [], [], []
        for k, (f, b) in enumerate(zip(transforms, bins)):
            near = (np.abs(b - omega[g]) <= half[g]) & (b > 0)
            d = (b[near] - omega[g]) / half[g]
            x = f[inputs][:, near].T  # (n_b, q)
            offset = np.zeros((near.sum(), len(records)), dtype=complex)
            offset[:, k] = 1.0
            rows.append(np.hstack([x, x * d[:, None], x * d[:, None] ** 2, offset]))
            targets.append(f[outputs][:, near].T)
            xs.append(x)
        design, y = np.vstack(rows), np.vstack(targets)
        if design.shape[0] <= n_terms:
            continue
        coef = np.linalg.lstsq(design, y, rcond=None)[0]
        noise = np.sum(np.abs(y - design @ coef) ** 2, axis=0) / (design.shape[0] - n_terms)
        h = coef[: len(inputs)]  # (q, n_outputs): H_0
        x = np.vstack(xs)
        g_xx = np.conj(x).T @ x / x.shape[0]
        g_xy = g_xx @ h
        g_yy = np.conj(h).T @ g_xx @ h + np.diag(noise)
        spectra[g][np.ix_(inputs, inputs)] = g_xx
        spectra[g][np.ix_(inputs, outputs)] = g_xy
        spectra[g][np.ix_(outputs, inputs)] = np.conj(g_xy).T
        spectra[g][np.ix_(outputs, outputs)] = g_yy
        dof[g] = 2.0 * (design.shape[0] - n_terms)
    return dof
