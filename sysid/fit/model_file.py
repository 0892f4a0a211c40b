"""Identified models on disk: versioned JSON (read and write) and MATLAB ``.mat`` (write).

The JSON holds everything :class:`IdentifiedModel` holds, so that a report can
be rebuilt from the file alone, plus the matrices and eigenvalues for readers
outside Python. NaN is written as ``null`` (the value of an unidentified
parameter). ``axes`` records each control input's axis, identified or not
and why; a file without it reads with the axes derived from the parameters
(:attr:`IdentifiedModel.axis_status`). ``linear_model`` and ``eigenvalues``
are those of the identified axes. Files are written atomically.
The guideline limits a fit applied travel in its provenance options
(``provenance.options.fit.max_cr_percent``); a file without them reads with
Tischler's (:attr:`IdentifiedModel.guidelines`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from flightlogs.errors import ModelError
from flightlogs.writers.atomic import atomic_output
from sysid._json import DocumentFields as _Fields
from sysid._json import finite_or_none as _num
from sysid._json import json_floats as _array
from sysid._json import read_json_object, write_json
from sysid._json import value_text as _show
from sysid.fit._json import axis_entry, parameter_entry
from sysid.fit.axes import AxisStatus
from sysid.fit.cost import CostSummary
from sysid.fit.guidelines import Guidelines
from sysid.fit.reduce import ReductionStep
from sysid.fit.result import (
    PARAMETER_STATUSES,
    IdentifiedModel,
    ParameterEstimate,
    Provenance,
    WindClockOffset,
    WindFit,
    WindTrace,
)
from sysid.freqresp import FrequencyResponse

__all__ = ["SCHEMA", "SCHEMA_VERSION", "model_to_dict", "model_from_dict", "write_model", "read_model", "write_mat"]

SCHEMA = "flight-sysid/identified-model"
SCHEMA_VERSION = 1


def model_to_dict(model: IdentifiedModel) -> dict[str, Any]:
    """The JSON document of a model (schema ``flight-sysid/identified-model`` version 1).

    Parameters
    ----------
    model : IdentifiedModel
        The model.

    Returns
    -------
    dict
        JSON-compatible (NaN as None).
    """
    from sysid.model.modes import modes

    linear = model.linear_model()
    return {
        "schema": SCHEMA,
        "schema_version": SCHEMA_VERSION,
        "structure": {"name": model.structure_name, "text": model.structure_text},
        "parameters": {p.name: parameter_entry(p) | {"value": _num(p.value)} for p in model.parameters},
        "correlation": {"names": list(model.correlation_names), "matrix": _array(model.correlation)},
        "cost": {
            "average": _num(model.cost.average),
            "responses": {k: _num(v) for k, v in model.cost.responses.items()},
        },
        "trim": {k: _num(v) for k, v in model.trim.items()},
        "constants": {k: _num(v) for k, v in model.constants.items()},
        "input_units": dict(model.input_units),
        "notes": list(model.notes),
        "axes": [axis_entry(a) for a in model.axis_status],
        "reduction": [
            {
                "step": s.step,
                "parameter": s.parameter,
                "action": s.action,
                "value": _num(s.value),
                "estimate": _num(s.estimate),
                "cr_percent": _num(s.cr_percent),
                "insensitivity_percent": _num(s.insensitivity_percent),
                "reason": s.reason,
                "cost_average": _num(s.cost_average),
                "cost_average_after": _num(s.cost_average_after),
                "cost_responses": {k: _num(v) for k, v in s.cost_responses.items()},
                "cost_responses_after": {k: _num(v) for k, v in s.cost_responses_after.items()},
            }
            for s in model.reduction
        ],
        "wind": None
        if model.wind is None
        else {
            "outputs": list(model.wind.outputs),
            "rms_before": [_num(v) for v in model.wind.rms_before],
            "rms_after": [_num(v) for v in model.wind.rms_after],
            "samples": model.wind.samples,
            "clock_offset": _clock_offset_doc(model.wind.clock_offset),
            "trace": _trace_doc(model.wind.trace),
        },
        "provenance": {
            "files": list(model.provenance.files),
            "sha256": dict(model.provenance.sha256),
            "options": dict(model.provenance.options),
            "versions": dict(model.provenance.versions),
            "created_utc": model.provenance.created_utc,
            "maneuvers": list(model.provenance.maneuvers),
        },
        "linear_model": {
            "states": list(linear.states),
            "inputs": list(linear.inputs),
            "outputs": list(linear.outputs),
            "a": _array(linear.a),
            "b": _array(linear.b),
            "c": _array(linear.c),
            "d": _array(linear.d),
            "input_delays_s": _array(linear.input_delays_s),
        },
        "eigenvalues": [{"real": m.real, "imag": m.imag, "mode": m.mode} for m in modes(linear)],
        "responses": [_response_to_dict(r) for r in model.responses],
    }


def _response_to_dict(r: FrequencyResponse) -> dict[str, Any]:
    return {
        "input": r.input,
        "output": r.output,
        "omega": _array(r.omega),
        "response_real": _array(r.response.real),
        "response_imag": _array(r.response.imag),
        "coherence": _array(r.coherence),
        "random_error": _array(r.random_error),
        "input_autospectrum": _array(r.input_autospectrum),
        "output_autospectrum": _array(r.output_autospectrum),
        "cross_spectrum_real": _array(r.cross_spectrum.real),
        "cross_spectrum_imag": _array(r.cross_spectrum.imag),
        "windows_s": list(r.windows_s),
        "conditioned_on": list(r.conditioned_on),
        "input_unit": r.input_unit,
        "output_unit": r.output_unit,
        "fit_range": None if r.fit_range is None else list(r.fit_range),
        "reference": r.reference,
        "whole_record": r.whole_record,
    }


def _response_from_dict(d: Mapping[str, Any], f: _Fields, where: str) -> FrequencyResponse:
    d = f.check(d, where, dict)
    fit_range = f.get(d, "fit_range", where, object, None)
    if fit_range is not None:
        fit_range = f.numbers(d, "fit_range", where, finite=True)
        if fit_range.size != 2:
            raise f.fail(f"{where}: fit_range must hold two numbers")
    windows = f.numbers(d, "windows_s", where, finite=True)
    try:
        return FrequencyResponse(
            input=f.get(d, "input", where, str),
            output=f.get(d, "output", where, str),
            omega=f.numbers(d, "omega", where),
            response=f.numbers(d, "response_real", where) + 1j * f.numbers(d, "response_imag", where),
            coherence=f.numbers(d, "coherence", where),
            random_error=f.numbers(d, "random_error", where),
            input_autospectrum=f.numbers(d, "input_autospectrum", where),
            output_autospectrum=f.numbers(d, "output_autospectrum", where),
            cross_spectrum=f.numbers(d, "cross_spectrum_real", where) + 1j * f.numbers(d, "cross_spectrum_imag", where),
            windows_s=tuple(float(v) for v in windows),
            conditioned_on=tuple(f.get(d, "conditioned_on", where, list, [])),
            input_unit=f.get(d, "input_unit", where, str, ""),
            output_unit=f.get(d, "output_unit", where, str, ""),
            fit_range=None if fit_range is None else (float(fit_range[0]), float(fit_range[1])),
            reference=f.get(d, "reference", where, object, None),
            whole_record=bool(f.get(d, "whole_record", where, bool, False)),
        )
    except (TypeError, ValueError) as err:
        raise f.fail(f"{where} is inconsistent: {err}") from None


def _parameters(doc: Mapping[str, Any], f: _Fields) -> tuple[ParameterEstimate, ...]:
    out = []
    for name, p in f.get(doc, "parameters", "the file", dict).items():
        where = f"parameter {name}"
        p = f.check(p, where, dict)
        status, stage = f.get(p, "status", where, str), f.get(p, "stage", where, str, "frequency")
        if status not in PARAMETER_STATUSES:
            raise f.fail(f"{where}: status is {status!r}, not {', '.join(PARAMETER_STATUSES[:-1])} or unidentified")
        value = f.number(p, "value", where, finite=status != "unidentified")
        if status == "unidentified" and math.isfinite(value):
            raise f.fail(f"{where}: an unidentified parameter has no value (null), not {_show(p['value'])}")
        if stage not in ("frequency", "wind"):
            raise f.fail(f"{where}: stage is {stage!r}, not frequency or wind")
        out.append(
            ParameterEstimate(
                name=name,
                value=value,
                cr_percent=f.number(p, "cr_percent", where),
                insensitivity_percent=f.number(p, "insensitivity_percent", where),
                status=status,
                unit=f.get(p, "unit", where, str, ""),
                stage=stage,
            )
        )
    return tuple(out)


def _correlation(doc: Mapping[str, Any], f: _Fields) -> tuple[tuple[str, ...], np.ndarray]:
    section = f.get(doc, "correlation", "the file", dict)
    names = tuple(f.get(section, "names", "correlation", list))
    rows = f.get(section, "matrix", "correlation", list)
    if len(rows) != len(names):
        raise f.fail(f"correlation: matrix has {len(rows)} rows for {len(names)} names")
    matrix = [f.numbers({f"row {k + 1}": row}, f"row {k + 1}", "correlation matrix") for k, row in enumerate(rows)]
    if any(row.size != len(names) for row in matrix):
        raise f.fail(f"correlation: matrix is not {len(names)} by {len(names)}")
    return names, np.array(matrix, dtype=float).reshape(len(names), len(names))


def _reduction(doc: Mapping[str, Any], f: _Fields) -> tuple[ReductionStep, ...]:
    steps = []
    for k, s in enumerate(f.get(doc, "reduction", "the file", list)):
        where = f"reduction step {k + 1}"
        s = f.check(s, where, dict)
        n = {
            key: f.number(s, key, where)
            for key in (
                "value",
                "estimate",
                "cr_percent",
                "insensitivity_percent",
                "cost_average",
                "cost_average_after",
            )
        }
        steps.append(
            ReductionStep(
                step=f.get(s, "step", where, int),
                parameter=f.get(s, "parameter", where, str),
                action=f.get(s, "action", where, str),
                value=n["value"],
                estimate=n["estimate"],
                cr_percent=n["cr_percent"],
                insensitivity_percent=n["insensitivity_percent"],
                reason=f.get(s, "reason", where, str),
                cost_average=n["cost_average"],
                cost_average_after=n["cost_average_after"],
                cost_responses=f.table(s, "cost_responses", where),
                cost_responses_after=f.table(s, "cost_responses_after", where),
            )
        )
    return tuple(steps)


def _axes(doc: Mapping[str, Any], f: _Fields) -> tuple[AxisStatus, ...]:
    """The recorded axis statuses; none in a file written before they were (then derived from the parameters)."""
    out = []
    for k, a in enumerate(f.get(doc, "axes", "the file", list, [])):
        where = f"axis entry {k + 1}"
        a = f.check(a, where, dict)
        status = f.get(a, "status", where, str)
        if status not in ("identified", "unidentified"):
            raise f.fail(f"{where}: status is {status!r}, not identified or unidentified")
        reason = f.get(a, "reason", where, str, "")
        if status == "unidentified" and not reason:
            raise f.fail(f"{where}: an unidentified axis needs a reason")
        out.append(
            AxisStatus(
                axis=f.get(a, "axis", where, str),
                input=f.get(a, "input", where, str),
                status=status,
                reason=reason,
                remedy=f.get(a, "remedy", where, str, ""),
            )
        )
    return tuple(out)


def _wind(doc: Mapping[str, Any], f: _Fields) -> WindFit | None:
    if doc.get("wind") is None:
        return None
    wind = f.get(doc, "wind", "the file", dict)
    outputs = tuple(f.get(wind, "outputs", "wind", list))
    before, after = f.numbers(wind, "rms_before", "wind"), f.numbers(wind, "rms_after", "wind")
    if not len(outputs) == len(before) == len(after):
        raise f.fail("wind: outputs, rms_before and rms_after differ in length")
    return WindFit(
        outputs=outputs,
        rms_before=tuple(float(v) for v in before),
        rms_after=tuple(float(v) for v in after),
        samples=f.get(wind, "samples", "wind", int),
        clock_offset=_clock_offset(wind, f),
        trace=_trace(wind, f),
    )


def _clock_offset_doc(clock: WindClockOffset | None) -> dict[str, Any] | None:
    if clock is None:
        return None
    return {
        "clock_offset_s": _num(clock.clock_offset_s),
        "sigma_s": _num(clock.sigma_s),
        "measured": clock.measured,
        "reason": clock.reason,
        "used_clock_offset_s": _num(clock.used_clock_offset_s),
        "transport_delay_s": _num(clock.transport_delay_s),
        "best_shift_s": _num(clock.best_shift_s),
        "shift_s": [_num(v) for v in clock.shift_s],
        "cost": [_num(v) for v in clock.cost],
        "cost_without_wind": _num(clock.cost_without_wind),
        "samples": clock.samples,
    }


def _clock_offset(wind: Mapping[str, Any], f: _Fields) -> WindClockOffset | None:
    if wind.get("clock_offset") is None:
        return None
    doc, where = f.get(wind, "clock_offset", "wind", dict), "wind.clock_offset"
    shift = f.numbers(doc, "shift_s", where, finite=True)
    return WindClockOffset(
        shift_s=shift,
        cost=f.numbers(doc, "cost", where, size=shift.size),
        cost_without_wind=f.number(doc, "cost_without_wind", where),
        best_shift_s=f.number(doc, "best_shift_s", where),
        sigma_s=f.number(doc, "sigma_s", where),
        used_clock_offset_s=f.number(doc, "used_clock_offset_s", where, finite=True),
        transport_delay_s=f.number(doc, "transport_delay_s", where),
        measured=f.get(doc, "measured", where, bool),
        reason=f.get(doc, "reason", where, str),
        samples=f.get(doc, "samples", where, int),
    )


def _trace_doc(trace: WindTrace | None) -> dict[str, Any] | None:
    if trace is None:
        return None
    return {
        "record": trace.record,
        "output": trace.output,
        "gain": _num(trace.gain),
        "transport_delay_s": _num(trace.transport_delay_s),
        "smoothing_hz": _num(trace.smoothing_hz),
        "time_s": [_num(v) for v in trace.time_s],
        "at_anemometer_m_s": [_num(v) for v in trace.at_anemometer_m_s],
        "at_vehicle_m_s": [_num(v) for v in trace.at_vehicle_m_s],
        "from_accelerations_m_s": [_num(v) for v in trace.from_accelerations_m_s],
    }


def _trace(wind: Mapping[str, Any], f: _Fields) -> WindTrace | None:
    if wind.get("trace") is None:
        return None
    doc, where = f.get(wind, "trace", "wind", dict), "wind.trace"
    time_s = f.numbers(doc, "time_s", where, finite=True)
    return WindTrace(
        record=f.get(doc, "record", where, str),
        time_s=time_s,
        at_anemometer_m_s=f.numbers(doc, "at_anemometer_m_s", where, size=time_s.size),
        at_vehicle_m_s=f.numbers(doc, "at_vehicle_m_s", where, size=time_s.size),
        from_accelerations_m_s=f.numbers(doc, "from_accelerations_m_s", where, size=time_s.size),
        output=f.get(doc, "output", where, str),
        gain=f.number(doc, "gain", where, finite=True),
        transport_delay_s=f.number(doc, "transport_delay_s", where, finite=True),
        smoothing_hz=f.number(doc, "smoothing_hz", where, finite=True),
    )


def model_from_dict(doc: Mapping[str, Any], *, source: str = "<dict>") -> IdentifiedModel:
    """Rebuild a model from its JSON document.

    Parameters
    ----------
    doc : Mapping[str, Any]
        As written by :func:`model_to_dict`.
    source : str, optional
        Where it came from, for error messages.

    Raises
    ------
    ModelError
        If the document is not an identified model of a known schema version, or a field is missing, of the
        wrong type or (for parameter values and trim constants) not finite, or a guideline limit recorded in
        the provenance options is not a positive number; the message names `source` and the field.
    """
    schema = doc.get("schema")
    if schema is None:
        raise ModelError(f"{source}: not a flight-sysid model file (it has no schema field)")
    if schema != SCHEMA:
        raise ModelError(f"{source}: not a flight-sysid model file (it is a {_show(schema)} file, not {SCHEMA!r})")
    if doc.get("schema_version") != SCHEMA_VERSION:
        raise ModelError(
            f"{source}: model schema version {_show(doc.get('schema_version'))} is not supported "
            f"(this version reads {SCHEMA_VERSION})"
        )
    f = _Fields(source)
    head = f.get(doc, "structure", "the file", dict)
    cost = f.get(doc, "cost", "the file", dict)
    prov = f.get(doc, "provenance", "the file", dict, {})
    names, matrix = _correlation(doc, f)
    try:
        model = IdentifiedModel(
            structure_name=f.get(head, "name", "structure", str),
            structure_text=f.get(head, "text", "structure", str),
            parameters=_parameters(doc, f),
            correlation_names=names,
            correlation=matrix,
            cost=CostSummary(average=f.number(cost, "average", "cost"), responses=f.table(cost, "responses", "cost")),
            responses=tuple(
                _response_from_dict(r, f, f"response {k + 1}")
                for k, r in enumerate(f.get(doc, "responses", "the file", list, []))
            ),
            trim=f.table(doc, "trim", "the file"),
            constants=f.table(doc, "constants", "the file", finite=True),
            reduction=_reduction(doc, f),
            provenance=Provenance(
                files=tuple(f.get(prov, "files", "provenance", list, [])),
                sha256=f.get(prov, "sha256", "provenance", dict, {}),
                options=f.get(prov, "options", "provenance", dict, {}),
                versions=f.get(prov, "versions", "provenance", dict, {}),
                created_utc=f.get(prov, "created_utc", "provenance", str, ""),
                maneuvers=tuple(f.get(prov, "maneuvers", "provenance", list, [])),
            ),
            wind=_wind(doc, f),
            input_units=dict(f.get(doc, "input_units", "the file", dict, {})),
            notes=tuple(f.get(doc, "notes", "the file", list, [])),
            axes=_axes(doc, f),
        )
    except (TypeError, ValueError) as err:
        if isinstance(err, ModelError):
            raise
        raise ModelError(f"{source}: model file is inconsistent: {err}") from None
    _check_structure(model, f)
    try:
        Guidelines.from_options(model.provenance.options)
    except ValueError as err:
        raise f.fail(f"provenance: {err}") from None
    return model


def _check_structure(model: IdentifiedModel, f: _Fields) -> None:
    """The structure parses, every parameter it reads has a value and the matrices assemble."""
    try:
        structure = model.structure
    except ModelError as err:
        raise f.fail(f"the structure text does not read: {err}") from None
    have = {p.name for p in model.parameters}
    missing = [n for n in structure.parameter_names if n not in have]
    if missing:
        raise f.fail(f"parameter {', '.join(missing)} of structure {structure.name} is missing")
    extra = sorted(have - set(structure.parameter_names))
    if extra:
        raise f.fail(f"parameter {', '.join(extra)} is not a parameter of structure {structure.name}")
    controls = {c.signal for c in structure.control_inputs}
    stray = [a.input for a in model.axes if a.input not in controls]
    if stray:
        raise f.fail(f"axis input {', '.join(stray)} is not a control input of structure {structure.name}")
    try:
        model.linear_model()
    except ModelError as err:
        raise f.fail(str(err)) from None


def write_model(path: str | Path, model: IdentifiedModel) -> Path:
    """Write a model as versioned JSON, atomically.

    Parameters
    ----------
    path : str or Path
        Destination (``model.json``).
    model : IdentifiedModel
        The model.

    Returns
    -------
    Path
    """
    return write_json(path, model_to_dict(model))


def read_model(path: str | Path) -> IdentifiedModel:
    """Read a model written by :func:`write_model`.

    Parameters
    ----------
    path : str or Path
        A model JSON file.

    Raises
    ------
    ModelError
        If the file cannot be read or is not a model file of a supported version.
    """
    return model_from_dict(read_json_object(path, ModelError, "model"), source=str(path))


def _cell(names: Iterable[str]) -> np.ndarray:
    """Strings as a MATLAB cell array (object array), shape (n,)."""
    return np.array(list(names), dtype=object)


def write_mat(path: str | Path, model: IdentifiedModel) -> Path:
    """Write the identified model for MATLAB (``A B C D``, names, delays, parameters), atomically.

    Parameters
    ----------
    path : str or Path
        Destination ``.mat`` (MATLAB 5 format).
    model : IdentifiedModel
        The model.

    Returns
    -------
    Path

    Notes
    -----
    Variables: ``A B C D`` (with wind inputs), ``states inputs outputs``
    (cell arrays), ``input_delays_s``, ``parameter_names``,
    ``parameter_values``, ``cr_percent``, ``insensitivity_percent``,
    ``parameter_status``, ``cost_average``, ``structure`` (the TOML text).
    An unidentified parameter's value is NaN, and the matrices are those of
    the identified axes (:meth:`IdentifiedModel.linear_model`).
    """
    linear = model.linear_model()
    content = {
        "A": linear.a,
        "B": linear.b,
        "C": linear.c,
        "D": linear.d,
        "states": _cell(linear.states),
        "inputs": _cell(linear.inputs),
        "outputs": _cell(linear.outputs),
        "input_delays_s": linear.input_delays_s,
        "parameter_names": _cell(p.name for p in model.parameters),
        "parameter_values": np.array([p.value for p in model.parameters]),
        "cr_percent": np.array([p.cr_percent for p in model.parameters]),
        "insensitivity_percent": np.array([p.insensitivity_percent for p in model.parameters]),
        "parameter_status": _cell(p.status for p in model.parameters),
        "cost_average": model.cost.average,
        "structure": model.structure_text,
    }
    from scipy import io as sio  # here: a .mat file is rare, and scipy.io takes 35 ms to load

    with atomic_output(path) as tmp:
        sio.savemat(tmp, content, appendmat=False, oned_as="column")
    return Path(path)
