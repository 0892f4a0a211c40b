"""Recover the injected excitation from closed-loop mixer inputs.

In closed loop the mixer input is the excitation plus the controller's
feedback, ``delta = e + c``, and a fast rate loop cancels most of a
mixer-level doublet within a fraction of a second, so its shape is lost in
``delta``. Near hover the feedback is close to linear in the measured states
of the same axis (rate, attitude, velocity), ``c ≈ K x + c0``. Fitting K by
least squares where no excitation runs and subtracting ``K x`` leaves ``e``,
whose doublets, 3211s and sweeps have their true shape again.

A short record (a doublet with a few seconds of hover either side) has too
little quiet data for that fit. Around each burst of activity the feedback
is therefore also fitted jointly with a doublet, and with a 3-2-1-1 (see
:mod:`flightlogs.maneuvers._doublet_fit`): where one explains the burst, the
excitation there is the input minus that joint fit of the feedback.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from flightlogs.errors import DataError
from flightlogs.maneuvers._detection import _activity, _bursts
from flightlogs.maneuvers._doublet_fit import fit_doublet
from flightlogs.masks import true_runs

__all__ = ["FEEDBACK_STATES", "ExcitationRecovery", "estimate_excitation"]

#: States each axis's controller feeds back (FRD/NED canonical names).
FEEDBACK_STATES: Mapping[str, tuple[str, ...]] = {
    "lat": ("p", "phi", "ve"),
    "lon": ("q", "theta", "vn"),
    "yaw": ("r", "psi"),
    "thr": ("vd", "height_agl"),
}
_ANGLES = ("phi", "theta", "psi")
_MIN_FIT_SAMPLES = 200
_TRUSTED_QUIET_S = 10.0  # a quiet fit over this much hover (several periods of the outer loops) is kept
# bursts searched for doublets: as flightlogs.maneuvers.segments.detect_segments finds them by default
_THRESHOLD, _TREND_S, _MERGE_S, _MIN_ACTIVE_S = 4.0, 10.0, 2.0, 0.3
_MAX_BURST_S = 15.0  # longer bursts are not one doublet (pulses up to 5 s, plus the loop settling)
_PAD_S = 3.0  # hover either side of a burst in the joint fit, s
_WIDE_PAD_S = 10.0  # the same where the quiet fit is not trusted: the joint fit replaces it as far as it can
_GAP_S = 0.5  # the window keeps this far from the axis's other bursts, s
_RAMP_S = 1.0  # the joint fit's excitation fades into the quiet-fit one over this much of the pad, s


def estimate_excitation(
    inputs: Mapping[str, np.ndarray],
    states: Mapping[str, np.ndarray],
    quiet: np.ndarray,
    *,
    time_s: np.ndarray | None = None,
) -> dict[str, np.ndarray]:
    """Mixer inputs with the linear state feedback removed.

    Parameters
    ----------
    inputs : Mapping[str, ndarray], each shape (n_samples,)
        Mixer input by axis (``"lat"``, ``"lon"``, ``"yaw"``, ``"thr"``).
    states : Mapping[str, ndarray], each shape (n_samples,)
        Canonical signals on the same time base (see :data:`FEEDBACK_STATES`).
    quiet : ndarray of bool, shape (n_samples,)
        Samples with no excitation, where the feedback law is fitted.
    time_s : ndarray, shape (n_samples,), optional
        Uniform sample times, s. When given, every burst of activity (up to
        15 s) is also searched for a doublet or a 3-2-1-1 fitted jointly
        with the feedback; without it only the quiet-sample fit is made.

    Returns
    -------
    dict of ndarray
        For each axis, the input minus its fitted feedback (``K x + c0`` on
        the quiet samples; with fewer than 200 of them, only the median).
        Where a doublet or a 3-2-1-1 explains a burst, the input minus the
        feedback fitted jointly with it, blended into the rest over 1 s,
        unless the quiet fit is trusted (10 s of quiet samples or more) and
        already shows it. Without the axis's states, the input itself;
        NaN as 0.

    Raises
    ------
    DataError
        If `time_s` does not match the inputs or is not uniform.

    Notes
    -----
    The joint fit (:mod:`flightlogs.maneuvers._doublet_fit`) models the input within
    3 s of a burst (10 s where the quiet fit is not trusted) as the
    states, their running integrals, cubic B-splines with 1 s knots and two
    adjacent pulses of equal width, scanned in start (from 1 s before the
    burst) and width (0.1 to 5 s). A doublet is kept when its pulses have
    opposite signs and agree in size within 3:1, each stands out of the
    residual by 10 standard errors, together they leave at most 5 % of the
    burst's energy unexplained, and 1 s of the window lies either side.
    A 3-2-1-1 (pulses of 3, 2, 1 and 1 units, the unit scanned from 0.1 to
    5/3 s) is fitted the same way; it replaces the doublet when its four
    pulses pass the same rules and it leaves at most half the energy the
    best doublet leaves. Bursts less than 3 s apart are fitted as one, so
    the steps of a 3-2-1-1 are not fitted as separate doublets. States
    named as angles are unwrapped.

    Examples
    --------
    A doublet hidden by a feedback that cancels it is recovered exactly.

    >>> rng = np.random.default_rng(0)
    >>> q = rng.normal(size=2000)
    >>> e = np.zeros(2000); e[1000:1100], e[1100:1200] = 1.0, -1.0
    >>> states = {"q": q, "theta": np.cumsum(q) * 0.01, "vn": np.zeros(2000)}
    >>> quiet = np.ones(2000, dtype=bool); quiet[990:1210] = False
    >>> out = estimate_excitation({"lon": e - 2.0 * q}, states, quiet)["lon"]
    >>> bool(np.allclose(out, e, atol=1e-9))
    True
    """
    return ExcitationRecovery(inputs, states, time_s=time_s).estimate(quiet)


class ExcitationRecovery:
    """:func:`estimate_excitation` of one record's inputs for one quiet mask after another.

    Segmentation fits the feedback twice (the second time without the
    maneuvers the first found); the bursts of activity in each raw input do
    not depend on the mask, so they are found once, on first use. (The
    doublets fitted jointly with the feedback depend on the bursts found in
    the fitted excitation as well, whose edges move by a sample from one
    pass to the next: kept, they saved 2 fits of 87 on 21 logs; not kept.)

    Parameters
    ----------
    inputs : Mapping[str, ndarray], each shape (n_samples,)
        Mixer input by axis, as :func:`estimate_excitation`'s.
    states : Mapping[str, ndarray], each shape (n_samples,)
        Canonical signals on the same time base.
    time_s : ndarray, shape (n_samples,), optional
        Uniform sample times, s (without them, only the quiet-sample fit).
    """

    def __init__(
        self, inputs: Mapping[str, np.ndarray], states: Mapping[str, np.ndarray], *, time_s: np.ndarray | None = None
    ) -> None:
        self._inputs, self._states, self._time_s = inputs, states, time_s
        self._raw: dict[str, tuple[float, list[tuple[int, int]]]] = {}  # by axis: the input's median and bursts

    def estimate(self, quiet: np.ndarray, read: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """The inputs with the feedback fitted on `quiet` removed.

        Parameters
        ----------
        quiet : ndarray of bool, shape (n_samples,)
            Samples with no excitation, where the feedback law is fitted.
        read : ndarray of bool, shape (n_samples,), optional
            The samples the caller reads of the result: a burst's joint fit, which changes the excitation
            within 10 s of it, is only made where it reaches one of them. Segmentation reads the stretches
            between the logged runs: a burst whose window (up to 10 s either side of it) lies within a
            logged run is not fitted (67 of the 408 bursts fitted on the chapter 3 campaign's 120 logs, none
            of which found a doublet).
            None: every sample.

        Returns
        -------
        dict of ndarray
            As :func:`estimate_excitation`; outside `read`, where a burst is not fitted, the quiet-sample
            fit's excitation.

        Raises
        ------
        DataError
            If `time_s` does not match the inputs or is not uniform.
        """
        dt = None if self._time_s is None else _interval(self._time_s, quiet.size)
        estimated = {}
        for axis, values in self._inputs.items():
            u = np.asarray(values, dtype=np.float64)
            names = FEEDBACK_STATES.get(axis, ())
            if not names or not all(name in self._states for name in names):
                estimated[axis] = np.nan_to_num(u)
                continue
            # the states as columns, not an (n, 3) copy: the regressors are built where fitted, a block at a time
            x = [np.asarray(self._states[name], dtype=np.float64) for name in names]
            finite = np.isfinite(u)
            for column in x:
                finite &= np.isfinite(column)
            out = _quiet_fit(u, x, quiet & finite)
            if dt is not None:
                if axis not in self._raw:
                    self._raw[axis] = _raw_bursts(u, finite, dt)
                trusted = bool(np.count_nonzero(quiet & finite) * dt >= _TRUSTED_QUIET_S)
                angles = [name in _ANGLES for name in names]
                out = _with_doublets(u, x, out, trusted, finite, dt, angles, self._raw[axis], read)
            estimated[axis] = out
        return estimated


def _interval(time_s: np.ndarray, n: int) -> float:
    t = np.asarray(time_s, dtype=np.float64)
    if t.shape != (n,) or n < 2 or not np.isfinite(t).all():
        raise DataError(f"time_s has shape {t.shape}, the inputs have {n} samples")
    steps = np.diff(t)
    dt = float(np.median(steps))
    if dt <= 0 or np.max(np.abs(steps - dt)) > 1e-3 * dt:
        raise DataError("time_s must be uniformly sampled")
    return dt


def _quiet_fit(u: np.ndarray, x: list[np.ndarray], usable: np.ndarray) -> np.ndarray:
    """Input minus ``K x + c0`` fitted on the usable quiet samples, or minus its median if too few (NaN as 0).

    `x` holds the states, each shape (n,). The feedback is subtracted
    `_BLOCK` samples at a time: an (n, 4) matrix of regressors would be the
    largest array of the whole segmentation on a long log.
    """
    if usable.sum() < _MIN_FIT_SAMPLES:
        finite = np.isfinite(u)
        return np.nan_to_num(u - (np.median(u[finite]) if finite.any() else 0.0))
    gains, *_ = np.linalg.lstsq(_regressors(x, usable), u[usable], rcond=None)
    out = np.empty(u.size)
    for start in range(0, u.size, _BLOCK):
        rows = slice(start, start + _BLOCK)
        np.subtract(u[rows], _regressors(x, rows) @ gains, out=out[rows])
    return np.nan_to_num(out, copy=False)


_BLOCK = 65_536  # samples of regressors built at once


def _regressors(x: list[np.ndarray], rows: np.ndarray | slice) -> np.ndarray:
    """The states at `rows` and a column of ones, shape (n_rows, len(x) + 1)."""
    columns = [column[rows] for column in x]
    return np.column_stack([*columns, np.ones(columns[0].size)])


def _with_doublets(
    u: np.ndarray,
    x: list[np.ndarray],
    base: np.ndarray,
    trusted: bool,
    finite: np.ndarray,
    dt: float,
    angles: list[bool],
    raw: tuple[float, list[tuple[int, int]]],
    read: np.ndarray | None = None,
) -> np.ndarray:
    """`base` with the joint fit of feedback and doublet (or 3-2-1-1) put in around the bursts one explains.

    Where `base` is `trusted` (its feedback fitted on enough hover) and a
    doublet or 3-2-1-1 already explains the burst in it, `base` is kept: a
    long quiet fit averages the feedback better than a few seconds around
    one burst. A burst whose window holds none of the samples `read` is not
    fitted (None: all are read).
    """
    bursts = _candidates(base, u, finite, dt, raw)
    pad = int(round((_PAD_S if trusted else _WIDE_PAD_S) / dt))
    gap, out = int(round(_GAP_S / dt)), base.copy()
    pieces = [(start, stop - 1) for start, stop in true_runs(finite)]  # inclusive, as the bursts
    for k, (a, b) in enumerate(bursts):
        piece = next((p for p in pieces if p[0] <= a and b <= p[1]), None)
        if piece is None or (b - a) * dt > _MAX_BURST_S:
            continue
        lo = max(a - pad, piece[0], bursts[k - 1][1] + gap if k else 0)
        hi = min(b + pad, piece[1], bursts[k + 1][0] - gap if k + 1 < len(bursts) else u.size - 1)
        burst = (a - lo, b - lo)
        if read is not None and not read[lo : hi + 1].any():
            continue  # whatever the fit, nothing of it is read
        if trusted and fit_doublet(base[lo : hi + 1], np.zeros((hi - lo + 1, 0)), dt, burst) is not None:
            continue  # the quiet-sample fit shows the doublet on its own
        window = np.column_stack([column[lo : hi + 1] for column in x])
        window[:, angles] = np.unwrap(window[:, angles], axis=0)
        fit = fit_doublet(u[lo : hi + 1], window, dt, burst)
        if fit is None:
            continue
        weight = _weight(hi - lo + 1, int(round(_RAMP_S / dt)), lo > piece[0], hi < piece[1])
        out[lo : hi + 1] += weight * (fit.excitation - out[lo : hi + 1])
    return out


def _raw_bursts(u: np.ndarray, finite: np.ndarray, dt: float) -> tuple[float, list[tuple[int, int]]]:
    """The median of the input where finite, and the first and last sample of each burst of activity in it."""
    median = float(np.median(u[finite])) if finite.any() else 0.0
    return median, _bursts_in(np.where(finite, u - median, 0.0), dt)


def _bursts_in(trace: np.ndarray, dt: float) -> list[tuple[int, int]]:
    activity = _activity(trace, dt, _THRESHOLD, _TREND_S)
    return [(b.first, b.last) for b in _bursts("", activity, dt, _THRESHOLD, _MERGE_S, _MIN_ACTIVE_S)]


def _candidates(
    base: np.ndarray, u: np.ndarray, finite: np.ndarray, dt: float, raw: tuple[float, list[tuple[int, int]]]
) -> list[tuple[int, int]]:
    """First and last sample of the bursts of activity in `base` or in the raw input, merged when closer than the pad.

    The raw closed-loop input shows every doublet (the loop's reaction is
    loud); `base` may show it where a poor fit of the feedback hides it.
    Bursts less than `_PAD_S` apart are fitted together, so a doublet is
    only accepted where nothing else happens within that distance (the
    pulses of a 3-2-1-1 are one burst that no doublet explains). `raw` is
    the input's median and bursts (:func:`_raw_bursts`).
    """
    median, raw_bursts = raw
    same = np.array_equal(np.where(finite, u - median, 0.0), base)
    found = sorted(raw_bursts if same else [*_bursts_in(base, dt), *raw_bursts])
    merged: list[tuple[int, int]] = []
    for a, b in found:
        if merged and (a - merged[-1][1]) * dt < _PAD_S:
            merged[-1] = (merged[-1][0], max(merged[-1][1], b))
        else:
            merged.append((a, b))
    return merged


def _weight(n: int, ramp: int, left: bool, right: bool) -> np.ndarray:
    """Ones, with raised-cosine ramps from 0 over `ramp` samples at the ends that meet other data."""
    weight = np.ones(n)
    ramp = min(ramp, n // 2)
    rise = 0.5 - 0.5 * np.cos(np.pi * (np.arange(ramp) + 0.5) / ramp) if ramp else np.zeros(0)
    if left:
        weight[:ramp] = rise
    if right:
        weight[n - ramp :] = rise[::-1]
    return weight
