"""A saved verification (:mod:`sysid.verify.io`) reads back exactly, refuses what it is not, and reads version 1."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from flightlogs.errors import DataError
from sysid.verify import Verification
from sysid.verify.io import VERIFICATION_SCHEMA_VERSION, read_verification, verification_to_dict, write_verification

import builders


@pytest.fixture(scope="module")
def sample() -> Verification:
    verification: Verification = builders.sample_verification()
    return verification


def _arrays(verification: Verification) -> list[np.ndarray]:
    found = []
    for record in (*verification.records, *verification.without_wind):
        found.append(record.time_s)
        for o in record.outputs:
            found.extend([o.measured, o.simulated] + ([o.predicted] if o.predicted is not None else []))
    return found


def test_a_saved_verification_reads_back_exactly(sample: Verification, tmp_path: Path) -> None:
    path = write_verification(
        tmp_path / "validation.json", sample, model="model.json", options={"initial_state": "estimated", "after_s": 1.0}
    )
    loaded = read_verification(path)
    assert loaded.model == "model.json" and dict(loaded.options) == {"initial_state": "estimated", "after_s": 1.0}
    assert verification_to_dict(loaded.verification) == verification_to_dict(sample)
    for before, after in zip(_arrays(sample), _arrays(loaded.verification), strict=True):
        np.testing.assert_array_equal(before, after)  # every digit kept: the report redraws the same
    assert [c.reduction_percent for c in loaded.verification.wind_correction] == [
        c.reduction_percent for c in sample.wind_correction
    ]
    record = loaded.verification.records[0]
    assert record.excited == "delta_lon" and record.off_axis == ("p",)  # what each record is judged on
    assert [s.name for s in loaded.verification.off_axis] == ["p"]


def test_a_model_without_wind_keeps_no_wind_fields(sample: Verification, tmp_path: Path) -> None:
    plain = dataclasses.replace(sample, without_wind=(), wind_correction=())
    loaded = read_verification(write_verification(tmp_path / "v.json", plain)).verification
    assert loaded.without_wind == () and loaded.wind_correction == ()
    assert [r.label for r in loaded.records] == [r.label for r in plain.records]


def test_version_1_files_read_with_every_output_judged(sample: Verification, tmp_path: Path) -> None:
    """Version 1 had no excited input, off-axis outputs or off-axis summary: every output was judged."""
    doc = verification_to_dict(sample)
    doc["schema_version"] = 1
    del doc["off_axis"]
    for record in (*doc["records"], *doc["without_wind"]):
        del record["excited"], record["off_axis"]
    path = tmp_path / "old.json"
    path.write_text(json.dumps(doc))
    loaded = read_verification(path).verification
    assert all(r.off_axis == () and r.excited is None for r in loaded.records) and loaded.off_axis == ()


@pytest.mark.parametrize(
    ("change", "fragment"),
    [
        (lambda d: {"model": "m.json", "records": [], "summary": {}, "overall": {}}, "sysid validate --json"),
        (lambda d: d | {"schema": "flight-sysid/identified-model"}, "not a flight-sysid verification file"),
        (lambda d: d | {"schema_version": VERIFICATION_SCHEMA_VERSION + 1}, "schema version"),
        (
            lambda d: d | {"records": [{k: v for k, v in d["records"][0].items() if k != "time_s"}]},
            "incomplete or damaged",
        ),
        (lambda d: d | {"records": [d["records"][0] | {"off_axis": ["nope"]}]}, "incomplete or damaged"),
    ],
)
def test_what_is_not_a_verification_is_refused_by_name(
    sample: Verification, tmp_path: Path, change: Any, fragment: str
) -> None:
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(change(verification_to_dict(sample))))
    with pytest.raises(DataError, match=fragment) as caught:
        read_verification(path)
    assert str(path) in str(caught.value)


def test_a_file_that_is_not_json_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "broken.json"
    path.write_text('{"schema": ')
    with pytest.raises(DataError, match="cannot read the verification file"):
        read_verification(path)
    with pytest.raises(DataError, match="cannot read"):
        read_verification(tmp_path / "missing.json")


def test_the_axes_not_verified_are_saved(sample: Verification, tmp_path: Path) -> None:
    said = dataclasses.replace(sample, unverified=("lat: no doublet in 2 logs; not verified",))
    loaded = read_verification(write_verification(tmp_path / "v.json", said)).verification
    assert loaded.unverified == ("lat: no doublet in 2 logs; not verified",)
    assert read_verification(write_verification(tmp_path / "w.json", sample)).verification.unverified == ()


def test_validate_json_gives_each_record_as_the_file_does_without_its_histories(sample: Verification) -> None:
    """One vocabulary (issue 33): a record of ``validate --json`` is the file's entry less its time histories."""
    saved = verification_to_dict(sample)
    for record, entry, digested in zip(sample.records, saved["records"], sample.digest()["records"]):
        assert (digested["start_s"], digested["end_s"]) == (record.time_s[0], record.time_s[-1])
        kept = {k: v for k, v in entry.items() if k != "time_s"}
        kept["outputs"] = [
            {k: v for k, v in o.items() if k not in ("measured", "simulated", "predicted")} for o in entry["outputs"]
        ]
        assert {k: v for k, v in digested.items() if k not in ("start_s", "end_s")} == kept
        assert digested["on_axis"] == [o.name for o in record.judged] and digested["on_axis"]


def test_records_that_diverge_share_one_note_and_the_others_keep_their_own(sample: Verification) -> None:
    first, second = sample.records[:2]
    diverging = dataclasses.replace(first, unstable=True, growth=40.0, unstable_modes=("pitch",), notice="own-a")
    also = dataclasses.replace(second, unstable=True, growth=12.0, unstable_modes=("pitch", "roll"), notice="own-b")
    (shared,) = dataclasses.replace(sample, records=(diverging, also)).record_notes()
    assert "pitch and roll modes" in shared and "up to 40-fold over 2 records" in shared
    assert f"({first.label}; {second.label})" in shared and "own-" not in shared  # their notices: the shared one
    one = dataclasses.replace(sample, records=(diverging, dataclasses.replace(second, notice="cut short")))
    assert one.record_notes() == (f"{first.label}: own-a", f"{second.label}: cut short")  # one alone: its own
