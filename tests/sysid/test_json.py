"""sysid's JSON helpers build on flightlogs' one encoder: float arrays out as nested lists and back."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import flightlogs.writers.jsonio as jsonio
from sysid import _json


def test_the_encoder_is_flightlogs_one() -> None:
    assert _json.finite_or_none is jsonio.finite_or_none
    assert _json.write_json is jsonio.write_json


@pytest.mark.parametrize(
    ("values", "expected"),
    [
        (np.array(2.0), [2.0]),
        (np.array([1, 2]), [1.0, 2.0]),
        (np.array([np.nan, np.inf, -np.inf, 0.5]), [None, None, None, 0.5]),
        (np.zeros((2, 0)), [[], []]),
        (np.zeros((0, 2)), []),
        (np.arange(8.0).reshape(2, 2, 2), [[[0.0, 1.0], [2.0, 3.0]], [[4.0, 5.0], [6.0, 7.0]]]),
        (np.array([0.1], dtype=np.float32), [float(np.float32(0.1))]),
    ],
    ids=["0-D", "int", "non-finite", "2x0", "0x2", "3-D", "float32"],
)
def test_json_floats(values: np.ndarray, expected: list[object]) -> None:
    got = _json.json_floats(values)
    assert got == expected
    assert all(type(v) is float for v in np.ravel(np.array(got, dtype=object)) if v is not None)


def test_a_float_array_round_trips_through_a_file(tmp_path: Path) -> None:
    values = np.array([1.25, np.nan, -np.inf, 3.0])
    path = _json.write_json(tmp_path / "a.json", {"values": _json.json_floats(values)})
    back = _json.float_array(json.loads(path.read_text())["values"])
    np.testing.assert_array_equal(back, np.where(np.isfinite(values), values, np.nan))
    assert math.isnan(_json.float_or_nan(None))
