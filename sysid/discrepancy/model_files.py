"""Model files in the simulation's place: the corrected simulation's JSON, and either kind read by its schema.

A corrected simulation (:class:`~.corrected.CorrectedModel`, ``sysid discrepancy --model-out``) is
written as versioned JSON (schema ``flight-sysid/corrected-simulation``); a model from ``sysid fit -o``
keeps its own schema (:mod:`sysid.fit.model_file`). :func:`read_simulation_model` reads either.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from flightlogs.errors import ModelError
from sysid._json import DocumentFields, json_floats, read_json_object, write_json
from sysid._json import value_text as _show
from sysid.discrepancy.baseline import BaselineModel, design_width
from sysid.discrepancy.catalogue import EFFECTS
from sysid.discrepancy.corrected import UNEXPLAINED, CorrectedModel, ModelTerm
from sysid.discrepancy.series import COMMANDS, OUTPUTS
from sysid.model.statespace import DelayedStateSpace

__all__ = [
    "SCHEMA",
    "SCHEMA_VERSION",
    "SimulationModel",
    "corrected_from_dict",
    "corrected_to_dict",
    "read_corrected_model",
    "read_simulation_model",
    "simulation_misfit",
    "write_corrected_model",
]

SCHEMA = "flight-sysid/corrected-simulation"
SCHEMA_VERSION = 1

#: What a model file holds: an identified state-space model, or the search's corrected simulation.
SimulationModel = DelayedStateSpace | CorrectedModel


def read_simulation_model(path: str | Path) -> SimulationModel:
    """The model a JSON file holds, by its schema.

    Parameters
    ----------
    path : str or Path
        A model from ``sysid fit -o`` or a corrected simulation from ``sysid discrepancy --model-out``.

    Raises
    ------
    ModelError
        If the file cannot be read or is neither.
    """
    doc = read_json_object(path, ModelError, "model")
    if doc.get("schema") == SCHEMA:
        return corrected_from_dict(doc, source=str(path))
    from sysid.fit.model_file import model_from_dict  # the fit's package: 0.5 s to import, only for its files

    return model_from_dict(doc, source=str(path)).linear_model(include_wind=False)


def simulation_misfit(path: str | Path) -> str | None:
    """Why a fitted model is no close model of its own flights, or None when it is (or is a corrected simulation).

    A model whose J_ave (eq. 3.9) is beyond an acceptable fit's (Tischler & Remple: 150) misses its own
    responses by more than any physics the search could name: finding nothing along a real flight is then
    no evidence that nothing is missing.

    Parameters
    ----------
    path : str or Path
        A model from ``sysid fit -o`` or a corrected simulation.

    Returns
    -------
    str or None
        One clause, e.g. ``"model.json fits its own responses with J_ave 216, beyond the 150 of an
        acceptable fit"``.

    Raises
    ------
    ModelError
        As :func:`read_simulation_model`.
    """
    from sysid.fit.guidelines import Guidelines

    doc = read_json_object(path, ModelError, "model")
    cost = doc.get("cost")
    average = cost.get("average") if isinstance(cost, dict) else None
    limit = Guidelines().j_average_acceptable
    if doc.get("schema") == SCHEMA or not isinstance(average, (int, float)) or not average > limit:
        return None
    return f"{Path(path).name} fits its own responses with J_ave {average:.0f}, beyond the {limit:.0f} of an acceptable fit"


def corrected_to_dict(model: CorrectedModel) -> dict[str, Any]:
    """The JSON document of a corrected simulation (schema ``flight-sysid/corrected-simulation`` version 1).

    Parameters
    ----------
    model : CorrectedModel
        The model.

    Returns
    -------
    dict
        JSON-compatible.
    """
    b = model.baseline
    return {
        "schema": SCHEMA,
        "schema_version": SCHEMA_VERSION,
        "made_from": list(model.made_from),
        "baseline": {
            "rate_hz": b.rate_hz,
            "lags": [int(k) for k in b.lags],
            "states": list(b.states),
            "squared": list(b.squared),
            "coefficients": {o: json_floats(np.asarray(w)) for o, w in b.coefficients.items()},
        },
        "thrust_trim": model.thrust_trim,
        "terms": [
            {
                "effect": t.effect,
                "value": None if not np.isfinite(t.value) else t.value,
                "coefficients": {o: json_floats(np.asarray(c)) for o, c in t.coefficients.items()},
                **({"regressors": {o: list(k) for o, k in t.regressors.items()}} if t.regressors else {}),
            }
            for t in model.terms
        ],
    }


def corrected_from_dict(doc: Mapping[str, Any], *, source: str = "<dict>") -> CorrectedModel:
    """A corrected simulation from its JSON document, checked field by field.

    Parameters
    ----------
    doc : Mapping
        As written by :func:`corrected_to_dict`.
    source : str, optional
        The file's name, for messages.

    Raises
    ------
    ModelError
        Naming the file and the field, if the document is not a corrected simulation of a supported version.
    """
    read = DocumentFields(source)
    if doc.get("schema") != SCHEMA:
        raise read.fail(f"not a corrected simulation (schema {_show(doc.get('schema'))}, not {SCHEMA!r})")
    if doc.get("schema_version") != SCHEMA_VERSION:
        raise read.fail(f"schema_version {_show(doc.get('schema_version'))} is not {SCHEMA_VERSION}")
    b = read.get(doc, "baseline", "the file", dict)
    lags = read.numbers(b, "lags", "baseline", finite=True)
    states = tuple(read.names(b, "states", "baseline"))
    squared = tuple(read.names(b, "squared", "baseline"))
    if lags.size == 0 or np.any(lags != np.round(lags)) or np.any(np.diff(lags) <= 0) or lags[0] < 0:
        raise read.fail("baseline: lags are not increasing whole samples from 0")
    if unknown := [c for c in squared if c not in COMMANDS]:
        raise read.fail(f"baseline: squared names {unknown[0]!r}, not a mixer input ({', '.join(COMMANDS)})")
    width = design_width(lags, states, squared)
    table = read.get(b, "coefficients", "baseline", dict)
    if sorted(table) != sorted(OUTPUTS):
        raise read.fail(f"baseline: coefficients are for {', '.join(table)}, not {', '.join(OUTPUTS)}")
    coefficients = {o: read.numbers(table, o, "baseline coefficients", finite=True, size=width) for o in OUTPUTS}
    baseline = BaselineModel(
        coefficients=coefficients,
        lags=lags.astype(int),
        states=states,
        rate_hz=read.number(b, "rate_hz", "baseline", finite=True),
        squared=squared,
    )
    terms = []
    for k, t in enumerate(read.get(doc, "terms", "the file", list)):
        where = f"terms[{k}]"
        t = read.check(t, where, dict)
        effect = read.get(t, "effect", where, str)
        if effect != UNEXPLAINED and effect not in EFFECTS:
            raise read.fail(f"{where}: effect {effect!r} is not in the catalogue ({', '.join(EFFECTS)}, unexplained)")
        value = t.get("value")
        if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))):
            raise read.fail(f"{where}: value is {_show(value)}, not a number")
        regressors = {o: tuple(read.names(t.get("regressors", {}), o, where)) for o in t.get("regressors", {})}
        table = read.get(t, "coefficients", where, dict)
        coefficients = {
            o: read.numbers(
                table, o, f"{where} coefficients", finite=True, size=len(regressors[o]) if regressors else None
            )
            for o in table
        }
        if effect == UNEXPLAINED and sorted(regressors) != sorted(coefficients):
            raise read.fail(f"{where}: regressors and coefficients name different outputs")
        if unknown := [o for o in coefficients if o not in OUTPUTS]:
            raise read.fail(f"{where}: coefficients for {unknown[0]!r}, not an output ({', '.join(OUTPUTS)})")
        terms.append(
            ModelTerm(
                effect=effect,
                value=float("nan") if value is None else float(value),
                coefficients=coefficients,
                regressors=regressors,
            )
        )
    return CorrectedModel(
        baseline=baseline,
        thrust_trim=read.number(doc, "thrust_trim", "the file", finite=True),
        terms=tuple(terms),
        made_from=tuple(read.names(doc, "made_from", "the file")),
    )


def write_corrected_model(path: str | Path, model: CorrectedModel) -> Path:
    """Write a corrected simulation as versioned JSON, atomically.

    Parameters
    ----------
    path : str or Path
        Destination (``corrected.json``).
    model : CorrectedModel
        The model.

    Returns
    -------
    Path
    """
    return write_json(path, corrected_to_dict(model))


def read_corrected_model(path: str | Path) -> CorrectedModel:
    """Read a corrected simulation written by :func:`write_corrected_model`.

    Parameters
    ----------
    path : str or Path
        The JSON file.

    Raises
    ------
    ModelError
        If the file cannot be read or is not a corrected simulation of a supported version.
    """
    return corrected_from_dict(read_json_object(path, ModelError, "corrected simulation"), source=str(path))
