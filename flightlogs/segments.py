"""Find the maneuvers in a flight: sweeps, doublets, 3211s, multisines and hover.

Spectra must be taken on the right pieces of a flight. The pieces come from
three places, in order of trust: ``"sids"``, the SIDS rows ArduPilot's System
ID mode logs when it starts a sweep (:func:`segments_from_sid`); ``"user"``, a
TOML or CSV file the engineer writes (:func:`read_segments_file`);
``"detected"``, found from the mixer inputs alone (:func:`detect_segments`).
Axes are the mixer inputs: ``lat`` (delta_lat, roll), ``lon`` (delta_lon,
pitch), ``yaw`` (delta_yaw) and ``thr`` (delta_thr).
"""

from __future__ import annotations

import csv
import re
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, Literal, get_args

import numpy as np
from scipy.ndimage import binary_dilation, median_filter, uniform_filter1d
from scipy.signal import fftconvolve
from scipy.stats import spearmanr

from .errors import DataError

__all__ = [
    "Axis", "Kind", "SegmentSource", "AXES", "SID_AXES",
    "Segment", "SidsRow", "detect_segments", "segments_from_sid", "read_segments_file",
]

Axis = Literal["lat", "lon", "yaw", "thr"]
Kind = Literal["sweep", "doublet", "3211", "multisine", "hover"]
SegmentSource = Literal["sids", "detected", "user"]

#: Mixer axes in canonical order (delta_lat, delta_lon, delta_yaw, delta_thr).
AXES: tuple[str, ...] = get_args(Axis)

#: ArduCopter ``SID_AXIS`` values: (mixer axis excited, ArduPilot's name).
#: Source: ``@Values`` of ``SID_AXIS`` in ``ArduCopter/mode_systemid.cpp``.
#: 1-3 angle input, 4-6 the same with feed-forward off ("recovery"), 7-9 rate,
#: 10-13 mixer; 14-19 act on the position loops and map to the attitude axis
#: that flies them.
SID_AXES: dict[int, tuple[str, str]] = {
    1: ("lat", "Input Roll Angle"), 2: ("lon", "Input Pitch Angle"), 3: ("yaw", "Input Yaw Angle"),
    4: ("lat", "Recovery Roll Angle"), 5: ("lon", "Recovery Pitch Angle"), 6: ("yaw", "Recovery Yaw Angle"),
    7: ("lat", "Rate Roll"), 8: ("lon", "Rate Pitch"), 9: ("yaw", "Rate Yaw"),
    10: ("lat", "Mixer Roll"), 11: ("lon", "Mixer Pitch"), 12: ("yaw", "Mixer Yaw"), 13: ("thr", "Mixer Thrust"),
    14: ("lat", "Measured Lateral Position"), 15: ("lon", "Measured Longitudinal Position"),
    16: ("lat", "Measured Lateral Velocity"), 17: ("lon", "Measured Longitudinal Velocity"),
    18: ("lat", "Input Lateral Velocity"), 19: ("lon", "Input Longitudinal Velocity"),
}

_SID_FIELDS = {"Ax": "axis", "Mag": "magnitude", "FSt": "f_start_hz", "FSp": "f_stop_hz",
               "TFin": "fade_in_s", "TC": "const_s", "TR": "record_s", "TFout": "fade_out_s"}
_USER_KEYS = ("start_s", "end_s", "axis", "kind", "f_min_hz", "f_max_hz")
_SHORT_S = 0.2  # window of the short moving mean and RMS, s
_GUARD_S, _BASELINE_S = 1.0, 10.0  # edge baseline: fitted from 11 s to 1 s before the burst
_QUADRATIC_S = 3.0  # edge baseline: straight below this much quiet trace, quadratic above
_LOOK_IN_S = 3.0  # edge baseline: trusted this far into a burst, s
_CALM = 3.0  # edges: calm within 3 noise σ ...
_RELATIVE_FLOOR = 0.015  # ... or within 1.5 % of the burst's peak, however clean the trace
_EDGE_PASSES = 6  # edges: searched again from the last edge found until they settle


@dataclass(frozen=True, slots=True)
class Segment:
    """One maneuver, or one stretch of hover, in a flight.

    Parameters
    ----------
    axis : {"lat", "lon", "yaw", "thr"} or None
        Mixer axis excited; None exactly when `kind` is ``"hover"``.
    kind : {"sweep", "doublet", "3211", "multisine", "hover"}
        What was flown.
    start_s, end_s : float
        Bounds on the log clock, s; a fade-in is inside.
    source : {"sids", "detected", "user"}
        Where the segment came from.
    f_min_hz, f_max_hz : float or None, optional
        Frequency range of a sweep (or multisine), Hz.
    detail : str, optional
        Free text, e.g. the ArduPilot axis that was excited.
    """

    axis: Axis | None
    kind: Kind
    start_s: float
    end_s: float
    source: SegmentSource
    f_min_hz: float | None = None
    f_max_hz: float | None = None
    detail: str = ""

    def __post_init__(self) -> None:
        if self.kind not in get_args(Kind):
            raise DataError(f"unknown kind {self.kind!r} (expected {', '.join(get_args(Kind))})")
        if self.kind == "hover" and self.axis is not None:
            raise DataError(f"a hover segment has no axis, got axis={self.axis!r}")
        if self.kind != "hover" and self.axis not in AXES:
            raise DataError(f"unknown axis {self.axis!r} for a {self.kind} (expected {', '.join(AXES)})")
        if self.source not in get_args(SegmentSource):
            raise DataError(f"unknown source {self.source!r}")
        start, end = float(self.start_s), float(self.end_s)
        if not (np.isfinite(start) and np.isfinite(end)) or end <= start:
            raise DataError(f"end_s={end:g} must be after start_s={start:g}")
        object.__setattr__(self, "start_s", start)
        object.__setattr__(self, "end_s", end)
        for name in ("f_min_hz", "f_max_hz"):
            value = getattr(self, name)
            if value is not None and not (np.isfinite(value) and value > 0):
                raise DataError(f"{name}={value} must be a positive frequency in Hz")
            object.__setattr__(self, name, None if value is None else float(value))
        if self.f_min_hz is not None and self.f_max_hz is not None and self.f_max_hz < self.f_min_hz:
            raise DataError(f"f_max_hz={self.f_max_hz:g} is below f_min_hz={self.f_min_hz:g}")

    @property
    def duration_s(self) -> float:
        """Length of the segment, s."""
        return self.end_s - self.start_s


@dataclass(frozen=True, slots=True)
class SidsRow:
    """One ArduPilot SIDS message: the settings of a System ID run.

    Parameters
    ----------
    time_s : float
        Log time the mode was entered, s (``TimeUS`` × 1e-6).
    axis : int
        ``SID_AXIS`` (``Ax``), see :data:`SID_AXES`.
    magnitude : float
        Sweep magnitude (``Mag``): deg, deg/s, or 0-1 for mixer axes.
    f_start_hz, f_stop_hz : float
        Start and stop frequency (``FSt``, ``FSp``), Hz.
    fade_in_s, const_s, record_s, fade_out_s : float
        Fade-in (``TFin``), dwell at the start frequency (``TC``), sweep
        length (``TR``) and fade-out (``TFout``), s.
    last_sidd_s : float or None, optional
        Time of the run's last SIDD sample, s; the run ends there at the
        latest. None (or NaN) when unknown.
    """

    time_s: float
    axis: int
    magnitude: float
    f_start_hz: float
    f_stop_hz: float
    fade_in_s: float
    const_s: float
    record_s: float
    fade_out_s: float
    last_sidd_s: float | None = None

    def __post_init__(self) -> None:
        if self.last_sidd_s is not None and not np.isfinite(self.last_sidd_s):
            object.__setattr__(self, "last_sidd_s", None)
        for item in fields(self):
            value = getattr(self, item.name)
            if value is not None and not np.isfinite(value):
                raise DataError(f"SIDS row at {self.time_s}: {item.name}={value} is not finite")
        if int(self.axis) != self.axis:
            raise DataError(f"SIDS row at {self.time_s:.2f} s: axis={self.axis} is not an integer")
        object.__setattr__(self, "axis", int(self.axis))


def detect_segments(
    time_s: np.ndarray,
    inputs: Mapping[str, np.ndarray],
    *,
    min_hover_s: float = 3.0,
    threshold: float = 4.0,
    trend_window_s: float = 10.0,
    merge_gap_s: float = 2.0,
    min_active_s: float = 0.3,
    hover_margin_s: float = 0.5,
) -> tuple[Segment, ...]:
    """Find sweeps, doublets, 3211s, multisines and hover in mixer inputs.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Uniform sample times, s.
    inputs : Mapping[str, ndarray of shape (n_samples,)]
        Mixer input by axis (``"lat"``, ``"lon"``, ``"yaw"``, ``"thr"``; any
        subset), as logged, finite.
    min_hover_s : float, optional
        Shortest stretch, quiet on every axis, reported as hover, s. Default 3.
    threshold : float, optional
        Activity threshold in noise-floor units. Default 4.
    trend_window_s : float, optional
        Window of the robust trend that removes trim and slow pilot inputs,
        s; about one period of the lowest sweep frequency. Default 10.
    merge_gap_s : float, optional
        Active stretches on one axis closer than this are one maneuver, s.
        Default 2.
    min_active_s : float, optional
        Bursts active for less than this in total are ignored, s. Default 0.3.
    hover_margin_s : float, optional
        Hover keeps this far from any activity, s. Default 0.5.

    Returns
    -------
    tuple of Segment
        In time order, ``source="detected"``. Activity of no known kind
        (pilot repositioning, take-off) is not returned but interrupts hover.

    Raises
    ------
    DataError
        If `time_s` is not uniform, an axis is unknown, or an input has the
        wrong length or non-finite values.

    Notes
    -----
    Per axis, a robust (bisquare) moving quadratic removes trim and drift;
    a 0.2 s moving mean (which sees the slow start of a faded-in sweep) and
    moving RMS (which sees its fast end) are normalised by noise floors of
    the quiet stretches. A burst is a run above `threshold`; overlapping
    bursts on several axes are one maneuver, owned by the axis with the
    largest normalised activity, the others being the closed loop's
    reaction. Each edge is where the owner's trace leaves a baseline fitted
    to the 10 s of trace before it (after it, for the end), within 3 σ or
    1.5 % of the peak; for clean inputs they fall within about 0.1-0.3 s of
    the excitation (a fade-in is found once it rises out of the noise). The
    trace is cut into half-waves at zero crossings (hysteresis `threshold`
    σ): two large ones of similar area make a doublet, four of durations
    3:2:1:1 a 3211, eight or more with a frequency trend (Spearman |ρ| > 0.6,
    range over 2:1) or at one frequency a sweep, otherwise a multisine.
    """
    t, dt = _uniform(time_s)
    traces = _check_inputs(inputs, t.size)
    acts = {axis: _activity(x, dt, threshold, trend_window_s) for axis, x in traces.items()}
    bursts = [b for axis, act in acts.items() for b in _bursts(axis, act, dt, threshold, merge_gap_s, min_active_s)]
    segments, busy = [], []
    margin = int(round(_GUARD_S / dt))
    for owner, reactions in _assign(bursts):
        axis, i0, i1, _ = owner
        others = [b for b in bursts if b is not owner and b not in reactions]
        before = max((b[2] + margin for b in others if b[2] < i0), default=0)
        after = min((b[1] - margin for b in others if b[1] > i1), default=t.size - 1)
        lo, hi = _edges(acts[axis], i0, i1, dt, (min(before, i0), max(after, i1)), threshold)
        busy += [(lo, hi)] + [(b[1], b[2]) for b in reactions]
        found = _classify(acts[axis], t, lo, hi, threshold)
        if found is not None:
            segments.append(Segment(axis, found[0], t[lo], t[hi], "detected", found[1], found[2]))
    segments.extend(_hover(t, busy, min_hover_s, hover_margin_s))
    return tuple(sorted(segments, key=lambda s: s.start_s))


def segments_from_sid(
    rows: Sequence[SidsRow] | Mapping[str, Any],
    *,
    sidd_time_s: np.ndarray | None = None,
    extent: Literal["excitation", "mode"] = "excitation",
    delay_s: float = 1.0,
) -> tuple[Segment, ...]:
    """Turn ArduPilot SIDS rows into sweep segments.

    Parameters
    ----------
    rows : sequence of SidsRow, or Mapping of SIDS field name to array
        The SIDS messages; a mapping holds ``TimeUS`` (µs) or ``time_s`` (s)
        and ``Ax, Mag, FSt, FSp, TFin, TC, TR, TFout``. Objects with the
        attributes of :class:`SidsRow` (``start_s`` for `time_s` and
        ``end_s`` for `last_sidd_s` also do, as in
        ``flightlogs.ardupilot.SystemIdRun``) are accepted too.
    sidd_time_s : ndarray, shape (n_samples,), optional
        Times of the SIDD samples, s. A run ends at its last SIDD sample at
        the latest (the mode was left early, or stopped on a lean-angle
        limit); a run without any SIDD sample is dropped.
    extent : {"excitation", "mode"}, optional
        ``"excitation"`` (default): from ``time_s + delay_s`` to
        ``time_s + delay_s + TR``, where the chirp is non-zero; ``"mode"``:
        from ``time_s`` to ``time_s + delay_s + TFin + TC + TR + TFout``, when
        the mode reports "SystemID Finished".
    delay_s : float, optional
        Wait between entering the mode and starting the chirp, s
        (``SYSTEM_ID_DELAY``, 1 s in ArduCopter). Default 1.

    Returns
    -------
    tuple of Segment
        One ``kind="sweep"``, ``source="sids"`` segment per run, in time order,
        with `f_min_hz` and `f_max_hz` from FSt and FSp.

    Raises
    ------
    DataError
        If a field is missing or a row names an unknown ``SID_AXIS``.

    Notes
    -----
    ``ModeSystemId::init`` writes SIDS on entering the mode and ``run`` feeds
    ``Chirp::update(t - SYSTEM_ID_DELAY)``; in ``AP_Math/chirp.cpp`` the
    fade-in, the dwell (``TC = 2 / FSt``) and the fade-out all lie inside
    ``TR``, after which the chirp is zero.

    Examples
    --------
    >>> row = SidsRow(100.0, 11, 0.1, 0.1, 10.0, 2.0, 20.0, 34.0, 1.0)
    >>> seg, = segments_from_sid([row])
    >>> seg.axis, seg.start_s, seg.end_s, seg.f_min_hz
    ('lon', 101.0, 135.0, 0.1)
    """
    if extent not in ("excitation", "mode"):
        raise DataError(f"{extent=} must be 'excitation' or 'mode'")
    table = sorted(_sids_rows(rows), key=lambda r: r.time_s)
    sidd = None if sidd_time_s is None else np.sort(np.asarray(sidd_time_s, dtype=np.float64))
    out = []
    for k, row in enumerate(table):
        if row.axis not in SID_AXES:
            raise DataError(f"SIDS row at {row.time_s:.2f} s: SID_AXIS={row.axis} is not a known axis (1-19)")
        axis, name = SID_AXES[row.axis]
        start, end = row.time_s + delay_s, row.time_s + delay_s + row.record_s
        if extent == "mode":
            start, end = row.time_s, end + row.fade_in_s + row.const_s + row.fade_out_s
        if row.last_sidd_s is not None:
            end = min(end, row.last_sidd_s)
        if sidd is not None:
            next_start = table[k + 1].time_s if k + 1 < len(table) else np.inf
            run = sidd[(sidd >= row.time_s) & (sidd < next_start)]
            end = min(end, float(run[-1])) if run.size else -np.inf
        if end <= start:
            continue
        lo, hi = sorted((row.f_start_hz, row.f_stop_hz))
        detail = f"SID_AXIS={row.axis} ({name}), magnitude {row.magnitude:g}"
        out.append(Segment(axis, "sweep", start, end, "sids", lo, hi, detail))  # type: ignore[arg-type]
    return tuple(out)


def read_segments_file(path: str | Path) -> tuple[Segment, ...]:
    """Read user-defined segments from a TOML or CSV file.

    Parameters
    ----------
    path : str or Path
        ``.toml`` with ``[[segment]]`` tables (keys ``start_s``, ``end_s``,
        ``axis``, ``kind``, ``f_min_hz``, ``f_max_hz``), or ``.csv`` with rows
        ``start_s,end_s,axis[,kind[,f_min_hz,f_max_hz]]`` (a header row naming
        the columns is optional; ``#`` starts a comment line). `kind` defaults
        to ``"sweep"``; hover rows leave `axis` empty.

    Returns
    -------
    tuple of Segment
        ``source="user"``, in time order.

    Raises
    ------
    DataError
        If the file cannot be read or parsed, holds no segment, or a row is
        invalid (end before start, unknown axis or kind, not a number); the
        message names the file and the line.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = Path(tmp) / "segments.csv"
    ...     _ = path.write_text("start_s,end_s,axis,kind\\n12.5,46.5,lon,sweep\\n")
    ...     read_segments_file(path)[0].axis
    'lon'
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise DataError(f"{path}: cannot be read ({err}).") from err
    suffix = path.suffix.lower()
    if suffix not in (".toml", ".csv"):
        raise DataError(f"{path}: a segments file is .toml or .csv, not {suffix or 'without extension'}.")
    entries = _toml_entries(path, text) if suffix == ".toml" else _csv_entries(path, text)
    if not entries:
        raise DataError(f"{path}: no segment found.")
    segments = []
    for line, entry in entries:
        try:
            segments.append(_user_segment(entry))
        except DataError as err:
            raise DataError(f"{path}:{line}: {err}.") from None
    return tuple(sorted(segments, key=lambda s: s.start_s))


# ------------------------------------------------------------------ detection


@dataclass(frozen=True, slots=True)
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
        return _Activity(self.raw[::-1], self.detrended[::-1], self.mean_z[::-1], self.rms_z[::-1],
                         self.sigma, self.sigma_mean)


def _uniform(time_s: np.ndarray) -> tuple[np.ndarray, float]:
    t = np.asarray(time_s, dtype=np.float64)
    if t.ndim != 1 or t.size < 10 or not np.isfinite(t).all():
        raise DataError(f"time_s must be a finite 1-D array of at least 10 samples, got shape {t.shape}")
    steps = np.diff(t)
    dt = float(np.median(steps))
    if dt <= 0 or np.max(np.abs(steps - dt)) > 1e-3 * dt:
        raise DataError("time_s must be uniformly sampled; resample the inputs first")
    return t, dt


def _check_inputs(inputs: Mapping[str, np.ndarray], n: int) -> dict[str, np.ndarray]:
    if not inputs:
        raise DataError("no mixer input given")
    traces = {}
    for axis, values in inputs.items():
        x = np.asarray(values, dtype=np.float64)
        if axis not in AXES:
            raise DataError(f"unknown axis {axis!r} (expected {', '.join(AXES)})")
        if x.shape != (n,):
            raise DataError(f"input {axis!r} has shape {x.shape}, time_s has {n} samples")
        if not np.isfinite(x).all():
            raise DataError(f"input {axis!r} holds non-finite values; split the record at its gaps")
        traces[axis] = x
    return traces


def _activity(x: np.ndarray, dt: float, threshold: float, trend_window_s: float) -> _Activity:
    """Detrend one axis and normalise its short envelopes by noise floors of quiet stretches."""
    xd = x - _trend(x, max(3, int(round(trend_window_s / dt)) | 1))
    width = max(1, int(round(_SHORT_S / dt)))
    mean = np.abs(uniform_filter1d(xd, width, mode="nearest"))
    rms = np.sqrt(uniform_filter1d(xd * xd, width, mode="nearest"))
    tiny = 1e-12 * max(1.0, float(np.max(np.abs(xd))))
    quiet = np.ones(xd.size, dtype=bool)
    for quantile in (0.25, 0.5, 0.5, 0.5):  # the first pass may see more maneuver than quiet
        sigma = max(_robust_std(xd[quiet], quantile), tiny)
        sigma_mean = max(_robust_std(mean[quiet], quantile, centred=True), tiny)
        calm = ~binary_dilation(np.maximum(mean / sigma_mean, rms / sigma) > threshold, iterations=int(1 / dt))
        if calm.sum() < 10:
            break
        quiet = calm
    return _Activity(x, xd, mean / sigma_mean, rms / sigma, sigma, sigma_mean)


def _trend(x: np.ndarray, width: int) -> np.ndarray:
    """Robust moving quadratic (bisquare weights, from a moving median): trim and drift, not maneuvers.

    A maneuver's lobes lose their weight, so the trend runs through the quiet
    samples and the zero crossings and follows a curving drift without lag.
    """
    trend = median_filter(x, size=width, mode="reflect")
    half = width // 2
    kernels = [(-np.arange(-half, half + 1) / half) ** k for k in range(5)]
    idx = np.arange(x.size)
    for _ in range(3):
        resid = x - trend
        r = resid / (4.685 * max(_robust_std(resid, 0.25), 1e-12 * (1.0 + float(np.max(np.abs(x))))))
        w = np.where(np.abs(r) < 1, (1 - r * r) ** 2, 0.0)
        m = [fftconvolve(w, k, mode="same") for k in kernels]
        b = np.stack([fftconvolve(w * x, k, mode="same") for k in kernels[:3]], axis=-1)
        a = np.stack([np.stack(m[i : i + 3], axis=-1) for i in range(3)], axis=-2)
        good = (m[0] > 0.2 * half) & (np.abs(np.linalg.det(a)) > 1e-6 * m[0] ** 3)
        if good.sum() < 2:
            break
        trend = np.interp(idx, idx[good], np.linalg.solve(a[good], b[good][..., None])[:, 0, 0])
    return trend


def _robust_std(x: np.ndarray, quantile: float = 0.5, *, centred: bool = False) -> float:
    """σ of the quietest part of `x` from a quantile of |x - median| (0.5: 1.4826 × MAD).

    A lower quantile stays right when maneuvers fill more than half the
    record; `centred` takes x as already |deviations|. Falls back to the
    standard deviation for quantised traces.
    """
    dev = x if centred else np.abs(x - np.median(x))
    spread = float(np.quantile(dev, quantile)) / {0.5: 0.6745, 0.25: 0.3186}[quantile]
    return spread if spread > 0 else float(np.std(x))


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Inclusive index ranges of the True runs of `mask`."""
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(np.int8), 0]))
    return [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2])]


def _bursts(axis: str, act: _Activity, dt: float, threshold: float, merge_s: float, active_s: float) -> list[tuple]:
    """(axis, first, last, score) of each burst: active runs merged over short pauses."""
    active = np.maximum(act.mean_z, act.rms_z) > threshold
    merged: list[list[int]] = []
    for a, b in _runs(active):
        if merged and (a - merged[-1][1]) * dt < merge_s:
            merged[-1][1] = b
        else:
            merged.append([a, b])
    score = np.maximum(act.mean_z, act.rms_z)
    return [(axis, a, b, float(np.percentile(score[a : b + 1], 95)))
            for a, b in merged if active[a : b + 1].sum() * dt >= active_s]


def _assign(bursts: list[tuple]) -> list[tuple[tuple, list[tuple]]]:
    """Greedy: the strongest burst owns a maneuver; weaker bursts overlapping it are its reactions."""
    pending, owned = sorted(bursts, key=lambda b: -b[3]), []
    while pending:
        owner, rest = pending[0], pending[1:]
        reactions = [b for b in rest if b[1] <= owner[2] and b[2] >= owner[1]]
        pending = [b for b in rest if b not in reactions]
        owned.append((owner, reactions))
    return sorted(owned, key=lambda pair: pair[0][1])


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
    mean = np.abs(uniform_filter1d(d, width, mode="nearest"))
    rms = np.sqrt(uniform_filter1d(d * d, width, mode="nearest"))
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
        r = resid / (4.685 * max(_robust_std(resid), 1e-300))
        w = np.where(np.abs(r) < 1, (1 - r * r) ** 2, 0.0)
        if np.count_nonzero(w) <= degree + 1:
            break
    return np.polyval(coef, at)


def _lobes(x: np.ndarray, t: np.ndarray, h: float) -> list[tuple[int, float, float, float]]:
    """(sign, begin_s, end_s, area) of the half-waves of `x`, cut at zero crossings with hysteresis h.

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
    return [(int(state[a]), b, e, float(s)) for a, b, e, s in zip(firsts, bounds[:-1], bounds[1:], areas)]


def _classify(act: _Activity, t: np.ndarray, lo: int, hi: int, threshold: float) -> tuple | None:
    """(kind, f_min_hz, f_max_hz) of the maneuver on samples [lo, hi], or None for no known kind."""
    lobes = _lobes(act.detrended[lo : hi + 1], t[lo : hi + 1], threshold * act.sigma)
    if len(lobes) >= 8:
        return _oscillation(lobes)
    if not lobes:
        return None
    areas = np.array([abs(lobe[3]) for lobe in lobes])
    durations = np.array([lobe[2] - lobe[1] for lobe in lobes])
    big = np.flatnonzero(areas >= 0.25 * areas.max())
    if big.size == 2 and big[1] == big[0] + 1:
        area_ratio, time_ratio = areas[big[1]] / areas[big[0]], durations[big[1]] / durations[big[0]]
        if 1 / 3 <= area_ratio <= 3 and 1 / 3 <= time_ratio <= 3:
            return "doublet", None, None
    if big.size == 4 and np.all(np.diff(big) == 1):
        unit = durations[big].sum() / 7.0
        if np.all(np.abs(durations[big] / unit - [3, 2, 1, 1]) <= [1.0, 0.7, 0.4, 0.4]):
            return "3211", None, None
    return None


def _oscillation(lobes: list) -> tuple:
    """Sweep (frequency trend, or one frequency) or multisine, from the half-wave durations."""
    durations = np.array([lobe[2] - lobe[1] for lobe in lobes[:-1]])  # the last may be cut short
    freq = 0.5 / durations
    mid = np.array([0.5 * (lobe[1] + lobe[2]) for lobe in lobes[:-1]])
    smooth = np.array([np.median(freq[max(0, i - 1) : i + 2]) for i in range(freq.size)])
    f_min, f_max = float(min(freq[0], smooth.min())), float(smooth.max())
    if (abs(spearmanr(mid, freq).statistic) > 0.6 and f_max > 2 * f_min) or f_max < 1.5 * f_min:
        return "sweep", f_min, f_max
    return "multisine", f_min, f_max


def _hover(t: np.ndarray, busy: list, min_hover_s: float, margin_s: float) -> list[Segment]:
    """Stretches at least `min_hover_s` long and `margin_s` away from any activity."""
    quiet = np.ones(t.size, dtype=bool)
    pad = int(round(margin_s / (t[1] - t[0])))
    for lo, hi in busy:
        quiet[max(0, lo - pad) : hi + pad + 1] = False
    return [Segment(None, "hover", t[a], t[b], "detected") for a, b in _runs(quiet) if t[b] - t[a] >= min_hover_s]


# ------------------------------------------------------------------ SIDS rows and segment files


def _sids_rows(rows: Sequence[SidsRow] | Mapping[str, Any]) -> list[SidsRow]:
    if not isinstance(rows, Mapping):
        return [_sids_row(row) for row in rows]
    if "time_s" in rows:
        times = np.asarray(rows["time_s"], dtype=np.float64)
    elif "TimeUS" in rows:
        times = np.asarray(rows["TimeUS"], dtype=np.float64) * 1e-6
    else:
        raise DataError("SIDS rows need a TimeUS (µs) or time_s (s) column")
    missing = [name for name in _SID_FIELDS if name not in rows]
    if missing:
        raise DataError(f"SIDS rows lack the field(s) {', '.join(missing)}")
    columns = {ours: np.asarray(rows[name], dtype=np.float64) for name, ours in _SID_FIELDS.items()}
    return [SidsRow(float(t), **{k: float(v[i]) for k, v in columns.items()}) for i, t in enumerate(times)]


def _sids_row(row: Any) -> SidsRow:
    """A SidsRow from a SidsRow, a tuple of its fields, or an object with its attributes."""
    if isinstance(row, SidsRow):
        return row
    if not hasattr(row, "f_start_hz"):
        return SidsRow(*row)
    names = [item.name for item in fields(SidsRow)][2:-1]
    time_s = getattr(row, "time_s", None)
    last = getattr(row, "last_sidd_s", None) if time_s is not None else getattr(row, "end_s", None)
    return SidsRow(row.start_s if time_s is None else time_s, row.axis, *(getattr(row, n) for n in names), last)


def _toml_entries(path: Path, text: str) -> list[tuple[int, dict]]:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise DataError(f"{path}: not valid TOML ({err}).") from err
    unknown = [key for key in data if key != "segment"]
    if unknown:
        raise DataError(f"{path}: unknown top-level key {unknown[0]!r} (expected [[segment]] tables).")
    tables = data.get("segment", [])
    if not isinstance(tables, list) or not all(isinstance(item, dict) for item in tables):
        raise DataError(f"{path}: 'segment' must be an array of tables, written [[segment]].")
    lines = [n for n, row in enumerate(text.splitlines(), 1) if re.match(r"\s*\[\[\s*segment\s*\]\]", row)]
    return list(zip(lines + [0] * (len(tables) - len(lines)), tables))


def _csv_entries(path: Path, text: str) -> list[tuple[int, dict]]:
    entries: list[tuple[int, dict]] = []
    header = None
    for line, row in enumerate(csv.reader(text.splitlines()), 1):
        cells = [cell.strip() for cell in row]
        if not any(cells) or cells[0].startswith("#"):
            continue
        if header is None and not entries and not _is_number(cells[0]):
            header = [cell.lower() for cell in cells]
            unknown = [name for name in header if name not in _USER_KEYS]
            if unknown:
                raise DataError(f"{path}:{line}: unknown column {unknown[0]!r} (expected {', '.join(_USER_KEYS)}).")
            continue
        names = header or list(_USER_KEYS)
        if len(cells) > len(names):
            raise DataError(f"{path}:{line}: {len(cells)} fields, expected at most {len(names)}.")
        entries.append((line, {name: cell for name, cell in zip(names, cells) if cell != ""}))
    return entries


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _user_segment(entry: dict) -> Segment:
    unknown = [key for key in entry if key not in _USER_KEYS]
    if unknown:
        raise DataError(f"unknown key {unknown[0]!r} (expected {', '.join(_USER_KEYS)})")
    values: dict[str, Any] = {}
    for key in ("start_s", "end_s", "f_min_hz", "f_max_hz"):
        if key in entry:
            try:
                values[key] = float(entry[key])
            except (TypeError, ValueError):
                raise DataError(f"{key}={entry[key]!r} is not a number") from None
        elif key in ("start_s", "end_s"):
            raise DataError(f"{key} is missing")
    if values["end_s"] <= values["start_s"]:
        raise DataError(f"end_s={values['end_s']:g} is not after start_s={values['start_s']:g}")
    axis = str(entry.get("axis", "")).strip().lower()
    kind = str(entry.get("kind", "sweep")).strip().lower()
    return Segment(None if axis in ("", "none") else axis, kind, source="user", **values)  # type: ignore[arg-type]
