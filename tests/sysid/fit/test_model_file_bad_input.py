"""Damaged model files and unknown trim names: one ModelError/FitError naming the file and the field, no internals."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest

from flightlogs.errors import FitError, ModelError
from simulator.vehicle.identified import CALM_HOVER
from sysid.fit import (
    FitOptions,
    IdentifiedModel,
    IdentifyOptions,
    fit_frequency_responses,
    identify_flights,
    model_from_fit,
    read_model,
    synthetic_responses,
    write_model,
)
from sysid.model import load_structure, structure_model

_INTERNALS = re.compile(r"KeyError|ValueError|TypeError|LinAlgError|\bNone\b|Traceback")


@pytest.fixture(scope="module")
def good_doc(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    structure = load_structure("hover")
    truth, _ = structure_model(structure, dict(CALM_HOVER))
    responses = synthetic_responses(
        truth, ["q/delta_lon", "p/delta_lat"], noise_db=0.3, noise_deg=2.0, fit_range=(0.8, 50.0)
    )
    model: IdentifiedModel = model_from_fit(
        fit_frequency_responses(structure, responses, options=FitOptions(max_steps=1))
    )
    path = write_model(tmp_path_factory.mktemp("good") / "model.json", model)
    return dict(json.loads(path.read_text()))


def _write(tmp_path: Path, doc: Any, name: str = "m.json") -> Path:
    path = tmp_path / name
    path.write_text(json.dumps(doc))  # allow_nan: json writes NaN and Infinity as the audit's files hold them
    return path


def _refused(path: Path, *needles: str) -> str:
    with pytest.raises(ModelError) as caught:
        read_model(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: "), message
    for needle in needles:
        assert needle in message, message
    assert not _INTERNALS.search(message), message
    assert "\n" not in message
    return message


def _with_parameter(doc: dict[str, Any], name: str, **entry: Any) -> dict[str, Any]:
    parameters = dict(doc["parameters"])
    parameters[name] = dict(parameters.get(name, {})) | entry
    return doc | {"parameters": parameters}


def test_the_good_document_reads(good_doc: dict[str, Any], tmp_path: Path) -> None:
    assert read_model(_write(tmp_path, good_doc)).structure_name == "hover"


@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf"), None])
def test_a_non_finite_parameter_value_is_refused_with_nothing_on_stdout(
    good_doc: dict[str, Any], tmp_path: Path, capfd: pytest.CaptureFixture[str], value: float | None
) -> None:
    path = _write(tmp_path, _with_parameter(good_doc, "X_u", value=value))
    _refused(path, "parameter X_u", "value", "not a finite number")
    out, err = capfd.readouterr()
    assert out == "" and err == ""  # no LAPACK DLASCL lines, no RuntimeWarning


def test_a_parameter_value_that_is_not_a_number_is_refused(good_doc: dict[str, Any], tmp_path: Path) -> None:
    for value in ("abc", True, [1.0]):
        _refused(_write(tmp_path, _with_parameter(good_doc, "X_u", value=value)), "parameter X_u", "not a number")


def test_missing_sections_and_fields_are_named(good_doc: dict[str, Any], tmp_path: Path) -> None:
    _refused(_write(tmp_path, {k: v for k, v in good_doc.items() if k != "structure"}), "has no structure")
    _refused(_write(tmp_path, good_doc | {"structure": {"name": "hover"}}), "structure has no text")
    extra = good_doc | {"parameters": good_doc["parameters"] | {"Zfoo": {"value": 1.0, "status": "estimated"}}}
    _refused(_write(tmp_path, extra), "parameter Zfoo has no cr_percent")
    _refused(_write(tmp_path, _with_parameter(good_doc, "X_u", status="bogus")), "parameter X_u", "'bogus'")
    _refused(_write(tmp_path, good_doc | {"constants": good_doc["constants"] | {"g": None}}), "constants", "g")
    _refused(_write(tmp_path, good_doc | {"reduction": [{"step": 1}]}), "reduction step 1 has no value")


def test_a_parameter_the_structure_lacks_or_needs_is_named_with_the_file(
    good_doc: dict[str, Any], tmp_path: Path
) -> None:
    without = good_doc | {"parameters": {k: v for k, v in good_doc["parameters"].items() if k != "M_u"}}
    _refused(_write(tmp_path, without), "M_u", "structure hover")
    entry = dict(good_doc["parameters"]["X_u"])
    _refused(
        _write(tmp_path, good_doc | {"parameters": good_doc["parameters"] | {"Zfoo": entry}}),
        "Zfoo is not a parameter of structure hover",
    )


def test_a_file_of_another_kind_says_what_its_schema_is(good_doc: dict[str, Any], tmp_path: Path) -> None:
    _refused(_write(tmp_path, {"flights": []}), "no schema field")
    _refused(_write(tmp_path, good_doc | {"schema": "flight-sysid/ingest"}), "'flight-sysid/ingest' file")


def test_an_unknown_trim_name_is_refused_naming_the_valid_ones() -> None:
    hover = load_structure("hover")
    with pytest.raises(ModelError, match=r"no trim constant 'Q0' .*U0.*theta0"):
        structure_model(hover, {}, constants={"Q0": 1.0})
    model, _ = structure_model(hover, {}, constants={"U0": 2.0})
    assert model.a.shape == (11, 11)
    with pytest.raises(ModelError, match="no trim constant 'Q0'"):
        identify_flights([], hover, options=IdentifyOptions(constants={"Q0": 1.0}))


def test_no_flight_to_fit_names_the_files() -> None:
    with pytest.raises(FitError) as caught:
        identify_flights([], "hover", files=["/data/t100.h5", "b.h5"])
    assert str(caught.value) == "t100.h5, b.h5: no flight to fit the model hover to"
