"""``sysid modes``: published derivatives and model files, JSON fields, usage errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from simulator.vehicle.identified import CALM_HOVER
from sysid.fit import fit_frequency_responses, model_from_fit, synthetic_responses, write_model
from sysid.model import load_structure, structure_model
from sysid_cli.main import cli

TABLE_3_3_CALM = [
    "X_u=-0.3172",
    "M_u=0.7690",
    "X_lon=-0.0985",
    "M_lon=0.5251",
    "Y_v=-0.2787",
    "L_v=-0.7406",
    "Y_lat=0.1185",
    "L_lat=0.6226",
    "N_yaw=0.0744",
    "Z_thr=-0.8712",
    "T_a=0.0458",
]


def test_modes_of_published_derivatives_are_the_si_values(runner: CliRunner) -> None:
    args = ["modes", "--model", "hover", "--json", "-"]
    for item in TABLE_3_3_CALM:
        args += ["--set", item]
    result = runner.invoke(cli, args)
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    pitch = sorted((m for m in summary["eigenvalues"] if m["mode"] == "pitch"), key=lambda m: -m["real"])
    assert pitch[0]["real"] == pytest.approx(0.878, abs=5e-4) and pitch[0]["imag"] == pytest.approx(1.694, abs=5e-4)
    assert pitch[1]["real"] == pytest.approx(-2.073, abs=5e-4)
    roll = sorted((m for m in summary["eigenvalues"] if m["mode"] == "roll"), key=lambda m: -m["real"])
    assert roll[0]["imag"] == pytest.approx(1.674, abs=5e-4) and roll[1]["real"] == pytest.approx(-2.034, abs=5e-4)
    assert set(summary["unset"]) >= {"N_r", "Z_w"} and "unstable" in result.stderr


def test_modes_of_a_model_file(runner: CliRunner, tmp_path: Path) -> None:
    structure = load_structure("hover")
    truth, _ = structure_model(structure, dict(CALM_HOVER))
    fit = fit_frequency_responses(
        structure, synthetic_responses(truth, ["q/delta_lon", "ax/delta_lon"], fit_range=(0.8, 50.0))
    )
    path = write_model(tmp_path / "model.json", model_from_fit(fit))
    result = runner.invoke(cli, ["modes", str(path), "--json", "-", "-q"])
    assert result.exit_code == 0, result.output
    reals = sorted(m["real"] for m in json.loads(result.stdout)["eigenvalues"] if m["mode"] == "pitch")
    assert reals == pytest.approx([-2.073, 0.878], abs=5e-4)  # noise-free fit: exact to the table's rounding


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (["modes"], 2, "either MODEL_FILE"),
        (["modes", "--model", "hover", "--set", "Q=1"], 1, "no parameter 'Q'"),
        (["modes", "--model", "hover", "--set", "X_u=abc"], 2, "NAME=VALUE"),
    ],
)
def test_modes_errors(runner: CliRunner, args: list[str], code: int, message: str) -> None:
    result = runner.invoke(cli, args)
    assert result.exit_code == code, result.output
    assert message in result.output


def test_modes_of_a_partial_model_are_those_of_its_identified_axes(runner: CliRunner, tmp_path: Path) -> None:
    """A model of pitch only: its pitch modes, and a line saying the other axes' modes are not known."""
    structure = load_structure("hover")
    truth, _ = structure_model(structure, dict(CALM_HOVER))
    responses = synthetic_responses(truth, ["q/delta_lon", "ax/delta_lon", "u/delta_lon"], fit_range=(0.8, 50.0))
    path = write_model(tmp_path / "pitch.json", model_from_fit(fit_frequency_responses(structure, responses)))
    result = runner.invoke(cli, ["modes", str(path), "--json", "-"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert summary["unidentified_axes"] == ["lat", "yaw", "thr"]
    assert {m["mode"] for m in summary["eigenvalues"]} <= {"pitch", "actuator"}
    assert "the lat, yaw, thr axes are unidentified: their modes are not known and not listed" in result.stderr
