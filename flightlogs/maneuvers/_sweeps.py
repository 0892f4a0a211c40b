"""Frequency sweeps found by their time-frequency signature, from an axis's input and responses together.

In closed loop the feedback cancels most of a sweep's low-frequency part in
the mixer input, while the rates and angles that follow it show it clearly;
at high frequency it is the other way round. Each trace of an axis (its
input, its reference, its rate and angle) is turned into constant-Q band
envelopes normalised by their own noise floor (:mod:`._scalogram`), and the
axis's score at each time and frequency is the best of its traces. A sweep
is a stretch where that score stands far out of the noise along one ridge
whose frequency rises or falls steadily (Spearman's ρ of log frequency
against time) over at least a 3:1 range and 15 s — neither the trim nor a
pilot's repositioning has that. A Schroeder-phased multisine sweeps its band
once a period: its ridge is a saw-tooth of short, like pieces, and it is
reported as a multisine. A doublet's ring-down can fall steadily for a
while; the caller lets the strict doublet fit win there. Edges are found in
the time domain, on each trace, where it leaves its local baseline
(:func:`._detection._edges`): the earliest start and the latest end.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from flightlogs._moving import moving_rank
from flightlogs._threads import map_traces
from flightlogs.maneuvers._detection import _activity, _bursts, _edges
from flightlogs.maneuvers._rank import spearman
from flightlogs.maneuvers._scalogram import band_envelopes, band_frequencies
from flightlogs.masks import true_runs

__all__: list[str] = []

_F_MIN_HZ, _F_MAX_HZ, _PER_OCTAVE, _CYCLES = 0.05, 15.0, 6, 4.0
_FRAME_S = 0.1  # time step of the envelopes, s
_FLOOR_QUANTILE = 0.2  # a band's noise floor: this quantile of its envelope over the quiet frames
_FLOOR_FRAMES = 20_000  # noise floors: read from at most this many evenly spaced frames
_SCORE = 6.0  # a frame is on the ridge when its best band (median over _SMOOTH_S) stands this many floors out
_SMOOTH_S = 1.0  # running median of the ridge's score and log frequency, s
_MAX_JUMP_OCTAVES = 0.5  # the ridge of one sweep moves less than this from one frame to the next
_MERGE_S = 3.0  # pieces of ridge closer than this, continuing each other, are one
_MIN_SWEEP_S = 15.0  # shortest sweep, s (a shorter sweeping piece counts only repeated: a multisine's period)
_MIN_PERIOD_S = 4.0  # shortest sweeping piece, s
_MIN_RHO = 0.8  # Spearman ρ of log ridge frequency against time, in magnitude
_MIN_RATIO = 3.0  # ridge frequency range (90th over 10th percentile)
_MIN_MEDIAN_SCORE = 10.0  # median score along a sweep's ridge
_DYNAMIC_RANGE = 0.01  # a band's floor is at least this fraction of its median envelope (a held setpoint has none)
_YIELD = 3.0  # a frame where another axis scores this many times higher is that axis's
_THRESHOLD, _TREND_S, _BURST_MERGE_S, _MIN_ACTIVE_S = 4.0, 10.0, 2.0, 0.3  # time-domain edges, as detect_segments
_HELD = 1e-9  # a trace whose quiet noise is below this fraction of its peak is held (a setpoint), not measured
_EDGE_WINDOW_S = 15.0  # edges are searched this far outside the ridge, s
_INTEGRAL_OF = {"phi": "p", "theta": "q", "vd": "az"}  # a trace, and the trace it integrates


@dataclass(frozen=True, slots=True, kw_only=True)
class FoundSweep:
    """A sweep found on one axis.

    Parameters
    ----------
    axis : str
        The axis that owns it.
    kind : {"sweep", "multisine", "broadband"}
        One sweep, a periodic (Schroeder-phased) multisine sweeping its band once a period, or a
        pilot's broadband input without a frequency trend (not a sweep: no trend to call one).
    first, last : int
        Its first and last sample (inclusive).
    f_min_hz, f_max_hz : float
        Range of its ridge frequency, Hz.
    direction : {"up", "down", "none"}
        Whether the frequency rises or falls; "none" for a pilot's broadband input without a trend.
    evidence : tuple of str
        The traces that carry it, strongest first.
    score : float
        Median ridge score over the sweep, in noise floors.
    """

    axis: str
    kind: Literal["sweep", "multisine", "broadband"]
    first: int
    last: int
    f_min_hz: float
    f_max_hz: float
    direction: Literal["up", "down", "none"]
    evidence: tuple[str, ...]
    score: float


@dataclass(frozen=True, slots=True, kw_only=True)
class _Ridge:
    """One axis's ridge: best-band score and frequency per frame, and the best trace per frame."""

    score: np.ndarray  # (n_frames,)
    freq_hz: np.ndarray  # (n_frames,)
    trace: np.ndarray  # (n_frames,) index into the trace names
    names: tuple[str, ...]


def find_sweeps(t: np.ndarray, dt: float, traces: Mapping[str, Mapping[str, np.ndarray]]) -> list[FoundSweep]:
    """Sweeps in the traces of each axis.

    Parameters
    ----------
    t : ndarray, shape (n_samples,)
        Uniform sample times, s.
    dt : float
        Their interval, s.
    traces : Mapping of axis to Mapping of name to ndarray, shape (n_samples,)
        For each axis, its finite input, reference and response traces.

    Returns
    -------
    list of FoundSweep
        In time order; where sweeps on several axes overlap, only the one
        that stands out most is kept (the others are the loop's reaction).
    """
    step = max(1, int(round(_FRAME_S / dt)))
    freqs = band_frequencies(_F_MIN_HZ, min(_F_MAX_HZ, 0.4 / dt), _PER_OCTAVE)
    ridges = _yield_to_stronger({axis: _ridge(named, dt, freqs, step) for axis, named in traces.items()})
    found: list[FoundSweep] = []
    for axis, named in traces.items():
        ridge = ridges[axis]
        tones = [tone for run in _runs(_pieces(ridge, step * dt), step * dt) for tone in _tones(ridge, run, step * dt)]
        if tones:  # each trace's activity, once for all the axis's sweeps
            activity = _Activities(named, dt)
            found += [_found(axis, ridge, kind, chain, step, dt, activity) for kind, chain in tones]
    return sorted(_owned(found), key=lambda s: s.first)


class _Activities:
    """The activity and bursts of each trace of one axis, computed once for all its sweeps' edges.

    A trace held exactly constant outside the maneuver (a setpoint before
    take-off) has no noise to measure its edges against: the trend's tails
    pass for activity there. Held traces are used only if every trace is held.
    """

    def __init__(self, named: Mapping[str, np.ndarray], dt: float) -> None:
        activities = dict(zip(named, map_traces(lambda x: _activity(x, dt, _THRESHOLD, _TREND_S), named.values())))
        noisy = {name: act for name, act in activities.items() if act.sigma > _HELD * np.max(np.abs(act.detrended))}
        self.used = noisy or activities
        self.bursts = {
            name: _bursts(name, act, dt, _THRESHOLD, _BURST_MERGE_S, _MIN_ACTIVE_S) for name, act in self.used.items()
        }
        self.n = next(iter(named.values())).size


def _ridge(named: Mapping[str, np.ndarray], dt: float, freqs: np.ndarray, step: int) -> _Ridge:
    """The best band of the best trace per frame, its score and log frequency smoothed by a running median.

    The traces' envelopes are taken on the cores at once and folded into a running best (first trace on a
    tie, as ``argmax``), so one axis's traces are held together, not every axis's.
    """
    index = np.uint8 if len(named) <= 256 else np.intp  # an axis has a few traces: a byte per frame and band
    combined, best_trace = np.empty((0, freqs.size)), np.empty((0, freqs.size), dtype=index)
    for k, score in enumerate(map_traces(lambda x: _normalised(x, dt, freqs, step), named.values())):
        if k == 0:
            combined, best_trace = score, np.zeros(score.shape, dtype=index)
            continue
        better = score > combined
        np.copyto(combined, score, where=better)
        best_trace[better] = k
    band = np.argmax(combined, axis=1)
    frames = np.arange(band.size)
    width = max(1, int(round(_SMOOTH_S / (step * dt)))) | 1
    return _Ridge(
        score=moving_rank(combined[frames, band], width, mode="nearest"),
        freq_hz=np.exp(moving_rank(np.log(freqs[band]), width, mode="nearest")),
        trace=best_trace[frames, band].astype(np.intp),
        names=tuple(named),
    )


def _yield_to_stronger(ridges: dict[str, _Ridge]) -> dict[str, _Ridge]:
    """Each axis's ridge without the frames where another axis stands out far more at a nearby frequency.

    A sweep on one axis moves the others a little, at its own frequency,
    through the loop and the airframe's coupling; those frames belong to the
    sweep's axis. Activity at another frequency (a climb, a landing) does not
    take a frame away.
    """
    out = {}
    for axis, ridge in ridges.items():
        weaker = np.zeros(ridge.score.size, dtype=bool)
        for other, rival in ridges.items():
            near = np.abs(np.log2(rival.freq_hz / ridge.freq_hz)) <= 1.0
            weaker |= (other != axis) & near & (rival.score > _YIELD * ridge.score)
        out[axis] = replace(ridge, score=np.where(weaker, 0.0, ridge.score))
    return out


def _pieces(ridge: _Ridge, frame_s: float) -> list[tuple[int, int]]:
    """Half-open frame ranges where one continuous ridge stands out of the noise.

    The ridge is cut where it jumps by more than half an octave between
    frames (noise, or another motion taking over), and pieces that continue
    each other across a short fade are joined.
    """
    octaves = np.log2(ridge.freq_hz)
    pieces: list[tuple[int, int]] = []
    for a, b in true_runs(ridge.score > _SCORE):
        cuts = np.flatnonzero(np.abs(np.diff(octaves[a:b])) > _MAX_JUMP_OCTAVES) + a + 1
        for lo, hi in zip([a, *cuts.tolist()], [*cuts.tolist(), b]):
            if (
                pieces
                and lo - pieces[-1][1] < _MERGE_S / frame_s
                and (abs(octaves[lo] - octaves[pieces[-1][1] - 1]) <= 2 * _MAX_JUMP_OCTAVES)
            ):
                pieces[-1] = (pieces[-1][0], hi)
            else:
                pieces.append((lo, hi))
    return pieces


def _normalised(x: np.ndarray, dt: float, freqs: np.ndarray, step: int) -> np.ndarray:
    """Band envelopes over each band's noise floor, taken where no band stands out (two passes)."""
    envelope = band_envelopes(x - np.median(x), dt, freqs, cycles=_CYCLES, step=step)
    tiny = 1e-12 * max(1.0, float(envelope.max()))
    sample = envelope[:: -(-envelope.shape[0] // _FLOOR_FRAMES)]  # floors from evenly spaced frames of a long log
    lowest = np.maximum(_DYNAMIC_RANGE * np.median(sample, axis=0), tiny)
    floor = np.maximum(np.quantile(sample, _FLOOR_QUANTILE, axis=0), lowest)
    quiet = (sample / floor).max(axis=1) < _SCORE
    if quiet.sum() >= 0.1 * quiet.size:
        floor = np.maximum(np.quantile(sample[quiet], _FLOOR_QUANTILE, axis=0), lowest)
    envelope /= floor  # in place: one (n_frames, n_bands) array per trace at a time
    return envelope


def _sweeping(ridge: _Ridge, a: int, b: int, frame_s: float) -> bool:
    """Whether frames [a, b) hold one tone sweeping steadily through a 3:1 range or more."""
    if (b - a) * frame_s < _MIN_PERIOD_S or np.median(ridge.score[a:b]) < _MIN_MEDIAN_SCORE:
        return False
    log_f = np.log(ridge.freq_hz[a:b])
    lo_hz, hi_hz = np.exp(np.quantile(log_f, [0.1, 0.9]))
    if hi_hz < _MIN_RATIO * lo_hz:
        return False
    return abs(spearman(np.arange(a, b), log_f)) >= _MIN_RHO


def _runs(pieces: list[tuple[int, int]], frame_s: float) -> list[list[tuple[int, int]]]:
    """Pieces of ridge grouped into runs of activity (gaps shorter than ``_MERGE_S``), jumps or not."""
    runs: list[list[tuple[int, int]]] = []
    for piece in pieces:
        if runs and (piece[0] - runs[-1][-1][1]) * frame_s < _MERGE_S:
            runs[-1].append(piece)
        else:
            runs.append([piece])
    return runs


def _tones(
    ridge: _Ridge, run: list[tuple[int, int]], frame_s: float
) -> list[tuple[Literal["sweep", "multisine", "piloted"], list[tuple[int, int]]]]:
    """The sweeps and multisines of one run of activity, each as the ridge pieces it spans.

    The whole run sweeps (a piloted sweep's ridge jumps, but its trend
    holds); or its pieces each sweep the same way, back to back, covering
    most of it: a Schroeder-phased multisine sweeps its band once per period,
    a saw-tooth; or some pieces sweep long enough on their own, unless they
    cover under half of a run that a pilot's command carries broadband
    (:func:`_piloted`), which is then one piloted input.
    """
    a, b = run[0][0], run[-1][1]
    if (b - a) * frame_s >= _MIN_SWEEP_S and _sweeping(ridge, a, b, frame_s):
        return [("sweep", run)]
    swept = [p for p in run if _sweeping(ridge, *p, frame_s)]
    if _periodic(ridge, swept, frame_s):
        return [("multisine", swept)]
    long = [p for p in swept if (p[1] - p[0]) * frame_s >= _MIN_SWEEP_S]
    if sum(hi - lo for lo, hi in long) < 0.5 * (b - a) and (b - a) * frame_s >= _MIN_SWEEP_S and _piloted(ridge, a, b):
        return [("piloted", run)]  # a trend in a short part of a broadband input is chance
    return [("sweep", [p]) for p in long]


def _piloted(ridge: _Ridge, a: int, b: int) -> bool:
    """Whether frames [a, b) are a pilot's frequency-rich stick input: broadband, carried by a command trace.

    A pilot's frequency sweep need not trend (the pilot moves between
    frequencies at will); it is still one when a command the pilot gives
    carries tones over a 3:1 range or more, standing far out of that
    trace's noise, most of the time. The command is the stick where one is
    logged (in position or altitude modes the setpoints are the outer
    loops' reaction, not the pilot's); else the attitude and rate setpoints.
    """
    if np.median(ridge.score[a:b]) < _MIN_MEDIAN_SCORE:
        return False
    lo_hz, hi_hz = np.quantile(ridge.freq_hz[a:b], [0.1, 0.9])
    sticks = np.array([name.startswith("stick_") for name in ridge.names])
    commands = sticks if sticks.any() else np.array([name.endswith("_ref") for name in ridge.names])
    return bool(hi_hz >= _MIN_RATIO * lo_hz and np.mean(commands[ridge.trace[a:b]]) >= 0.5)


def _periodic(ridge: _Ridge, swept: list[tuple[int, int]], frame_s: float) -> bool:
    """Whether sweeping pieces repeat one another: short, back to back, the same way over the same band."""
    lengths = [(hi - lo) * frame_s for lo, hi in swept]
    if len(swept) < 2 or np.median(lengths) >= _MIN_SWEEP_S:  # the outer pieces may be stretched by a slow band
        return False
    if len({_direction(ridge, *p) for p in swept}) > 1:
        return False
    bands = np.array([np.log(np.quantile(ridge.freq_hz[lo:hi], [0.1, 0.9])) for lo, hi in swept])
    overlap = np.minimum(bands[:-1, 1], bands[1:, 1]) - np.maximum(bands[:-1, 0], bands[1:, 0])
    narrower = np.minimum(np.diff(bands[:-1], axis=1), np.diff(bands[1:], axis=1))[:, 0]
    gaps = np.array([b[0] - a[1] for a, b in zip(swept[:-1], swept[1:])]) * frame_s
    return bool(np.all(overlap >= 0.5 * narrower) and np.all(gaps < _MERGE_S))


def _direction(ridge: _Ridge, a: int, b: int) -> int:
    """+1 where the ridge frequency rises over frames [a, b), -1 where it falls."""
    return 1 if spearman(np.arange(a, b), np.log(ridge.freq_hz[a:b])) > 0 else -1


def _found(
    axis: str,
    ridge: _Ridge,
    kind: Literal["sweep", "multisine", "piloted"],
    chain: list[tuple[int, int]],
    step: int,
    dt: float,
    activity: _Activities,
) -> FoundSweep:
    a, b = chain[0][0], chain[-1][1]
    frames = np.concatenate([np.arange(lo, hi) for lo, hi in chain])
    rho = spearman(frames, np.log(ridge.freq_hz[frames]))
    first, last = _time_edges(activity, a * step, min((b - 1) * step, activity.n - 1), dt)
    counts = np.bincount(ridge.trace[frames], minlength=len(ridge.names))
    return FoundSweep(
        axis=axis,
        kind="broadband" if kind == "piloted" else kind,
        first=first,
        last=last,
        f_min_hz=float(ridge.freq_hz[frames].min()),
        f_max_hz=float(ridge.freq_hz[frames].max()),
        direction="none" if kind == "piloted" else "up" if rho > 0 else "down",
        evidence=tuple(ridge.names[k] for k in np.argsort(-counts) if counts[k] > 0),
        score=float(np.median(ridge.score[frames])),
    )


def _time_edges(activity: _Activities, i0: int, i1: int, dt: float) -> tuple[int, int]:
    """Earliest start and latest end, over the traces, of the activity overlapping samples [i0, i1].

    A trace that integrates another one carrying the activity (the attitude its rate, the vertical speed
    its acceleration) rings on after the sweep's last, slowest half-waves; it does not set the end.
    """
    window = (max(0, i0 - int(_EDGE_WINDOW_S / dt)), min(activity.n - 1, i1 + int(_EDGE_WINDOW_S / dt)))
    starts, ends = [], {}
    for name, act in activity.used.items():
        bursts = [burst for burst in activity.bursts[name] if burst.last >= i0 and burst.first <= i1]
        if bursts:
            lo, hi = _edges(act, min(b.first for b in bursts), max(b.last for b in bursts), dt, window, _THRESHOLD)
            starts.append(lo)
            ends[name] = hi
    if not starts:
        return i0, i1
    settling = [hi for name, hi in ends.items() if _INTEGRAL_OF.get(name) not in ends]
    return min(starts), max(settling or ends.values())


def _owned(found: list[FoundSweep]) -> list[FoundSweep]:
    """Of overlapping sweeps, the strongest, and any of comparable strength on another axis.

    Another axis reacts to a sweep far more weakly than the sweep's own
    traces stand out (scores are in each trace's noise floors); one that
    stands out within a factor ``_YIELD`` of it is flown on its own (a pilot
    moving two sticks at once).
    """
    kept: list[FoundSweep] = []
    for sweep in sorted(found, key=lambda s: -s.score):
        rivals = [k for k in kept if sweep.first <= k.last and k.first <= sweep.last]
        if all(k.axis != sweep.axis and _YIELD * sweep.score >= k.score for k in rivals):
            kept.append(sweep)
    return kept
