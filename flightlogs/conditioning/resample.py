"""Bring signals with different, possibly jittery, time bases onto one uniform time base.

A flight log holds each canonical signal on its own clock ticks (100 Hz
states, 20 Hz anemometer, 1 kHz IMU, with timing jitter and dropped samples);
identification needs one uniformly sampled table. This module builds that
time base (:func:`uniform_time_base`), interpolates each signal onto it
(:func:`resample_signal`, :func:`resample_signals`) and reports the gaps that
must not be bridged (:func:`find_gaps`, :func:`contiguous_spans`), so that the
caller can split a record rather than invent data. The ``Record`` table itself
is assembled elsewhere from the arrays returned here.

Interpolation never extrapolates: a time outside the span of the source (or
inside one of its gaps) gets NaN, or raises :class:`~flightlogs.errors.DataError`
on request.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Literal

import numpy as np

from flightlogs._arrays import ByContents
from flightlogs.conditioning._resampling import (
    TIME_TOL_S,
    AntiAlias,
    Interpolant,
    check_time_base,
    check_times,
    complement,
    intersect,
    nominal_interval,
    piece_bounds,
    snap,
)
from flightlogs.errors import DataError
from flightlogs.flightlog import Signal, logged_rate_hz

__all__ = [
    "Method",
    "SeriesLike",
    "Gap",
    "ContiguousSpans",
    "find_gaps",
    "uniform_time_base",
    "resample_signal",
    "resample_signals",
    "contiguous_spans",
]

#: Interpolation methods: cubic spline, shape-preserving PCHIP, straight lines.
Method = Literal["spline", "pchip", "linear"]

#: A signal as accepted here: a :class:`Signal`, or a ``(time_s, values)`` pair of arrays.
SeriesLike = Signal | tuple[np.ndarray, np.ndarray]

_DOWNSAMPLE_MARGIN = 1.02  # filter only when the source is > 2 % faster than the target


@dataclass(frozen=True, slots=True)
class Gap:
    """A stretch where a signal has no samples close enough to interpolate across.

    Parameters
    ----------
    signal : str
        Name of the signal with the gap.
    start_s : float
        Time of the last sample before the gap, s (or the start of the span
        asked for, when the signal starts late).
    end_s : float
        Time of the first sample after the gap, s (or the end of the span
        asked for, when the signal stops early).
    """

    signal: str
    start_s: float
    end_s: float

    def __post_init__(self) -> None:
        if not (np.isfinite(self.start_s) and np.isfinite(self.end_s)) or self.end_s < self.start_s:
            raise ValueError(f"gap of {self.signal!r}: end_s={self.end_s} before start_s={self.start_s}")

    @property
    def duration_s(self) -> float:
        """Length of the gap, s."""
        return self.end_s - self.start_s

    def describe(self) -> str:
        """One-line description, e.g. ``"q: 0.84 s gap at 12.30 s"``."""
        return f"{self.signal}: {self.duration_s:.2f} s gap at {self.start_s:.2f} s"


@dataclass(frozen=True, slots=True, kw_only=True)
class ContiguousSpans:
    """Pieces of a time span where every signal has data, and the gaps that cut it.

    Parameters
    ----------
    spans : tuple of (float, float)
        ``(start_s, end_s)`` of each piece, s, in time order; both ends hold
        data for every signal (on the time base, when one was given).
    gaps : tuple of Gap
        Every stretch of the requested span a signal does not cover, in time
        order (several signals may report overlapping gaps).
    """

    spans: tuple[tuple[float, float], ...]
    gaps: tuple[Gap, ...]

    def __post_init__(self) -> None:
        spans = tuple((float(a), float(b)) for a, b in self.spans)
        for (a, b), nxt in zip(spans, spans[1:] + ((np.inf, np.inf),)):
            if not a <= b < nxt[0]:
                raise ValueError(f"spans must be ordered and disjoint, got {spans}")
        object.__setattr__(self, "spans", spans)
        object.__setattr__(self, "gaps", tuple(sorted(self.gaps, key=lambda g: (g.start_s, g.signal))))

    @property
    def duration_s(self) -> float:
        """Total time covered by the spans, s."""
        return float(sum(b - a for a, b in self.spans))

    def messages(self) -> tuple[str, ...]:
        """Warnings for a user, e.g. ``"q: 0.84 s gap at 12.30 s; record split"``."""
        if not self.spans:
            return tuple(f"{g.describe()}; nothing left" for g in self.gaps)
        first, last = self.spans[0][0], self.spans[-1][1]
        out = []
        for gap in self.gaps:
            inside = gap.start_s >= first - TIME_TOL_S and gap.end_s <= last + TIME_TOL_S
            out.append(f"{gap.describe()}; record {'split' if inside else 'trimmed'}")
        return tuple(out)


def find_gaps(time_s: np.ndarray, *, max_gap_samples: float = 5, name: str = "") -> tuple[Gap, ...]:
    """Find where consecutive samples are too far apart to interpolate across.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Sample times, s, strictly increasing.
    max_gap_samples : float, optional
        A step longer than this many nominal sample intervals (the median
        interval) is a gap. Default 5.
    name : str, optional
        Signal name written into each :class:`Gap`.

    Returns
    -------
    tuple of Gap
        The gaps in time order, each from the last sample before to the first
        sample after.

    Raises
    ------
    DataError
        If the times are not finite and strictly increasing.

    Examples
    --------
    >>> t = np.r_[np.arange(0, 12.31, 0.01), np.arange(13.14, 20, 0.01)]
    >>> find_gaps(t, name="q")[0].describe()
    'q: 0.84 s gap at 12.30 s'
    """
    time_s = check_times(time_s, name or "time_s")
    bounds = piece_bounds(time_s, nominal_interval(time_s), max_gap_samples)
    return tuple(
        Gap(name, float(time_s[prev_end - 1]), float(time_s[start]))
        for (_, prev_end), (start, _) in zip(bounds[:-1], bounds[1:])
    )


def uniform_time_base(
    signals: Mapping[str, Signal] | Iterable[SeriesLike],
    *,
    rate_hz: float | None = None,
    start_s: float | None = None,
    end_s: float | None = None,
) -> np.ndarray:
    """Build a uniform time base over the span all signals cover.

    Parameters
    ----------
    signals : Mapping[str, Signal] or iterable of Signal or (time_s, values)
        Signals to cover; only their times are used.
    rate_hz : float, optional
        Sample rate, Hz. Default: the fastest logged rate among `signals`
        (one over the median interval: :func:`~flightlogs.flightlog.logged_rate_hz`,
        which a gap does not move), rounded to the nearest 1 Hz (kept as is below 1 Hz).
    start_s, end_s : float, optional
        Span to cover, s. Default: the intersection of the signals' spans
        (latest first sample to earliest last sample).

    Returns
    -------
    ndarray, shape (n_samples,)
        Times ``k / rate_hz`` for integer ``k``, s, inside the span; on whole
        multiples of the sample interval, so records cut from one flight share
        their grid.

    Raises
    ------
    DataError
        If there is no signal, the signals do not overlap, or the span holds
        fewer than 2 samples.

    Examples
    --------
    >>> fast = (np.arange(0.003, 10, 0.01), np.zeros(1000))
    >>> slow = (np.arange(0.5, 8, 0.05), np.zeros(150))
    >>> t = uniform_time_base([fast, slow])
    >>> float(t[0]), float(t[-1]), round(1 / float(t[1] - t[0]))
    (0.5, 7.95, 100)
    """
    series = _series_list(signals)
    if not series:
        raise DataError("no signal to build a time base from")
    if rate_hz is None:
        times = {id(t): t for _, t, _ in series if len(t) > 1 and t[-1] > t[0]}  # a message's fields share theirs
        rates = [logged_rate_hz(t) for t in times.values()]
        if not rates:
            raise DataError("cannot infer a sample rate: every signal has fewer than 2 samples")
        fastest = max(rates)
        rate_hz = float(round(fastest)) if fastest >= 1.0 else fastest
    if not (np.isfinite(rate_hz) and rate_hz > 0):
        raise DataError(f"{rate_hz=} must be a positive, finite rate in Hz")
    latest = max(series, key=lambda s: s[1][0])
    earliest = min(series, key=lambda s: s[1][-1])
    start = float(latest[1][0]) if start_s is None else float(start_s)
    end = float(earliest[1][-1]) if end_s is None else float(end_s)
    if end <= start:
        raise DataError(
            f"no common time span: {earliest[0]} ends at {earliest[1][-1]:.2f} s, "
            f"{latest[0]} starts at {latest[1][0]:.2f} s"
            if start_s is None and end_s is None
            else f"end_s={end} must be after start_s={start}"
        )
    k = np.arange(np.ceil((start - TIME_TOL_S) * rate_hz), np.floor((end + TIME_TOL_S) * rate_hz) + 1)
    if k.size < 2:
        raise DataError(f"the span {start:.3f}-{end:.3f} s holds fewer than 2 samples at {rate_hz} Hz")
    return k / rate_hz


def resample_signal(
    signal: SeriesLike,
    time_base: np.ndarray,
    *,
    method: Method = "spline",
    max_gap_samples: float = 5,
    anti_alias: bool = True,
    outside: Literal["nan", "raise"] = "nan",
) -> np.ndarray:
    """Interpolate one signal onto a uniform time base.

    Parameters
    ----------
    signal : Signal or (time_s, values)
        Source samples; times strictly increasing, s; values finite.
    time_base : ndarray, shape (n_samples,)
        Uniform target times, s (e.g. from :func:`uniform_time_base`).
    method : {"spline", "pchip", "linear"}, optional
        ``"spline"`` (default): not-a-knot cubic spline, which reproduces
        polynomials up to degree 3 (the dissertation's "fourth-order", i.e.
        degree-3, spline); ``"pchip"``: monotone piecewise cubic, no overshoot,
        for step-like signals; ``"linear"``: straight lines.
    max_gap_samples : float, optional
        Source steps longer than this many nominal intervals are gaps and are
        not interpolated across (see :func:`find_gaps`). Default 5.
    anti_alias : bool, optional
        Low-pass the source before downsampling (default True); turn off for
        step-like signals where the filter's ringing matters more than aliasing.
    outside : {"nan", "raise"}, optional
        Target times outside the source span, or inside a gap, get NaN
        (default) or raise :class:`DataError`.

    Returns
    -------
    ndarray, shape (n_samples,)
        Values on `time_base`, in the source unit; NaN where not covered.

    Raises
    ------
    DataError
        If the source or the time base is malformed, or `outside` is
        ``"raise"`` and `time_base` leaves the source's samples.

    Notes
    -----
    When the source rate exceeds the target rate by more than 2 %, the source
    is first low-passed: a jittery source is splined onto a uniform grid at its
    own mean rate, then convolved with a Kaiser-window FIR (cutoff at half the
    target rate, pass band to 0.4 × and stop band from 0.6 × the target rate,
    60 dB stop-band attenuation, pass-band ripple below 0.01 dB). The kernel is
    symmetric and applied centred, so the filter has exactly zero phase; its
    DC gain is one and the ends are padded by odd reflection, so straight lines
    pass unchanged. Anything that could alias into 0-0.4 × the target rate
    (the band used for identification, 0-40 Hz at 100 Hz) is at least 60 dB
    down; only 0.4-0.5 × may receive aliases from the transition band. The
    first and last half-kernel (about 0.1 s at 1 kHz → 100 Hz) of each
    contiguous piece see reflected data. A Butterworth ``sosfiltfilt`` was not
    used: its roll-off would need order > 20 for the same stop band.

    Examples
    --------
    >>> t_src = np.arange(0, 2.01, 0.05)  # 20 Hz
    >>> t_new = np.arange(0, 201) / 100   # 100 Hz
    >>> y = resample_signal((t_src, 3 * t_src**3 - t_src), t_new)
    >>> bool(np.allclose(y, 3 * t_new**3 - t_new))
    True
    """
    name, t, v = _as_series(signal)
    if outside not in ("nan", "raise"):
        raise DataError(f"{outside=} must be 'nan' or 'raise'")
    out = _resample_columns(t, [v], time_base, method, max_gap_samples, anti_alias)[:, 0]
    if outside == "raise" and np.isnan(out).any():
        first = float(time_base[np.isnan(out)][0])
        raise DataError(
            f"{name}: no data to interpolate at {first:.3f} s "
            f"(samples span {t[0]:.3f}-{t[-1]:.3f} s, gaps over {max_gap_samples} intervals excluded)"
        )
    return out


def _resample_columns(
    t: np.ndarray,
    columns: list[np.ndarray],
    time_base: np.ndarray,
    method: str,
    max_gap_samples: float,
    anti_alias: bool,
) -> np.ndarray:
    """Columns sampled at the same times `t` (s, shape (n,)), each (n,), onto `time_base`: shape (n_base, k).

    One spline system (or filter) per piece for all columns, solved for as many columns at once as
    :data:`_BLOCK_VALUES` allows: signals of one message share their times (one column at a time, the
    halvings of the spline's system took a tenth of conditioning a sweep; 24 columns of 4 000 knots are one
    block).
    """
    tb, dt_target = check_time_base(time_base)
    if method not in ("spline", "pchip", "linear"):
        raise DataError(f"{method=} must be 'spline', 'pchip' or 'linear'")
    dt_src = nominal_interval(t)
    out = np.full((len(columns), tb.size), np.nan).T  # (n_base, k), each column contiguous: the signals to come
    filter_needed = anti_alias and dt_target > _DOWNSAMPLE_MARGIN * dt_src
    for i0, i1 in piece_bounds(t, dt_src, max_gap_samples):
        pt = t[i0:i1]
        first = int(np.searchsorted(tb, pt[0] - TIME_TOL_S, side="left"))  # the base's samples inside the piece
        stop = int(np.searchsorted(tb, pt[-1] + TIME_TOL_S, side="right"))
        if stop <= first:
            continue
        if pt.size == 1:
            out[first:stop] = [column[i0] for column in columns]
            continue
        low = AntiAlias(pt, dt_src, 1.0 / dt_target) if filter_needed else None
        knots = pt if low is None else low.grid
        at = Interpolant(knots, np.clip(tb[first:stop], knots[0], knots[-1]), method)
        width = max(1, _BLOCK_VALUES // max(knots.size, stop - first))
        for lo in range(0, len(columns), width):
            block = np.empty((knots.size, min(width, len(columns) - lo)))
            for k, column in enumerate(columns[lo : lo + width]):
                piece = column[i0:i1].astype(np.float64, copy=False)
                block[:, k] = piece if low is None else low(piece)
            at(block, out[first:stop, lo : lo + block.shape[1]])
    return out


_BLOCK_VALUES = 1 << 18  # values of a block of columns interpolated at once (2 MB; several such working arrays)


def resample_signals(
    signals: Mapping[str, Signal],
    time_base: np.ndarray,
    *,
    method: Method | Mapping[str, Method] = "spline",
    max_gap_samples: float = 5,
    anti_alias: bool = True,
) -> dict[str, np.ndarray]:
    """Resample several signals onto one time base.

    Parameters
    ----------
    signals : Mapping[str, Signal]
        Signals by name.
    time_base : ndarray, shape (n_samples,)
        Uniform target times, s.
    method : {"spline", "pchip", "linear"} or Mapping[str, str], optional
        One method for all, or a method per signal name (``"spline"`` for the
        names not listed). See :func:`resample_signal`.
    max_gap_samples : float, optional
        Gap threshold in nominal source intervals. Default 5.
    anti_alias : bool, optional
        Low-pass before downsampling. Default True.

    Returns
    -------
    dict of str to ndarray, shape (n_samples,)
        Resampled values by name, NaN where a signal has no data; use
        :func:`contiguous_spans` to cut the time base into fully covered pieces.

    Raises
    ------
    DataError
        If a signal or the time base is malformed.
    """
    groups: dict[str, ByContents[list[tuple[str, np.ndarray]]]] = {}
    shared: list[tuple[str, np.ndarray, list[tuple[str, np.ndarray]]]] = []
    for name, signal in signals.items():  # signals of one method on equal times: resampled together
        chosen = method.get(name, "spline") if isinstance(method, Mapping) else method
        _, t, v = _as_series(signal, name)
        same = groups.setdefault(chosen, ByContents())
        members = same.get(t)
        if members is None:
            members = []
            same.put(t, members)
            shared.append((chosen, t, members))
        members.append((name, v))
    out: dict[str, np.ndarray] = {}
    for kind, t, members in shared:
        values = _resample_columns(t, [v for _, v in members], time_base, kind, max_gap_samples, anti_alias)
        out |= {name: values[:, k] for k, (name, _) in enumerate(members)}
    return {name: out[name] for name in signals}


def contiguous_spans(
    signals: Mapping[str, Signal] | Iterable[SeriesLike],
    span: np.ndarray | tuple[float, float],
    *,
    max_gap_samples: float = 5,
    min_duration_s: float = 0.0,
) -> ContiguousSpans:
    """Split a span into the pieces where every signal has data.

    Parameters
    ----------
    signals : Mapping[str, Signal] or iterable of Signal or (time_s, values)
        Signals that must all be present.
    span : ndarray, shape (n_samples,), or (float, float)
        A time base (pieces are then snapped to its samples) or a
        ``(start_s, end_s)`` span, s.
    max_gap_samples : float, optional
        Gap threshold in nominal source intervals, as in :func:`find_gaps`.
        Default 5.
    min_duration_s : float, optional
        Drop pieces shorter than this, s. Default 0 (keep every piece that
        holds at least one time-base sample).

    Returns
    -------
    ContiguousSpans
        The pieces and every gap that cut or trimmed the span.

    Raises
    ------
    DataError
        If a signal is malformed or the span is empty.

    Examples
    --------
    >>> t = np.arange(0, 3000) / 100
    >>> q = np.r_[t[:1230], t[1314:]]
    >>> found = contiguous_spans({"p": (t, t), "q": (q, q)}, t)
    >>> found.spans
    ((0.0, 12.29), (13.14, 29.99))
    >>> found.messages()
    ('q: 0.85 s gap at 12.29 s; record split',)
    """
    grid = None
    if isinstance(span, tuple):
        lo, hi = float(span[0]), float(span[1])
    else:
        grid, _ = check_time_base(span)
        lo, hi = float(grid[0]), float(grid[-1])
    if not hi > lo:
        raise DataError(f"the span {lo}-{hi} s is empty")
    covered = [(lo, hi)]
    gaps: list[Gap] = []
    for name, t, _ in _series_list(signals):
        pieces = [(float(t[a]), float(t[b - 1])) for a, b in piece_bounds(t, nominal_interval(t), max_gap_samples)]
        holes = complement(pieces, lo, hi)
        gaps.extend(Gap(name, a, b) for a, b in holes)
        covered = intersect(covered, pieces)
    if grid is not None:
        covered = snap(covered, grid)
    kept = tuple((a, b) for a, b in covered if b - a >= min_duration_s - TIME_TOL_S)
    return ContiguousSpans(spans=kept, gaps=tuple(gaps))


# ---------------------------------------------------------------- helpers


def _series_list(signals: Mapping[str, Signal] | Iterable[SeriesLike]) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """Normalise the accepted signal collections to (name, time_s, values) triples."""
    if isinstance(signals, Mapping):
        items = [_as_series(sig, str(name)) for name, sig in signals.items()]
    else:
        items = [_as_series(sig, f"signal {i}") for i, sig in enumerate(signals)]
    return items


def _as_series(signal: SeriesLike, default_name: str = "signal") -> tuple[str, np.ndarray, np.ndarray]:
    """Validate a Signal or (time_s, values) pair and return (name, time_s, values)."""
    if isinstance(signal, Signal):
        name, t, v = signal.name, signal.time_s, signal.stored_values  # float32 widened a piece at a time
    else:
        try:
            t, v = signal
        except (TypeError, ValueError) as err:
            raise DataError(f"{default_name}: expected a Signal or a (time_s, values) pair") from err
        name = default_name
    t = check_times(t, name)
    v = np.asarray(v)
    if v.dtype != np.float32:
        v = v.astype(np.float64, copy=False)
    if v.shape != t.shape:
        raise DataError(f"{name}: {t.size} times but values of shape {v.shape}")
    if not np.isfinite(v).all():
        raise DataError(f"{name}: {int((~np.isfinite(v)).sum())} non-finite values; drop them before resampling")
    return name, t, v
