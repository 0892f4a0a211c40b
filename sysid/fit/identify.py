"""The whole identification: flights to frequency responses, gating, F/G_u fit, wind step, model.

This is what ``sysid fit`` runs. Each mixer axis's sweeps give the
responses of Table 3.4's pairs (conditioned on the structure's wind signals
when the records carry them), gated by eq. 3.8; the structure's F and G_u
parameters are fitted to them and reduced; its G_w parameters come from
the time-domain residual of eq. 3.14.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from types import MappingProxyType
from typing import Literal

import numpy as np
from scipy import linalg

from flightlogs.conditioning.condition import ConditionedFlight, ConditioningOptions
from flightlogs.errors import FitError, FitWarning, SysidWarning, collected_warnings
from flightlogs.parallel import map_forked
from flightlogs.readers.dispatch import ReadOptions
from flightlogs.record import Record
from flightlogs.store.hashing import file_sha256
from flightlogs.writers.jsonio import jsonable
from sysid.fit.accuracy import Accuracy, with_spread
from sysid.fit.axes import merge_axes, partial_warning, structure_axes, unidentified_message
from sysid.fit.engine import FitOptions, FrequencyFit, fit_frequency_responses
from sysid.fit.guidelines import Guidelines
from sysid.fit.reduce import ReductionStep
from sysid.fit.result import IdentifiedModel, ParameterEstimate, Provenance, WindClockOffset
from sysid.fit.trim_paths import trim_only_responses
from sysid.fit.wind import (
    WindStepResult,
    fit_wind,
    sharing_delayed_winds,
    speed_derivatives,
    speed_spread,
    step_one_spread,
    unfitted_wind,
)
from sysid.fit.wind_offset import moved_flights, moved_wind, offset_given, timed_wind, untimed_wind
from sysid.fit.wind_trace import wind_trace
from sysid.freqresp import (
    ChannelWindows,
    FrequencyResponse,
    Gating,
    GatingResult,
    ResponseOptions,
    coupled_inputs,
    frequency_response_sets,
    gate_responses,
    maneuver_band,
    maneuver_records,
    quiet_records,
    reference_options,
    within_band,
)
from sysid.model.assemble import structure_model
from sysid.model.structure import ModelStructure
from sysid.model.toml_format import load_structure

__all__ = ["FIT_PAIRS", "IdentifyOptions", "identify_flights", "identify_logs", "model_from_fit"]

#: Outputs fitted per mixer axis (Table 3.4): the input is ``delta_<axis>``.
FIT_PAIRS: Mapping[str, tuple[str, ...]] = MappingProxyType(
    {
        "lat": ("v", "p", "ay"),
        "lon": ("u", "w", "q", "ax"),
        "yaw": ("r",),
        "thr": ("az",),
    }
)
_AXES = ("lat", "lon", "yaw", "thr")

Progress = Callable[[str, int, int], None]


@dataclass(frozen=True, slots=True, kw_only=True)
class IdentifyOptions:
    """Choices of the whole identification.

    Parameters
    ----------
    fit : FitOptions
        Search, cost weights and reduction.
    responses : ResponseOptions
        Frequency grid and windows of the responses.
    min_record_periods : float
        Lowest frequency fitted: the longest record must hold this many of
        its periods (Tischler's guideline, 4-5), so ``omega_min`` is raised
        to ``2 pi min_record_periods / T_record`` (0.87 rad/s for the
        dissertation's 36 s sweep records); below it, closed-loop responses
        of short records are biased by leakage. Where a sweep's band (its
        segment's ``f_min_hz``) starts below ``responses.omega_min``, the grid
        starts there instead, as far as this allows: a 240 s sweep from
        0.15 rad/s is fitted from 0.15 rad/s.
    pairs : tuple of (str, str) or None
        ``(output, input)`` pairs to fit; None for :data:`FIT_PAIRS` of every
        axis flown (outputs the records or the structure lack are left out).
    kind : str
        Maneuvers the responses come from (``sweep``).
    gating : Gating
        The rule of eq. 3.8 a response must pass to be fitted (coherence and span).
    constants : Mapping[str, float] or None
        Trim constants to use instead of the flights' trim (``U0``, ``theta0`` ...).
    initial : Mapping[str, float] or None
        Starting values overriding the structure's.
    condition_on_wind : bool
        Condition each response on the structure's wind signals when the
        records carry them (partial coherence).
    use_excitation : bool
        Use the logged excitation (ArduPilot SIDD) as the reference of the
        mixer input's responses where every sweep carries it, which removes
        the bias of noise and turbulence fed back by the autopilot.
    wind_outputs : tuple of str
        Outputs whose eq. 3.14 residual the wind step fits.
    wind_axes : tuple of str
        Maneuvers whose records the wind step uses: those of the axes whose
        outputs carry the wind terms (yaw sweeps turn the nose through the
        wind and mix its components).
    partial : bool
        Identify the axes that can be, and leave the others ``unidentified``
        (a warning says which); False (default) raises a FitError naming
        every axis of the structure without a usable maneuver.
    """

    fit: FitOptions = field(default_factory=FitOptions)
    responses: ResponseOptions = field(default_factory=ResponseOptions)
    min_record_periods: float = 5.0
    pairs: tuple[tuple[str, str], ...] | None = None
    kind: str = "sweep"
    gating: Gating = Gating()
    constants: Mapping[str, float] | None = None
    initial: Mapping[str, float] | None = None
    condition_on_wind: bool = True
    use_excitation: bool = True
    wind_outputs: tuple[str, ...] = ("ax", "az")
    wind_axes: tuple[str, ...] = ("lon", "thr")
    partial: bool = False


def _report(progress: Progress | None, stage: str, done: int, total: int) -> None:
    if progress is not None:
        progress(stage, done, total)


def _axis_responses(
    structure: ModelStructure,
    records: list[Record],
    axis: str,
    options: IdentifyOptions,
    band: tuple[float, float] | None = None,
    quiet: Sequence[Record] = (),
) -> tuple[tuple[FrequencyResponse, ...], str | None]:
    """The responses of one axis's pairs, and the note saying what they were computed against (None if none).

    With the maneuvers' `band` (rad/s) known and no reference, the grid keeps within it
    (:func:`~sysid.freqresp.within_band`); `quiet` flight (:func:`~sysid.freqresp.quiet_records`) gives the
    feedback floor removed from the responses, unless they are conditioned on the measured wind: that takes
    the fed-back gusts out instead (on the strong-wind tuning log the floor, gusts of other stretches of
    flight, gated out everything below 5 rad/s and with it X_u, M_u and the wind step).
    """
    control = f"delta_{axis}"
    logged = set.intersection(*(set(r.signals) for r in records))
    if options.pairs is not None:
        outputs = [o for o, i in options.pairs if i == control]
    else:
        outputs = [o for o in FIT_PAIRS[axis] if o in structure.outputs]
    outputs = [o for o in outputs if o in logged]
    if not outputs or control not in logged:
        return (), None
    winds = [s for s in dict.fromkeys(c.signal for c in structure.wind_inputs) if s in logged]
    inputs = [control] + (winds if options.condition_on_wind else [])
    longest = max(r.end_s - r.start_s for r in records)
    low = options.responses.omega_min
    if band is not None and band[0] < low:  # a sweep flown below the grid: fitted down to where it starts
        low = band[0]
    lowest = max(low, 2.0 * np.pi * options.min_record_periods / longest)
    grid = dataclasses.replace(options.responses, omega_min=min(lowest, options.responses.omega_max / 2.0))
    grid, note = reference_options(records, axis, inputs, options.kind, grid, options.use_excitation)
    grid = within_band(grid, band)
    others = [f"delta_{a}" for a in _AXES if a != axis and f"delta_{a}" in logged]
    windows = ChannelWindows(records, grid)  # the coupling's and the responses': the control transformed once
    sets = []
    coupled = coupled_inputs(records, control, others, grid, windows=windows)
    for extra, group in _by_coupling(structure, outputs, coupled).items():
        used = [*inputs, *extra]
        sets.append((used, group, [r for r in quiet if {*used, *group} <= set(r.signals)] if len(inputs) == 1 else []))
    found = [r for responses in frequency_response_sets(records, sets, grid, windows=windows) for r in responses]
    return tuple(r for o in outputs for r in found if r.input == control and r.output == o), note


def _by_coupling(
    structure: ModelStructure, outputs: Sequence[str], coupled: Sequence[str]
) -> dict[tuple[str, ...], list[str]]:
    """Outputs grouped by the `coupled` mixer inputs that drive them in `structure` (initial values, trim zero).

    A response is conditioned on another mixer input only when that input moves with the maneuver's
    (:func:`~sysid.freqresp.coupling.coupled_inputs`) and the structure lets it drive the output.
    """
    groups: dict[tuple[str, ...], list[str]] = {}
    gain = None
    if coupled:
        model, _ = structure_model(structure, structure.values(), include_wind=False)
        gain = np.abs(model.frequency_response(np.array([1.0, 3.0, 10.0])))
        names = (model.outputs, model.inputs)
    for output in outputs:
        extra: tuple[str, ...] = ()
        if gain is not None and output in names[0]:
            row = gain[:, names[0].index(output)]
            extra = tuple(i for i in coupled if np.max(row[:, names[1].index(i)]) > 1e-9 * np.max(row))
        groups.setdefault(extra, []).append(output)
    return groups


def identify_flights(
    flights: Sequence[ConditionedFlight],
    structure: ModelStructure | str,
    *,
    options: IdentifyOptions = IdentifyOptions(),
    files: Sequence[str | Path] = (),
    progress: Progress | None = None,
) -> IdentifiedModel:
    """Identify a model structure from conditioned flights.

    Parameters
    ----------
    flights : sequence of ConditionedFlight
        Flights with sweeps (and, for the wind step, air-relative velocities
        and the wind in their records).
    structure : ModelStructure or str
        The structure, or a built-in name / structure file.
    options : IdentifyOptions, optional
        Choices.
    files : sequence of str or Path, optional
        Files the flights came from, hashed into the provenance.
    progress : callable, optional
        ``progress(stage, done, total)`` as the work advances.

    Returns
    -------
    IdentifiedModel

    Raises
    ------
    FitError
        If there is no flight, or no sweep gives a response that passes gating; naming the files. Unless
        ``options.partial``, also if an axis of the structure has no usable response: one sentence per axis
        says why and what to do (:func:`sysid.fit.axes.unidentified_message`).
    ModelError
        If ``options.constants`` names a constant the structure has no trim constant for.

    Notes
    -----
    The model's ``notes`` say what each axis's responses were computed
    against, which responses gating dropped and why, whether the wind
    parameters were left out; then the message of each project warning
    raised during the identification, which also goes on to the caller.
    """
    with collected_warnings() as caught:
        model = _identified(flights, structure, options, files, progress, superseded=caught.discard)
    return dataclasses.replace(model, notes=model.notes + caught.messages)


def _identified(
    flights: Sequence[ConditionedFlight],
    structure: ModelStructure | str,
    options: IdentifyOptions,
    files: Sequence[str | Path],
    progress: Progress | None,
    *,
    timed: tuple[WindClockOffset, list[str]] | None = None,
    superseded: Callable[[], None] | None = None,
) -> IdentifiedModel:
    """The identification; `timed` is the clock offset scanned and applied to the flights by an earlier pass.

    When the offset is to be measured, it is scanned on a fit of the wind axes alone first
    (:func:`_scouted_wind`); when it moves the wind, the identification is run again on the moved flights,
    the other axes' responses never computed on the unmoved ones, and `superseded` is called first: the first
    pass's warnings are said again by the second where they still hold.
    """
    if isinstance(structure, str):
        structure = load_structure(structure)
    structure.check_constants(options.constants or {})
    used = {axis: records for axis in _AXES if (records := maneuver_records(flights, axis, kind=options.kind))}
    flown = list(used)

    def axis_responses(k: int) -> tuple[tuple[FrequencyResponse, ...], str | None]:
        band = maneuver_band(flights, flown[k], kind=options.kind)
        return _axis_responses(structure, used[flown[k]], flown[k], options, band, quiet_records(flights, flown[k]))

    computed: dict[str, tuple[tuple[FrequencyResponse, ...], str | None]] = {}

    def compute(wanted: Sequence[str]) -> None:
        todo = [k for k, axis in enumerate(flown) if axis in wanted and axis not in computed]
        for k, found in zip(todo, map_forked(lambda j: axis_responses(todo[j]), len(todo))):  # the axes on the cores
            _report(progress, f"responses {flown[k]}", len(computed) + 1, len(_AXES) + 2)
            computed[flown[k]] = found

    trim = _mean_trim([r for records in used.values() for r in records])
    constants = structure.constants_from_trim(trim) | dict(options.constants or {})
    _report(progress, "responses", 0, len(_AXES) + 2)
    scouted = None
    if timed is None and _measures_clock(structure, flights, used, options):
        compute(options.wind_axes)
        scouted = _scouted_wind(structure, flights, used, computed, constants, options)
        clock = scouted[1] if scouted is not None else None
        if scouted is not None and clock is not None and clock.measured and _moves(clock, flights):
            if superseded is not None:  # step 1 on the moved flights, u v w in time
                superseded()
            moved = moved_flights(flights, clock.best_shift_s)
            return _identified(moved, structure, options, files, progress, timed=(clock, scouted[2]))
    compute(flown)
    responses = [r for axis in flown for r in computed[axis][0]]
    notes = [note for axis in flown if (note := computed[axis][1]) is not None]
    gated = _gated(structure, responses, used, constants, options)
    axes = structure_axes(structure, flights, used, responses, gated, kind=options.kind, gating=options.gating)
    if flights and any(not a.identified for a in axes) and not (options.partial and gated.kept):
        raise FitError(unidentified_message(axes, model=structure.name, partial=options.partial))
    if not responses:
        given = ", ".join(Path(f).name for f in files) or "the data given"
        if not flights:
            raise FitError(f"{given}: no flight to fit the model {structure.name} to")
        names = ", ".join(f.source.name for f in flights)
        raise FitError(
            f"{given}: no {options.kind} in flight {names} gives a response the model {structure.name} can be fitted to"
        )
    notes += [d.reason for d in gated.dropped]
    if not gated.kept:
        raise FitError("no frequency response passed gating: " + " ".join(d.reason for d in gated.dropped))
    _report(progress, "fitting F, G_u", len(_AXES), len(_AXES) + 2)
    fit = fit_frequency_responses(
        structure, gated.kept, constants=constants, initial=options.initial, options=options.fit
    )
    fit = dataclasses.replace(fit, axes=merge_axes(axes, fit.axes))
    if fit.unidentified_axes:
        if not options.partial:
            raise FitError(unidentified_message(fit.axes, model=structure.name))
        warnings.warn(FitWarning(partial_warning(fit.axes, model=structure.name)), stacklevel=2)
    wind = None
    if structure.wind_parameters:
        _report(progress, "wind step", len(_AXES) + 1, len(_AXES) + 2)
        records = _wind_records(used, options)
        if _carry_wind(structure, records):
            if scouted is not None:
                records, clock, said = scouted
            elif timed is None:
                records, clock, said = timed_wind(
                    structure, fit.values, constants, records, flights, options.wind_outputs
                )
                if clock is not None and clock.measured and _moves(clock, flights):  # step 1 again, u v w in time
                    moved = moved_flights(flights, clock.best_shift_s)
                    if superseded is not None:
                        superseded()
                    return _identified(moved, structure, options, files, progress, timed=(clock, said))
            else:
                (clock, said), records = timed, moved_wind(records, flights, 0.0)  # smoothed as in the first pass
            notes += said
            untimed = untimed_wind(clock)
            if untimed:
                wind = unfitted_wind(structure, untimed)
            else:
                with sharing_delayed_winds():  # its fits scan the same delays of the same records' wind
                    wind = _wind_step(structure, fit, constants, records, options)
            if wind.fit is not None:
                identified = dict(fit.values) | dict(wind.speed_values) | dict(wind.values)
                trace = wind_trace(structure, identified, constants, records, flights)
                wind = dataclasses.replace(wind, fit=dataclasses.replace(wind.fit, clock_offset=clock, trace=trace))
        else:
            notes.append(
                f"no record carries {', '.join(sorted({c.signal for c in structure.wind_inputs}))}: wind parameters "
                "left out (give `wind_paths`)"
            )
    _report(progress, "done", len(_AXES) + 2, len(_AXES) + 2)
    maneuvers = sorted({f"{s.kind} {s.axis} {s.source}" for f in flights for s in f.segments if s.kind == options.kind})
    provenance = dataclasses.replace(_provenance(files, options), maneuvers=tuple(maneuvers))
    return model_from_fit(fit, wind, trim=trim, provenance=provenance, notes=notes)


def _wind_step(
    structure: ModelStructure,
    fit: FrequencyFit,
    constants: Mapping[str, float],
    records: Sequence[Record],
    options: IdentifyOptions,
) -> WindStepResult:
    """G_w at the speed derivatives estimated again with it; the bounds carry step 1's uncertainty and theirs.

    A speed derivative the joint solution cannot measure (its I% and its CR%
    both beyond the guidelines, from the solution's own information: Z_w
    where the thrust loop holds w, CR 100-118 % on the generator's flights)
    is dropped, as step 1's reduction would (unless reduction is off), and
    the rest solved again without it.
    """
    estimated = [n for n, status in fit.status.items() if status == "estimated"]
    values, dropped = dict(fit.values), []
    while True:
        speed, speed_accuracy = speed_derivatives(
            structure, values, constants, records, estimated, outputs=options.wind_outputs
        )
        step = (
            _unmeasured(structure, speed, speed_accuracy, options.fit.guidelines, fit) if options.fit.reduce else None
        )
        if step is None:
            break
        dropped.append(step)
        values[step.parameter], estimated = step.value, [n for n in estimated if n != step.parameter]

    def fitted(speeds: Mapping[str, float]) -> WindStepResult:
        return fit_wind(
            structure,
            values | dict(speeds),
            constants,
            records,
            outputs=options.wind_outputs,
            reduce=options.fit.reduce,
            guidelines=options.fit.guidelines,
        )

    wind = fitted(speed)
    delays = {n: v for n, v in wind.values.items() if n in structure.wind_parameters and math.isfinite(v)}
    spread = step_one_spread(
        structure, values, constants, records, estimated, fit.accuracy, delays=delays, outputs=options.wind_outputs
    )
    speed_accuracy = with_spread(speed_accuracy, spread)
    at_speeds = speed_spread(wind, speed, speed_accuracy, fitted)
    return dataclasses.replace(
        wind,
        accuracy=with_spread(with_spread(wind.accuracy, spread), at_speeds),
        reduction=(*dropped, *wind.reduction),
        speed_values=speed | {s.parameter: s.value for s in dropped},
        speed_accuracy=speed_accuracy if speed else None,
        speed_dropped=tuple(s.parameter for s in dropped),
    )


def _unmeasured(
    structure: ModelStructure,
    speed: Mapping[str, float],
    speed_accuracy: Accuracy,
    guidelines: Guidelines,
    fit: FrequencyFit,
) -> ReductionStep | None:
    """The speed derivative of the joint solution furthest beyond both guidelines (I% and CR%), or None."""
    worst, worst_ins = None, 0.0
    for k, name in enumerate(speed_accuracy.names):
        ins, cr = float(speed_accuracy.insensitivity_percent[k]), float(speed_accuracy.cramer_rao_percent[k])
        if name in speed and ins > guidelines.max_insensitivity_percent and cr > guidelines.max_cr_percent:
            if ins > worst_ins:
                worst, worst_ins = (name, speed[name], cr, ins), ins
    if worst is None:
        return None
    name, estimate, cr, ins = worst
    return ReductionStep(
        step=0,
        parameter=name,
        action="dropped",
        value=structure.parameter(name).drop_value,
        estimate=estimate,
        cr_percent=cr,
        insensitivity_percent=ins,
        reason=(
            f"I% = {ins:.3g} > {guidelines.max_insensitivity_percent:g} and CR% = {cr:.3g} > "
            f"{guidelines.max_cr_percent:g} when estimated again with G_w (wind step)"
        ),
        cost_average=fit.cost.average,
        cost_average_after=fit.cost.average,
    )


def _gated(
    structure: ModelStructure,
    responses: Sequence[FrequencyResponse],
    used: Mapping[str, Sequence[Record]],
    constants: Mapping[str, float],
    options: IdentifyOptions,
) -> GatingResult:
    """The responses gating keeps, less those the structure reaches only through trims too small to carry them
    (:mod:`sysid.fit.trim_paths`), those added to the dropped."""
    gated = gate_responses(responses, options.gating)
    unfit = trim_only_responses(structure, gated.kept, structure.values(options.initial), constants, _swings(used))
    if unfit:
        left = {(d.input, d.output) for d in unfit}
        kept = tuple(r for r in gated.kept if (r.input, r.output) not in left)
        gated = dataclasses.replace(gated, kept=kept, dropped=(*gated.dropped, *unfit))
    return gated


def _measures_clock(
    structure: ModelStructure,
    flights: Sequence[ConditionedFlight],
    used: Mapping[str, Sequence[Record]],
    options: IdentifyOptions,
) -> bool:
    """Whether the anemometer's clock is to be measured (its offset not given) from wind-axis records that carry
    the wind: then it is scanned on a fit of the wind axes alone (:func:`_scouted_wind`) before the other axes'
    responses are computed, which a clock that moves the wind would only have to compute again."""
    records = _wind_records(used, options)
    return bool(structure.wind_parameters) and not offset_given(flights) and _carry_wind(structure, records)


def _wind_records(used: Mapping[str, Sequence[Record]], options: IdentifyOptions) -> list[Record]:
    """The wind step's records: the maneuvers of its axes (``options.wind_axes``)."""
    return [r for axis in options.wind_axes for r in used.get(axis, [])]


def _carry_wind(structure: ModelStructure, records: Sequence[Record]) -> bool:
    """Whether any of `records` carries every wind signal the structure's G_w reads."""
    signals = {c.signal for c in structure.wind_inputs}
    return any(signals <= set(r.signals) for r in records)


def _scouted_wind(
    structure: ModelStructure,
    flights: Sequence[ConditionedFlight],
    used: Mapping[str, Sequence[Record]],
    computed: Mapping[str, tuple[tuple[FrequencyResponse, ...], str | None]],
    constants: Mapping[str, float],
    options: IdentifyOptions,
) -> tuple[list[Record], WindClockOffset | None, list[str]] | None:
    """:func:`~sysid.fit.wind_offset.timed_wind` on F and G_u fitted to the wind axes' responses alone.

    The residual of eq. 3.14 on the wind outputs (a_x, a_z) reads only the wind axes' parameters, so the
    other axes' responses are not needed to time the wind. None when those responses cannot be fitted (the
    whole identification then says why); the fit's warnings are the whole identification's to say, the
    scan's are said here.
    """
    responses = [r for axis in options.wind_axes if axis in computed for r in computed[axis][0]]
    records = _wind_records(used, options)
    with warnings.catch_warnings():  # said by the fit of every axis, or by the one on the moved flights
        warnings.simplefilter("ignore", SysidWarning)
        gated = _gated(structure, responses, used, constants, options)
        if not gated.kept:
            return None
        try:
            fit = fit_frequency_responses(
                structure, gated.kept, constants=constants, initial=options.initial, options=options.fit
            )
        except FitError:
            return None
    return timed_wind(structure, fit.values, constants, records, flights, options.wind_outputs)


def _moves(clock: WindClockOffset, flights: Sequence[ConditionedFlight]) -> bool:
    """Whether the offset measured is applied and moves the wind by more than its own uncertainty."""
    return not offset_given(flights) and abs(clock.best_shift_s) > max(2 * clock.sigma_s, 0.02)


def identify_logs(
    log_paths: Sequence[str | Path],
    structure: ModelStructure | str,
    *,
    wind_paths: Sequence[str | Path] = (),
    conditioning: ConditioningOptions = ConditioningOptions(),
    options: IdentifyOptions = IdentifyOptions(),
    progress: Progress | None = None,
    reading: ReadOptions = ReadOptions(),
) -> IdentifiedModel:
    """Read, condition and identify: ``sysid fit LOGS... --wind CSV``.

    Parameters
    ----------
    log_paths : sequence of str or Path
        Flight logs with sweeps (any supported format), or the HDF5 datasets an ingest wrote of them.
    structure : ModelStructure or str
        The structure, or a built-in name / structure file.
    wind_paths : sequence of str or Path, optional
        Anemometer CSV files or folders.
    conditioning : ConditioningOptions, optional
        Wind alignment and resampling choices.
    options : IdentifyOptions, optional
        Identification choices.
    progress : callable, optional
        ``progress(stage, done, total)``.
    reading : ReadOptions, optional
        How tables among `log_paths` are read, and whether a log of another vehicle is refused.

    Returns
    -------
    IdentifiedModel

    Raises
    ------
    LogFormatError, DataError
        On logs or wind files that cannot be used.
    FitError
        If nothing can be fitted.
    """
    from flightlogs.store.campaign import expand_wind_paths
    from flightlogs.store.sources import conditioned_sources

    def read(name: str, done: int, total: int) -> None:
        _report(progress, f"reading {name}", done, total)

    unreported = dataclasses.replace(conditioning, residual_offset=False)  # no flight's alignment is returned
    flights = conditioned_sources(log_paths, wind_paths, options=unreported, progress=read, reading=reading)
    winds = expand_wind_paths([Path(p) for p in wind_paths])
    return identify_flights(flights, structure, options=options, files=[*log_paths, *winds], progress=progress)


def _swings(used: Mapping[str, Sequence[Record]]) -> dict[str, dict[str, float]]:
    """By mixer input, the RMS swing of u, v, w (m/s), phi and theta (rad) about each record's mean over that axis'
    records."""
    swings: dict[str, dict[str, float]] = {}
    for axis, records in used.items():
        swings[f"delta_{axis}"] = {
            name: float(np.sqrt(np.mean(np.concatenate([(r[name] - np.mean(r[name])) ** 2 for r in records]))))
            for name in ("u", "v", "w", "phi", "theta")
            if records and all(name in r.signals for r in records)
        }
    return swings


def _mean_trim(records: Sequence[Record]) -> dict[str, float]:
    names = dict.fromkeys(name for r in records for name in r.trim)
    return {name: float(np.mean([r.trim[name] for r in records if name in r.trim])) for name in names}


def _provenance(files: Sequence[str | Path], options: IdentifyOptions) -> Provenance:
    from importlib.metadata import PackageNotFoundError, version

    versions = {}
    for package in ("flight-sysid", "numpy", "scipy", "control"):
        try:
            versions[package] = version(package)
        except PackageNotFoundError:
            versions[package] = "unknown"
    paths = [str(p) for p in files]
    return Provenance(
        files=tuple(paths),
        sha256={p: file_sha256(p) for p in paths},
        options=jsonable(options, default=str),
        versions=versions,
        created_utc=datetime.now(UTC).isoformat(timespec="seconds"),
    )


def model_from_fit(
    fit: FrequencyFit,
    wind: WindStepResult | None = None,
    *,
    trim: Mapping[str, float] | None = None,
    provenance: Provenance = Provenance(),
    notes: Sequence[str] = (),
) -> IdentifiedModel:
    """Assemble an :class:`IdentifiedModel` from the two steps' results.

    Parameters
    ----------
    fit : FrequencyFit
        Step 1 (F, G_u).
    wind : WindStepResult or None, optional
        Step 2 (G_w, wind delays); None leaves the wind parameters out (set
        to their drop values, logged as a reduction step).
    trim : Mapping[str, float], optional
        Trim of the flights.
    provenance : Provenance, optional
        Files, options, versions.
    notes : sequence of str, optional
        Remarks (responses dropped by gating ...).

    Returns
    -------
    IdentifiedModel
    """
    structure = fit.structure
    units = {r.input: r.input_unit for r in fit.responses if r.input_unit}
    estimates = []
    reduction = list(fit.reduction) + (list(wind.reduction) if wind is not None else [])
    cr = dict(zip(fit.accuracy.names, fit.accuracy.cramer_rao_percent.tolist()))
    ins = dict(zip(fit.accuracy.names, fit.accuracy.insensitivity_percent.tolist()))
    if wind is not None:
        for again in (wind.accuracy, wind.speed_accuracy):
            if again is not None:
                kept = [k for k, n in enumerate(again.names) if n in wind.speed_values or again is wind.accuracy]
                cr |= {again.names[k]: float(again.cramer_rao_percent[k]) for k in kept}
                ins |= {again.names[k]: float(again.insensitivity_percent[k]) for k in kept}
    for p in structure.parameters:
        stage: Literal["frequency", "wind"]
        unit = p.unit
        for signal, text in units.items():
            unit = unit.replace("{" + signal + "}", text)
        unit = unit.replace("{", "unit of ").replace("}", "")  # an input with no response: its unit is not known
        if wind is not None and p.name in wind.speed_values:  # estimated again with G_w
            status = "dropped" if p.name in wind.speed_dropped else fit.status[p.name]
            value, stage = wind.speed_values[p.name], "wind"
        elif p.name in fit.status:
            status, value, stage = fit.status[p.name], fit.values[p.name], "frequency"
        elif wind is not None:
            status, value, stage = wind.status[p.name], wind.values[p.name], "wind"
        else:
            status, value, stage = "dropped", p.drop_value, "wind"
            reduction.append(
                ReductionStep(
                    step=len(reduction) + 1,
                    parameter=p.name,
                    action="dropped",
                    value=value,
                    estimate=math.nan,
                    cr_percent=math.nan,
                    insensitivity_percent=math.nan,
                    reason="no wind record to fit it",
                    cost_average=fit.cost.average,
                    cost_average_after=fit.cost.average,
                )
            )
        estimated = status == "estimated"
        estimates.append(
            ParameterEstimate(
                name=p.name,
                value=float(value),
                cr_percent=cr[p.name] if estimated else math.nan,
                insensitivity_percent=ins[p.name] if estimated else math.nan,
                status=status,
                unit=unit,
                stage=stage,
            )
        )
    reduction = [dataclasses.replace(step, step=k + 1) for k, step in enumerate(reduction)]
    names = fit.accuracy.names + (wind.accuracy.names if wind is not None else ())
    blocks = [fit.accuracy.correlation] + ([wind.accuracy.correlation] if wind is not None else [])
    correlation = linalg.block_diag(*blocks) if names else np.zeros((0, 0))
    return IdentifiedModel(
        structure_name=structure.name,
        structure_text=structure.text,
        parameters=tuple(estimates),
        correlation_names=names,
        correlation=correlation.reshape(len(names), len(names)),
        cost=fit.cost,
        responses=fit.responses,
        trim=MappingProxyType(dict(trim or {})),
        constants=fit.constants,
        reduction=tuple(reduction),
        provenance=provenance,
        wind=None if wind is None else wind.fit,
        input_units=units,
        notes=tuple(notes),
        axes=fit.axes,
    )
