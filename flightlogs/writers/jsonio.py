"""The one JSON encoder of flight-sysid: plain values from numpy and dataclasses, NaN as ``null``, atomic write.

The JSON the packages write goes through :func:`jsonable`, so every file
spells a value the same way: numpy scalars and arrays become numbers and
nested lists, tuples lists, dataclasses and mappings objects with string
keys, paths strings, and a non-finite float (NaN or ±inf, which JSON cannot
hold) ``null``. :func:`write_json` writes such a document atomically.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Callable, Mapping
from pathlib import Path, PurePath
from typing import Any, Literal

import numpy as np

from flightlogs.writers.atomic import atomic_output

__all__ = ["finite_or_none", "jsonable", "json_text", "write_json"]


def finite_or_none(value: float | None) -> float | None:
    """`value` as a float, or None (JSON ``null``) when it is None, NaN or infinite.

    Parameters
    ----------
    value : float or None
        Any real number, in its own unit.

    Returns
    -------
    float or None

    Examples
    --------
    >>> finite_or_none(2), finite_or_none(float("nan")), finite_or_none(None)
    (2.0, None, None)
    """
    return None if value is None or not math.isfinite(value) else float(value)


def jsonable(
    value: Any,
    *,
    nonfinite: Literal["null", "keep"] = "null",
    default: Callable[[Any], Any] | None = None,
) -> Any:
    """`value` as plain JSON-ready Python: dicts, lists, str, int, float, bool and None.

    Parameters
    ----------
    value : object
        None, bool, int, float, str, a numpy scalar or array, a path, a
        dataclass instance, a mapping, a list or tuple, nested at will.
    nonfinite : {"null", "keep"}, optional
        What becomes of NaN and ±inf: ``"null"`` (default) writes None, as a
        JSON file must; ``"keep"`` leaves the float, for :func:`json.dumps`
        to spell ``NaN`` in an internal store that reads it back with
        :func:`json.loads`.
    default : callable, optional
        Called on any other object, its result converted in turn (``str``
        writes the object's text). Without it such an object raises.

    Returns
    -------
    object
        Dataclasses and mappings as dicts with string keys (``str(key)``),
        lists, tuples and arrays as lists (nested as deep as the array),
        numpy scalars as the Python ``bool``, ``int`` or ``float``, paths
        as strings.

    Raises
    ------
    TypeError
        If an object is none of those and `default` is not given.

    Examples
    --------
    >>> jsonable({"gain": np.float64(2.5), "band": (np.nan, np.inf), 3: np.arange(2)})
    {'gain': 2.5, 'band': [None, None], '3': [0, 1]}
    >>> jsonable([np.nan], nonfinite="keep")
    [nan]
    >>> jsonable(object(), default=lambda item: "an object")
    'an object'
    """
    if value is None or isinstance(value, (str, bool, int)):
        return value
    if isinstance(value, float):  # np.float64 too
        return float(value) if nonfinite == "keep" else finite_or_none(value)
    if isinstance(value, np.ndarray):
        value = value.tolist()  # Python numbers, nested lists (a 0-D array: its scalar)
    elif isinstance(value, np.generic):
        value = value.item()
    elif isinstance(value, PurePath):
        return str(value)
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        value = {field.name: getattr(value, field.name) for field in dataclasses.fields(value)}
    elif default is not None and not isinstance(value, (Mapping, list, tuple)):
        value = default(value)
    if isinstance(value, Mapping):
        return {str(k): jsonable(v, nonfinite=nonfinite, default=default) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v, nonfinite=nonfinite, default=default) for v in value]
    if value is None or isinstance(value, (str, bool, int, float)):
        return jsonable(value, nonfinite=nonfinite)
    raise TypeError(f"{type(value).__name__} {value!r:.40} cannot be written as JSON")


def json_text(doc: Any, *, indent: int = 1) -> str:
    """A document as JSON text (through :func:`jsonable`, so NaN as ``null``) with a final newline.

    Parameters
    ----------
    doc : object
        Anything :func:`jsonable` converts.
    indent : int, optional
        Spaces per nesting level. Default 1.

    Returns
    -------
    str

    Examples
    --------
    >>> print(json_text({"rmse": float("nan"), "params": (1.5, np.int64(2))}, indent=2), end="")
    {
      "rmse": null,
      "params": [
        1.5,
        2
      ]
    }
    """
    return json.dumps(jsonable(doc), indent=indent, allow_nan=False) + "\n"


def write_json(path: str | Path, doc: Any, *, indent: int = 1) -> Path:
    """Write a document as JSON (:func:`json_text`), atomically.

    Parameters
    ----------
    path : str or Path
        Destination; its folder must exist.
    doc : object
        Anything :func:`jsonable` converts; NaN and infinities are written ``null``.
    indent : int, optional
        Spaces per nesting level. Default 1.

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    DataError
        If the folder of `path` does not exist.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> target = write_json(pathlib.Path(tempfile.mkdtemp()) / "out.json", {"cost": np.inf})
    >>> target.read_text()
    '{\\n "cost": null\\n}\\n'
    """
    text = json_text(doc, indent=indent)
    with atomic_output(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)
