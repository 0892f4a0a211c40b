"""Find the maneuvers in a flight: sweeps, doublets, 3211s, multisines and hover.

Spectra must be taken on the right pieces of a flight. The pieces come from
three places, in order of trust: ``"sids"``, the runs ArduPilot's System ID
mode logs when it starts a sweep (SIDS messages, in
:attr:`FlightLog.system_id_runs <flightlogs.flightlog.FlightLog>`;
:func:`segments_from_sid`); ``"user"``, a TOML or CSV file the engineer
writes (:func:`flightlogs.readers.segments_file.read_segments_file`);
``"detected"``, found from the mixer inputs alone (:func:`detect_segments`).
Axes are the mixer inputs: ``lat`` (delta_lat, roll), ``lon`` (delta_lon,
pitch), ``yaw`` (delta_yaw) and ``thr`` (delta_thr).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields, replace
from typing import Any, Literal, cast

import numpy as np

from flightlogs.errors import DataError
from flightlogs.flightlog import SystemIdRun
from flightlogs.maneuvers._detection import FoundManeuver, find_maneuvers, hover_spans
from flightlogs.maneuvers._sweeps import FoundSweep, find_sweeps
from flightlogs.segment import AXES, Axis, Kind, Segment, SegmentSource

__all__ = [
    "Axis",
    "Kind",
    "SegmentSource",
    "AXES",
    "SID_AXES",
    "Segment",
    "DetectionOptions",
    "detect_segments",
    "SegmentDetector",
    "segments_from_sid",
]

#: ArduCopter ``SID_AXIS`` values: (mixer axis excited, ArduPilot's name).
#: Source: ``@Values`` of ``SID_AXIS`` in ``ArduCopter/mode_systemid.cpp``.
#: 1-3 angle input, 4-6 the same with feed-forward off ("recovery"), 7-9 rate,
#: 10-13 mixer; 14-19 act on the position loops and map to the attitude axis
#: that flies them.
SID_AXES: dict[int, tuple[str, str]] = {
    1: ("lat", "Input Roll Angle"),
    2: ("lon", "Input Pitch Angle"),
    3: ("yaw", "Input Yaw Angle"),
    4: ("lat", "Recovery Roll Angle"),
    5: ("lon", "Recovery Pitch Angle"),
    6: ("yaw", "Recovery Yaw Angle"),
    7: ("lat", "Rate Roll"),
    8: ("lon", "Rate Pitch"),
    9: ("yaw", "Rate Yaw"),
    10: ("lat", "Mixer Roll"),
    11: ("lon", "Mixer Pitch"),
    12: ("yaw", "Mixer Yaw"),
    13: ("thr", "Mixer Thrust"),
    14: ("lat", "Measured Lateral Position"),
    15: ("lon", "Measured Longitudinal Position"),
    16: ("lat", "Measured Lateral Velocity"),
    17: ("lon", "Measured Longitudinal Velocity"),
    18: ("lat", "Input Lateral Velocity"),
    19: ("lon", "Input Longitudinal Velocity"),
}

_SID_FIELDS = {
    "Ax": "axis",
    "Mag": "magnitude",
    "FSt": "f_start_hz",
    "FSp": "f_stop_hz",
    "TFin": "fade_in_s",
    "TC": "const_s",
    "TR": "record_s",
    "TFout": "fade_out_s",
}
_RING_S = 5.0  # the loop rings this long after a doublet or 3211
_STEP_JUMP = 5.0  # a logged step: a sample-to-sample change this many times the input's typical one
_STEP_LOOK_BACK_S = 0.5  # the first step is searched from this long before the fitted start
_STEP_RISE_S = 0.05  # a logged step's change is measured over this long
_FIRST_STEP = 0.25  # the first step is at least this fraction of the largest (a doublet's first is half its second)
_MIN_TONE_S = 15.0  # a sweep runs at least this long besides any step it overlaps
#: The rate (or, for thrust, the acceleration) a step on each axis moves.
_RATE_OF = {"lat": "p", "lon": "q", "yaw": "r", "thr": "az"}
_FOLLOWED = 2.0  # a step's rate: its RMS over the step and one second after, this many times the hover's before


@dataclass(frozen=True, slots=True, kw_only=True)
class DetectionOptions:
    """Thresholds and durations of maneuver detection (:func:`detect_segments`).

    Parameters
    ----------
    min_hover_s : float
        Shortest stretch, quiet on every axis, reported as hover, s. Default 3.
    threshold : float
        Activity threshold in noise-floor units. Default 4.
    trend_window_s : float
        Window of the robust trend that removes trim and slow pilot inputs,
        s; about one period of the lowest sweep frequency. Default 10.
    merge_gap_s : float
        Active stretches on one axis closer than this are one maneuver, s.
        Default 2.
    min_active_s : float
        Bursts active for less than this in total are ignored, s. Default 0.3.
    hover_margin_s : float
        Hover keeps this far from any activity, s. Default 0.5.

    Raises
    ------
    ValueError
        If a value is not a positive number (the hover margin may be zero).
    """

    min_hover_s: float = 3.0
    threshold: float = 4.0
    trend_window_s: float = 10.0
    merge_gap_s: float = 2.0
    min_active_s: float = 0.3
    hover_margin_s: float = 0.5

    def __post_init__(self) -> None:
        for name in ("min_hover_s", "threshold", "trend_window_s", "merge_gap_s", "min_active_s"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name}={getattr(self, name)!r} must be > 0")
        if not self.hover_margin_s >= 0:
            raise ValueError(f"hover_margin_s={self.hover_margin_s!r} must be >= 0")


def detect_segments(
    time_s: np.ndarray,
    inputs: Mapping[str, np.ndarray],
    *,
    responses: Mapping[str, Mapping[str, np.ndarray]] | None = None,
    options: DetectionOptions = DetectionOptions(),
) -> tuple[Segment, ...]:
    """Find sweeps, doublets, 3211s, multisines and hover in mixer inputs.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Uniform sample times, s.
    inputs : Mapping[str, ndarray of shape (n_samples,)]
        Mixer input by axis (``"lat"``, ``"lon"``, ``"yaw"``, ``"thr"``; any
        subset), as logged, finite.
    responses : Mapping of axis to Mapping of signal name to ndarray of shape (n_samples,), optional
        For each axis, the traces that show its maneuvers: its mixer input
        as logged, the references the autopilot logs (sticks, attitude and
        rate setpoints) and the rates and angles that follow (canonical
        names, finite). Given, sweeps and multisines are found by their
        time-frequency signature in these traces together, and the
        segment's `detail` names the traces that carried it; `inputs` then
        serve the doublets and 3211s only.
    options : DetectionOptions, optional
        Thresholds and durations of the detection.

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
    the quiet stretches. A burst is a run above ``options.threshold``; overlapping
    bursts on several axes are one maneuver, owned by the axis with the
    largest normalised activity, the others being the closed loop's
    reaction. Each edge is where the owner's trace leaves a baseline fitted
    to the 10 s of trace before it (after it, for the end), within 3 σ or
    1.5 % of the peak; for clean inputs they fall within about 0.1-0.3 s of
    the excitation (a fade-in is found once it rises out of the noise). The
    trace is cut into half-waves at zero crossings (hysteresis ``options.threshold``
    σ): two large ones of similar area make a doublet, four of durations
    3:2:1:1 (the outer two timed from the first and to the last loud
    sample) a 3211, both bounded by those samples since their edges are
    steps; eight or more with a frequency trend (Spearman |ρ| > 0.6, range
    over 2:1) or at one frequency a sweep, otherwise a multisine. In closed
    loop, pass the excitation of :func:`flightlogs.maneuvers.excitation_recovery.estimate_excitation`,
    which fits doublets and 3-2-1-1s jointly with the feedback (a 3-2-1-1 bent
    by a poorly fitted feedback can show an adjacent pair of pulses that
    passes for a doublet).
    """
    return SegmentDetector(time_s, responses=responses, options=options).detect(inputs)


class SegmentDetector:
    """:func:`detect_segments` over one stretch of flight, for several sets of mixer inputs.

    Sweeps and multisines are found from the response traces alone (their
    time-frequency signature), doublets and 3211s from the mixer inputs. A
    caller that detects again with other inputs (an excitation estimate
    refitted without the maneuvers found first) pays for the response
    traces' part once: :meth:`detect` with the same inputs gives what
    :func:`detect_segments` gives. Parameters as there.
    """

    def __init__(
        self,
        time_s: np.ndarray,
        *,
        responses: Mapping[str, Mapping[str, np.ndarray]] | None = None,
        options: DetectionOptions = DetectionOptions(),
    ) -> None:
        self._t, self._dt = _uniform(time_s)
        self._responses = None if responses is None else _check_responses(responses, self._t.size)
        self._found_sweeps: list[FoundSweep] | None = None
        self._options = options

    def _sweeps(self) -> list[FoundSweep]:
        if self._found_sweeps is None:
            assert self._responses is not None
            self._found_sweeps = find_sweeps(self._t, self._dt, self._responses)
        return self._found_sweeps

    def detect(self, inputs: Mapping[str, np.ndarray]) -> tuple[Segment, ...]:
        """The segments, with `inputs` the mixer input by axis (as :func:`detect_segments`'), in time order."""
        t, dt = self._t, self._dt
        o = self._options
        if not inputs and self._responses is None:
            raise DataError("no mixer input given")
        traces = _check_inputs(inputs, t.size) if inputs else {}
        maneuvers, busy = (
            find_maneuvers(t, dt, traces, o.threshold, o.trend_window_s, o.merge_gap_s, o.min_active_s)
            if traces
            else ([], [])
        )
        segments: list[Segment] = []
        if self._responses is not None:
            checked = self._responses
            steps = [m for m in maneuvers if m.kind in ("doublet", "3211")]
            sweeps = [s for s in self._sweeps() if not _ringing(s, steps, dt)]
            segments += [
                Segment(
                    axis=cast(Axis, s.axis),
                    kind=s.kind,
                    start_s=t[s.first],
                    end_s=t[s.last],
                    source="detected",
                    f_min_hz=s.f_min_hz,
                    f_max_hz=s.f_max_hz,
                    detail=(
                        f"{s.direction} ridge in {', '.join(s.evidence)}"
                        if s.direction != "none"
                        else f"piloted, without a frequency trend, in {', '.join(s.evidence)}"
                    ),
                )
                for s in sweeps
            ]
            busy += [(s.first, s.last) for s in sweeps]
            # sweeps come from their signature alone; steps (doublets, 3211s) and multisines of any phasing from
            # the inputs, where no tone runs
            maneuvers = [
                m
                for m in maneuvers
                if m.kind != "sweep" and not any(m.first <= s.last and s.first <= m.last for s in sweeps)
            ]
            maneuvers = [
                stepped
                for m in maneuvers
                if (stepped := _stepped(m, checked.get(m.axis, {}).get(f"delta_{m.axis}"), dt)) is not None
                and _followed(stepped, checked.get(m.axis, {}).get(_RATE_OF[m.axis]), dt)
            ]
        segments += [
            Segment(
                axis=cast(Axis, m.axis),  # the keys of `traces`, checked against AXES
                kind=m.kind,
                start_s=t[m.first],
                end_s=t[m.last],
                source="detected",
                f_min_hz=m.f_min_hz,
                f_max_hz=m.f_max_hz,
            )
            for m in maneuvers
        ]
        segments += [
            Segment(axis=None, kind="hover", start_s=a, end_s=b, source="detected")
            for a, b in hover_spans(t, busy, o.min_hover_s, o.hover_margin_s)
        ]
        return tuple(sorted(segments, key=lambda s: s.start_s))


def segments_from_sid(
    runs: Sequence[SystemIdRun] | Mapping[str, Any],
    *,
    sidd_time_s: np.ndarray | None = None,
    extent: Literal["excitation", "mode"] = "excitation",
    delay_s: float = 1.0,
) -> tuple[Segment, ...]:
    """Turn ArduPilot System ID runs into sweep segments.

    Parameters
    ----------
    runs : sequence of SystemIdRun, or Mapping of SIDS field name to array
        The runs, as in :attr:`FlightLog.system_id_runs
        <flightlogs.flightlog.FlightLog>` (a run ends at its `end_s`, the
        last SIDD sample, at the latest; NaN when unknown); or the SIDS
        messages as columns, holding ``TimeUS`` (µs) or ``time_s`` (s) and
        ``Ax, Mag, FSt, FSp, TFin, TC, TR, TFout``, with no end known.
    sidd_time_s : ndarray, shape (n_samples,), optional
        Times of the SIDD samples, s. A run ends at its last SIDD sample at
        the latest (the mode was left early, or stopped on a lean-angle
        limit); a run without any SIDD sample is dropped.
    extent : {"excitation", "mode"}, optional
        ``"excitation"`` (default): from ``start_s + delay_s`` to
        ``start_s + delay_s + TR``, where the chirp is non-zero; ``"mode"``:
        from ``start_s`` to ``start_s + delay_s + TFin + TC + TR + TFout``,
        when the mode reports "SystemID Finished".
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
        If a field is missing or not finite, or a run names an unknown
        ``SID_AXIS``.

    Notes
    -----
    ``ModeSystemId::init`` writes SIDS on entering the mode and ``run`` feeds
    ``Chirp::update(t - SYSTEM_ID_DELAY)``; in ``AP_Math/chirp.cpp`` the
    fade-in, the dwell (``TC = 2 / FSt``) and the fade-out all lie inside
    ``TR``, after which the chirp is zero.

    Examples
    --------
    >>> run = SystemIdRun(start_s=100.0, end_s=float("nan"), axis=11, axis_name="mixer pitch", magnitude=0.1,
    ...                   f_start_hz=0.1, f_stop_hz=10.0, fade_in_s=2.0, const_s=20.0, record_s=34.0, fade_out_s=1.0)
    >>> seg, = segments_from_sid([run])
    >>> seg.axis, seg.start_s, seg.end_s, seg.f_min_hz
    ('lon', 101.0, 135.0, 0.1)
    """
    if extent not in ("excitation", "mode"):
        raise DataError(f"{extent=} must be 'excitation' or 'mode'")
    table = sorted(_sids_runs(runs), key=lambda r: r.start_s)
    sidd = None if sidd_time_s is None else np.sort(np.asarray(sidd_time_s, dtype=np.float64))
    out = []
    for k, run in enumerate(table):
        if run.axis not in SID_AXES:
            raise DataError(f"SIDS row at {run.start_s:.2f} s: SID_AXIS={run.axis} is not a known axis (1-19)")
        axis, name = SID_AXES[run.axis]
        start, end = run.start_s + delay_s, run.start_s + delay_s + run.record_s
        if extent == "mode":
            start, end = run.start_s, end + run.fade_in_s + run.const_s + run.fade_out_s
        if np.isfinite(run.end_s):
            end = min(end, run.end_s)
        if sidd is not None:
            next_start = table[k + 1].start_s if k + 1 < len(table) else np.inf
            inside = sidd[(sidd >= run.start_s) & (sidd < next_start)]
            end = min(end, float(inside[-1])) if inside.size else -np.inf
        if end <= start:
            continue
        lo, hi = sorted((run.f_start_hz, run.f_stop_hz))
        detail = f"SID_AXIS={run.axis} ({name}), magnitude {run.magnitude:g}"
        out.append(
            Segment(
                axis=axis,  # type: ignore[arg-type]
                kind="sweep",
                start_s=start,
                end_s=end,
                source="sids",
                f_min_hz=lo,
                f_max_hz=hi,
                detail=detail,
            )
        )
    return tuple(out)


# ------------------------------------------------------------------ checks of detection inputs


def _uniform(time_s: np.ndarray) -> tuple[np.ndarray, float]:
    t = np.asarray(time_s, dtype=np.float64)
    if t.ndim != 1 or t.size < 10 or not np.isfinite(t).all():
        raise DataError(f"time_s must be a finite 1-D array of at least 10 samples, got shape {t.shape}")
    steps = np.diff(t)
    dt = float(np.median(steps))
    if dt <= 0 or np.max(np.abs(steps - dt)) > 1e-3 * dt:
        raise DataError("time_s must be uniformly sampled; resample the inputs first")
    return t, dt


def _stepped(found: FoundManeuver, raw: np.ndarray | None, dt: float) -> FoundManeuver | None:
    """A doublet or 3211 started at the first step of the mixer input as logged; None if that input never steps.

    An injected step changes the logged input within a sample or two; the
    loop's own reaction to a disturbance, or its recovery after a
    maneuver, moves it smoothly. The joint fit can also reach back into the
    hover before the first step where the feedback model leaves a drift.
    """
    if found.kind not in ("doublet", "3211") or raw is None:
        return found
    lag = max(1, int(round(_STEP_RISE_S / dt)))  # a step smoothed by the resampling filter still rises this fast
    jumps = np.abs(raw[lag:] - raw[:-lag])
    spread = float(np.median(jumps)) / 0.6745
    if spread <= 0:
        return found
    lo = max(0, found.first - int(round(_STEP_LOOK_BACK_S / dt)))
    window = jumps[lo : found.last]
    if window.size == 0 or window.max() <= _STEP_JUMP * spread:
        return None
    sharp = np.flatnonzero(window > max(_STEP_JUMP / 2 * spread, _FIRST_STEP * window.max()))
    return replace(found, first=max(found.first, lo + int(sharp[0])))  # the change from sharp[0] to + lag


def _followed(found: FoundManeuver, rate: np.ndarray | None, dt: float) -> bool:
    """Whether the axis's rate answers a doublet or 3211: it moves more during it than in the hover before.

    A step injected anywhere in the loop turns the vehicle; the controller's
    own chatter (a mission's descent, a gust) moves the mixer input as much
    while the rate stays at its noise (True where no rate is logged).
    """
    if found.kind not in ("doublet", "3211") or rate is None:
        return True
    span = found.last - found.first + 1
    after = min(rate.size, found.last + 1 + int(round(1.0 / dt)))
    before = rate[max(0, found.first - span) : found.first]
    if before.size < max(10, span // 2):
        return True
    during = rate[found.first : after]
    return bool(np.std(during) >= _FOLLOWED * np.std(before))


def _ringing(sweep: FoundSweep, steps: Sequence[FoundManeuver], dt: float) -> bool:
    """Whether a ridge "sweep" is only a doublet's or 3211's reaction: less than a sweep's length outside it.

    A step excites every frequency at once and the closed loop rings down
    after it, so its ridge may fall steadily for a while; the strict joint
    fit that found the step is the better witness.
    """
    outside = sweep.last - sweep.first
    for step in steps:
        if step.axis == sweep.axis and step.first <= sweep.last and sweep.first <= step.last:
            outside -= min(sweep.last, step.last + int(_RING_S / dt)) - max(sweep.first, step.first)
    return outside * dt < _MIN_TONE_S


def _check_responses(responses: Mapping[str, Mapping[str, np.ndarray]], n: int) -> dict[str, dict[str, np.ndarray]]:
    checked = {}
    for axis, named in responses.items():
        if axis not in AXES:
            raise DataError(f"unknown axis {axis!r} (expected {', '.join(AXES)})")
        traces = {}
        for name, values in named.items():
            x = np.asarray(values, dtype=np.float64)
            if x.shape != (n,) or not np.isfinite(x).all():
                raise DataError(f"{axis} trace {name!r} must be {n} finite samples, got shape {x.shape}")
            traces[name] = x
        if traces:
            checked[axis] = traces
    return checked


def _check_inputs(inputs: Mapping[str, np.ndarray], n: int) -> dict[str, np.ndarray]:
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


# ------------------------------------------------------------------ System ID runs and segment files


def _sids_runs(runs: Sequence[SystemIdRun] | Mapping[str, Any]) -> list[SystemIdRun]:
    """Checked runs, from runs or from SIDS columns (whose runs have no known end)."""
    if not isinstance(runs, Mapping):
        return [_checked_run(run) for run in runs]
    if "time_s" in runs:
        times = np.asarray(runs["time_s"], dtype=np.float64)
    elif "TimeUS" in runs:
        times = np.asarray(runs["TimeUS"], dtype=np.float64) * 1e-6
    else:
        raise DataError("SIDS rows need a TimeUS (µs) or time_s (s) column")
    missing = [name for name in _SID_FIELDS if name not in runs]
    if missing:
        raise DataError(f"SIDS rows lack the field(s) {', '.join(missing)}")
    columns = {ours: np.asarray(runs[name], dtype=np.float64) for name, ours in _SID_FIELDS.items()}
    rows = [
        SystemIdRun(
            start_s=float(t),
            end_s=float("nan"),
            axis=int(columns["axis"][i]),
            axis_name="",
            **{k: float(columns[k][i]) for k in _SID_FIELDS.values() if k != "axis"},
        )
        for i, t in enumerate(times)
    ]
    return [replace(run, axis_name=_axis_name(run.axis)) for run in map(_checked_run, rows)]


def _axis_name(axis: int) -> str:
    """ArduPilot's name of a ``SID_AXIS`` in lower case (``"rate roll"``), ``"other"`` if unknown."""
    return SID_AXES[axis][1].lower() if axis in SID_AXES else "other"


def _checked_run(run: SystemIdRun) -> SystemIdRun:
    """`run` with an integer axis, after checking its settings are finite (a non-finite end is unknown)."""
    for item in fields(SystemIdRun):
        value = getattr(run, item.name)
        if item.name not in ("end_s", "axis_name") and not np.isfinite(value):
            raise DataError(f"SIDS row at {run.start_s}: {item.name}={value} is not finite")
    if int(run.axis) != run.axis:
        raise DataError(f"SIDS row at {run.start_s:.2f} s: axis={run.axis} is not an integer")
    return replace(run, axis=int(run.axis))
