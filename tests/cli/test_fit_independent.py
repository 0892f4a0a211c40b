"""``sysid fit`` on a log our simulator did not write, as a new user runs it (issue 14): no --segments.

``heldout-px4-no-lat`` (tests/independent_sim, held out from the detector's tuning) is an ordinary closed-loop
PX4 log with lon, yaw and thrust sweeps and doublets, nothing logged about the excitation, and lat never excited.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner
from independent_sim.fixtures import independent_corpus_fixture  # noqa: F401 (registers the fixture)

from sysid.fit import read_model
from sysid_cli.main import cli

pytestmark = [pytest.mark.slow, pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning")]


def test_the_axis_never_flown_is_exit_1_naming_it(independent_corpus, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    log = independent_corpus.files("heldout-px4-no-lat").log
    out = tmp_path / "model.json"
    result = CliRunner().invoke(cli, ["fit", str(log), "-o", str(out), "-q"])
    assert result.exit_code == 1, result.output
    assert "model hover: 1 of its 4 axes cannot be identified." in result.output
    assert (
        "lat: no sweep found in 1 log; the delta_lat input never passed the sweep test; give the maneuvers with "
        "--segments, or --partial to write a model of the other axes." in result.output
    )
    assert not out.exists() and "Traceback" not in result.output


def test_partial_marks_that_axis_unidentified(independent_corpus, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    log = independent_corpus.files("heldout-px4-no-lat").log
    out = tmp_path / "model.json"
    result = CliRunner().invoke(cli, ["fit", str(log), "--partial", "-o", str(out), "-q"])
    assert result.exit_code == 0, result.output
    doc = json.loads(out.read_text())
    status = {a["axis"]: a["status"] for a in doc["axes"]}
    assert status == {"lat": "unidentified", "lon": "identified", "yaw": "identified", "thr": "identified"}
    for name in ("Y_v", "L_v", "Y_lat", "L_lat", "tau_lat"):
        assert doc["parameters"][name]["value"] is None and doc["parameters"][name]["status"] == "unidentified"
    assert read_model(out).linear_model().inputs == ("delta_lon", "delta_yaw", "delta_thr")
