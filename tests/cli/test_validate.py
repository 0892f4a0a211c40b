"""``sysid validate`` end to end: simulator logs in a real format, an anemometer file, a model file.

The strong-wind truth (Tables 3.3 and 3.5) is written as an identified-model
file and flown by the linear simulator; its doublets go through reading,
wind alignment and conditioning before they are verified. (Kept with the
verification tests: ``tests/cli`` is another engineer's.)
"""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from simulator.campaign.fly import run_scenario
from simulator.campaign.scenario import read_scenario
from simulator.vehicle.identified import CALM_HOVER, STRONG_WIND_TERMS
from sysid.fit import read_model, write_model
from sysid_cli.main import cli

from builders import with_unidentified

SCENARIO = """
[scenario]
description = "strong-wind lon doublets on the linear octocopter"
vehicle = "linear-octo"
formats = ["dataflash"]
trials = 2
seed = 5
utc_start = "2024-05-01T10:00:00Z"
margin_s = 3.0

[anemometer]
distance_m = 4.6
rate_hz = 20.0
clock_offset_s = 1.5

[[condition]]
name = "strong"
mean_speed_m_s = 5.4
direction_from_deg = 300.0
turbulence_ratio = 0.2

[[maneuver]]
axis = "lon"
kind = "doublet"
amplitude = 15.0
duration_s = 2.0
"""


def _truth_model_file(path: Path) -> Path:
    """Tables 3.3 and 3.5 as an identified hover-wind model; control derivatives per normalised input (x100)."""
    from sysid.fit import CostSummary, IdentifiedModel, ParameterEstimate, write_model
    from sysid.model import parse_structure

    text = (resources.files("sysid.model") / "builtin" / "hover-wind.toml").read_text()
    values = dict(CALM_HOVER) | dict(STRONG_WIND_TERMS) | {"N_r": 0.0, "Z_w": 0.0}
    for name in ("X_lon", "M_lon", "Y_lat", "L_lat", "N_yaw", "Z_thr"):
        values[name] *= 100.0  # the ArduPilot log holds the mixer input normalised to -1..1
    structure = parse_structure(text, source="hover-wind")
    parameters = tuple(ParameterEstimate(name=p.name, value=values[p.name]) for p in structure.parameters)
    constants = {"g": 9.81, "U0": 0.0, "V0": 0.0, "W0": 0.0, "phi0": 0.0, "theta0": 0.0}
    model = IdentifiedModel(
        structure_name="hover-wind",
        structure_text=text,
        parameters=parameters,
        correlation_names=(),
        correlation=np.zeros((0, 0)),
        cost=CostSummary(average=50.0),
        constants=constants,
    )
    return write_model(path, model)


@pytest.fixture(scope="module")
def flights(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[Path], list[Path]]:
    folder = tmp_path_factory.mktemp("strong")
    (folder / "strong.toml").write_text(SCENARIO)
    written = run_scenario(read_scenario(folder / "strong.toml"), folder)
    logs = [t.logs[0] for t in written]
    winds = [t.wind_csv for t in written if t.wind_csv is not None]
    return _truth_model_file(folder / "model.json"), logs, winds


def test_validate_reports_the_wind_correction(flights: tuple[Path, list[Path], list[Path]], tmp_path: Path) -> None:
    model, logs, winds = flights
    report = tmp_path / "validate.html"
    args = [
        "validate",
        str(model),
        *map(str, logs),
        *sum((["--wind", str(w)] for w in winds), []),
        "--wind-distance",
        "4.6",
        "--wind-offset",
        "1.5",
        "--report",
        str(report),
        "-o",
        str(tmp_path / "validation.json"),
        "--json",
        "-",
        "-q",
    ]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    saved = json.loads((tmp_path / "validation.json").read_text())  # one vocabulary: the file's entries are --json's
    assert {s["name"]: s for s in saved["summary"]} == summary["summary"]
    assert {c["name"]: c for c in saved["wind_correction"]} == summary["wind_correction"]
    assert len(summary["records"]) == 2
    assert set(summary["summary"]) == {"u", "q", "theta", "ax"}  # lon doublets: judged on the lon outputs
    assert {"w", "az", "v", "p"} <= set(summary["off_axis"])  # the others, for information
    for name in ("u", "q", "theta", "ax"):
        assert summary["summary"][name]["tic"] <= 0.25
    assert summary["wind_correction"]["ax"]["reduction_percent"] >= 13.0  # Table 3.6, strong wind
    assert summary["wind_correction"]["ax"]["rmse_with"] < summary["wind_correction"]["ax"]["rmse_without"]
    ax = summary["wind_correction"]["ax"]
    assert ax["band_hz"] == 2.0 and ax["reduction_in_band_percent"] >= ax["reduction_percent"]
    assert summary["unstable"] is True and summary["summary"]["q"]["prediction_tic"] is not None
    page = report.read_text()  # the model report, with the verification
    assert 'id="verification"' in page and "With and without the wind term" in page
    assert "change in the wind's band" in page and f"{-ax['reduction_in_band_percent']:+.1f} %" in page
    assert 'id="parameters"' in page and page.count("<svg ") == 1 + 1 + 2  # poles, wind bars, two records


def test_the_wind_term_is_driven_with_the_wind_it_was_fitted_on(
    flights: tuple[Path, list[Path], list[Path]], tmp_path: Path
) -> None:
    """G_w is fitted on the anemometer's wind low-passed at 2 Hz, and verified with it: an anemometer with the
    noise of a real one (0.3 m/s, 3 deg, white) leaves the strong wind's ax cut at 72 % (81 % without the
    noise); driven with the raw reading, the model passed the noise through X_w_lon to ax and cut it 12 %."""
    model, logs, winds = flights
    rng = np.random.default_rng(1)
    noisy = []
    for wind in winds:
        table = pd.read_csv(wind)
        table["speed_m_s"] = (table["speed_m_s"] + 0.3 * rng.standard_normal(len(table))).round(3)
        table["direction_deg"] = (table["direction_deg"] + 3.0 * rng.standard_normal(len(table))).round(1)
        noisy.append(tmp_path / wind.name)
        table.to_csv(noisy[-1], index=False)
    args = ["validate", str(model), *map(str, logs), *sum((["--wind", str(w)] for w in noisy), [])]
    result = CliRunner().invoke(cli, [*args, "--wind-distance", "4.6", "--wind-offset", "1.5", "--json", "-", "-q"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["wind_correction"]["ax"]["reduction_percent"] >= 50.0


def test_validate_without_wind_verifies_the_model_without_it(flights: tuple[Path, list[Path], list[Path]]) -> None:
    model, logs, _ = flights
    result = CliRunner().invoke(cli, ["validate", str(model), str(logs[0]), "--json", "-", "-q"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert "wind_correction" not in summary
    assert any("--wind" in note for note in summary["notes"])


def test_validate_without_doublets_fails_with_one_sentence(
    flights: tuple[Path, list[Path], list[Path]], tmp_path: Path
) -> None:
    model, logs, _ = flights
    segments = tmp_path / "none.csv"
    segments.write_text("start_s,end_s,axis,kind\n21.0,22.0,lon,sweep\n")
    result = CliRunner().invoke(cli, ["validate", str(model), str(logs[0]), "--segments", str(segments)])
    assert result.exit_code == 1
    assert "no doublet found" in result.output and "Traceback" not in result.output


def test_axes_without_doublets_are_said_not_verified(flights: tuple[Path, list[Path], list[Path]]) -> None:
    """Lon doublets only: the lat, yaw and thr axes are named as not verified, with no TIC of nothing."""
    model, logs, _ = flights
    result = CliRunner().invoke(cli, ["validate", str(model), str(logs[0]), "--json", "-", "-q"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    for axis in ("lat", "yaw", "thr"):
        assert f"{axis}: no doublet in 1 log; not verified" in summary["notes"]
    assert not any(note.startswith("lon:") for note in summary["notes"])
    assert set(summary["summary"]) == {"u", "q", "theta", "ax"}


def test_an_unidentified_axis_is_not_verified(flights: tuple[Path, list[Path], list[Path]], tmp_path: Path) -> None:
    """A model written with --partial whose lon axis is unidentified: its lon doublets are not simulated, and said."""
    model, logs, _ = flights
    pitch = {"X_u", "M_u", "X_lon", "M_lon", "tau_lon"}
    partial = with_unidentified(read_model(model), pitch, {"lon": "no sweep found in 5 logs"})
    path = write_model(tmp_path / "partial.json", partial)
    result = CliRunner().invoke(cli, ["validate", str(path), str(logs[0])])
    assert result.exit_code == 1, result.output
    assert "no doublet found" in result.output
    assert (
        "lon: the model's lon axis is unidentified (no sweep found in 5 logs); its 1 doublet is not verified"
        in result.output
    )
