"""The whole-record member of the composite: each record transformed over its full length.

Windowed estimates are biased wherever the response changes within a
window's spectral lobe or the system remembers its input for longer than a
window: near a closed loop's notch in the mixer input, around an unstable
pair (whose impulse response never decays: the output inside a window keeps
answering input from before it) and next to the sweep's fade-in tone. A
record that starts and ends at trim holds the whole transient, and its
Fourier transforms obey ``Y(omega) = H(omega) X(omega)`` exactly at every
frequency: no window, no leakage, no resolution bias. Averaged over the
``K`` records (``n_d = K``, less one per further input), these spectra are
the composite's longest member.

Two details make the member usable:

* the ends: each record is tapered over its first and last 0.5 s (a
  raised cosine, the rest untouched) and its level over the first 0.5 s (the
  trim flown before the maneuver) removed, so an offset or an unfinished
  response at the ends leaks little;
* its noise: from ``K`` records the output noise ``G_nn`` (the part no
  input explains, :func:`~sysid.freqresp._conditioning.residual_noise`)
  has only ``2 (K - q)`` degrees of freedom per frequency, too few to weigh
  the member by. The noise varies slowly with frequency, so it is averaged
  over ``±max(3 bins, 10 %)`` of each frequency (bins of ``2 pi / T``) and
  put back into the output autospectra, unbiased; the coherence, the
  composite weight and the random error all follow from that smoothed noise
  and the pointwise signal. The composite then uses the member only where its
  output power stands out of that noise at the 1e-4 level
  (:func:`significance_threshold`): with few records a noise-only frequency
  would otherwise now and then look coherent. From as many records as
  inputs or fewer (one sweep per axis, the usual log) there is no residual
  between records: the noise, and with several inputs the responses too,
  come from each record's neighbouring bins (:mod:`sysid.freqresp._local`).

The signal is not smoothed across frequency: in closed loop the mixer
input's notch is a bin or two wide, and weighting ``H`` by ``|X|^2`` over
even ±1 bin brings the bias back (2.5 dB on the octocopter's q/delta_lon at
0.5 rad/s, measured). A whole record also gathers the noise of its whole
length, where a window only that of the seconds the sweep spends near each
frequency, so at high frequency the windows are the better estimates; the
composite's weights (inverse random error) sort that out.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

import numpy as np

from sysid.freqresp._conditioning import residual_noise
from sysid.freqresp._local import local_member, local_noise
from sysid.freqresp._spectra import WindowSpectra

__all__: list[str] = []

EDGE_S = 0.5  # taper at each end, and the stretch whose level is removed, s
SMOOTH_BINS = 3.0  # noise averaged over at least ±3 bins of 2 pi / T ...
SMOOTH_FRACTION = 0.1  # ... or ±10 % of the frequency
SIGNIFICANCE = 1e-4  # chance that a noise-only frequency passes the member's test
_CHUNK = 8192  # samples transformed at once


def whole_record_spectra(
    data: Sequence[np.ndarray],
    dt: float,
    omega: np.ndarray,
    *,
    inputs: Sequence[int],
    outputs: Sequence[int],
    instrument: int | None,
    min_cycles: float,
) -> WindowSpectra | None:
    """Spectral matrix of the records' full-length transforms, noise smoothed; None when it cannot be had.

    `data` holds one array per record, shape (n_channels, n_samples). With
    more records than inputs the noise is measured between them; with as
    many or fewer (one sweep per axis, as most logs have) between each
    record's neighbouring frequency bins (:mod:`sysid.freqresp._local`),
    which needs no reference unless there is one input
    (:func:`member_possible`).
    """
    n_records, n_inputs = len(data), len(inputs)
    if not member_possible(n_records, n_inputs, instrument):
        return None
    n_channels = data[0].shape[0]
    longest = max(block.shape[1] for block in data)
    stacked = np.zeros((n_records * n_channels, longest))  # tapered, levelled, zero beyond each record's end
    energy = 0.0
    edge = max(1, int(round(EDGE_S / dt)))
    for k, block in enumerate(data):
        taper = _edge_taper(block.shape[1], dt)
        stacked[k * n_channels : (k + 1) * n_channels, : block.shape[1]] = (
            block - block[:, :edge].mean(axis=1, keepdims=True)
        ) * taper
        energy += float(np.sum(taper**2))
    scales = [dt / (np.pi * float(np.sum(_edge_taper(block.shape[1], dt) ** 2))) for block in data]
    x = np.zeros((omega.size, n_records * n_channels), dtype=complex)
    for start in range(0, longest, _CHUNK):  # a long record's kernel would not fit in memory at once
        stop = min(start + _CHUNK, longest)
        x += _kernel(omega * dt, start, stop) @ stacked[:, start:stop].T
    x = x.reshape(omega.size, n_records, n_channels)
    spectra = np.einsum("fka,fkb->fab", np.conj(x), x) * (dt / (np.pi * energy))
    lengths_s = [block.shape[1] * dt for block in data]
    omega_low = 2.0 * np.pi * min_cycles / max(lengths_s)
    valid = omega >= omega_low * (1.0 - 1e-12)
    bin_rad_s = 2.0 * np.pi / min(lengths_s)
    scale = dt / (np.pi * energy)
    blocks = [stacked[k * n_channels : (k + 1) * n_channels, : block.shape[1]] for k, block in enumerate(data)]
    if n_records > n_inputs:
        dof = _smooth_noise(spectra, omega, valid, inputs, outputs, instrument, n_records, bin_rad_s)
    elif n_inputs == 1:
        dof = local_noise(spectra, blocks[0], omega, valid, inputs[0], outputs, scale, dt)
    else:
        dof = local_member(spectra, blocks, omega, valid, inputs, outputs, scales, dt)
    spectra[~valid] = 0.0
    return WindowSpectra(
        window_s=max(lengths_s),
        spectra=spectra,
        n_windows=n_records,
        n_effective=float(n_records),
        omega_low=omega_low,
        noise_dof=dof,
    )


def member_possible(n_records: int, n_inputs: int, instrument: int | None) -> bool:
    """Whether the whole-record member can be formed: more records than inputs, one input, or no reference."""
    return n_records > n_inputs or n_inputs == 1 or instrument is None


def whole_record_floor(data: Sequence[np.ndarray], dt: float, omega: np.ndarray, min_cycles: float) -> np.ndarray:
    """The records' whole-length spectral matrix, averaged over them and smoothed across frequency.

    The floor of the whole-record member (records flown without the
    excitation; see :func:`sysid.freqresp.estimate.frequency_responses`):
    each record tapered and levelled as the member's are, the squared
    transforms averaged over the records and over ``±max(3 bins, 10 %)`` of
    each frequency (a floor of feedback and noise is smooth in frequency).
    Shape (n_freq, n_channels, n_channels); zero below ``min_cycles``
    periods of the longest record.
    """
    n_channels = data[0].shape[0]
    edge = max(1, int(round(EDGE_S / dt)))
    spectra = np.zeros((omega.size, n_channels, n_channels), dtype=complex)
    energy = 0.0
    for block in data:
        taper = _edge_taper(block.shape[1], dt)
        levelled = (block - block[:, :edge].mean(axis=1, keepdims=True)) * taper
        x = np.zeros((omega.size, n_channels), dtype=complex)
        for start in range(0, block.shape[1], _CHUNK):
            stop = min(start + _CHUNK, block.shape[1])
            x += _kernel(omega * dt, start, stop) @ levelled[:, start:stop].T
        spectra += np.conj(x)[:, :, None] * x[:, None, :]
        energy += float(np.sum(taper**2))
    spectra *= dt / (np.pi * energy)
    lengths_s = [block.shape[1] * dt for block in data]
    valid = omega >= 2.0 * np.pi * min_cycles / max(lengths_s) * (1.0 - 1e-12)
    half = np.maximum(SMOOTH_BINS * 2.0 * np.pi / min(lengths_s), SMOOTH_FRACTION * omega)
    near = ((np.abs(omega[:, None] - omega[None, :]) <= half[:, None]) & valid[None, :]).astype(float)
    smoothed = np.einsum("fg,gab->fab", near, spectra) / np.maximum(near.sum(axis=1), 1.0)[:, None, None]
    smoothed[~valid] = 0.0
    return cast(np.ndarray, smoothed)


def significance_threshold(noise_dof: np.ndarray, level: float = SIGNIFICANCE) -> np.ndarray:
    """``x`` with ``P(F > x) = level`` for ``F`` of (2, `noise_dof`) degrees of freedom, shape of `noise_dof`.

    The ratio of a cross-spectral power from unrelated signals (2 degrees of
    freedom) to the noise estimate (``noise_dof``) is F-distributed,
    ``P(F > x) = (1 + 2 x / d)^(-d / 2)``; ``ln(1 / level)`` for large ``d``.
    """
    d = np.maximum(np.asarray(noise_dof, dtype=float), 1.0)
    return cast(np.ndarray, d / 2.0 * (level ** (-2.0 / d) - 1.0))


def _edge_taper(n_samples: int, dt: float) -> np.ndarray:
    taper = np.ones(n_samples)
    edge = min(int(round(EDGE_S / dt)), n_samples // 4)
    if edge > 0:
        ramp = 0.5 - 0.5 * np.cos(np.pi * (np.arange(edge) + 0.5) / edge)
        taper[:edge], taper[n_samples - edge :] = ramp, ramp[::-1]
    return taper


def _kernel(step_rad: np.ndarray, start: int, stop: int, block: int = 64) -> np.ndarray:
    """``exp(-j step n)`` for ``start <= n < stop``, shape (n_freq, stop - start), from two small tables
    (``n = start + m block + r``) rather than a sine and cosine per element."""
    n_blocks = -(-(stop - start) // block)
    inner = np.exp(-1j * np.outer(step_rad, np.arange(block)))
    outer = np.exp(-1j * np.outer(step_rad, start + block * np.arange(n_blocks)))
    return (outer[:, :, None] * inner[:, None, :]).reshape(step_rad.size, n_blocks * block)[:, : stop - start]


def _smooth_noise(
    spectra: np.ndarray,
    omega: np.ndarray,
    valid: np.ndarray,
    inputs: Sequence[int],
    outputs: Sequence[int],
    instrument: int | None,
    n_records: int,
    bin_rad_s: float,
) -> np.ndarray:
    """Replace each output's noise in `spectra` (in place) by its frequency average; its degrees of freedom."""
    n_inputs = len(inputs)
    half = np.maximum(SMOOTH_BINS * bin_rad_s, SMOOTH_FRACTION * omega)
    near = (np.abs(omega[:, None] - omega[None, :]) <= half[:, None]) & valid[None, :]  # (n_freq, n_freq)
    counts = near.sum(axis=1)
    independent = np.minimum(counts, 2.0 * half / bin_rad_s + 1.0)
    dof = 2.0 * (n_records - n_inputs) * np.maximum(independent, 1.0)
    kept = (n_records - n_inputs) / n_records  # a residual from K records keeps (K - q) / K of the noise
    for y in outputs:
        raw = np.zeros(omega.size)
        raw[valid] = residual_noise(spectra[valid], inputs, y, instrument)
        smoothed = near.astype(float) @ (raw / kept) / np.maximum(counts, 1)
        spectra[:, y, y] += smoothed * kept - raw
    return np.where(valid, dof, 0.0)
