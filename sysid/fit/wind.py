"""The wind step (eq. 3.14): G_w and the wind delays from the one-step-prediction residual.

With F and G_u identified without wind (step 1), each record's measured
states predict the outputs one step ahead::

    residual = y - H0 x - H1 (F x + G_u u(t - tau_u))           (eq. 3.14)

States the record lacks (the actuator lags) are reconstructed by simulating
their own rows from the recorded inputs and states. What is left in the
accelerometer outputs is explained by ``H1 G_w u_w(t - tau_w)``: the G_w
entries are found by linear least squares at given delays, each wind delay
by a 1-D scan (coarse then fine, coordinate-wise, twice over when there are
two delays or more), then all of them are polished together by nonlinear
least squares. Each output's residual is weighted by its own level, and each
record's mean is taken out of the residual and of the wind (a per-record
bias, as VERIFY's: accelerometer bias and the trim leave a constant the wind
does not explain). Wind parameters that miss the CR% / I% guidelines are
dropped one at a time, as in step 1 (a wind delay the data cannot resolve
becomes 0).

Cramér–Rao bounds are those of the weighted least squares, corrected for
the residual's autocorrelation by an effective number of independent
samples (N_eff = N / (1 + 2 sum rho_k), Bartlett); insensitivities come from
the diagonal of the same information matrix.

The regression needs the wind where the vehicle meets it. An anemometer
clock off by more than the wind delays can take up puts the wind and the
residual apart, and every G_w term would come out insensitive as if the
wind did nothing: :mod:`sysid.fit.wind_offset` finds the offset from this
same residual (:func:`wind_cost`) before the step. Outputs of an
unidentified axis have no residual to fit; a wind parameter that only they
would inform is unidentified too (:func:`unfitted_wind` when none is left).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Literal

import numpy as np
from scipy import linalg, optimize

from flightlogs.errors import FitError, FitWarning
from flightlogs.parallel import map_forked
from flightlogs.record import Record
from sysid.fit.accuracy import Accuracy, accuracy, correlated_lags
from sysid.fit.guidelines import DEFAULT_GUIDELINES, Guidelines
from sysid.fit.reduce import ReductionStep, worst_parameter
from sysid.fit.result import WindFit
from sysid.model.assemble import Assembler, SystemMatrices
from sysid.model.axes import axis_parts
from sysid.model.structure import ModelStructure

__all__ = [
    "WindCost",
    "WindStepResult",
    "fit_wind",
    "identified_outputs",
    "prediction_residual",
    "residual_inflation",
    "sharing_delayed_winds",
    "speed_derivatives",
    "speed_spread",
    "step_one_spread",
    "unfitted_wind",
    "wind_cost",
]

WindStatus = Literal["estimated", "dropped", "unidentified"]

_SCAN_STEP_S = 0.002
_LONGEST_SCAN_S = 1.0  # the longest wind delay the scans of the G_w fit reach, s
_LONGEST_JOINT_SCAN_S = 0.5  # the longest the scans of the speed derivatives' joint solution reach, s


@dataclass(frozen=True, slots=True, kw_only=True)
class WindStepResult:
    """Wind parameters from the residual of eq. 3.14.

    Parameters
    ----------
    values : Mapping[str, float]
        Values of the wind parameters (G_w entries, 1/s; delays, s); NaN for the unidentified.
    status : Mapping[str, str]
        ``estimated``, ``dropped`` or ``unidentified`` for each wind parameter.
    accuracy : Accuracy
        CR bounds (autocorrelation-corrected), insensitivities and
        correlations of the estimated ones.
    fit : WindFit or None
        Residual RMS before and after, per output; None when nothing was fitted.
    reduction : tuple of ReductionStep
        Wind parameters dropped (J_ave columns hold the weighted residual
        sum of squares per sample).
    speed_values : Mapping[str, float]
        Step 1 parameters estimated again with G_w (:func:`speed_derivatives`): they replace step 1's.
    speed_accuracy : Accuracy or None
        Their accuracy (the G_w gains solved beside them included).
    speed_dropped : tuple of str
        Those of them the wind step could not measure (both guidelines missed): at their drop values in
        `speed_values`, each with its step in `reduction`.
    """

    values: Mapping[str, float]
    status: Mapping[str, WindStatus]
    accuracy: Accuracy
    fit: WindFit | None
    reduction: tuple[ReductionStep, ...] = ()
    speed_values: Mapping[str, float] = field(default_factory=dict)
    speed_accuracy: Accuracy | None = None
    speed_dropped: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class _Data:
    """Eq. 3.14 residuals of the records and their delayed winds (the signal of each wind channel), with output weights."""

    residual: list[np.ndarray]
    delayed: _DelayedWinds
    signals: tuple[str, ...]
    rows: list[int]
    scale: np.ndarray


class _DelayedWinds:
    """The wind signals of a set of records delayed by any amount, each record's mean taken out, records end to end.

    Cached by signal and delay, within :data:`_CACHE_BYTES`: the delay scans revisit their grids, the
    channels that carry one signal (the along-nose wind on u and on w) share it, and within
    :func:`sharing_delayed_winds` so do the fits of the same records.
    """

    def __init__(self, records: Sequence[Record], signals: Sequence[str]) -> None:
        self.times = [record.time_s for record in records]
        self.winds = {s: [record[s] for record in records] for s in signals}
        self.ends = np.cumsum([t.size for t in self.times])[:-1]
        self._cache: dict[tuple[str, float], np.ndarray] = {}
        steps = [(t[-1] - t[0]) / (t.size - 1) if t.size > 1 else 0.0 for t in self.times]
        uniform = all(dt > 0 and np.max(np.abs(np.diff(t) - dt)) <= 1e-9 * dt for t, dt in zip(self.times, steps))
        self.steps = np.array(steps) if uniform else None  # (n_records,), s: None unless every record is uniform

    def stacked(self, signal: str, tau: float) -> np.ndarray:
        """`signal` delayed by `tau` (s), shape (n_samples,), read-only."""
        key = (signal, round(float(tau), 12))
        if key not in self._cache:
            if sum(x.nbytes for x in self._cache.values()) > _CACHE_BYTES:
                self._cache.clear()
            if self.steps is not None and tau >= 0:  # np.interp's blend of two whole lags, without its search
                shifted = [_delayed_uniform(w, tau / dt) for w, dt in zip(self.winds[signal], self.steps)]
            else:
                shifted = [np.interp(t - tau, t, w) for t, w in zip(self.times, self.winds[signal])]
            stacked = np.concatenate([x - x.mean() for x in shifted])  # as the residual: a bias per record
            stacked.flags.writeable = False
            self._cache[key] = stacked
        return self._cache[key]


def _delayed_uniform(wind: np.ndarray, position: float) -> np.ndarray:
    """`wind` (n_samples,), evenly sampled, delayed by `position` >= 0 samples: ``np.interp(t - tau, t, wind)``
    with ``tau = position dt``, the first sample held before it, as the blend of the two whole lags around it
    (:class:`_LagProducts`), to rounding."""
    lag = int(position)
    fraction = position - lag
    n = wind.size
    held = np.concatenate([np.full(min(lag + 1, n + 1), wind[0]), wind[: max(n - lag, 0)]])  # held[m]: m - lag - 1
    late, later = held[1:], held[:-1]  # delayed by lag and by lag + 1 samples
    delayed: np.ndarray = late + (later - late) * fraction if fraction else late
    return delayed


#: Bytes of delayed winds kept: a scan's grids of two channels (about 140 delays) at 100 000 samples.
_CACHE_BYTES = 160 * 2**20


class _LagProducts:
    """Products of each wind channel's delayed signal (:meth:`_DelayedWinds.stacked`) with fixed columns, at any
    delay, from their products at whole-sample lags.

    Within a uniformly sampled record, ``np.interp`` delays the wind by ``tau = (m + f) dt`` as ``1 - f``
    times the wind delayed by m whole samples plus f times it delayed by m + 1, the first sample held before
    the record, and its mean is the same blend of theirs; so are its products with the columns. Those of
    every whole lag up to `longest_s` are computed at once (:func:`_whole_lag_products`), the records read
    once, and a delay scan's point costs no pass over the columns. They equal the delayed winds' products to
    rounding (summed in another order). Records not uniformly sampled, negative
    delays and those of :data:`_MOST_WHOLE_LAGS` samples or more take the delayed winds' products.

    Parameters
    ----------
    delayed : _DelayedWinds
        The records' winds.
    signals : sequence of str
        The signal of each wind channel.
    fixed : ndarray, shape (n_samples, n_columns)
        The columns, the records end to end.
    longest_s : float
        The longest delay expected, s (longer ones double the lags computed).
    """

    def __init__(self, delayed: _DelayedWinds, signals: Sequence[str], fixed: np.ndarray, longest_s: float) -> None:
        self.delayed, self.signals, self.fixed, self.longest_s = delayed, list(signals), fixed, longest_s
        self.pieces = np.split(fixed, delayed.ends)
        self.tables: dict[str, np.ndarray] = {}  # by signal: (n_records, n_lags, n_columns)

    def __call__(self, k: int, tau: float) -> np.ndarray:
        """``stacked(signal of channel k, tau) @ fixed``, shape (n_columns,)."""
        signal, steps = self.signals[k], self.delayed.steps
        if steps is None or tau < 0 or tau >= _MOST_WHOLE_LAGS * np.min(steps):
            direct: np.ndarray = self.delayed.stacked(signal, tau) @ self.fixed
            return direct
        position = tau / steps  # (n_records,): whole lag and fraction in each record
        lag = np.floor(position).astype(int)
        fraction = (position - lag)[:, None]
        table = self.tables.get(signal)
        if table is None or table.shape[1] < lag.max() + 2:
            lags = int(np.max(np.ceil(self.longest_s / steps))) if table is None else 2 * table.shape[1]
            lags = min(max(lags, int(lag.max()) + 1), _MOST_WHOLE_LAGS)
            table = np.array([_whole_lag_products(w, f, lags) for w, f in zip(self.delayed.winds[signal], self.pieces)])
            self.tables[signal] = table
        records = np.arange(lag.size)
        blend: np.ndarray = np.sum((1.0 - fraction) * table[records, lag] + fraction * table[records, lag + 1], axis=0)
        return blend


def _whole_lag_products(wind: np.ndarray, fixed: np.ndarray, lags: int) -> np.ndarray:
    """Products of `wind` delayed by 0 to `lags` whole samples (its first sample held before it, as np.interp
    holds it), each less its mean, with `fixed`'s columns (n_samples, n_columns): shape (lags + 1, n_columns)."""
    n = wind.size
    centred = wind - wind.mean()  # a constant changes no delayed wind less its mean
    held = np.concatenate([np.full(lags, centred[0]), centred])
    table = np.zeros((lags + 1, fixed.shape[1]))
    for start in range(0, n, _WHOLE_LAG_BLOCK):  # (lags + 1, block) delayed winds at a time
        stop = min(start + _WHOLE_LAG_BLOCK, n)
        rows = np.lib.stride_tricks.sliding_window_view(held[start : stop + lags], stop - start)[::-1]
        table += np.ascontiguousarray(rows) @ fixed[start:stop]  # row m: the samples m late
    sums = np.concatenate([[0.0], np.cumsum(centred)])  # sums[j]: of the first j samples
    m = np.arange(lags + 1)
    means = (sums[np.maximum(n - m, 0)] + np.minimum(m, n) * centred[0]) / n
    table -= np.outer(means, fixed.sum(axis=0))
    return table


_MOST_WHOLE_LAGS = 256  # whole lags tabulated at most: a scan of longer delays (a fast log) has fewer points
_WHOLE_LAG_BLOCK = 16_384  # samples of a record's delayed winds built at once (13 MiB at 100 lags)


_SHARED: ContextVar[dict[tuple[int, ...], tuple[Sequence[Record], _DelayedWinds]] | None] = ContextVar(
    "_SHARED", default=None
)


_SIMULATED: ContextVar[dict[tuple[object, ...], tuple[Record, np.ndarray, np.ndarray]] | None] = ContextVar(
    "_SIMULATED", default=None
)


@contextmanager
def sharing_delayed_winds() -> Iterator[None]:
    """Within this, the wind step's fits of the same records (the same arrays) share their delayed winds, and
    the states simulated for them.

    :func:`speed_derivatives`, :func:`fit_wind` and the spreads scan the same delays on the same records, and
    simulate the states the records lack (the actuator lags) from rows most of step 1's moves leave alone;
    the caches are freed on leaving.
    """
    token, simulated = _SHARED.set({}), _SIMULATED.set({})
    try:
        yield
    finally:
        _SIMULATED.reset(simulated)
        _SHARED.reset(token)


def _delayed_winds(records: Sequence[Record], signals: Sequence[str]) -> _DelayedWinds:
    """The records' delayed winds: shared with earlier fits of the same arrays inside :func:`sharing_delayed_winds`."""
    shared = _SHARED.get()
    if shared is None:
        return _DelayedWinds(records, signals)
    key = tuple(id(a) for r in records for a in (r.time_s, *(r[s] for s in sorted(set(signals)))))
    if key not in shared:  # the entry holds the records, so the arrays the key names outlive it
        shared[key] = (list(records), _DelayedWinds(records, signals))
    return shared[key][1]


def prediction_residual(
    structure: ModelStructure,
    values: Mapping[str, float],
    constants: Mapping[str, float],
    record: Record,
    output: str,
) -> np.ndarray:
    """One output's residual of eq. 3.14 without the wind terms, the record's mean taken out.

    Parameters
    ----------
    structure : ModelStructure
        A structure with wind inputs.
    values : Mapping[str, float]
        F and G_u values.
    constants : Mapping[str, float]
        Trim constants, SI.
    record : Record
        A record with the structure's states and inputs.
    output : str
        An output of the structure.

    Returns
    -------
    ndarray, shape (n_samples,)
        Residual, in the output's unit.
    """
    residual: np.ndarray = _prediction_data(structure, values, constants, [record], [output]).residual[0][:, 0]
    return residual


def _prediction_data(
    structure: ModelStructure,
    values: Mapping[str, float],
    constants: Mapping[str, float],
    records: Sequence[Record],
    outputs: Sequence[str],
) -> _Data:
    wind = set(structure.wind_parameters)
    plain = Assembler(
        structure,
        free=(),
        fixed={k: v for k, v in values.items() if k not in wind},
        constants=constants,
        include_wind=False,
    )
    m = plain.matrices(np.zeros(0))
    rows = [structure.outputs.index(o) for o in outputs]
    signals = tuple(c.signal for c in structure.wind_inputs)
    residual = []
    for record in records:
        x, u = _simulated_states(record, structure, plain, m)
        y = np.column_stack([record[o] for o in outputs])
        r = y - x @ m.c[rows].T - u @ m.d[rows].T
        residual.append(r - r.mean(axis=0))  # a bias per record (sensor bias, trim): not the wind's
    scale = 1.0 / np.maximum(np.vstack(residual).std(axis=0), 1e-12)
    return _Data(residual=residual, delayed=_delayed_winds(records, signals), signals=signals, rows=rows, scale=scale)


def _simulated_states(
    record: Record, structure: ModelStructure, plain: Assembler, m: SystemMatrices
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_states`, read-only, kept within :func:`sharing_delayed_winds` for the next fit of the same record
    with the same rows of the states it lacks and the same input delays: all that the simulation reads."""
    kept = _SIMULATED.get()
    if kept is None:
        return _states(record, structure, plain, m)
    lacking = [k for k, s in enumerate(structure.states) if s not in record.signals]
    key = (id(record), id(structure), m.delays.tobytes(), m.a[lacking].tobytes(), m.b[lacking].tobytes())
    if key not in kept:  # the entry holds the record, so the id the key names outlives it
        x, u = _states(record, structure, plain, m)
        x.flags.writeable = u.flags.writeable = False
        kept[key] = (record, x, u)
    return kept[key][1], kept[key][2]


def _states(
    record: Record, structure: ModelStructure, plain: Assembler, m: SystemMatrices
) -> tuple[np.ndarray, np.ndarray]:
    """Recorded states (others simulated from their own rows) and delayed inputs, of one record."""
    t = record.time_s
    u = np.column_stack([np.interp(t - tau, t, record[c.signal]) for c, tau in zip(plain.channels, m.delays)])
    known = [k for k, s in enumerate(structure.states) if s in record.signals]
    unknown = [k for k, s in enumerate(structure.states) if s not in record.signals]
    x = np.zeros((t.size, len(structure.states)))
    for k in known:
        x[:, k] = record[structure.states[k]]
    if unknown:
        a_uu = m.a[np.ix_(unknown, unknown)]
        forcing = x[:, known] @ m.a[np.ix_(unknown, known)].T + u @ m.b[unknown].T
        try:
            x0 = -np.linalg.solve(a_uu, forcing[0])
        except np.linalg.LinAlgError:
            x0 = np.zeros(len(unknown))
        x[:, unknown] = _simulate(a_uu, forcing, t, x0)
    return x, u


def _simulate(a: np.ndarray, forcing: np.ndarray, t: np.ndarray, x0: np.ndarray) -> np.ndarray:
    """``x' = a x + f(t)`` with f linear between samples, shape (n_samples, n); decoupled states by filtering."""
    n = a.shape[0]
    if not np.array_equal(a, np.diag(np.diag(a))) or np.any(np.diag(a) == 0):
        from scipy import signal as sps  # coupled states only: scipy.signal takes 0.75 s to load

        _, x_sim, _ = sps.lsim((a, np.eye(n), np.eye(n), np.zeros((n, n))), forcing, t - t[0], X0=x0)
        return np.reshape(x_sim, (t.size, n))
    dt = float(np.mean(np.diff(t)))
    out = np.empty((t.size, n))
    for k, pole in enumerate(np.diag(a)):
        phi = np.exp(pole * dt)
        g0 = (phi - 1.0) / pole  # exact for a first-order hold on f, as lsim does
        g1 = (phi - 1.0 - pole * dt) / (pole**2 * dt)
        out[:, k] = _first_order(phi, g1, g0 - g1, forcing[:, k], x0[k])
    return out


def _first_order(phi: float, b0: float, b1: float, f: np.ndarray, x0: float) -> np.ndarray:
    """``x[0] = x0``, ``x[n] = phi x[n-1] + b0 f[n] + b1 f[n-1]``, shape (n_samples,).

    The recursion is a lower bidiagonal system, solved by LAPACK (``scipy.signal.lfilter`` with
    its initial state gives the same to rounding, and costs scipy.signal's import).
    """
    out = np.empty(f.size)
    out[0] = x0
    if f.size > 1:
        rhs = b0 * f[1:] + b1 * f[:-1]
        rhs[0] += phi * x0
        bands = np.vstack([np.ones(f.size - 1), np.full(f.size - 1, -phi)])  # diagonal, then below it
        out[1:] = linalg.solve_banded((1, 0), bands, rhs)
    return out


class _Problem:
    """Weighted residual after the wind terms, for a set of free wind parameters."""

    def __init__(
        self,
        structure: ModelStructure,
        values: Mapping[str, float],
        constants: Mapping[str, float],
        data: _Data,
        free: Sequence[str],
    ) -> None:
        self.structure, self.data, self.free = structure, data, tuple(free)
        self.assembler = Assembler(structure, free=self.free, fixed=values, constants=constants, include_wind=True)
        self.columns = [j for j, c in enumerate(self.assembler.channels) if c.wind]
        self.start = np.array([values[n] for n in self.free])

    def shifted(self, k: int, tau: float) -> list[np.ndarray]:
        """Wind channel `k` delayed by `tau`, per record (views into :meth:`stacked`)."""
        return np.split(self.stacked(k, tau), self.data.delayed.ends)

    def stacked(self, k: int, tau: float) -> np.ndarray:
        """Wind channel `k` delayed by `tau`, each record's mean taken out, the records end to end, shape (n,)."""
        return self.data.delayed.stacked(self.data.signals[k], tau)

    def wind_delays(self, theta: np.ndarray) -> np.ndarray:
        """Each wind channel's delay at the free values `theta`, s, shape (n_wind,)."""
        delays: np.ndarray = self.assembler.delays(theta)[self.columns]
        return delays

    def winds(self, theta: np.ndarray) -> np.ndarray:
        """The wind channels delayed as `theta` says, records end to end, shape (n_samples, n_wind)."""
        return np.column_stack([self.stacked(k, tau) for k, tau in enumerate(self.wind_delays(theta))])

    def products(self, fixed: np.ndarray, longest_s: float) -> _LagProducts:
        """The products of each wind channel, delayed up to about `longest_s`, with `fixed` (n_samples, n_columns):
        ``(k, tau) -> (n_columns,)``."""
        return _LagProducts(self.data.delayed, self.data.signals, fixed, longest_s)

    def gram(self, delays: np.ndarray) -> np.ndarray:
        """Inner products of the wind channels delayed by `delays`, s, shape (n_wind, n_wind).

        From the delayed winds themselves: tabulating them at whole lags, as :class:`_LagProducts` does the
        products with fixed columns, cost the 60-sweep fit as much as it saved (a table of 100 by 100 lags
        per record).
        """
        winds = [self.stacked(k, tau) for k, tau in enumerate(delays)]
        out = np.empty((len(winds), len(winds)))
        for k, a in enumerate(winds):
            for j in range(k, len(winds)):
                out[k, j] = out[j, k] = a @ winds[j]
        return out

    def parts(self, theta: np.ndarray) -> tuple[SystemMatrices, list[np.ndarray]]:
        m = self.assembler.matrices(theta)
        delays = m.delays[self.columns]
        per_channel = [self.shifted(k, tau) for k, tau in enumerate(delays)]
        return m, [np.column_stack(c) for c in zip(*per_channel)]

    def vector(self, theta: np.ndarray) -> np.ndarray:
        m, winds = self.parts(theta)
        d_w = m.d[self.data.rows][:, self.columns]
        return np.concatenate([((r - w @ d_w.T) * self.data.scale).ravel() for r, w in zip(self.data.residual, winds)])

    def delay_and_gain_index(self) -> tuple[list[int], list[int]]:
        delays = [
            k for k, n in enumerate(self.free) if any(n in self.assembler.channels[j].delay.names for j in self.columns)
        ]
        return delays, [k for k in range(len(self.free)) if k not in delays]


class _Normal:
    """Normal equations of the gains at given delays, from inner products of the shifted winds (cheap to redo)."""

    def __init__(self, problem: _Problem, theta: np.ndarray, gains: Sequence[int]) -> None:
        self.problem, self.gains = problem, list(gains)
        zero = theta.copy()
        zero[self.gains] = 0.0
        m0 = problem.assembler.matrices(zero)
        rows, columns = problem.data.rows, problem.columns
        self.d0 = m0.d[rows][:, columns]  # (n_out, n_wind): what does not scale with a gain
        dm = problem.assembler.derivatives(zero, m0)
        self.e = np.array([dm.d[k][rows][:, columns] for k in self.gains]).reshape(len(self.gains), *self.d0.shape)
        self.weight = problem.data.scale**2
        self.residual = np.vstack(problem.data.residual)
        self._residual_squares = np.einsum("nr,nr->r", self.residual, self.residual)  # (n_out,): the scans reuse it
        self._on_residual = problem.products(self.residual, _LONGEST_SCAN_S)

    def solve(self, theta: np.ndarray) -> tuple[np.ndarray, float]:
        """Least-squares gains at the delays of `theta` (entries linear in their gains) and the cost.

        The winds' products come from their products at whole-sample lags (:class:`_LagProducts`): a scan's
        points cost no pass over the residual.
        """
        delays = self.problem.wind_delays(theta)
        cross = np.array([self._on_residual(k, tau) for k, tau in enumerate(delays)])
        return self.solve_products(theta, self.problem.gram(delays), cross, self._residual_squares)

    def solve_for(self, theta: np.ndarray, winds: np.ndarray, residual: np.ndarray) -> tuple[np.ndarray, float]:
        """As :meth:`solve`, with the delayed winds (n, n_wind) and the residual (n, n_out) given."""
        rr = self._residual_squares if residual is self.residual else np.einsum("nr,nr->r", residual, residual)
        return self.solve_products(theta, winds.T @ winds, winds.T @ residual, rr)

    def solve_products(
        self, theta: np.ndarray, gram: np.ndarray, cross: np.ndarray, rr: np.ndarray
    ) -> tuple[np.ndarray, float]:
        """The gains and cost from the winds' inner products (n_wind, n_wind), their products with the residual
        (n_wind, n_out) and the residual's squares per output (n_out,)."""
        # target per output: residual - w d0^T; regressor g per output: w e_g^T
        tt = rr - 2 * np.einsum("rc,cr->r", self.d0, cross) + np.einsum("rc,cd,rd->r", self.d0, gram, self.d0)
        out = theta.copy()
        cost = float(self.weight @ tt)
        if self.gains:
            normal = np.einsum("r,grc,cd,hrd->gh", self.weight, self.e, gram, self.e)
            rhs = np.einsum("r,grc,cr->g", self.weight, self.e, cross) - np.einsum(
                "r,grc,cd,rd->g", self.weight, self.e, gram, self.d0
            )
            solution = np.linalg.lstsq(normal, rhs, rcond=None)[0]
            out[self.gains] = solution
            cost -= float(rhs @ solution)
        return out, cost


def _rounds(n_delays: int) -> int:
    """Rounds of a coordinate-wise delay scan: two, or one for a single delay (none without one).

    The gains are solved afresh at every point, so with one delay a second round would visit the
    same points at the same costs and change nothing.
    """
    return 2 if n_delays > 1 else n_delays


def _scan(problem: _Problem) -> np.ndarray:
    """Each delay by a coarse then fine 1-D scan (gains solved at every point), :func:`_rounds` times over."""
    delays, gains = problem.delay_and_gain_index()
    normal = _Normal(problem, problem.start, gains)
    theta, best = normal.solve(problem.start)
    for _ in range(_rounds(len(delays))):
        for k in delays:
            p = problem.structure.parameter(problem.free[k])
            lo, hi = max(p.lower, 0.0), min(p.upper, _LONGEST_SCAN_S)
            for grid in (np.arange(lo, hi + 1e-12, 5 * _SCAN_STEP_S), None):
                points = np.clip(theta[k] + np.arange(-5, 6) * _SCAN_STEP_S, lo, hi) if grid is None else grid
                for tau in points:
                    trial = theta.copy()
                    trial[k] = tau
                    trial, cost = normal.solve(trial)
                    if cost < best:
                        theta, best = trial, cost
    return theta


def residual_inflation(residual: np.ndarray) -> float:
    """N / N_eff of a weighted residual (Bartlett) times its variance: what J^T J is divided by.

    Parameters
    ----------
    residual : ndarray, shape (n_samples, n_outputs)
        Weighted residual, one column per output.

    Returns
    -------
    float
        The largest over the outputs of ``(1 + 2 sum rho_k) mean(e^2)``, summed while rho_k >= 0.05.
    """
    factor = 0.0
    for column in residual.T:
        rho = correlated_lags(column)
        factor = max(factor, (1.0 + 2.0 * float(np.sum(rho[1:]))) * float(np.mean(column**2)))
    return max(factor, 1e-12)


def _fit_free(
    structure: ModelStructure,
    values: Mapping[str, float],
    constants: Mapping[str, float],
    data: _Data,
    free: Sequence[str],
) -> tuple[dict[str, float], Accuracy, float, list[np.ndarray]]:
    """Fit the free wind parameters; values, accuracy, weighted cost per sample and the final residuals."""
    problem = _Problem(structure, values, constants, data, free)
    out = dict(values)
    if not free:
        m, winds = problem.parts(np.zeros(0))
        theta = np.zeros(0)
        acc = accuracy(np.zeros((1, 0)), theta, ())
    else:
        lower = np.array([structure.parameter(n).lower for n in free])
        upper = np.array([structure.parameter(n).upper for n in free])
        solved = optimize.least_squares(
            problem.vector, np.clip(_scan(problem), lower, upper), bounds=(lower, upper), x_scale="jac", method="trf"
        )
        theta = solved.x
        out |= dict(zip(free, theta.tolist()))
        m, winds = problem.parts(theta)
    d_w = m.d[data.rows][:, problem.columns]
    after = [r - w @ d_w.T for r, w in zip(data.residual, winds)]
    stacked = np.vstack(after)
    if free:
        acc = accuracy(solved.jac / math.sqrt(residual_inflation(stacked * data.scale)), theta, tuple(free))
    cost = float(np.mean(np.sum((stacked * data.scale) ** 2, axis=1)))
    return out, acc, cost, after


def fit_wind(
    structure: ModelStructure,
    values: Mapping[str, float],
    constants: Mapping[str, float],
    records: Sequence[Record],
    *,
    outputs: Sequence[str] = ("ax", "az"),
    reduce: bool = True,
    guidelines: Guidelines = DEFAULT_GUIDELINES,
) -> WindStepResult:
    """Fit the wind parameters of `structure` to the residual of eq. 3.14.

    Parameters
    ----------
    structure : ModelStructure
        A structure with wind inputs (``hover-wind``).
    values : Mapping[str, float]
        Values of the F and G_u parameters (step 1); wind parameters start
        from these if present, else from the structure.
    constants : Mapping[str, float]
        Trim constants, SI.
    records : sequence of Record
        Time-domain records with the structure's measured states, the
        outputs, the control inputs and the wind signals (``wind_lon``).
    outputs : sequence of str, optional
        Outputs whose residual is fitted (the accelerometers).
    reduce : bool, optional
        Drop wind parameters beyond the guidelines, one at a time.
    guidelines : Guidelines, optional
        The CR% and I% limits (% of ``|value|``) wind parameters are dropped beyond; default Tischler's
        (:data:`~sysid.fit.guidelines.DEFAULT_GUIDELINES`).

    Returns
    -------
    WindStepResult
        A wind parameter that no fitted output's row reads, or whose outputs
        belong to unidentified axes (parameters in `values` that are NaN), is
        ``unidentified``.

    Raises
    ------
    FitError
        If the structure has no wind parameter, or no record carries every
        signal needed.
    ValueError
        If a guideline is not a positive number.
    """
    names = structure.wind_parameters
    if not names:
        raise FitError(f"model {structure.name} has no wind parameters to fit")
    values, outputs, lost = identified_outputs(structure, values, outputs)
    if not outputs:
        return unfitted_wind(structure, f"the outputs of the wind step belong to unidentified axes ({lost})")
    needed = {c.signal for c in structure.inputs} | set(outputs)
    usable = [r for r in records if needed <= set(r.signals)]
    if not usable:
        raise FitError(f"no record has every signal the wind step needs ({', '.join(sorted(needed))})")
    current = _with_wind_defaults(structure, values)
    data = _prediction_data(structure, current, constants, usable, outputs)
    informed = _informed(structure, current, constants, data.rows, names)
    status: dict[str, WindStatus] = {n: "estimated" if n in informed else "unidentified" for n in names}
    steps: list[ReductionStep] = []
    while True:
        free = [n for n in names if status[n] == "estimated"]
        current, acc, cost, after = _fit_free(structure, current, constants, data, free)
        if steps:
            steps[-1] = replace(steps[-1], cost_average_after=cost)
        worst = worst_parameter(acc, guidelines=guidelines) if reduce else None
        if worst is None:
            break
        name, reason = worst
        k = acc.names.index(name)
        parameter = structure.parameter(name)
        steps.append(
            ReductionStep(
                step=len(steps) + 1,
                parameter=name,
                action="dropped",
                value=parameter.drop_value,
                estimate=current[name],
                cr_percent=float(acc.cramer_rao_percent[k]),
                insensitivity_percent=float(acc.insensitivity_percent[k]),
                reason=reason + " (wind step)",
                cost_average=cost,
            )
        )
        current[name], status[name] = parameter.drop_value, "dropped"
    rms_before = np.sqrt(np.mean(np.vstack(data.residual) ** 2, axis=0))
    rms_after = np.sqrt(np.mean(np.vstack(after) ** 2, axis=0))
    fit = WindFit(
        outputs=tuple(outputs),
        rms_before=tuple(float(v) for v in rms_before),
        rms_after=tuple(float(v) for v in rms_after),
        samples=int(sum(a.shape[0] for a in after)),
    )
    return WindStepResult(
        values=MappingProxyType({n: math.nan if status[n] == "unidentified" else current[n] for n in names}),
        status=MappingProxyType(status),
        accuracy=acc,
        fit=fit,
        reduction=tuple(steps),
    )


#: States whose measured values carry the wind (eq. 3.1: air-relative velocities).
_AIR_STATES = ("u", "v", "w")


def _gains_problem(
    structure: ModelStructure, current: Mapping[str, float], constants: Mapping[str, float], data: _Data
) -> tuple[_Problem, _Normal, list[int], list[int]]:
    """The least-squares problem of the G_w gains the fitted rows read, at `current`'s delays.

    Returns the problem, its normal equations, and the indices of its delays and of its gains in ``problem.free``.
    """
    names = structure.wind_parameters
    free = sorted(_informed(structure, current, constants, data.rows, names), key=names.index)
    problem = _Problem(structure, current, constants, data, free)
    delays, gains = problem.delay_and_gain_index()
    return problem, _Normal(problem, problem.start, gains), delays, gains


#: Lags of the wind the airspeed's instruments are made of, s: the ground speed answers the gusts within seconds
#: (0-3 s in 0.2 s and 0-5 s in 0.25 s gave the same on the tuning flights, within 0.4 %; fewer instruments
#: bias an IV estimate less towards least squares).
_INSTRUMENT_LAGS_S = np.arange(0.0, 2.0 + 1e-9, 0.5)


def _lagged_wind(problem: _Problem) -> np.ndarray:
    """Each wind signal at every lag of :data:`_INSTRUMENT_LAGS_S`, records stacked, shape (n_samples, n_lags n_signal).

    Channels that carry the same signal (the along-nose wind on u and on w) give it once.
    """
    signals = [problem.assembler.channels[j].signal for j in problem.columns]
    first = [k for k, signal in enumerate(signals) if signals.index(signal) == k]
    return np.column_stack([problem.stacked(k, float(lag)) for k in first for lag in _INSTRUMENT_LAGS_S])


def _projected(columns: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """`columns` (n, m) projected onto the span of `basis` (n, k) by least squares, shape (n, m)."""
    fitted: np.ndarray = basis @ np.linalg.lstsq(basis, columns, rcond=None)[0]
    return fitted


def _onto(regressors: np.ndarray, instruments: np.ndarray) -> np.ndarray:
    """`regressors` (n, m) projected onto the span of `instruments` (n, m): the IV estimate's information design."""
    if regressors.shape[1] == 0:
        return regressors
    q, _ = np.linalg.qr(instruments)
    projected: np.ndarray = q @ (q.T @ regressors)
    return projected


def _with_wind_defaults(structure: ModelStructure, values: Mapping[str, float]) -> dict[str, float]:
    """`values` with each wind parameter it lacks at the structure's starting value."""
    return dict(values) | {n: values.get(n, structure.parameter(n).value) for n in structure.wind_parameters}


def wind_cost(
    structure: ModelStructure,
    values: Mapping[str, float],
    constants: Mapping[str, float],
    records: Sequence[Record],
    outputs: Sequence[str] = ("ax", "az"),
) -> WindCost | None:
    """The eq. 3.14 residual's cost after the best G_w gains, as a function of the records' wind and u v w.

    The residual of `records` is computed once; a call gives new values of
    some of their signals (the wind and the air-relative velocities, moved
    along the clock) and the residual changes by their terms in the output
    rows. States the records lack (the actuator lags) keep the values
    simulated for `records`: in ``hover-wind`` they read no velocity. The
    wind delays stay at their values in `values` (or the structure's), the
    gains are solved by linear least squares, and each output is weighted
    by its residual level in `records`.

    Parameters
    ----------
    structure : ModelStructure
        A structure with wind inputs.
    values : Mapping[str, float]
        F and G_u values (step 1).
    constants : Mapping[str, float]
        Trim constants, SI.
    records : sequence of Record
        Records with the structure's measured states, outputs, inputs and wind signals.
    outputs : sequence of str, optional
        Outputs whose residual is fitted.

    Returns
    -------
    WindCost or None
        None when every output belongs to an unidentified axis.
    """
    values, outputs, _ = identified_outputs(structure, values, outputs)
    if not outputs:
        return None
    current = _with_wind_defaults(structure, values)
    data = _prediction_data(structure, current, constants, records, outputs)
    problem, normal, _, _ = _gains_problem(structure, current, constants, data)
    return WindCost(structure, records, data, problem, normal)


class WindCost:
    """The cost of :func:`wind_cost`: ``cost(changed)`` for one set of moved signals, ``cost.costs(...)`` for many.

    The costs are weighted sums of squares per sample (dimensionless).
    """

    def __init__(
        self, structure: ModelStructure, records: Sequence[Record], data: _Data, problem: _Problem, normal: _Normal
    ) -> None:
        self.records, self.data, self.problem, self.normal = list(records), data, problem, normal
        m = problem.assembler.matrices(problem.start)
        self.delays = m.delays[problem.columns]
        self.signals = [c.signal for c in structure.wind_inputs]
        moving = [k for k, s in enumerate(structure.states) if s in _AIR_STATES]
        self.states = [structure.states[k] for k in moving]
        self.c_moving = m.c[data.rows][:, moving]  # (n_out, n_moving): the outputs' rows read the velocities so

    def __call__(self, changed: Sequence[Mapping[str, np.ndarray]]) -> tuple[float, float, np.ndarray]:
        """The cost with the best gains, the cost without wind, and the weighted residual after, shape
        (n_samples, n_outputs); `changed` is one mapping of signal name to new values (n_samples,) per record."""
        residual, winds = [], []
        for record, r0, new in zip(self.records, self.data.residual, changed):
            t = record.time_s
            residual.append(self._moved_residual(record, r0, new))
            w = np.column_stack(
                [np.interp(t - tau, t, new.get(s, record[s])) for s, tau in zip(self.signals, self.delays)]
            )
            winds.append(w - w.mean(axis=0))
        stacked, wind = np.vstack(residual), np.vstack(winds)
        theta, left = self.normal.solve_for(self.problem.start, wind, stacked)
        d_w = self.problem.assembler.matrices(theta).d[self.data.rows][:, self.problem.columns]
        after = (stacked - wind @ d_w.T) * self.data.scale
        n = stacked.shape[0]
        return left / n, float(np.sum((stacked * self.data.scale) ** 2)) / n, after

    def costs(self, changed: Iterable[Mapping[str, np.ndarray]]) -> np.ndarray:
        """The cost with the best gains of each of several sets of moved signals, shape (n_moves,).

        `changed` gives, record by record (it may be a generator: a record's moves are dropped once read),
        a mapping of signal name to new values of shape (n_moves, n_samples). Each cost equals that of
        ``cost([...])`` for the one set, to rounding: the winds' and residual's products are summed record by
        record for all the moves at once.
        """
        sums: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None  # the winds' gram, with r, r's squares
        n = 0
        for record, r0, new in zip(self.records, self.data.residual, changed):
            t = record.time_s
            n_moves = next(iter(new.values())).shape[0]
            r = np.broadcast_to(self._moved_residual(record, r0, new), (n_moves, *r0.shape))
            w = np.stack(
                [_interpolated_rows(t - tau, t, new.get(s, record[s])) for s, tau in zip(self.signals, self.delays)],
                axis=-1,
            )
            w = np.broadcast_to(w, (n_moves, *w.shape[-2:])) - w.mean(axis=-2, keepdims=True)
            w_t = w.transpose(0, 2, 1)
            parts = (w_t @ w, w_t @ r, np.einsum("mno,mno->mo", r, r))
            sums = parts if sums is None else (sums[0] + parts[0], sums[1] + parts[1], sums[2] + parts[2])
            n += t.size
        if sums is None:
            return np.zeros(0)
        start = self.problem.start
        return np.array([self.normal.solve_products(start, g, c, s)[1] for g, c, s in zip(*sums)]) / n

    def _moved_residual(self, record: Record, r0: np.ndarray, new: Mapping[str, np.ndarray]) -> np.ndarray:
        """The record's residual `r0` (n_samples, n_out), bias removed, with u v w moved to `new`'s: shape
        (n_samples, n_out), or (n_moves, n_samples, n_out) for moved signals (n_moves, n_samples); `r0` itself
        where `new` moves no velocity."""
        given = [new[s] for s in self.states if s in new]
        if not given:
            return r0
        zero = np.zeros(np.broadcast_shapes(*(g.shape for g in given)))  # a velocity the move leaves as it was
        dx = np.stack([new[s] - record[s] if s in new else zero for s in self.states], axis=-1)
        r = r0 - dx @ self.c_moving.T
        moved: np.ndarray = r - r.mean(axis=-2, keepdims=True)
        return moved


def _interpolated_rows(x: np.ndarray, xp: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """``np.interp(x, xp, row)`` for each row of `fp` (..., n_xp), shape (..., n_x): the end values held."""
    j = np.clip(np.searchsorted(xp, x, side="right") - 1, 0, xp.size - 2)
    fraction = np.clip((x - xp[j]) / (xp[j + 1] - xp[j]), 0.0, 1.0)
    low = fp[..., j]
    out: np.ndarray = low + (fp[..., j + 1] - low) * fraction
    return out


class _Joint:
    """The speed derivatives and the G_w gains solved together by instrumental variables, at given wind delays.

    A regressor or instrument is one array per output, (n_samples, n_out),
    and inner products weight each output by its scale squared: the speed
    regressors, their instruments and the residual are fixed, so a new set
    of delayed winds costs their products with the winds alone (as
    :class:`_Normal`'s).
    """

    def __init__(
        self, normal: _Normal, data: _Data, speeds: Sequence[np.ndarray], instruments: Sequence[np.ndarray]
    ) -> None:
        self.normal, self.scale, self.weight = normal, data.scale, data.scale**2
        self.speeds, self.instruments = list(speeds), list(instruments)
        self.n_speed, self.residual = len(self.speeds), normal.residual
        fixed = [*self.speeds, *self.instruments, self.residual]
        self.fixed = np.ascontiguousarray(np.hstack(fixed))  # (n, (2 n_speed + 1) n_out), for one BLAS product
        self.n_fixed, self.n_out = len(fixed), self.residual.shape[1]
        self.speed_speed = self._inner(self.speeds, self.speeds)
        self.instrument_speed = self._inner(self.instruments, self.speeds)
        self.speed_residual = self._inner(self.speeds, [self.residual])[:, 0]
        self.instrument_residual = self._inner(self.instruments, [self.residual])[:, 0]
        self.residual_residual = float(self._inner([self.residual], [self.residual])[0, 0])
        self._on_fixed: _LagProducts | None = None

    def _inner(self, a: Sequence[np.ndarray], b: Sequence[np.ndarray]) -> np.ndarray:
        return np.array([[float(np.einsum("nr,nr,r->", x, y, self.weight)) for y in b] for x in a]).reshape(
            len(a), len(b)
        )

    def solve(self, wind: np.ndarray) -> tuple[float, np.ndarray]:
        """Cost (weighted residual sum of squares) and solution ``[speed changes, gains]`` for the winds (n, n_wind)."""
        return self._solved(wind.T @ wind, wind.T @ self.fixed)

    def solve_at(self, delays: np.ndarray) -> tuple[float, np.ndarray]:
        """As :meth:`solve`, for the winds of the normal equations' problem delayed by `delays` (n_wind,), s:
        from their products at whole lags (:class:`_LagProducts`), which a scan's points share."""
        problem = self.normal.problem
        if self._on_fixed is None:
            self._on_fixed = problem.products(self.fixed, _LONGEST_JOINT_SCAN_S)
        cross = np.array([self._on_fixed(k, tau) for k, tau in enumerate(delays)])
        return self._solved(problem.gram(delays), cross)

    def _solved(self, gram: np.ndarray, products: np.ndarray) -> tuple[float, np.ndarray]:
        """:meth:`solve` from the winds' inner products (n_wind, n_wind) and their products with the fixed
        columns (n_wind, n_fixed n_out)."""
        e, d0, w, k = self.normal.e, self.normal.d0, self.weight, self.n_speed
        cross = products.reshape(gram.shape[0], self.n_fixed, self.n_out).transpose(1, 0, 2)
        on_speeds, on_instruments, on_residual = cross[:k], cross[k : 2 * k], cross[2 * k]
        # <A, G_g> = sum_r w_r e_g[r, c] <A[:, r], wind[:, c]>; <A, T> = <A, res> - sum_r w_r d0[r, c] <A[:, r], wind[:, c]>
        speed_gain = np.einsum("r,grc,fcr->fg", w, e, on_speeds)
        instrument_gain = np.einsum("r,grc,fcr->fg", w, e, on_instruments)
        gain_gain = np.einsum("r,grc,cd,hrd->gh", w, e, gram, e)
        gain_residual = np.einsum("r,grc,cr->g", w, e, on_residual) - np.einsum("r,grc,cd,rd->g", w, e, gram, d0)
        speed_target = self.speed_residual - np.einsum("r,rc,fcr->f", w, d0, on_speeds)
        instrument_target = self.instrument_residual - np.einsum("r,rc,fcr->f", w, d0, on_instruments)
        target_target = (
            self.residual_residual
            - 2 * float(np.einsum("r,rc,cr->", w, d0, on_residual))
            + float(np.einsum("r,rc,cd,rd->", w, d0, gram, d0))
        )
        regressors_regressors = np.block([[self.speed_speed, speed_gain], [speed_gain.T, gain_gain]])
        instruments_regressors = np.block([[self.instrument_speed, instrument_gain], [speed_gain.T, gain_gain]])
        regressors_target = np.concatenate([speed_target, gain_residual])
        instruments_target = np.concatenate([instrument_target, gain_residual])
        solution = np.linalg.lstsq(instruments_regressors, instruments_target, rcond=None)[0]
        cost = (
            target_target - 2 * float(solution @ regressors_target) + float(solution @ regressors_regressors @ solution)
        )
        return cost, solution

    def explicit(self, wind: np.ndarray, solution: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The weighted residual after (n, n_out) and the information design (n n_out, n_param) of `solution`.

        The design is the regressors projected onto the instruments: its ``J^T J`` is the inverse of the IV
        estimate's covariance for a unit residual variance.
        """
        e, d0, scale = self.normal.e, self.normal.d0, self.scale
        gains = [(wind @ e[g].T) * scale for g in range(e.shape[0])]
        regressors = np.column_stack([(c * scale).ravel() for c in self.speeds] + [g.ravel() for g in gains])
        instruments = np.column_stack([(c * scale).ravel() for c in self.instruments] + [g.ravel() for g in gains])
        target = ((self.residual - wind @ d0.T) * scale).ravel()
        after = (target - regressors @ solution).reshape(self.residual.shape)
        return after, _onto(regressors, instruments)


def speed_derivatives(
    structure: ModelStructure,
    values: Mapping[str, float],
    constants: Mapping[str, float],
    records: Sequence[Record],
    estimated: Sequence[str],
    *,
    outputs: Sequence[str] = ("ax", "az"),
    delays: Mapping[str, float] | None = None,
    with_accuracy: bool = True,
) -> tuple[dict[str, float], Accuracy]:
    """The speed derivatives of the fitted outputs, estimated again with G_w from the residual of eq. 3.14.

    Under position hold the air-relative velocity is the wind less a little
    ground speed, and the position loop's feedback biases a speed damping
    fitted to closed-loop frequency responses (X_u came out 13-72 % short on
    the independent generator's windy flights). An error of X_u leaves
    ``dX_u u`` in the ax residual, and with u close to minus the wind G_w takes
    it up: X_w_lon came out short by the same amount. The gusts excite the
    airspeed apart from the loop, so the residual measures both: each
    step 1 parameter the fitted outputs' rows read through u, v or w alone
    (``X_u`` in ax, ``Z_w`` in az) is solved for with the G_w gains, each
    output weighted by its residual level, at the wind delays that leave the
    least residual (every 10 ms over each delay's bounds, then every 2 ms
    about the best, coordinate-wise, twice where there are two delays or more:
    u carries the wind undelayed, so the split between X_u and X_w_lon follows
    the delay).

    The solution is by instrumental variables, not least squares. What tells
    X_u from X_w_lon is the ground speed (u is the wind less it), a few
    tenths of a m/s under position hold, and two things in it are not the
    air: the velocity estimate's own error, and the ground speed's answer to
    unmeasured forces that are also in the residual. Least squares read both
    as airspeed and came out 3-7 % short on X_u and X_w_lon alike on the
    generator's tuning flights (−1 to −2 % with either taken away). The
    instruments of a speed regressor are its projection on the wind at lags
    :data:`_INSTRUMENT_LAGS_S` (the ground speed's answer to the gusts), which
    neither error reaches; the G_w regressors are their own instruments.
    The Cramér–Rao bounds are those of the IV estimate (the regressors
    projected onto the instruments), corrected for the residual's
    autocorrelation as the wind step's.

    Parameters
    ----------
    structure : ModelStructure
        A structure with wind inputs.
    values : Mapping[str, float]
        Step 1's values.
    constants : Mapping[str, float]
        Trim constants, SI.
    records : sequence of Record
        Records of the wind step, the wind where the vehicle met it.
    estimated : sequence of str
        Parameters step 1 estimated (a dropped one stays dropped).
    outputs : sequence of str, optional
        Outputs whose residual is fitted.
    delays : Mapping[str, float], optional
        Wind delays to solve at instead of scanning them, s.
    with_accuracy : bool, optional
        Compute the bounds (else they are left infinite: the values alone are wanted).

    Returns
    -------
    tuple
        New values of those parameters, and the accuracy of the joint solution (the G_w gains solved beside
        them); no values when the structure has none of them, nothing when it cannot be solved.
    """
    empty = accuracy(np.zeros((1, 0)), np.zeros(0), ())
    names = structure.wind_parameters
    known, outputs, _ = identified_outputs(structure, values, outputs)
    moving = [k for k, s in enumerate(structure.states) if s in _AIR_STATES]
    if not outputs or not moving or not all({structure.states[k] for k in moving} <= set(r.signals) for r in records):
        return {}, empty
    current = _with_wind_defaults(structure, known)
    free = tuple(n for n in estimated if n not in names and math.isfinite(values.get(n, math.nan)))
    plain = Assembler(
        structure,
        free=free,
        fixed={k: v for k, v in current.items() if k not in free and k not in names},
        constants=constants,
        include_wind=False,
    )
    theta = np.array([current[n] for n in free])
    rows = [structure.outputs.index(o) for o in outputs]
    dm = plain.derivatives(theta, plain.matrices(theta))
    others = [k for k in range(len(structure.states)) if k not in moving]
    chosen = [
        k
        for k in range(len(free))
        if np.any(dm.c[k][np.ix_(rows, moving)] != 0)
        and not np.any(dm.c[k][np.ix_(rows, others)] != 0)
        and not np.any(dm.d[k][rows] != 0)
    ]
    data = _prediction_data(structure, current, constants, records, outputs)
    problem, normal, delay_index, gains = _gains_problem(structure, current, constants, data)
    states = np.vstack(
        [np.column_stack([r[structure.states[k]] - r[structure.states[k]].mean() for k in moving]) for r in records]
    )
    speeds = [states @ dm.c[k][np.ix_(rows, moving)].T for k in chosen]  # (n, n_out) per parameter

    lagged = _lagged_wind(problem) if speeds else np.zeros((0, 0))
    joint = _Joint(normal, data, speeds, [_projected(c, lagged) for c in speeds])

    def solved(at: np.ndarray) -> tuple[float, np.ndarray]:
        """Cost and solution at the wind delays of `at`: a scan's point (:meth:`_Joint.solve_at`), or the one
        solution at given delays."""
        if delays is not None:
            return joint.solve(problem.winds(at))
        return joint.solve_at(problem.wind_delays(at))

    # u carries the wind undelayed: the split between X_u and X_w_lon follows the wind delay, so it is scanned,
    # every 10 ms then every 2 ms about the best
    at = problem.start.copy()
    for k in delay_index if delays is not None else ():
        at[k] = (delays or {}).get(problem.free[k], at[k])
    best = solved(at)[0] if delays is None else math.inf
    for _ in range(0 if delays is not None else _rounds(len(delay_index))):
        for k in delay_index:
            p = structure.parameter(problem.free[k])
            lo, hi = max(p.lower, 0.0), min(p.upper, _LONGEST_JOINT_SCAN_S)
            for grid in (np.arange(lo, hi + 1e-12, 5 * _SCAN_STEP_S), None):
                points = np.clip(at[k] + np.arange(-5, 6) * _SCAN_STEP_S, lo, hi) if grid is None else grid
                for tau in points:
                    trial = at.copy()
                    trial[k] = tau
                    cost = solved(trial)[0]
                    if cost < best:
                        at, best = trial, cost
    _, solution = solved(at)
    labels = tuple(free[k] for k in chosen) + tuple(problem.free[g] for g in gains)
    estimates = np.concatenate([theta[chosen] + solution[: len(chosen)], solution[len(chosen) :]])
    if with_accuracy:
        after, design = joint.explicit(problem.winds(at), solution)
        acc = accuracy(design / math.sqrt(residual_inflation(after)), estimates, labels)
    else:  # the values alone: no information, every bound infinite
        acc = accuracy(np.zeros((1, len(labels))), estimates, labels)
    return {free[k]: float(estimates[j]) for j, k in enumerate(chosen)}, acc


def step_one_spread(
    structure: ModelStructure,
    values: Mapping[str, float],
    constants: Mapping[str, float],
    records: Sequence[Record],
    estimated: Sequence[str],
    step_one: Accuracy,
    *,
    delays: Mapping[str, float],
    outputs: Sequence[str] = ("ax", "az"),
) -> dict[str, float]:
    """One standard deviation of each wind-step estimate from step 1's own uncertainty.

    The residual of eq. 3.14 is computed with step 1's F and G_u, whose
    errors the wind step takes for wind: under closed loop the thrust and
    pitch commands answer the gusts, so a Z_thr 3 % off moves Z_w_lon by
    several %. Each step 1 estimate is moved by its Cramér–Rao bound, the
    joint solution (:func:`speed_derivatives` at the wind delays found) is
    solved again, and the changes are combined with step 1's correlation.

    Parameters
    ----------
    structure : ModelStructure
        A structure with wind inputs.
    values : Mapping[str, float]
        Step 1's values (the speed derivatives as step 1 left them).
    constants : Mapping[str, float]
        Trim constants, SI.
    records : sequence of Record
        Records of the wind step.
    estimated : sequence of str
        Parameters step 1 estimated.
    step_one : Accuracy
        Step 1's accuracy (CR bounds, correlation).
    delays : Mapping[str, float]
        Wind delays the wind step found, s.
    outputs : sequence of str, optional
        Outputs whose residual is fitted.

    Returns
    -------
    dict
        Standard deviation of each parameter of the joint solution (speed derivatives and G_w gains), in its
        unit; empty when nothing could be solved.
    """
    speed, base = speed_derivatives(
        structure, values, constants, records, estimated, outputs=outputs, delays=delays, with_accuracy=False
    )
    read = _read_by_residual(structure, values, constants, records, outputs)
    moved = [
        k
        for k, n in enumerate(step_one.names)
        if n in read and n not in speed and math.isfinite(step_one.cramer_rao[k]) and step_one.cramer_rao[k] > 0
    ]
    if not base.names or not moved:
        return {}

    def change(j: int) -> np.ndarray:
        k = moved[j]
        nudged = dict(values) | {step_one.names[k]: values[step_one.names[k]] + float(step_one.cramer_rao[k])}
        _, again = speed_derivatives(
            structure, nudged, constants, records, estimated, outputs=outputs, delays=delays, with_accuracy=False
        )
        return again.values - base.values if again.names == base.names else np.zeros(len(base.names))

    changes = list(map_forked(change, len(moved)))  # the moves on the cores
    sensitivity = np.array(changes)  # (n_moved, n_joint): the change for a 1-sigma move of each
    correlation = np.nan_to_num(step_one.correlation[np.ix_(moved, moved)], nan=0.0)
    np.fill_diagonal(correlation, 1.0)
    variance = np.einsum("ij,ik,jk->k", correlation, sensitivity, sensitivity)
    return {n: float(np.sqrt(max(v, 0.0))) for n, v in zip(base.names, variance)}


def _read_by_residual(
    structure: ModelStructure,
    values: Mapping[str, float],
    constants: Mapping[str, float],
    records: Sequence[Record],
    outputs: Sequence[str],
) -> set[str]:
    """Step 1 parameters the residual of `outputs` reads: in their rows of C or D, in the rows of the states
    a record lacks (simulated: the actuator lags), or as an input delay."""
    known, outputs, _ = identified_outputs(structure, values, outputs)
    free = tuple(n for n in known if n not in structure.wind_parameters and n in structure.parameter_names)
    plain = Assembler(structure, free=free, fixed={}, constants=constants, include_wind=False)
    theta = np.array([known[n] for n in free])
    dm = plain.derivatives(theta, plain.matrices(theta))
    rows = [structure.outputs.index(o) for o in outputs]
    logged = set.intersection(*(set(r.signals) for r in records)) if records else set()
    hidden = [k for k, s in enumerate(structure.states) if s not in logged]
    return {
        n
        for k, n in enumerate(free)
        if np.any(dm.c[k][rows] != 0)
        or np.any(dm.d[k][rows] != 0)
        or np.any(dm.a[k][hidden] != 0)
        or np.any(dm.b[k][hidden] != 0)
        or np.any(dm.delays[k] != 0)
    }


def speed_spread(
    base: WindStepResult,
    speed: Mapping[str, float],
    speed_accuracy: Accuracy,
    fitted: Callable[[Mapping[str, float]], WindStepResult],
) -> dict[str, float]:
    """One standard deviation of each wind parameter from the speed derivatives' own uncertainty.

    The wind step fits G_w and the wind delays at the speed derivatives
    :func:`speed_derivatives` found, and its bounds hold them fixed. But u
    carries the wind undelayed, so X_u, X_w_lon and tau_w_lon share one
    split: on the chapter 3 strong-wind flights tau_w_lon moved 0.55 ms per
    0.001 of X_u (13.3 ms at the true X_u, 17.6 ms at X_u 3.6 % off, where
    its bound held at X_u said ±0.8 ms). Each speed derivative is moved by its
    bound, the wind step fitted again, and the changes are added in
    quadrature.

    Parameters
    ----------
    base : WindStepResult
        The wind step at `speed`.
    speed : Mapping[str, float]
        The speed derivatives the wind step was fitted at.
    speed_accuracy : Accuracy
        Their accuracy (of the joint solution, step 1's uncertainty carried in).
    fitted : callable
        ``fitted(speed)``: the wind step at other speed derivatives.

    Returns
    -------
    dict
        Standard deviation of each wind parameter estimated in both fits, in its unit.
    """
    squares: dict[str, float] = {}
    if not any(status == "estimated" for status in base.status.values()):
        return squares  # nothing to move
    moves = [
        (name, bound)
        for name, bound in zip(speed_accuracy.names, map(float, speed_accuracy.cramer_rao))
        if name in speed and math.isfinite(bound) and bound > 0
    ]
    for again in map_forked(
        lambda j: fitted(dict(speed) | {moves[j][0]: speed[moves[j][0]] + moves[j][1]}), len(moves)
    ):
        for n, status in base.status.items():
            if status == "estimated" and again.status.get(n) == "estimated":
                squares[n] = squares.get(n, 0.0) + (again.values[n] - base.values[n]) ** 2
    return {n: math.sqrt(v) for n, v in squares.items()}


def identified_outputs(
    structure: ModelStructure, values: Mapping[str, float], outputs: Sequence[str]
) -> tuple[dict[str, float], list[str], str]:
    """The outputs of `outputs` that identified axes alone read, and values the matrices can be built from.

    Parameters
    ----------
    structure : ModelStructure
        The structure.
    values : Mapping[str, float]
        Identified values, NaN for the unidentified.
    outputs : sequence of str
        Outputs asked for.

    Returns
    -------
    tuple
        Values with each unidentified parameter at its starting value (it reads no output kept), the outputs
        kept, and the axes left out (for a message; "" when none).
    """
    unknown = {k for k, v in values.items() if not math.isfinite(v)}
    if not unknown:
        return dict(values), list(outputs), ""
    parts = axis_parts(structure, values)
    lost = {signal: part for signal, part in parts.items() if unknown & set(part.parameters)}
    gone = {o for part in lost.values() for o in part.outputs}
    declared = structure.values()
    kept = {k: declared[k] if k in unknown else v for k, v in values.items()}
    return kept, [o for o in outputs if o not in gone], ", ".join(lost)


def _informed(
    structure: ModelStructure,
    values: Mapping[str, float],
    constants: Mapping[str, float],
    rows: Sequence[int],
    names: Sequence[str],
) -> set[str]:
    """Wind parameters the fitted outputs' rows read (a G_w entry in them, or the delay of a column that has one)."""
    assembler = Assembler(structure, free=names, fixed=values, constants=constants, include_wind=True)
    theta = np.array([values[n] for n in names])
    m = assembler.matrices(theta)
    dm = assembler.derivatives(theta, m)
    columns = [j for j, c in enumerate(assembler.channels) if c.wind]
    reaching = [j for j in columns if np.any(m.d[list(rows), j] != 0) or np.any(dm.d[:, list(rows), j] != 0)]
    return {
        n
        for k, n in enumerate(names)
        if np.any(dm.d[k][np.ix_(list(rows), columns)] != 0) or np.any(dm.delays[k, reaching] != 0)
    }


def unfitted_wind(structure: ModelStructure, reason: str) -> WindStepResult:
    """The wind step's result when it cannot be run: every wind parameter unidentified, and a warning saying why.

    Parameters
    ----------
    structure : ModelStructure
        The structure, with wind parameters.
    reason : str
        Why the wind terms cannot be identified, and what to do; raised as a :class:`FitWarning`.

    Returns
    -------
    WindStepResult
        Values NaN, status ``unidentified``, no accuracy, no residual fit.

    Warns
    -----
    FitWarning
        With `reason`.
    """
    names = structure.wind_parameters
    warnings.warn(FitWarning(f"wind terms {', '.join(names)} not identified: {reason}"), stacklevel=2)
    return WindStepResult(
        values=MappingProxyType(dict.fromkeys(names, math.nan)),
        status=MappingProxyType(dict.fromkeys(names, "unidentified")),
        accuracy=accuracy(np.zeros((1, 0)), np.zeros(0), ()),
        fit=None,
    )
