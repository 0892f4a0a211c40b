"""Multi-window composite: at each frequency, the windows that measure it best count most.

CIFER's COMPOSITE finds, per frequency, the spectra that best fit all
windows' spectra in a weighted least-squares sense. With a diagonal weighting
that solution is the weighted mean, which is what is computed here: the
spectral matrices of the window lengths are averaged per frequency with
weights ``1 / eps_r^2 = 2 n_d gamma^2 / (1 - gamma^2)``, eps_r being each
window's normalised random error (from its own, partial, coherence and its
effective number of averages), and zero below the lowest frequency the window
resolves. The response, coherence and random error then follow from the
composite spectra; the random error uses a weighted mean of ``n_d`` (the
windows reuse the same data, so their errors are not independent and the
composite is credited no more averages than its windows had), each member
counted by its share of the estimate, its weight times the spectrum the
response is divided by (``G_xx``, or ``|G_rx|`` with a reference): a member
whose spectra are larger there carries more of the estimate than its weight.

Both the weights and the random error use the coherence with the bias of a
finite number of averages removed, ``(n_d g^2 - 1) / (n_d - 1)``: unrelated
signals give ``E[g^2] = 1 / n_d``, and a long window with few averages would
otherwise look coherent in noise and claim too small an error. The coherence
reported is the usual estimate, the one thresholds (eq. 3.8) refer to.

The whole-record member (:mod:`sysid.freqresp._whole`), when present, is one
more member weighed the same way, but only where its output power passes its
significance test; where no member is usable the coherence is zero.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np

from sysid.freqresp._conditioning import Estimate, conditioned_spectra, pair_estimate, random_error
from sysid.freqresp._spectra import WindowSpectra
from sysid.freqresp._whole import significance_threshold

__all__: list[str] = []


@dataclass(frozen=True, slots=True, kw_only=True)
class PairEstimate:
    """Composite estimate of one output's response to one input, arrays of shape (n_freq,)."""

    response: np.ndarray
    coherence: np.ndarray
    random_error: np.ndarray
    input_autospectrum: np.ndarray
    output_autospectrum: np.ndarray
    cross_spectrum: np.ndarray
    windows_s: tuple[float, ...]
    whole_record: bool


def composite_pair(
    windows: Sequence[WindowSpectra],
    omega: np.ndarray,
    inputs: Sequence[int],
    j: int,
    y: int,
    instrument: int | None = None,
    floors: Sequence[np.ndarray | None] | None = None,
    min_ratio: float = 4.0,
) -> PairEstimate:
    """Composite estimate of channel `y` against input channel ``inputs[j]`` (conditioned, or by `instrument`).

    `floors`, one per member (None where the quiet records do not reach), are the feedback's spectra: the
    composite floor (the members' weights) is removed from the conditioned spectra, see :func:`_floored`.
    """
    n_conditioned = len(inputs) - 1
    n_d = np.array([max(w.n_effective - n_conditioned, 1.0) for w in windows])
    weights = np.zeros((len(windows), omega.size))
    reach = np.array([omega >= w.omega_low * (1.0 - 1e-12) for w in windows]).reshape(len(windows), omega.size)
    valid = reach.copy()
    for i, window in enumerate(windows):
        gamma2 = pair_estimate(window.spectra[reach[i]], inputs, j, y, instrument).coherence
        if window.noise_dof is not None:  # the whole-record member: only where its signal is significant
            valid[i, reach[i]] = _significant(gamma2, window.n_windows, len(inputs), window.noise_dof[reach[i]])
        single = window.noise_dof is not None and window.n_windows <= len(inputs)  # its coherence is unbiased
        unbiased = np.where(valid[i, reach[i]], gamma2 if single else _unbiased_coherence(gamma2, n_d[i]), 0.0)
        weights[i, reach[i]] = 2.0 * n_d[i] * unbiased / np.maximum(1.0 - unbiased, 1e-12)
    whole = any(w.noise_dof is not None and bool(np.any(weights[k] > 0)) for k, w in enumerate(windows))
    usable = valid.any(axis=0)
    fallback = np.where(usable, valid, reach).astype(float)  # no coherence anywhere: plain mean of the members
    weights = np.where(weights.sum(axis=0) > 0, weights, fallback)
    weights /= np.maximum(weights.sum(axis=0), np.finfo(float).tiny)
    stacked = np.stack([window.spectra for window in windows])  # (n_windows, n_freq, n_ch, n_ch)
    spectra = np.einsum("if,ifab->fab", weights, stacked)
    estimate = pair_estimate(spectra, inputs, j, y, instrument)
    gamma2 = np.where(usable, estimate.coherence, 0.0)
    response = estimate.response
    if floors is not None and instrument is None:
        response, excited = _floored(estimate, floors, weights, inputs, j, y, min_ratio)
        gamma2 = np.where(excited, gamma2, 0.0)
    # averages credited: each member's, by its share of the estimate (weight x the spectrum H is divided by)
    divisor = instrument if instrument is not None and j == 0 else inputs[j]
    share = weights * np.abs(stacked[:, :, divisor, inputs[j]])
    n_d_mean = np.where(
        share.sum(axis=0) > 0, (share.T @ n_d) / np.maximum(share.sum(axis=0), np.finfo(float).tiny), weights.T @ n_d
    )
    used = tuple(float(w.window_s) for k, w in enumerate(windows) if w.noise_dof is None and np.any(weights[k] > 0))
    return PairEstimate(
        response=response,
        coherence=gamma2,
        random_error=random_error(_unbiased_coherence(gamma2, n_d_mean), n_d_mean),
        input_autospectrum=estimate.g_jj,
        output_autospectrum=estimate.g_yy,
        cross_spectrum=estimate.g_jy if response is estimate.response else response * estimate.g_jj,
        windows_s=used,
        whole_record=whole,
    )


def _floored(
    estimate: Estimate,
    floors: Sequence[np.ndarray | None],
    weights: np.ndarray,
    inputs: Sequence[int],
    j: int,
    y: int,
    min_ratio: float,
) -> tuple[np.ndarray, np.ndarray]:
    """The response with the feedback floor removed, and where the excitation dominates the input.

    The floor is averaged with the members' weights (those with a floor, renormalised) and conditioned as
    the estimate was: ``H = (G_jy - F_jy) / (G_jj - F_jj)`` where ``G_jj >= min_ratio F_jj``. Where no
    member has a floor the response is left as it is and counts as excited.
    """
    shape = next(f for f in floors if f is not None).shape
    have = np.array([f is not None for f in floors], dtype=float)[:, None] * weights
    norm = have.sum(axis=0)
    stacked = np.stack([f if f is not None else np.zeros(shape, dtype=complex) for f in floors])
    floor = np.einsum("if,ifab->fab", have / np.maximum(norm, np.finfo(float).tiny), stacked)
    f_jj, _, f_jy = conditioned_spectra(floor, inputs[j], [k for n, k in enumerate(inputs) if n != j], y)
    known = norm > 0
    excited = ~known | (estimate.g_jj >= min_ratio * f_jj)
    corrected = (estimate.g_jy - f_jy) / np.maximum(estimate.g_jj - f_jj, np.finfo(float).tiny)
    return np.where(known & excited, corrected, estimate.response), excited


def _significant(gamma2: np.ndarray, n_records: float, n_inputs: int, noise_dof: np.ndarray) -> np.ndarray:
    """Whether the whole-record member's output power stands out of its smoothed noise (F test, see ``_whole``).

    Its autospectra carry the noise as ``(K - q) / K`` of the smoothed estimate, so signal over noise is
    ``(K - q) / K g^2 / (1 - g^2)``; the statistic is ``n_d`` times that, ``n_d = K - q + 1``. From one
    record of one input the coherence is already ``1 - G_nn / G_yy``: the statistic is ``G_yy / G_nn =
    1 / (1 - g^2)``.
    """
    if n_records <= n_inputs:
        return cast(np.ndarray, 1.0 / np.maximum(1.0 - gamma2, 1e-300) > significance_threshold(noise_dof))
    n_d = n_records - n_inputs + 1
    statistic = n_d * (n_records - n_inputs) / n_records * gamma2 / np.maximum(1.0 - gamma2, 1e-300)
    return statistic > significance_threshold(noise_dof)


def _unbiased_coherence(gamma2: np.ndarray, n_d: float | np.ndarray) -> np.ndarray:
    """Coherence with the bias of few averages removed: ``(n_d g^2 - 1) / (n_d - 1)``, clipped to [0, 1].

    Unrelated signals give ``E[g^2] = 1 / n_d``, not 0; without the correction a
    long window with a handful of averages would look coherent in noise and
    be trusted over a short one with hundreds. One average carries no weight.
    """
    n = np.asarray(n_d, dtype=float)
    corrected = (n * gamma2 - 1.0) / np.maximum(n - 1.0, 1e-12)
    return np.where(n > 1.0, np.clip(corrected, 0.0, 1.0), 0.0)
