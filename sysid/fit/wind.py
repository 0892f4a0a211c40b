"""The wind step (eq. 3.14): G_w and the wind delays from the one-step-prediction residual.

With F and G_u identified without wind (step 1), each record's measured
states predict the outputs one step ahead::

    residual = y - H0 x - H1 (F x + G_u u(t - tau_u))           (eq. 3.14)

States the record lacks (the actuator lags) are reconstructed by simulating
their own rows from the recorded inputs and states. What is left in the
accelerometer outputs is explained by ``H1 G_w u_w(t - tau_w)``: the G_w
entries are found by linear least squares at given delays, each wind delay
by a 1-D scan (coarse then fine, coordinate-wise, twice over), then all of
them are polished together by nonlinear least squares. Each output's
residual is weighted by its own level, and each record's mean is taken out of
the residual and of the wind (a per-record bias, as VERIFY's: accelerometer
bias and the trim leave a constant the wind does not explain). Wind
parameters that miss the CR% /
I% guidelines are dropped one at a time, as in step 1 (a wind delay the
data cannot resolve becomes 0).

Cramér–Rao bounds are those of the weighted least squares, corrected for
the residual's autocorrelation by an effective number of independent
samples (N_eff = N / (1 + 2 sum rho_k), Bartlett); insensitivities come from
the diagonal of the same information matrix.

The regression needs the wind where the vehicle meets it. When the
anemometer's clock is off by more than the wind delays can take up (the
conditioning measures the residual offset against the autopilot's wind
estimate, but applies it only when asked), the wind and the residual do not
line up: every G_w term comes out insensitive and would be dropped as if the
wind did nothing. :func:`sysid.fit.wind_alignment.wind_misalignment` detects
it, and the wind parameters are then left ``unidentified``
(:func:`unfitted_wind`) with the offset to give. Outputs of an unidentified axis have no residual to fit; a
wind parameter that only they would inform is unidentified too.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import Literal

import numpy as np
from scipy import linalg, optimize

from flightlogs.errors import FitError, FitWarning
from flightlogs.record import Record
from sysid.fit.accuracy import Accuracy, accuracy
from sysid.fit.guidelines import DEFAULT_GUIDELINES, Guidelines
from sysid.fit.reduce import ReductionStep, worst_parameter
from sysid.fit.result import WindFit
from sysid.model.assemble import Assembler, SystemMatrices
from sysid.model.axes import axis_parts
from sysid.model.structure import ModelStructure

__all__ = ["WindStepResult", "fit_wind", "unfitted_wind"]

WindStatus = Literal["estimated", "dropped", "unidentified"]

_SCAN_STEP_S = 0.002


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
    """

    values: Mapping[str, float]
    status: Mapping[str, WindStatus]
    accuracy: Accuracy
    fit: WindFit | None
    reduction: tuple[ReductionStep, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class _Data:
    """Eq. 3.14 residuals and wind signals of the records, with output weights."""

    residual: list[np.ndarray]
    winds: list[np.ndarray]
    times: list[np.ndarray]
    rows: list[int]
    scale: np.ndarray


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
    signals = [c.signal for c in structure.wind_inputs]
    residual, winds, times = [], [], []
    for record in records:
        x, u = _states(record, structure, plain, m)
        y = np.column_stack([record[o] for o in outputs])
        r = y - x @ m.c[rows].T - u @ m.d[rows].T
        residual.append(r - r.mean(axis=0))  # a bias per record (sensor bias, trim): not the wind's
        winds.append(np.column_stack([record[s] for s in signals]))
        times.append(record.time_s)
    scale = 1.0 / np.maximum(np.vstack(residual).std(axis=0), 1e-12)
    return _Data(residual=residual, winds=winds, times=times, rows=rows, scale=scale)


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
        self._cache: dict[tuple[int, float], list[np.ndarray]] = {}

    def shifted(self, k: int, tau: float) -> list[np.ndarray]:
        """Wind channel `k` delayed by `tau`, per record."""
        key = (k, round(float(tau), 12))
        if key not in self._cache:
            if len(self._cache) > 64:  # the scan revisits few delays; the polish visits many once
                self._cache.clear()
            shifted = [np.interp(t - tau, t, w[:, k]) for t, w in zip(self.data.times, self.data.winds)]
            self._cache[key] = [x - x.mean() for x in shifted]  # as the residual: each record's bias taken out
        return self._cache[key]

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
        residual = np.vstack(problem.data.residual)
        self.rr = np.einsum("nr,nr->r", residual, residual)
        self.residual = residual

    def solve(self, theta: np.ndarray) -> tuple[np.ndarray, float]:
        """Least-squares gains at the delays of `theta` (entries linear in their gains) and the cost."""
        delays = self.problem.assembler.matrices(theta).delays[self.problem.columns]
        winds = np.column_stack([np.concatenate(self.problem.shifted(k, tau)) for k, tau in enumerate(delays)])
        gram = winds.T @ winds  # (n_wind, n_wind)
        cross = winds.T @ self.residual  # (n_wind, n_out)
        # target per output: residual - w d0^T; regressor g per output: w e_g^T
        tt = self.rr - 2 * np.einsum("rc,cr->r", self.d0, cross) + np.einsum("rc,cd,rd->r", self.d0, gram, self.d0)
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


def _scan(problem: _Problem) -> np.ndarray:
    """Each delay by a coarse then fine 1-D scan (gains solved at every point), twice over."""
    delays, gains = problem.delay_and_gain_index()
    normal = _Normal(problem, problem.start, gains)
    theta, best = normal.solve(problem.start)
    for _ in range(2 if delays else 0):
        for k in delays:
            p = problem.structure.parameter(problem.free[k])
            lo, hi = max(p.lower, 0.0), min(p.upper, 1.0)
            for grid in (np.arange(lo, hi + 1e-12, 5 * _SCAN_STEP_S), None):
                points = np.clip(theta[k] + np.arange(-5, 6) * _SCAN_STEP_S, lo, hi) if grid is None else grid
                for tau in points:
                    trial = theta.copy()
                    trial[k] = tau
                    trial, cost = normal.solve(trial)
                    if cost < best:
                        theta, best = trial, cost
    return theta


def _inflation(residual: np.ndarray) -> float:
    """N / N_eff of the weighted residual (Bartlett) times its variance: what J^T J is divided by."""
    factor = 0.0
    for column in residual.T:
        c = column - column.mean()
        acf = np.fft.irfft(np.abs(np.fft.rfft(c, 2 * c.size)) ** 2)[: c.size]
        rho = acf / acf[0] if acf[0] > 0 else np.zeros(1)
        cut = int(np.argmax(rho < 0.05)) if np.any(rho < 0.05) else rho.size
        factor = max(factor, (1.0 + 2.0 * float(np.sum(rho[1:cut]))) * float(np.mean(column**2)))
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
        acc = accuracy(solved.jac / math.sqrt(_inflation(stacked * data.scale)), theta, tuple(free))
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
    max_cr_percent: float = DEFAULT_GUIDELINES.max_cr_percent,
    max_insensitivity_percent: float = DEFAULT_GUIDELINES.max_insensitivity_percent,
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
    max_cr_percent : float, optional
        CR% guideline, % of ``|value|``; default Tischler's (:data:`~sysid.fit.guidelines.DEFAULT_GUIDELINES`).
    max_insensitivity_percent : float, optional
        I% guideline, % of ``|value|``; default Tischler's.

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
    values, outputs, lost = _identified_outputs(structure, values, outputs)
    if not outputs:
        return unfitted_wind(structure, f"the outputs of the wind step belong to unidentified axes ({lost})")
    needed = {c.signal for c in structure.inputs} | set(outputs)
    usable = [r for r in records if needed <= set(r.signals)]
    if not usable:
        raise FitError(f"no record has every signal the wind step needs ({', '.join(sorted(needed))})")
    current = dict(values) | {n: values.get(n, structure.parameter(n).value) for n in names}
    data = _prediction_data(structure, current, constants, usable, outputs)
    informed = _informed(structure, current, constants, data.rows, names)
    status: dict[str, WindStatus] = {n: "estimated" if n in informed else "unidentified" for n in names}
    steps: list[ReductionStep] = []
    guidelines = Guidelines(max_cr_percent=max_cr_percent, max_insensitivity_percent=max_insensitivity_percent)
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


def _identified_outputs(
    structure: ModelStructure, values: Mapping[str, float], outputs: Sequence[str]
) -> tuple[dict[str, float], list[str], str]:
    """Values with each unidentified (NaN) parameter at its starting value, the outputs of identified axes only,
    and the axes left out (for a message)."""
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
