"""Identified models on disk: versioned JSON (read and write) and MATLAB ``.mat`` (write).

The JSON holds everything :class:`IdentifiedModel` holds, so that a report can
be rebuilt from the file alone, plus the matrices and eigenvalues for readers
outside Python. NaN is written as ``null``. Files are written atomically.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from scipy import io as sio

from flightlogs.atomic import atomic_output
from flightlogs.errors import ModelError

from .._json import finite_or_none as _num
from .._json import float_array as _vector
from .._json import float_or_nan as _float
from .._json import json_floats as _array
from .._json import read_json_object, write_json
from ..freqresp import FrequencyResponse
from ._json import parameter_entry
from .cost import CostSummary
from .reduce import ReductionStep
from .result import IdentifiedModel, ParameterEstimate, Provenance, WindFit

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
    from ..modes import modes

    linear = model.linear_model()
    return {
        "schema": SCHEMA, "schema_version": SCHEMA_VERSION,
        "structure": {"name": model.structure_name, "text": model.structure_text},
        "parameters": {p.name: parameter_entry(p) | {"value": _num(p.value)} for p in model.parameters},
        "correlation": {"names": list(model.correlation_names), "matrix": _array(model.correlation)},
        "cost": {"average": _num(model.cost.average), "responses": {k: _num(v) for k, v in model.cost.responses.items()}},
        "trim": {k: _num(v) for k, v in model.trim.items()},
        "constants": {k: _num(v) for k, v in model.constants.items()},
        "input_units": dict(model.input_units),
        "notes": list(model.notes),
        "reduction": [{"step": s.step, "parameter": s.parameter, "action": s.action, "value": _num(s.value),
                       "estimate": _num(s.estimate), "cr_percent": _num(s.cr_percent),
                       "insensitivity_percent": _num(s.insensitivity_percent), "reason": s.reason,
                       "cost_average": _num(s.cost_average), "cost_average_after": _num(s.cost_average_after)}
                      for s in model.reduction],
        "wind": None if model.wind is None else {
            "outputs": list(model.wind.outputs), "rms_before": [_num(v) for v in model.wind.rms_before],
            "rms_after": [_num(v) for v in model.wind.rms_after], "samples": model.wind.samples},
        "provenance": {"files": list(model.provenance.files), "sha256": dict(model.provenance.sha256),
                       "options": dict(model.provenance.options), "versions": dict(model.provenance.versions),
                       "created_utc": model.provenance.created_utc},
        "linear_model": {"states": list(linear.states), "inputs": list(linear.inputs), "outputs": list(linear.outputs),
                         "a": _array(linear.a), "b": _array(linear.b), "c": _array(linear.c), "d": _array(linear.d),
                         "input_delays_s": _array(linear.input_delays_s)},
        "eigenvalues": [{"real": m.real, "imag": m.imag, "mode": m.mode} for m in modes(linear)],
        "responses": [_response_to_dict(r) for r in model.responses],
    }


def _response_to_dict(r: FrequencyResponse) -> dict[str, Any]:
    return {"input": r.input, "output": r.output, "omega": _array(r.omega),
            "response_real": _array(r.response.real), "response_imag": _array(r.response.imag),
            "coherence": _array(r.coherence), "random_error": _array(r.random_error),
            "input_autospectrum": _array(r.input_autospectrum), "output_autospectrum": _array(r.output_autospectrum),
            "cross_spectrum_real": _array(r.cross_spectrum.real), "cross_spectrum_imag": _array(r.cross_spectrum.imag),
            "windows_s": list(r.windows_s), "conditioned_on": list(r.conditioned_on), "input_unit": r.input_unit,
            "output_unit": r.output_unit, "fit_range": None if r.fit_range is None else list(r.fit_range),
            "reference": r.reference, "whole_record": r.whole_record}


def _response_from_dict(d: Mapping[str, Any]) -> FrequencyResponse:
    fit_range = d.get("fit_range")
    return FrequencyResponse(
        d["input"], d["output"], _vector(d["omega"]), _vector(d["response_real"]) + 1j * _vector(d["response_imag"]),
        _vector(d["coherence"]), _vector(d["random_error"]), _vector(d["input_autospectrum"]),
        _vector(d["output_autospectrum"]), _vector(d["cross_spectrum_real"]) + 1j * _vector(d["cross_spectrum_imag"]),
        tuple(float(v) for v in d["windows_s"]), tuple(d.get("conditioned_on", ())), d.get("input_unit", ""),
        d.get("output_unit", ""), None if fit_range is None else (float(fit_range[0]), float(fit_range[1])),
        reference=d.get("reference"), whole_record=bool(d.get("whole_record", False)))


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
        If the document is not an identified model of a known schema version.
    """
    if doc.get("schema") != SCHEMA:
        raise ModelError(f"{source}: not a flight-sysid model file (schema {doc.get('schema')!r})")
    if doc.get("schema_version") != SCHEMA_VERSION:
        raise ModelError(f"{source}: model schema version {doc.get('schema_version')!r} is not supported "
                         f"(this version reads {SCHEMA_VERSION})")
    try:
        parameters = tuple(ParameterEstimate(name, _float(p["value"]), _float(p["cr_percent"]),
                                             _float(p["insensitivity_percent"]), p["status"], p.get("unit", ""),
                                             p.get("stage", "frequency")) for name, p in doc["parameters"].items())
        names = tuple(doc["correlation"]["names"])
        matrix = np.array([[_float(v) for v in row] for row in doc["correlation"]["matrix"]]).reshape(len(names),
                                                                                                      len(names))
        reduction = tuple(ReductionStep(s["step"], s["parameter"], s["action"], _float(s["value"]),
                                        _float(s["estimate"]), _float(s["cr_percent"]),
                                        _float(s["insensitivity_percent"]), s["reason"], _float(s["cost_average"]),
                                        _float(s["cost_average_after"])) for s in doc["reduction"])
        wind = doc.get("wind")
        prov = doc.get("provenance", {})
        return IdentifiedModel(
            doc["structure"]["name"], doc["structure"]["text"], parameters, names, matrix,
            CostSummary(_float(doc["cost"]["average"]), {k: _float(v) for k, v in doc["cost"]["responses"].items()}),
            tuple(_response_from_dict(r) for r in doc.get("responses", [])),
            {k: _float(v) for k, v in doc.get("trim", {}).items()},
            {k: _float(v) for k, v in doc.get("constants", {}).items()}, reduction,
            Provenance(tuple(prov.get("files", ())), prov.get("sha256", {}), prov.get("options", {}),
                       prov.get("versions", {}), prov.get("created_utc", "")),
            None if wind is None else WindFit(tuple(wind["outputs"]), tuple(_float(v) for v in wind["rms_before"]),
                                              tuple(_float(v) for v in wind["rms_after"]), int(wind["samples"])),
            dict(doc.get("input_units", {})), tuple(doc.get("notes", ())),
        )
    except (KeyError, TypeError, ValueError) as err:
        raise ModelError(f"{source}: model file is incomplete or damaged ({type(err).__name__}: {err})") from None


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
    """
    linear = model.linear_model()
    cell = lambda names: np.array(list(names), dtype=object)  # noqa: E731 - MATLAB cell array of strings
    content = {
        "A": linear.a, "B": linear.b, "C": linear.c, "D": linear.d,
        "states": cell(linear.states), "inputs": cell(linear.inputs), "outputs": cell(linear.outputs),
        "input_delays_s": linear.input_delays_s,
        "parameter_names": cell(p.name for p in model.parameters),
        "parameter_values": np.array([p.value for p in model.parameters]),
        "cr_percent": np.array([p.cr_percent for p in model.parameters]),
        "insensitivity_percent": np.array([p.insensitivity_percent for p in model.parameters]),
        "parameter_status": cell(p.status for p in model.parameters),
        "cost_average": model.cost.average, "structure": model.structure_text,
    }
    with atomic_output(path) as tmp:
        sio.savemat(tmp, content, appendmat=False, oned_as="column")
    return Path(path)
