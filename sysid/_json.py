"""JSON shared by the files sysid writes: float arrays as nested lists, ``null`` back as NaN, checked read.

The encoding itself (NaN as ``null``, numpy values as numbers, the atomic
write) is flightlogs' one encoder, :mod:`flightlogs.writers.jsonio`;
:func:`finite_or_none` and :func:`write_json` are its, re-exported.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from flightlogs.errors import ModelError, SysidError
from flightlogs.writers.jsonio import finite_or_none, jsonable, write_json

__all__ = [
    "DocumentFields",
    "finite_or_none",
    "float_or_nan",
    "json_floats",
    "float_array",
    "value_text",
    "write_json",
    "read_json_object",
]


def float_or_nan(value: Any) -> float:
    """A JSON number back as a float: ``null`` (None) reads as NaN.

    Parameters
    ----------
    value : float, int or None
        As read from JSON.

    Returns
    -------
    float

    Examples
    --------
    >>> float_or_nan(None), float_or_nan(3)
    (nan, 3.0)
    """
    return math.nan if value is None else float(value)


def json_floats(values: np.ndarray) -> Any:
    """An array as nested JSON lists of floats, NaN and infinities as None.

    Parameters
    ----------
    values : ndarray, any shape
        Real numbers.

    Returns
    -------
    list
        Nested as deep as `values` has dimensions (a flat list for 0-D and 1-D).

    Examples
    --------
    >>> json_floats(np.array([[1.0, np.nan], [np.inf, 2.0]]))
    [[1.0, None], [None, 2.0]]
    """
    return jsonable(np.atleast_1d(np.asarray(values, dtype=float)))


def float_array(values: Any) -> np.ndarray:
    """A JSON list of numbers back as a float array, None as NaN.

    Parameters
    ----------
    values : sequence of (float or None)
        As read from JSON.

    Returns
    -------
    ndarray, shape (len(values),)

    Examples
    --------
    >>> float_array([1, None]).tolist()
    [1.0, nan]
    """
    return np.array([float_or_nan(v) for v in values], dtype=float)


def value_text(value: Any) -> str:
    """A JSON value as an error message shows it: ``null`` for None, else its repr cut to 40 characters.

    Parameters
    ----------
    value : object
        As read from JSON.

    Returns
    -------
    str

    Examples
    --------
    >>> value_text(None), value_text("abc"), value_text(list(range(30)))
    ('null', "'abc'", '[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11...')
    """
    text = "null" if value is None else repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def read_json_object(path: str | Path, error: type[SysidError], what: str) -> dict[str, Any]:
    """Read a JSON file that must hold an object.

    Parameters
    ----------
    path : str or Path
        The JSON file.
    error : type of SysidError
        Raised when the file cannot be read or holds no object.
    what : str
        The kind of file, for messages (``"model"`` makes "cannot read the model file").

    Returns
    -------
    dict

    Raises
    ------
    SysidError
        Of type `error`, naming `path`.
    """
    try:
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise error(f"{path}: cannot read the {what} file ({err})") from None
    if not isinstance(doc, dict):
        raise error(f"{path}: not a flight-sysid {what} file")
    return doc


_REQUIRED: Any = object()
_KINDS = {dict: "an object", list: "a list", str: "text", int: "a whole number", bool: "true or false"}


class DocumentFields:
    """Reads a JSON document field by field; a missing or bad field raises an error naming file and field.

    Parameters
    ----------
    source : str
        The file's name, first in every message.
    error : type of SysidError, optional
        What is raised (default :class:`~flightlogs.errors.ModelError`).
    """

    def __init__(self, source: str, error: type[SysidError] = ModelError) -> None:
        self.source = source
        self.error = error

    def fail(self, message: str) -> SysidError:
        """The error to raise, its message after the file's name."""
        return self.error(f"{self.source}: {message}")

    def get(self, parent: Mapping[str, Any], key: str, where: str, kind: type, default: Any = _REQUIRED) -> Any:
        if key not in parent:
            if default is _REQUIRED:
                raise self.fail(f"{where} has no {key}")
            return default
        return self.check(parent[key], f"{where}: {key}", kind)

    def check(self, value: Any, what: str, kind: type) -> Any:
        if not isinstance(value, kind) or (isinstance(value, bool) and kind is int):
            raise self.fail(f"{what} is {value_text(value)}, not {_KINDS[kind]}")
        return value

    def number(self, parent: Mapping[str, Any], key: str, where: str, *, finite: bool = False) -> float:
        value = self.get(parent, key, where, object)
        if value is None:
            if finite:
                raise self.fail(f"{where}: {key} is null, not a finite number")
            return math.nan
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(f"{where}: {key} is {value_text(value)}, not a number")
        if finite and not math.isfinite(value):
            raise self.fail(f"{where}: {key} is {value_text(value)}, not a finite number")
        return float(value)

    def numbers(
        self, parent: Mapping[str, Any], key: str, where: str, *, finite: bool = False, size: int | None = None
    ) -> np.ndarray:
        values = self.get(parent, key, where, list)
        bad = [v for v in values if (isinstance(v, bool) or not isinstance(v, (int, float))) and v is not None]
        if bad:
            raise self.fail(f"{where}: {key} holds {value_text(bad[0])}, not a number")
        out = float_array(values)
        if finite and not np.all(np.isfinite(out)):
            raise self.fail(f"{where}: {key} holds a missing or non-finite value")
        if size is not None and out.size != size:
            raise self.fail(f"{where}: {key} has {out.size} values, not {size}")
        return out

    def names(self, parent: Mapping[str, Any], key: str, where: str) -> list[str]:
        values = self.get(parent, key, where, list)
        if not all(isinstance(v, str) for v in values):
            raise self.fail(f"{where}: {key} holds a value that is not a name")
        return list(values)

    def table(self, parent: Mapping[str, Any], key: str, where: str, *, finite: bool = False) -> dict[str, float]:
        table = self.get(parent, key, where, dict, {})
        label = key if where == "the file" else f"{where} {key}"
        return {k: self.number(table, k, label, finite=finite) for k in table}
