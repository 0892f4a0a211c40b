"""Maneuver detection in mixer inputs, behind :func:`flightlogs.maneuvers.segments.detect_segments`.

Per axis: a robust trend is removed and short moving envelopes are
normalised by noise floors (:func:`_activity`); bursts above a threshold are
merged, shared between axes (:func:`_assign`), given edges against a local
baseline (:func:`_edges`) and classified from their half-waves
(:func:`_classify`). Inputs are checked by the caller; indices are samples of
the uniform time base.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Literal, NamedTuple, cast

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from flightlogs._moving import dilate, moving_mean
from flightlogs._threads import map_traces
from flightlogs.maneuvers import _rank
from flightlogs.maneuvers._rank import spearman
from flightlogs.masks import true_runs

__all__: list[str] = []

_SHORT_S = 0.2  # window of the short moving mean and RMS, s
_TREND_KNOTS_PER_WINDOW = 8  # robust trend: fits per window length, joined by straight lines
_TREND_RATE_HZ = 100.0  # robust trend: fitted to at most this many samples a second
_TREND_MEDIAN_SAMPLES = 256  # robust trend: its starting moving median takes at most this many samples a window
_ROBUST_SAMPLES = 50_000  # noise floors: order statistics of at most this many evenly spaced samples
_GUARD_S, _BASELINE_S = 1.0, 10.0  # edge baseline: fitted from 11 s to 1 s before the burst
_QUADRATIC_S = 3.0  # edge baseline: straight below this much quiet trace, quadratic above
_LOOK_IN_S = 3.0  # edge baseline: trusted this far into a burst, s
_CALM = 3.0  # edges: calm within 3 noise σ ...
_RELATIVE_FLOOR = 0.015  # ... or within 1.5 % of the burst's peak, however clean the trace
_EDGE_PASSES = 6  # edges: searched again from the last edge found until they settle

ManeuverKind = Literal["sweep", "multisine", "doublet", "3211"]


@dataclass(frozen=True, slots=True, kw_only=True)
class FoundManeuver:
    """A maneuver of a known kind found by :func:`find_maneuvers`.

    Parameters
    ----------
    axis : str
        The axis whose input owns it.
    kind : str
        ``"sweep"``, ``"multisine"``, ``"doublet"`` or ``"3211"``.
    first, last : int
        Its first and last sample (inclusive), indices of the uniform time base.
    f_min_hz, f_max_hz : float or None
        Frequency range of a sweep or multisine, Hz; None for doublets and 3211s.
    """

    axis: str
    kind: ManeuverKind
    first: int
    last: int
    f_min_hz: float | None
    f_max_hz: float | None


class _Burst(NamedTuple):
    """A run of activity on one axis, merged over short pauses: inclusive sample range and 95th-percentile score."""

    axis: str
    first: int
    last: int
    score: float


class _Lobe(NamedTuple):
    """A half-wave of a trace: its sign, begin and end time (s) and signed area."""

    sign: int
    begin_s: float
    end_s: float
    area: float


class _Shape(NamedTuple):
    """What :func:`_classify` recognised: the kind, its frequency range (Hz), refined bounds for steps."""

    kind: ManeuverKind
    f_min_hz: float | None
    f_max_hz: float | None
    span: tuple[int, int] | None = None  # first and last loud sample of a doublet or 3211


def find_maneuvers(
    t: np.ndarray,
    dt: float,
    traces: dict[str, np.ndarray],
    threshold: float,
    trend_window_s: float,
    merge_gap_s: float,
    min_active_s: float,
) -> tuple[list[FoundManeuver], list[tuple[int, int]]]:
    """Maneuvers found in `traces` and the sample ranges kept busy by any activity.

    Parameters
    ----------
    t : ndarray, shape (n_samples,)
        Uniform sample times, s.
    dt : float
        Their interval, s.
    traces : dict of str to ndarray, shape (n_samples,)
        Finite mixer input by axis.
    threshold, trend_window_s, merge_gap_s, min_active_s : float
        As in :func:`flightlogs.maneuvers.segments.detect_segments`.

    Returns
    -------
    maneuvers : list of FoundManeuver
        Each maneuver of a known kind, in the order the bursts start.
    busy : list of (int, int)
        Inclusive index ranges of every maneuver and every reaction to one.
    """
    acts = dict(zip(traces, map_traces(lambda x: _activity(x, dt, threshold, trend_window_s), traces.values())))
    bursts = [b for axis, act in acts.items() for b in _bursts(axis, act, dt, threshold, merge_gap_s, min_active_s)]
    maneuvers: list[FoundManeuver] = []
    busy: list[tuple[int, int]] = []
    margin = int(round(_GUARD_S / dt))
    for owner, reactions in _assign(bursts):
        axis, i0, i1 = owner.axis, owner.first, owner.last
        others = [b for b in bursts if b is not owner and b not in reactions]
        before = max((b.last + margin for b in others if b.last < i0), default=0)
        after = min((b.first - margin for b in others if b.first > i1), default=t.size - 1)
        lo, hi = _edges(acts[axis], i0, i1, dt, (min(before, i0), max(after, i1)), threshold)
        busy += [(lo, hi)] + [(b.first, b.last) for b in reactions]
        shape = _classify(acts[axis], t, lo, hi, threshold)
        if shape is not None:
            first, last = shape.span if shape.span is not None else (lo, hi)
            maneuvers.append(
                FoundManeuver(
                    axis=axis, kind=shape.kind, first=first, last=last, f_min_hz=shape.f_min_hz, f_max_hz=shape.f_max_hz
                )
            )
    return maneuvers, busy


@dataclass(frozen=True, slots=True, kw_only=True)
class _Activity:
    """One axis: raw and detrended trace (n_samples,), normalised envelopes, noise σ of both."""

    raw: np.ndarray
    detrended: np.ndarray
    mean_z: np.ndarray  # |0.2 s moving mean| / sigma_mean
    rms_z: np.ndarray  # 0.2 s moving RMS / sigma
    sigma: float
    sigma_mean: float

    def flipped(self) -> _Activity:
        """The same axis with time reversed (to find an end as a start)."""
        return _Activity(
            raw=self.raw[::-1],
            detrended=self.detrended[::-1],
            mean_z=self.mean_z[::-1],
            rms_z=self.rms_z[::-1],
            sigma=self.sigma,
            sigma_mean=self.sigma_mean,
        )


def _activity(x: np.ndarray, dt: float, threshold: float, trend_window_s: float) -> _Activity:
    """Detrend one axis and normalise its short envelopes by noise floors of quiet stretches."""
    xd = x - _subsampled_trend(x, dt, trend_window_s)
    width = max(1, int(round(_SHORT_S / dt)))
    mean = np.abs(moving_mean(xd, width))
    rms = np.sqrt(np.maximum(moving_mean(xd * xd, width), 0.0))  # rounding can dip below 0
    tiny = 1e-12 * max(1.0, float(np.max(np.abs(xd))))
    quiet = np.ones(xd.size, dtype=bool)
    for quantile in (0.25, 0.5, 0.5, 0.5):  # the first pass may see more maneuver than quiet
        sigma = max(_robust_std(xd[quiet], quantile), tiny)
        sigma_mean = max(_robust_std(mean[quiet], quantile, centred=True), tiny)
        calm = ~dilate(np.maximum(mean / sigma_mean, rms / sigma) > threshold, int(1 / dt))
        if calm.sum() < 10:
            break
        quiet = calm
    return _Activity(
        raw=x, detrended=xd, mean_z=mean / sigma_mean, rms_z=rms / sigma, sigma=sigma, sigma_mean=sigma_mean
    )


def _subsampled_trend(x: np.ndarray, dt: float, window_s: float) -> np.ndarray:
    """:func:`_trend` over `window_s`, fitted to at most `_TREND_RATE_HZ` samples a second and interpolated back.

    A trend that varies over seconds is as well fitted to 100 samples a second
    as to 400, at a quarter of the cost.
    """
    every = max(1, int(1.0 / (dt * _TREND_RATE_HZ) + 1e-9))
    if every == 1 or x.size < 2 * every:
        return _trend(x, max(3, int(round(window_s / dt)) | 1))
    kept = np.arange(0, x.size, every)  # the last few samples take the last fit's value
    coarse = _trend(x[kept], max(3, int(round(window_s / (dt * every))) | 1))
    return cast(np.ndarray, np.interp(np.arange(x.size), kept, coarse))


def _trend(x: np.ndarray, width: int) -> np.ndarray:
    """Robust moving quadratic (bisquare weights, from a moving median): trim and drift, not maneuvers.

    A maneuver's lobes lose their weight, so the trend runs through the quiet
    samples and the zero crossings and follows a curving drift without lag.
    The fits are made every eighth of a window (`_TREND_KNOTS_PER_WINDOW`)
    and joined by straight lines: a trend varies over a window, not a sample,
    and the cost stays linear in the trace's length.
    """
    half = width // 2
    idx = np.arange(x.size)
    stride = max(1, width // _TREND_KNOTS_PER_WINDOW)
    centres = np.unique(np.r_[idx[::stride], x.size - 1])
    mirrored = np.pad(x, (half, half), mode="symmetric")
    every = max(1, width // _TREND_MEDIAN_SAMPLES)  # the starting trend: each window's median of evenly spaced samples
    trend = np.interp(idx, centres, np.median(sliding_window_view(mirrored, width)[centres, ::every], axis=1))

    def moments(signal: np.ndarray, k: int) -> np.ndarray:  # sum over each window of signal × (local time)^0..k-1
        return _window_moments(signal, half, stride, k)

    for _ in range(3):
        resid = x - trend
        r = resid / (4.685 * max(_robust_std(resid, 0.25), 1e-12 * (1.0 + float(np.max(np.abs(x))))))
        w = np.where(np.abs(r) < 1, (1 - r * r) ** 2, 0.0)
        m0, m1, m2, m3, m4 = moments(w, 5).T
        b0, b1, b2 = moments(w * x, 3).T
        # normal equations [[m0 m1 m2] [m1 m2 m3] [m2 m3 m4]] c = b; the trend is c0 (Cramer's rule)
        minor = m2 * m4 - m3 * m3
        det = m0 * minor - m1 * (m1 * m4 - m3 * m2) + m2 * (m1 * m3 - m2 * m2)
        good = (m0 > 0.2 * half) & (np.abs(det) > 1e-6 * m0**3)
        if good.sum() < 2:
            break
        c0 = (b0 * minor - m1 * (b1 * m4 - m3 * b2) + m2 * (b1 * m3 - m2 * b2))[good] / det[good]
        trend = np.interp(idx, centres[good], c0)
    return cast(np.ndarray, trend)


def _window_moments(signal: np.ndarray, half: int, stride: int, k: int) -> np.ndarray:
    """``sum_u signal[c + u] (u / half)^p`` over ``u = -half..half`` (zero beyond the ends), ``p < k``.

    At the centres ``c = 0, stride, 2 stride, ...`` and the last sample, as :func:`_trend`
    places them; shape (n_centres, k). With ``8 stride <= 2 half + 1``, a window is eight
    blocks of `stride` samples and a short tail: each block's own moments (one matrix
    product over the trace) are moved to the window's centre by the binomial theorem, so
    the cost is one pass over the trace, not one per window.
    """
    n = signal.size
    tail = 2 * half + 1 - 8 * stride  # samples of a window after its eight blocks
    if tail < 0:  # windows shorter than eight strides: each window directly
        centres = np.unique(np.r_[np.arange(0, n, stride), n - 1])
        powers_of_time = (np.arange(-half, half + 1) / half)[:, None] ** np.arange(k)
        return cast(np.ndarray, sliding_window_view(np.pad(signal, half), 2 * half + 1)[centres] @ powers_of_time)
    regular = np.arange(0, n, stride)
    blocks_needed = regular.size + 8
    length = max(blocks_needed * stride, int(regular[-1]) + 2 * half + 1)
    padded = np.zeros(length + stride)
    padded[half : half + n] = signal
    local, shifts, after, whole = _moment_kernels(half, stride, k)
    block = padded[: blocks_needed * stride].reshape(blocks_needed, stride) @ local  # (blocks, k)
    eight = sliding_window_view(block[: regular.size + 7], 8, axis=0)  # (n_regular, k, 8): a window's blocks
    out = np.einsum("ijq,qjp->ip", eight, shifts)
    if tail:
        out += padded[regular[:, None] + 8 * stride + np.arange(tail)] @ after
    if regular[-1] != n - 1:  # the last sample, off the stride: its window directly
        out = np.vstack([out, padded[n - 1 : n - 1 + 2 * half + 1] @ whole])
    return cast(np.ndarray, out)


@lru_cache(maxsize=64)
def _moment_kernels(half: int, stride: int, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """For :func:`_window_moments`: a block's local powers (stride, k); the binomial shifts of the
    eight blocks to the window's centre (8, k, k); the tail's powers (tail, k); a whole window's (width, k)."""
    powers = np.arange(k)
    local = (np.arange(stride) / half)[:, None] ** powers
    binomial = np.array([[math.comb(p, j) for p in powers] for j in powers], dtype=np.float64)
    shifts = np.empty((8, k, k))
    for q in range(8):  # block q starts q stride - half samples from the centre
        offset = (q * stride - half) / half
        lifted = np.maximum(powers[None, :] - powers[:, None], 0)
        shifts[q] = binomial * np.where(powers[None, :] >= powers[:, None], offset**lifted, 0.0)
    tail = 2 * half + 1 - 8 * stride
    after = ((8 * stride + np.arange(tail) - half) / half)[:, None] ** powers
    whole = (np.arange(-half, half + 1) / half)[:, None] ** powers
    for kernel in (local, shifts, after, whole):
        kernel.flags.writeable = False  # shared by every call with these sizes
    return local, shifts, after, whole


def _robust_std(x: np.ndarray, quantile: float = 0.5, *, centred: bool = False) -> float:
    """σ of the quietest part of `x` from a quantile of |x - median| (0.5: 1.4826 × MAD).

    A lower quantile stays right when maneuvers fill more than half the
    record; `centred` takes x as already |deviations|. Falls back to the
    standard deviation for quantised traces. A long trace is read at evenly
    spaced samples, at most `_ROBUST_SAMPLES` of them: the order statistics
    of a noise floor need no more, and the cost stays flat in log length.
    """
    if x.size > _ROBUST_SAMPLES:
        x = x[:: -(-x.size // _ROBUST_SAMPLES)]
    dev = x if centred else np.abs(x - _rank.median(x))
    spread = _rank.quantile(dev, quantile) / {0.5: 0.6745, 0.25: 0.3186}[quantile]
    return spread if spread > 0 else float(np.std(x))


def _bursts(axis: str, act: _Activity, dt: float, threshold: float, merge_s: float, active_s: float) -> list[_Burst]:
    """Each burst: active runs merged over short pauses."""
    active = np.maximum(act.mean_z, act.rms_z) > threshold
    merged: list[list[int]] = []
    for a, stop in true_runs(active):
        b = stop - 1  # a burst spans samples first..last inclusive
        if merged and (a - merged[-1][1]) * dt < merge_s:
            merged[-1][1] = b
        else:
            merged.append([a, b])
    score = np.maximum(act.mean_z, act.rms_z)
    return [
        _Burst(axis=axis, first=a, last=b, score=_rank.quantile(score[a : b + 1], 0.95))
        for a, b in merged
        if active[a : b + 1].sum() * dt >= active_s
    ]


def _assign(bursts: list[_Burst]) -> list[tuple[_Burst, list[_Burst]]]:
    """Greedy: the strongest burst owns a maneuver; weaker bursts overlapping it are its reactions."""
    pending: list[_Burst] = sorted(bursts, key=lambda b: -b.score)
    owned: list[tuple[_Burst, list[_Burst]]] = []
    while pending:
        owner, rest = pending[0], pending[1:]
        reactions = [b for b in rest if b.first <= owner.last and b.last >= owner.first]
        pending = [b for b in rest if b not in reactions]
        owned.append((owner, reactions))
    return sorted(owned, key=lambda pair: pair[0].first)


def _edges(act: _Activity, i0: int, i1: int, dt: float, limits: tuple[int, int], threshold: float) -> tuple[int, int]:
    """First and last sample of the maneuver around burst [i0, i1], within `limits`.

    The end is found as the start of the time-reversed trace. Each edge is
    searched again from where it was found until it settles, so the baseline
    ends up next to the edge even when noise misplaced the burst boundary.
    """
    peak, n, back = float(np.max(np.abs(act.detrended[i0 : i1 + 1]))), act.raw.size, act.flipped()
    lo, hi = i0, n - 1 - i1
    for _ in range(_EDGE_PASSES):
        lo, before = _onset(act, lo, dt, (limits[0], i1), peak, threshold), lo
        if lo == before:
            break
    for _ in range(_EDGE_PASSES):
        hi, before = _onset(back, hi, dt, (n - 1 - limits[1], n - 1 - i0), peak, threshold), hi
        if hi == before:
            break
    return lo, max(n - 1 - hi, lo + 1)


def _onset(act: _Activity, core: int, dt: float, limits: tuple[int, int], peak: float, threshold: float) -> int:
    """Last calm sample before the trace leaves its local baseline near `core`.

    The baseline is a robust polynomial through up to `_BASELINE_S` of trace
    ending `_GUARD_S` before `core`, extended `_LOOK_IN_S` past it: a fade-in
    too weak to detect lies in the guard, not in the fit, and a curving drift
    is followed.
    """
    guard, x = int(round(_GUARD_S / dt)), act.raw
    lo = max(core - guard - int(round(_BASELINE_S / dt)), limits[0], 0)
    hi = int(min(core + _LOOK_IN_S / dt, limits[1], x.size - 1))
    fit_end = max(lo, core - guard)
    t = (np.arange(lo, hi + 1) - core) * dt
    n_fit = fit_end - lo + 1
    if n_fit >= max(3, int(round(0.5 / dt))):
        degree = 2 if n_fit * dt >= _QUADRATIC_S else 1
        d = x[lo : hi + 1] - _robust_poly(t[:n_fit], x[lo : fit_end + 1], degree, t)
    else:
        d = act.detrended[lo : hi + 1]
    width = max(1, int(round(_SHORT_S / dt)))
    mean = np.abs(moving_mean(d, width))
    rms = np.sqrt(np.maximum(moving_mean(d * d, width), 0.0))
    floor = _RELATIVE_FLOOR * peak
    loud = (mean > max(threshold * act.sigma_mean, 2 * floor)) | (rms > max(threshold * act.sigma, 2 * floor))
    calm = (mean < max(_CALM * act.sigma_mean, floor)) & (rms < max(_CALM * act.sigma, floor))
    leaving = np.flatnonzero(loud[fit_end - lo :])
    first = fit_end - lo + int(leaving[0]) if leaving.size else core - lo
    quiet = np.flatnonzero(calm[:first])
    return lo + int(quiet[-1]) if quiet.size else lo


def _robust_poly(t: np.ndarray, x: np.ndarray, degree: int, at: np.ndarray) -> np.ndarray:
    """Polynomial fit of x(t), re-weighted twice with bisquare weights, evaluated at `at`."""
    w = np.ones_like(x)
    for _ in range(3):
        coef = np.polyfit(t, x, degree, w=np.sqrt(w))
        resid = x - np.polyval(coef, t)
        r = resid / (4.685 * max(_robust_std(resid), 1e-12 * (1.0 + float(np.max(np.abs(x))))))
        w = np.where(np.abs(r) < 1, (1 - np.minimum(r * r, 1.0)) ** 2, 0.0)
        if np.count_nonzero(w) <= degree + 1:
            break
    return np.polyval(coef, at)


def _lobes(x: np.ndarray, t: np.ndarray, h: float) -> list[_Lobe]:
    """The half-waves of `x`, cut at zero crossings with hysteresis h.

    A half-wave begins at the zero crossing before `x` passes ±h with the
    other sign; the first begins at t[0], the last ends at t[-1].
    """
    state = np.where(x > h, 1, np.where(x < -h, -1, 0))
    loud = np.flatnonzero(state)
    if loud.size == 0:
        return []
    firsts = loud[np.r_[0, np.flatnonzero(np.diff(state[loud]) != 0) + 1]]
    idx = np.arange(x.size)
    last_nonpos = np.maximum.accumulate(np.where(x <= 0, idx, 0))
    last_nonneg = np.maximum.accumulate(np.where(x >= 0, idx, 0))
    bounds = [float(t[0])]
    for a in firsts[1:]:
        j = int(last_nonpos[a] if state[a] > 0 else last_nonneg[a])
        bounds.append(float(t[j] + x[j] / (x[j] - x[j + 1]) * (t[j + 1] - t[j])))
    bounds.append(float(t[-1]))
    cum = np.r_[0.0, np.cumsum(0.5 * (x[1:] + x[:-1]) * np.diff(t))]
    areas = np.diff(np.interp(bounds, t, cum))
    return [
        _Lobe(sign=int(state[a]), begin_s=b, end_s=e, area=float(s))
        for a, b, e, s in zip(firsts, bounds[:-1], bounds[1:], areas)
    ]


def _classify(act: _Activity, t: np.ndarray, lo: int, hi: int, threshold: float) -> _Shape | None:
    """Kind and frequency range of the maneuver on samples [lo, hi], or None.

    Doublets and 3211s come with refined bounds: the first and last sample
    of their two (four) lobes that stand out of the noise (and above 3 % of
    their peak), since their edges are steps.
    """
    x, h = act.detrended[lo : hi + 1], threshold * act.sigma
    lobes = _lobes(x, t[lo : hi + 1], h)
    if len(lobes) >= 8:
        return _oscillation(lobes)
    if not lobes:
        return None
    areas = np.array([abs(lobe.area) for lobe in lobes])
    durations = np.array([lobe.end_s - lobe.begin_s for lobe in lobes])
    big = np.flatnonzero(areas >= 0.25 * areas.max())
    if big.size == 2 and big[1] == big[0] + 1:
        area_ratio, time_ratio = areas[big[1]] / areas[big[0]], durations[big[1]] / durations[big[0]]
        if 1 / 3 <= area_ratio <= 3 and 1 / 3 <= time_ratio <= 3:
            return _Shape("doublet", None, None, _loud_span(x, t, lo, lobes[big[0]], lobes[big[1]], h))
    if big.size == 3 and np.all(np.diff(big) == 1):
        # closed loop: the rate loop cancels each edge of the doublet, leaving +, -, + (middle largest);
        # the third lobe is the recovery after the doublet has ended
        signs = [lobes[i].sign for i in big]
        if signs[0] == signs[2] == -signs[1] and areas[big[1]] == areas[big].max():
            return _Shape("doublet", None, None, _loud_span(x, t, lo, lobes[big[0]], lobes[big[1]], h))
    if big.size == 4 and np.all(np.diff(big) == 1):
        # the outer pulses run from the first loud sample and to the last: their steps, not the
        # zero crossings the noise or the loop's settling move away from them
        first, last = _loud_span(x, t, lo, lobes[big[0]], lobes[big[3]], h)
        steps = durations[big].copy()
        steps[0], steps[3] = lobes[big[0]].end_s - t[first], t[last] + (t[1] - t[0]) - lobes[big[3]].begin_s
        unit = steps.sum() / 7.0
        if unit > 0 and np.all(np.abs(steps / unit - [3, 2, 1, 1]) <= [1.0, 0.7, 0.4, 0.4]):
            return _Shape("3211", None, None, (first, last))
    pair = _dominant_pair(lobes, areas)
    if pair is not None:
        return _Shape("doublet", None, None, _loud_span(x, t, lo, lobes[pair], lobes[pair + 1], h))
    return None


def _loud_span(x: np.ndarray, t: np.ndarray, lo: int, first: _Lobe, second: _Lobe, h: float) -> tuple[int, int]:
    """Absolute indices of the first and last sample from lobe `first` to `second` that are loud.

    Loud: above `h` in magnitude and above twice the relative floor of the
    peak, as for the edges (a trace almost free of noise may still drift by
    a fraction of a percent before its first step).
    """
    local = t[lo : lo + x.size]
    span = (local >= first.begin_s) & (local <= second.end_s)
    if not span.any():
        return _span(t, lo, first.begin_s, second.end_s)
    level = max(h, 2 * _RELATIVE_FLOOR * float(np.max(np.abs(x[span]))))
    inside = np.flatnonzero(span & (np.abs(x) > level))
    if inside.size == 0:
        return _span(t, lo, first.begin_s, second.end_s)
    return lo + int(inside[0]), lo + int(inside[-1])


def _dominant_pair(lobes: list[_Lobe], areas: np.ndarray) -> int | None:
    """Index of the adjacent opposite pair of lobes that holds most of the burst, if it looks like a doublet.

    In closed loop with an unstable airframe the controller's reaction adds
    lobes before and after; the doublet itself is the adjacent pair of
    opposite sign with the largest area, of similar size (ratio 1/3 to 3),
    holding at least 45 % of the burst's area.
    """
    best, best_area = None, 0.0
    for i in range(len(lobes) - 1):
        if lobes[i].sign == -lobes[i + 1].sign and 1 / 3 <= areas[i + 1] / areas[i] <= 3:
            if areas[i] + areas[i + 1] > best_area:
                best, best_area = i, areas[i] + areas[i + 1]
    return best if best is not None and best_area >= 0.45 * areas.sum() else None


def _span(t: np.ndarray, lo: int, begin_s: float, end_s: float) -> tuple[int, int]:
    """Sample indices (absolute) of the times `begin_s`..`end_s` inside the burst starting at `lo`."""
    del lo  # t is the full time base; kept for symmetry with the caller's indices
    return int(np.searchsorted(t, begin_s)), min(int(np.searchsorted(t, end_s)), t.size - 1)


def _oscillation(lobes: list[_Lobe]) -> _Shape:
    """Sweep (frequency trend, or one frequency) or multisine, from the half-wave durations."""
    durations = np.array([lobe.end_s - lobe.begin_s for lobe in lobes[:-1]])  # the last may be cut short
    freq = 0.5 / durations
    mid = np.array([0.5 * (lobe.begin_s + lobe.end_s) for lobe in lobes[:-1]])
    smooth = np.array([np.median(freq[max(0, i - 1) : i + 2]) for i in range(freq.size)])
    f_min, f_max = float(min(freq[0], smooth.min())), float(smooth.max())
    if (abs(spearman(mid, freq)) > 0.6 and f_max > 2 * f_min) or f_max < 1.5 * f_min:
        return _Shape("sweep", f_min, f_max)
    return _Shape("multisine", f_min, f_max)


def hover_spans(
    t: np.ndarray, busy: list[tuple[int, int]], min_hover_s: float, margin_s: float
) -> list[tuple[float, float]]:
    """``(start_s, end_s)`` of the stretches at least `min_hover_s` long and `margin_s` from any `busy` range."""
    quiet = np.ones(t.size, dtype=bool)
    pad = int(round(margin_s / (t[1] - t[0])))
    for lo, hi in busy:
        quiet[max(0, lo - pad) : hi + pad + 1] = False
    return [(float(t[a]), float(t[b - 1])) for a, b in true_runs(quiet) if t[b - 1] - t[a] >= min_hover_s]
