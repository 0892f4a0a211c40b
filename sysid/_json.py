"""JSON shared by the files sysid writes: float arrays as nested lists, ``null`` back as NaN, checked read.

The encoding itself (NaN as ``null``, numpy values as numbers, the atomic
write) is flightlogs' one encoder, :mod:`flightlogs.writers.jsonio`;
:func:`finite_or_none` and :func:`write_json` are its, re-exported.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from flightlogs.errors import SysidError
from flightlogs.writers.jsonio import finite_or_none, jsonable, write_json

__all__ = [
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
