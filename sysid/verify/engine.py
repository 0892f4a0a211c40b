"""Simulate an identified model from measured inputs and score it (chapter 3.5.3; Tischler's VERIFY).

Per record:

1. the model is discretised exactly (zero-order hold) at the record's rate,
   each input delay split into whole samples and a fraction handled by the
   modified z-transform (:mod:`sysid.model.discrete`);
2. the initial state is taken from the record: a state whose name is a
   record column starts at that column's value at the first sample (a line
   fitted over the first `initial_window_s`, so sensor noise is averaged);
   the other states start at rest given those and the first inputs (an
   actuator lag at its input), or at zero where that is undetermined
   (``initial_state="estimated"`` also fits a correction to it in step 4,
   which absorbs a trim that is not an equilibrium; ``"zero"`` starts at 0);
3. the model is simulated from *all* its measured inputs, ``y_model(u)``:
   during a doublet on one axis the autopilot keeps flying the others (and
   counters the wind with thrust), and leaving those commands out would
   blame the model for what the pilot did;
4. as in VERIFY, a constant reference shift ``Δu`` per input and a bias
   ``b`` per output are estimated by linear least squares on
   ``y_meas ≈ y_model(u) + Σ Δu_j s_j + b``, where ``s_j`` is the
   simulated response to a unit constant on input j from zero state, so a
   trim or sensor offset is not blamed on the dynamics. The shifts (and the
   initial-state correction) are fitted on the judged outputs only: the
   trim terms couple the axes (``w' = U0 q - V0 p``), and an off-axis output
   the model predicts poorly, or a misaligned wind on it, would otherwise
   move the shifts and so the on-axis verdict; each off-axis output gets its
   own bias;
5. RMS error and Theil inequality coefficient per output; a record that
   excites one axis is judged on that axis' outputs only (`on_axis`; the
   others are kept for information as off-axis), overall as Tischler's
   J_rms with angles and angular rates in degrees;
6. an open-loop unstable model (``max Re λ > 0`` of the states the judged
   outputs depend on) amplifies any error by ``exp(Re λ · T)`` over a record
   of length T: when that exceeds `max_growth` the record is flagged and the
   one-step-ahead prediction error is reported as well (each step starts from
   the measured states, the unmeasured ones from the model, as in the
   residual of eq. 3.14).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal, cast

import numpy as np

from flightlogs.errors import DataError
from flightlogs.record import Record
from sysid.model.axes import reachable
from sysid.model.discrete import DiscreteModel, delayed_inputs, discretize, predict_one_step, simulate
from sysid.model.modes import state_modes
from sysid.model.statespace import DelayedStateSpace
from sysid.verify.results import (
    OutputSummary,
    OutputVerification,
    RecordVerification,
    Verification,
    WindCorrection,
    mode_names,
    rms_error,
    theil_inequality,
)
from sysid.verify.submodel import driven_part

__all__ = ["VerificationOptions", "verify_record", "verify"]

_ANGULAR_UNITS = ("rad", "rad/s", "rad/s^2", "rad/s²")


@dataclass(frozen=True, slots=True, kw_only=True)
class VerificationOptions:
    """Choices for :func:`verify_record` and :func:`verify`.

    Parameters
    ----------
    fit_bias : bool
        Estimate a constant bias per output.
    fit_reference_shift : bool
        Estimate a constant reference shift per input.
    initial_state : {"measured", "estimated", "zero"}
        Start from the record's measured states (the rest at rest); from
        those corrected by least squares with the bias and shifts (this also
        absorbs trim values that are not an equilibrium, and over long
        records the growth of an unstable mode); or from zero.
    initial_window_s : float
        Span over which each measured state's starting value is fitted, s.
    max_growth : float
        Open-loop growth over the record above which the simulation is
        flagged as unreliable (>= 1).
    one_step : {"auto", "always", "never"}
        Report the one-step-ahead prediction error when flagged, always, or never.
    """

    fit_bias: bool = True
    fit_reference_shift: bool = True
    initial_state: Literal["measured", "estimated", "zero"] = "measured"
    initial_window_s: float = 0.1
    max_growth: float = 10.0
    one_step: Literal["auto", "always", "never"] = "auto"

    def __post_init__(self) -> None:
        if self.initial_state not in ("measured", "estimated", "zero"):
            raise ValueError(f"initial_state={self.initial_state!r} must be 'measured', 'estimated' or 'zero'")
        if self.one_step not in ("auto", "always", "never"):
            raise ValueError(f"one_step={self.one_step!r} must be 'auto', 'always' or 'never'")
        if not self.initial_window_s >= 0:
            raise ValueError(f"initial_window_s={self.initial_window_s} must be >= 0")
        if not self.max_growth >= 1:
            raise ValueError(f"max_growth={self.max_growth} must be >= 1")


def _weight(unit: str) -> float:
    """J_rms weight: angles and angular rates in degrees, the rest in SI."""
    return float(np.degrees(1.0)) if unit.strip() in _ANGULAR_UNITS else 1.0


def _signals(record: Record, names: Sequence[str], what: str) -> np.ndarray:
    missing = [n for n in dict.fromkeys(names) if n not in record.signals]
    if missing:
        raise DataError(f"{record.source.name}: record {record.label!r} lacks the model {what} {', '.join(missing)}")
    return np.column_stack([record[n] for n in names]) if names else np.zeros((record.time_s.size, 0))


def _initial_state(
    model: DelayedStateSpace, disc: DiscreteModel, record: Record, inputs: np.ndarray, options: VerificationOptions
) -> np.ndarray:
    """Measured states at the first sample (line fit), the rest at rest given them; zero if asked."""
    n_x = len(model.states)
    x0 = np.zeros(n_x)
    if options.initial_state == "zero":
        return x0
    time_s = record.time_s - record.time_s[0]
    window = max(2, int(np.searchsorted(time_s, options.initial_window_s, side="right")))
    measured = np.array([name in record.signals for name in model.states])
    for i in np.flatnonzero(measured):
        values = record[model.states[i]][:window]
        x0[i] = np.polynomial.polynomial.polyfit(time_s[:window], values, 1)[0] if values.size > 2 else values[0]
    free = ~measured
    if free.any():
        now, prev = delayed_inputs(disc, inputs[:1])
        held = np.where(disc.fraction > 0, prev[0], now[0])
        a = np.asarray(model.a, dtype=float)
        rhs = -(a[np.ix_(free, measured)] @ x0[measured] + np.asarray(model.b, dtype=float)[free] @ held)
        x0[free] = np.linalg.lstsq(a[np.ix_(free, free)], rhs, rcond=1e-9)[0]
    return x0


def _shift_responses(model: DelayedStateSpace, disc: DiscreteModel, names: Sequence[str], n_samples: int) -> np.ndarray:
    """Each named input's response to a unit constant, shape (n_names, n_samples, n_outputs)."""
    responses = np.empty((len(names), n_samples, len(model.outputs)))
    for k, name in enumerate(names):
        unit = np.tile([float(n == name) for n in model.inputs], (n_samples, 1))
        responses[k] = simulate(disc, unit, np.zeros(len(model.states)))
    return responses


def _free_responses(model: DelayedStateSpace, disc: DiscreteModel, n_samples: int) -> np.ndarray:
    """Response to a unit initial value of each state, no input, shape (n_states, n_samples, n_outputs)."""
    zero = np.zeros((n_samples, len(model.inputs)))
    return (
        np.stack([simulate(disc, zero, unit) for unit in np.eye(len(model.states))])
        if model.states
        else (np.zeros((0, n_samples, len(model.outputs))))
    )


def _offsets(residual: np.ndarray, regressors: list[np.ndarray], weights: np.ndarray) -> list[np.ndarray]:
    """Weighted least-squares coefficients of each group of regressors, each (n_group, n_samples, n_outputs)."""
    columns = [group[k] for group in regressors for k in range(group.shape[0])]
    if not columns:
        return [np.zeros(0) for _ in regressors]
    design = np.stack([(c * weights).ravel() for c in columns], axis=1)
    solution = np.linalg.lstsq(design, (residual * weights).ravel(), rcond=1e-10)[0]
    bounds = np.cumsum([0] + [group.shape[0] for group in regressors])
    return [solution[a:b] for a, b in zip(bounds[:-1], bounds[1:])]


def _growth(model: DelayedStateSpace, judged: Sequence[int], duration_s: float) -> tuple[float, tuple[str, ...]]:
    """Open-loop growth over the record of the states the judged outputs depend on (through C and A), and the
    labels of its unstable modes (``("pitch",)``), largest real part first."""
    a, c = np.asarray(model.a, dtype=float), np.asarray(model.c, dtype=float)
    seen = reachable(a.T, np.any(c[list(judged)] != 0, axis=0))
    unstable = [m for m in state_modes(a[np.ix_(seen, seen)], tuple(np.asarray(model.states)[seen])) if m.unstable]
    if not unstable:
        return 1.0, ()
    rate = max(m.real for m in unstable)
    labels = tuple(dict.fromkeys(m.mode for m in sorted(unstable, key=lambda m: -m.real)))
    return float(np.exp(min(rate * duration_s, 700.0))), labels


def _one_step(
    model: DelayedStateSpace,
    disc: DiscreteModel,
    record: Record,
    inputs: np.ndarray,
    x0: np.ndarray,
    outputs: list[int],
    measured: np.ndarray,
) -> np.ndarray:
    """One-step-ahead outputs (columns `outputs`), their mean residual removed as the bias."""
    states = np.full((inputs.shape[0], len(model.states)), np.nan)
    for i, name in enumerate(model.states):
        if name in record.signals:
            states[:, i] = record[name]
    predicted = predict_one_step(disc, inputs, states, x0)[:, outputs]
    return cast(
        np.ndarray, predicted + (measured - predicted).mean(axis=0)
    )  # bias only: one step is too short to see a shift


def _overall(measured: np.ndarray, simulated: np.ndarray, weights: np.ndarray) -> tuple[float, float]:
    return rms_error(measured * weights, simulated * weights), theil_inequality(measured * weights, simulated * weights)


def verify_record(
    model: DelayedStateSpace,
    record: Record,
    *,
    on_axis: Sequence[str] | None = None,
    excited: str | None = None,
    options: VerificationOptions = VerificationOptions(),
) -> RecordVerification:
    """Simulate `model` from the measured inputs of `record` and compare its outputs.

    Parameters
    ----------
    model : DelayedStateSpace
        Perturbation model; all its inputs and the outputs to verify must be
        record columns (outputs that are not are skipped).
    record : Record
        A stretch of flight not used in the fit (a doublet), trim removed.
    on_axis : sequence of str, optional
        The outputs to judge the record on (the excited axis'); the others
        are reported as off-axis, for information. Default: every output.
    excited : str, optional
        The input the record excites, kept with the result.
    options : VerificationOptions, optional
        Bias, reference shift, initial state and instability choices.

    Returns
    -------
    RecordVerification

    Raises
    ------
    DataError
        If the record lacks a model input, or every model output to judge.

    Examples
    --------
    A first-order lag verified against its own response, offset by a bias:

    >>> from pathlib import Path
    >>> model = DelayedStateSpace(a=np.array([[-2.0]]), b=np.array([[2.0]]), c=np.array([[1.0]]), d=np.zeros((1, 1)),
    ...                           states=("q",), inputs=("delta_lon",), outputs=("q",), input_delays_s=np.array([0.0]))
    >>> t = np.arange(200) * 0.01
    >>> step = (t >= 0.5).astype(float)
    >>> columns = {"delta_lon": step, "q": 0.1 + step * (1 - np.exp(-2 * (t - 0.5)))}
    >>> record = Record(time_s=t, columns=columns, units={"delta_lon": "%", "q": "rad/s"}, trim={}, source=Path("demo.ulg"))
    >>> result = verify_record(model, record,
    ...                        options=VerificationOptions(initial_state="zero", fit_reference_shift=False))
    >>> round(result.output("q").bias, 3), result.output("q").tic < 0.01
    (0.1, True)
    """
    outputs = [k for k, name in enumerate(model.outputs) if name in record.signals]
    wanted = tuple(model.outputs) if on_axis is None else tuple(on_axis)
    judged = [j for j, k in enumerate(outputs) if model.outputs[k] in wanted]
    if not judged:
        raise DataError(
            f"{record.source.name}: record {record.label!r} has none of the model outputs {', '.join(wanted)}"
        )
    inputs = _signals(record, model.inputs, "inputs")
    disc = discretize(model, 1.0 / record.rate_hz)
    measured = np.column_stack([record[model.outputs[k]] for k in outputs])
    units = [record.units[model.outputs[k]] for k in outputs]
    weights = np.array([_weight(unit) for unit in units])
    x0 = _initial_state(model, disc, record, inputs, options)
    raw = simulate(disc, inputs, x0)[:, outputs]
    simulated, shifts, biases, correction = _fit_offsets(model, disc, raw, measured, outputs, weights, judged, options)
    growth, unstable_modes = _growth(model, [outputs[j] for j in judged], record.end_s - record.start_s)
    unstable = growth > options.max_growth
    predicted = None
    if options.one_step == "always" or (options.one_step == "auto" and unstable):
        predicted = _one_step(model, disc, record, inputs, x0 + correction, outputs, measured)
    results = tuple(
        _output(
            model.outputs[k],
            units[j],
            measured[:, j],
            simulated[:, j],
            float(biases[j]),
            None if predicted is None else predicted[:, j],
        )
        for j, k in enumerate(outputs)
    )
    rmse, tic = _overall(measured[:, judged], simulated[:, judged], weights[judged])
    notice = ""
    if unstable:
        reach = ", ".join(model.outputs[outputs[j]] for j in judged)
        notice = (
            f"the model is unstable open loop in its {mode_names(unstable_modes)}, which {reach} depend"
            f"{'s' if len(judged) == 1 else ''} on, and grows {growth:.0f}-fold over this "
            f"{record.end_s - record.start_s:.1f} s record (limit {options.max_growth:g}): small input or "
            "initial-state errors diverge, so judge it also by the one-step-ahead prediction error"
        )
    off_axis = tuple(o.name for j, o in enumerate(results) if j not in judged)
    return RecordVerification(
        label=record.label,
        source=record.source,
        time_s=record.time_s,
        inputs=tuple(model.inputs),
        outputs=results,
        reference_shifts=shifts,
        rmse=rmse,
        tic=tic,
        growth=growth,
        unstable=unstable,
        notice=notice,
        excited=excited,
        off_axis=off_axis,
        unstable_modes=unstable_modes,
    )


def _fit_offsets(
    model: DelayedStateSpace,
    disc: DiscreteModel,
    raw: np.ndarray,
    measured: np.ndarray,
    outputs: list[int],
    weights: np.ndarray,
    judged: list[int],
    options: VerificationOptions,
) -> tuple[np.ndarray, dict[str, float], np.ndarray, np.ndarray]:
    """Reference shifts, biases and (if asked) the initial-state correction; the simulation with them applied.

    Shifts and the correction are fitted on the judged outputs only, so that an off-axis output the model
    predicts poorly cannot move the on-axis verdict; each off-axis output then gets its own bias.
    """
    n_samples, n_out = measured.shape
    none = np.zeros((0, n_samples, n_out))
    names = list(dict.fromkeys(model.inputs))
    groups = [
        _shift_responses(model, disc, names, n_samples)[:, :, outputs] if options.fit_reference_shift else none,
        np.eye(n_out)[:, None, :] * np.ones((1, n_samples, 1)) if options.fit_bias else none,
        _free_responses(model, disc, n_samples)[:, :, outputs] if options.initial_state == "estimated" else none,
    ]
    on_axis = np.isin(np.arange(n_out), judged)
    shifts, biases, correction = _offsets(measured - raw, groups, np.where(on_axis, weights, 0.0))
    simulated = raw + sum(
        (np.tensordot(c, g, axes=1) for c, g in zip((shifts, correction), groups[::2])), np.zeros_like(raw)
    )
    biases = biases if options.fit_bias else np.zeros(n_out)
    if options.fit_bias:
        biases[~on_axis] = (measured - simulated)[:, ~on_axis].mean(axis=0)
    simulated = simulated + biases
    shifts = shifts if options.fit_reference_shift else np.zeros(len(names))
    correction = correction if options.initial_state == "estimated" else np.zeros(len(model.states))
    return simulated, dict(zip(names, (float(v) for v in shifts))), biases, correction


def _output(
    name: str, unit: str, measured: np.ndarray, simulated: np.ndarray, bias: float, predicted: np.ndarray | None
) -> OutputVerification:
    return OutputVerification(
        name=name,
        unit=unit,
        measured=measured,
        simulated=simulated,
        bias=bias,
        rmse=rms_error(measured, simulated),
        tic=theil_inequality(measured, simulated),
        predicted=predicted,
        prediction_rmse=None if predicted is None else rms_error(measured, predicted),
        prediction_tic=None if predicted is None else theil_inequality(measured, predicted),
    )


def _pooled(records: Sequence[RecordVerification], *, judged: bool = True) -> tuple[OutputSummary, ...]:
    """Per output, pooled over the records where it is judged (or, with ``judged=False``, off-axis)."""
    picked = [(r, r.judged if judged else r.informative) for r in records]
    names = list(dict.fromkeys(o.name for _, outputs in picked for o in outputs))  # on-axis: grouped by axis
    if not judged:  # off-axis: in model order
        names = [n for n in dict.fromkeys(o.name for r in records for o in r.outputs) if n in names]
    summaries = []
    for name in names:
        pieces = [o for _, outputs in picked for o in outputs if o.name == name]
        measured = np.concatenate([p.measured for p in pieces])
        simulated = np.concatenate([p.simulated for p in pieces])
        with_prediction = [p for p in pieces if p.predicted is not None]
        prediction_rmse = prediction_tic = None
        if with_prediction:
            m = np.concatenate([p.measured for p in with_prediction])
            s = np.concatenate([p.predicted for p in with_prediction if p.predicted is not None])
            prediction_rmse, prediction_tic = rms_error(m, s), theil_inequality(m, s)
        summaries.append(
            OutputSummary(
                name=name,
                unit=pieces[0].unit,
                rmse=rms_error(measured, simulated),
                tic=theil_inequality(measured, simulated),
                n_records=len(pieces),
                n_samples=int(measured.size),
                prediction_rmse=prediction_rmse,
                prediction_tic=prediction_tic,
            )
        )
    return tuple(summaries)


def _pooled_in_wind_band(records: Sequence[RecordVerification]) -> dict[str, float]:
    """Per judged output, the RMS error pooled over the records after the wind step's own low-pass of the wind.

    The anemometer's wind drives G_w low-passed at :data:`~sysid.fit.wind_offset.SMOOTHING_HZ` (zero
    phase): filtered the same way, the error keeps what G_w can correct.
    """
    from sysid.fit.wind_offset import smoothed

    squares: dict[str, list[float]] = {}
    for record in records:
        rate_hz = 1.0 / float(np.median(np.diff(record.time_s))) if record.time_s.size > 1 else math.nan
        for o in record.judged:
            error = smoothed((o.measured - o.simulated)[:, None], rate_hz)[:, 0]
            total = squares.setdefault(o.name, [0.0, 0.0])
            total[0] += float(np.sum(error**2))
            total[1] += error.size
    return {name: math.sqrt(s / n) for name, (s, n) in squares.items() if n > 0}


def _overall_pooled(records: Sequence[RecordVerification]) -> tuple[float, float]:
    measured = np.concatenate([o.measured * _weight(o.unit) for r in records for o in r.judged])
    simulated = np.concatenate([o.simulated * _weight(o.unit) for r in records for o in r.judged])
    return rms_error(measured, simulated), theil_inequality(measured, simulated)


def verify(
    model: DelayedStateSpace,
    records: Sequence[Record],
    *,
    wind_model: DelayedStateSpace | None = None,
    excited: Sequence[str | None] | None = None,
    axes: Mapping[str, Sequence[str]] | None = None,
    options: VerificationOptions = VerificationOptions(),
) -> Verification:
    """Verify a model on several records, with and without its wind term.

    Every record is simulated from all the model's measured inputs; a record
    that excites one axis is judged on that axis' outputs only.

    Parameters
    ----------
    model : DelayedStateSpace
        The model without the wind term G_w (or the only model).
    records : sequence of Record
        Records not used in the fit (doublets), trim removed.
    wind_model : DelayedStateSpace, optional
        The same model with G_w (wind inputs such as ``wind_lon``); then
        `Verification.records` holds it, `without_wind` the model without,
        and `wind_correction` compares them per on-axis output.
    excited : sequence of (str or None), optional
        Per record, the input it excites (``"delta_lon"``): the record is
        judged on that input's on-axis outputs (`axes`), the others are
        reported as off-axis. None judges a record on every output.
    axes : Mapping[str, sequence of str], optional
        On-axis outputs of each excited input (:func:`axis_outputs` of an
        identified model); default: the outputs it drives in `model`
        (:func:`driven_part`), right for a model of decoupled axes but not
        for one whose trim terms couple them.
    options : VerificationOptions, optional
        Choices shared by every record.

    Returns
    -------
    Verification

    Raises
    ------
    DataError
        If there are no records, `excited` has not one entry per record, or a record lacks a model input or every
        output to judge.
    ModelError
        If an excited input is not a model input.
    """
    if not records:
        raise DataError("no records to verify the model on")
    picks = list(excited) if excited is not None else [None] * len(records)
    if len(picks) != len(records):
        raise DataError(
            f"excited has {len(picks)} entries for {len(records)} records: one per record, None for all outputs"
        )
    judged: dict[str, tuple[str, ...]] = {}
    for pick in dict.fromkeys(p for p in picks if p is not None):
        judged[pick] = tuple(axes[pick]) if axes is not None and pick in axes else driven_part(model, pick).outputs

    def run(which: DelayedStateSpace) -> tuple[RecordVerification, ...]:
        return tuple(
            verify_record(which, record, on_axis=None if pick is None else judged[pick], excited=pick, options=options)
            for record, pick in zip(records, picks)
        )

    without = run(model)
    final = run(wind_model) if wind_model is not None else without
    summary = _pooled(final)
    off_axis = _pooled(final, judged=False)
    rmse, tic = _overall_pooled(final)
    if wind_model is None:
        return Verification(records=final, summary=summary, rmse=rmse, tic=tic, off_axis=off_axis)
    from sysid.fit.wind_offset import SMOOTHING_HZ  # here: sysid.fit loads SciPy's optimisers

    before = {s.name: s for s in _pooled(without)}
    band_without, band_with = _pooled_in_wind_band(without), _pooled_in_wind_band(final)
    corrections = tuple(
        WindCorrection(
            name=s.name,
            unit=s.unit,
            rmse_without=before[s.name].rmse,
            rmse_with=s.rmse,
            band_hz=SMOOTHING_HZ,
            rmse_without_in_band=band_without.get(s.name, math.nan),
            rmse_with_in_band=band_with.get(s.name, math.nan),
        )
        for s in summary
        if s.name in before
    )
    return Verification(
        records=final,
        summary=summary,
        rmse=rmse,
        tic=tic,
        without_wind=without,
        wind_correction=corrections,
        off_axis=off_axis,
    )
