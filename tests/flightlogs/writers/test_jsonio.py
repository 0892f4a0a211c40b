"""The one JSON encoder: what each value becomes, the text it writes, and that it reads back."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from flightlogs.errors import DataError
from flightlogs.writers.jsonio import finite_or_none, json_text, jsonable, write_json


@dataclass(frozen=True)
class _Options:
    gain: float = 2.0
    band: tuple[float, float] = (0.5, math.inf)
    names: tuple[str, ...] = ("ax", "az")
    where: Path = Path("logs/a.bin")
    extra: dict[str, float] = field(default_factory=lambda: {"q": math.nan})


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        (math.nan, None),
        (math.inf, None),
        (-math.inf, None),
        (1.5, 1.5),
        (np.float64("nan"), None),
        (np.float32(0.5), 0.5),
        (np.float64(-np.inf), None),
        (np.int64(3), 3),
        (np.bool_(True), True),
        (True, True),
        (None, None),
        ("text", "text"),
        (np.array(2.5), 2.5),
        (np.array([[1.0, np.nan], [np.inf, 2.0]]), [[1.0, None], [None, 2.0]]),
        (np.arange(3), [0, 1, 2]),
        ((1, (2.0, (math.nan,))), [1, [2.0, [None]]]),
        ({1: "a", "b": (np.int32(2),)}, {"1": "a", "b": [2]}),
        (MappingProxyType({"k": math.nan}), {"k": None}),
        (Path("a/b.json"), "a/b.json"),
    ],
    ids=repr,
)
def test_jsonable(value: object, expected: object) -> None:
    got = jsonable(value)
    assert got == expected
    assert json.loads(json.dumps(got, allow_nan=False)) == json.loads(json.dumps(expected))


def test_numbers_come_out_as_python_types() -> None:
    assert [type(v) for v in jsonable([np.float64(1.0), np.int64(1), np.bool_(False)])] == [float, int, bool]


def test_a_dataclass_becomes_an_object_of_its_fields() -> None:
    assert jsonable(_Options()) == {
        "gain": 2.0,
        "band": [0.5, None],
        "names": ["ax", "az"],
        "where": "logs/a.bin",
        "extra": {"q": None},
    }


def test_nonfinite_can_be_kept_for_a_store_that_reads_nan_back() -> None:
    text = json.dumps(jsonable({"std": (math.nan, math.inf)}, nonfinite="keep"))
    assert text == '{"std": [NaN, Infinity]}'
    assert math.isnan(json.loads(text)["std"][0])


def test_an_unknown_object_raises_unless_a_default_converts_it() -> None:
    with pytest.raises(TypeError, match="object"):
        jsonable({"x": object()})
    assert jsonable({"x": {1, 2}}, default=sorted) == {"x": [1, 2]}
    assert jsonable([complex(1, 2)], default=str) == ["(1+2j)"]


def test_finite_or_none() -> None:
    assert finite_or_none(2) == 2.0 and type(finite_or_none(2)) is float
    assert finite_or_none(math.nan) is None and finite_or_none(-math.inf) is None and finite_or_none(None) is None


def test_json_text_spells_the_files_the_same_way() -> None:
    """One-space indent by default, a final newline, NaN as null, keys in the order given."""
    assert json_text({"b": math.nan, "a": (1, 2)}) == '{\n "b": null,\n "a": [\n  1,\n  2\n ]\n}\n'
    assert json_text([np.float64(0.1)], indent=2) == "[\n  0.1\n]\n"


def test_write_json_round_trips(tmp_path: Path) -> None:
    doc = {"cost": np.float64(12.25), "eig": np.array([-1.0, np.nan]), "opts": _Options(), "n": np.int64(7)}
    target = write_json(tmp_path / "out.json", doc)
    assert target == tmp_path / "out.json"
    assert json.loads(target.read_text(encoding="utf-8")) == jsonable(doc)
    assert [p.name for p in tmp_path.iterdir()] == ["out.json"]


def test_write_json_writes_nothing_when_the_document_cannot_be_encoded(tmp_path: Path) -> None:
    target = tmp_path / "out.json"
    target.write_text("old")
    with pytest.raises(TypeError):
        write_json(target, {"x": object()})
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["out.json"]


def test_write_json_needs_the_folder(tmp_path: Path) -> None:
    with pytest.raises(DataError, match="does not exist"):
        write_json(tmp_path / "missing" / "out.json", {})


nested = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=5),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=4), inner, max_size=4),
    max_leaves=20,
)


@given(nested)
def test_any_nested_value_round_trips_with_nonfinite_as_null(value: object) -> None:
    """Encoding is idempotent and what it gives survives a strict JSON round trip unchanged."""
    plain = jsonable(value)
    assert jsonable(plain) == plain
    assert json.loads(json_text(plain)) == plain
