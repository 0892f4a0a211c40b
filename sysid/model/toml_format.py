"""Model structures as TOML files: parsing, validation, and the built-in ones.

A structure file::

    name = "roll"
    description = "roll rate only"
    states = ["p"]
    outputs = ["p"]

    [constants]                     # trim constants; `trim` names the signal that sets them
    g = 9.81
    theta0 = { value = 0.0, trim = "theta" }

    [[inputs]]                      # control channels (columns of G_u), each with a delay
    name = "delta_lat"
    delay = "tau_lat"               # a parameter, a number or arithmetic, s
    # signal = "delta_lat"          # the canonical signal read (default: name)
    # wind = true                   # a column of G_w instead

    [parameters]                    # value, bounds, unit, free, reduce ("drop" | "fix"), input
    L_p = { value = -2.0, bounds = [-50, 50], unit = "1/s" }
    L_lat = { value = 50.0, unit = "rad/s^2 per {delta_lat}", input = "delta_lat" }
    tau_lat = { value = 0.01, bounds = [0.0, 0.2], unit = "s" }

    [F]                             # rows by state, columns by state
    p = { p = "L_p" }
    [G_u]                           # rows by state, columns by control channel
    p = { delta_lat = "L_lat" }

``H0``/``H1`` rows are keyed by output; an output named like a state with no
row reads that state. ``M`` (default identity) is keyed like ``F``.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from importlib import resources
from pathlib import Path
from typing import Any

from flightlogs.errors import ModelError
from sysid.model.expression import parse_expression
from sysid.model.structure import MATRICES, Constant, Entry, InputChannel, ModelStructure, Parameter

__all__ = ["parse_structure", "read_structure", "builtin_structures", "load_structure"]

_TOP_KEYS = {"name", "description", "states", "outputs", "constants", "inputs", "parameters", *MATRICES}
_PARAMETER_KEYS = {"value", "bounds", "unit", "free", "reduce", "drop_value", "input"}


def parse_structure(text: str, *, source: str = "<text>") -> ModelStructure:
    """Read a structure from TOML text.

    Parameters
    ----------
    text : str
        The TOML document.
    source : str, optional
        Where it came from (a path or a built-in name), for error messages.

    Returns
    -------
    ModelStructure

    Raises
    ------
    ModelError
        If the TOML is malformed, a name is unknown or repeated, or an entry
        is not a valid expression.

    Examples
    --------
    >>> s = parse_structure('''
    ... name = "roll"
    ... states = ["p"]
    ... outputs = ["p"]
    ... [[inputs]]
    ... name = "delta_lat"
    ... delay = 0.01
    ... [parameters]
    ... L_p = { value = -2.0 }
    ... L_lat = { value = 50.0 }
    ... [F]
    ... p = { p = "L_p" }
    ... [G_u]
    ... p = { delta_lat = "L_lat" }
    ... ''')
    >>> s.parameter_names, s.outputs
    (('L_p', 'L_lat'), ('p',))
    """
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ModelError(f"{source}: not valid TOML ({err})") from err
    unknown = sorted(set(doc) - _TOP_KEYS)
    if unknown:
        raise ModelError(f"{source}: unknown key {unknown[0]!r} (expected {', '.join(sorted(_TOP_KEYS))})")
    name = str(doc.get("name", Path(source).stem))
    states = _names(doc, "states", source)
    outputs = _names(doc, "outputs", source)
    inputs = tuple(_input(item, source) for item in _list_of_tables(doc.get("inputs", []), "inputs", source))
    parameters = tuple(_parameter(key, spec, source) for key, spec in _table(doc, "parameters", source).items())
    constants = tuple(_constant(key, spec, source) for key, spec in _table(doc, "constants", source).items())
    entries = _entries(doc, states, outputs, inputs, source)
    inputs_named = {c.name for c in inputs}
    for parameter in parameters:
        if parameter.input is not None and parameter.input not in inputs_named:
            raise ModelError(
                f"{source}: parameter {parameter.name} is per unit of input {parameter.input!r}, "
                "which is not an input of the structure"
            )
    structure = ModelStructure(
        name=name,
        description=str(doc.get("description", "")),
        states=states,
        inputs=inputs,
        outputs=outputs,
        parameters=parameters,
        constants=constants,
        entries=entries,
        text=text,
    )
    _check_outputs(structure, source)
    return structure


def read_structure(path: str | Path) -> ModelStructure:
    """Read a structure file.

    Parameters
    ----------
    path : str or Path
        A ``.toml`` structure file.

    Raises
    ------
    ModelError
        If the file cannot be read or is not a valid structure.
    """
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise ModelError(f"{path}: cannot read the model structure ({err})") from err
    return parse_structure(text, source=str(path))


def builtin_structures() -> dict[str, str]:
    """Built-in structure names and their one-line descriptions.

    Returns
    -------
    dict of str to str

    Examples
    --------
    >>> sorted(builtin_structures())
    ['hover', 'hover-wind']
    """
    folder = resources.files("sysid.model") / "builtin"
    found = {}
    for item in sorted(folder.iterdir(), key=lambda p: p.name):
        if item.name.endswith(".toml"):
            found[item.name[: -len(".toml")]] = str(
                tomllib.loads(item.read_text(encoding="utf-8")).get("description", "")
            )
    return found


def load_structure(name_or_path: str | Path) -> ModelStructure:
    """A built-in structure by name (``hover``, ``hover-wind``), or a structure file by path.

    Parameters
    ----------
    name_or_path : str or Path
        Built-in name, or a path to a ``.toml`` file.

    Raises
    ------
    ModelError
        If it is neither a built-in name nor a readable structure file.
    """
    text = str(name_or_path)
    if text in builtin_structures():
        item = resources.files("sysid.model") / "builtin" / f"{text}.toml"
        return parse_structure(item.read_text(encoding="utf-8"), source=text)
    if Path(text).is_file():
        return read_structure(text)
    raise ModelError(
        f"model {text!r} is neither a built-in structure ({', '.join(builtin_structures())}) nor a structure file"
    )


def _names(doc: Mapping[str, Any], key: str, source: str) -> tuple[str, ...]:
    value = doc.get(key)
    if not isinstance(value, list) or not value or not all(isinstance(v, str) and v for v in value):
        raise ModelError(f"{source}: {key} must be a non-empty list of names")
    return tuple(value)


def _table(doc: Mapping[str, Any], key: str, source: str) -> Mapping[str, Any]:
    value = doc.get(key, {})
    if not isinstance(value, dict):
        raise ModelError(f"{source}: [{key}] must be a table")
    return value


def _list_of_tables(value: Any, key: str, source: str) -> list[Mapping[str, Any]]:
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise ModelError(f"{source}: {key} must be an array of tables ([[{key}]])")
    return value


def _input(item: Mapping[str, Any], source: str) -> InputChannel:
    unknown = sorted(set(item) - {"name", "signal", "delay", "wind"})
    if unknown or not isinstance(item.get("name"), str):
        raise ModelError(
            f"{source}: each [[inputs]] needs a name and may have signal, delay, wind (got {sorted(item)})"
        )
    name = item["name"]
    delay = parse_expression(item.get("delay", 0.0), where=f"{source}: delay of {name}")
    return InputChannel(
        name=name, signal=str(item.get("signal", name)), delay=delay, wind=bool(item.get("wind", False))
    )


def _parameter(name: str, spec: Any, source: str) -> Parameter:
    if isinstance(spec, (int, float)) and not isinstance(spec, bool):
        spec = {"value": spec}
    if not isinstance(spec, dict) or "value" not in spec or set(spec) - _PARAMETER_KEYS:
        raise ModelError(
            f"{source}: parameter {name} must be a number or a table with value "
            f"(and optionally {', '.join(sorted(_PARAMETER_KEYS - {'value'}))})"
        )
    lower, upper = spec.get("bounds", [-math.inf, math.inf])
    try:
        return Parameter(
            name=name,
            value=float(spec["value"]),
            lower=float(lower),
            upper=float(upper),
            free=bool(spec.get("free", True)),
            unit=str(spec.get("unit", "")),
            reduce=spec.get("reduce", "drop"),
            drop_value=float(spec.get("drop_value", 0.0)),
            input=spec.get("input"),
        )
    except (TypeError, ValueError) as err:
        raise ModelError(f"{source}: parameter {name}: {err}") from err


def _constant(name: str, spec: Any, source: str) -> Constant:
    if isinstance(spec, (int, float)) and not isinstance(spec, bool):
        return Constant(name, float(spec))
    if isinstance(spec, dict) and "value" in spec and not set(spec) - {"value", "trim"}:
        return Constant(name, float(spec["value"]), spec.get("trim"))
    raise ModelError(f'{source}: constant {name} must be a number or {{ value = ..., trim = "signal" }}')


def _entries(
    doc: Mapping[str, Any],
    states: tuple[str, ...],
    outputs: tuple[str, ...],
    inputs: tuple[InputChannel, ...],
    source: str,
) -> tuple[Entry, ...]:
    state_index = {n: k for k, n in enumerate(states)}
    output_index = {n: k for k, n in enumerate(outputs)}
    control_index = {c.name: k for k, c in enumerate(inputs) if not c.wind}
    wind_index = {c.name: k for k, c in enumerate(inputs) if c.wind}
    layout = {
        "M": (state_index, state_index),
        "F": (state_index, state_index),
        "G_u": (state_index, control_index),
        "G_w": (state_index, wind_index),
        "H0": (output_index, state_index),
        "H1": (output_index, state_index),
    }
    entries = []
    for matrix, (rows, columns) in layout.items():
        for row, cells in _table(doc, matrix, source).items():
            if row not in rows:
                raise ModelError(f"{source}: [{matrix}] row {row!r} is not one of {', '.join(rows) or 'nothing'}")
            if not isinstance(cells, dict):
                raise ModelError(f"{source}: [{matrix}] row {row} must be a table {{ column = entry }}")
            for column, text in cells.items():
                if column not in columns:
                    raise ModelError(
                        f"{source}: [{matrix}] column {column!r} (row {row}) is not one of "
                        f"{', '.join(columns) or 'nothing'}"
                    )
                expression = parse_expression(text, where=f"{source}: {matrix}[{row}, {column}]")
                entries.append(Entry(matrix=matrix, row=rows[row], column=columns[column], expression=expression))
    return tuple(entries)


def _check_outputs(structure: ModelStructure, source: str) -> None:
    measured = {e.row for e in structure.entries if e.matrix in ("H0", "H1")}
    for k, output in enumerate(structure.outputs):
        if k not in measured and output not in structure.states:
            raise ModelError(f"{source}: output {output!r} is not a state and has no H0/H1 row")
