"""``sysid ground-effect fit|spacing`` end to end: exit codes, JSON, the model file and report, bad input."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sysid.groundeffect import formulas as laws
from sysid.groundeffect import read_ground_effect_model
from sysid_cli.main import cli

R = 0.0225
F0 = 0.374  # N: the Crazyflie's hover thrust (0.03812 kg)
EQ_2_5 = (laws.FITTED_4ROTOR_SLOPE, laws.FITTED_4ROTOR_INTERCEPT, laws.FITTED_4ROTOR_BREAKPOINT)
HEIGHTS_CM = np.arange(2.5, 20.51, 1.0)


def rig_csv(
    path: Path,
    ratio: np.ndarray,
    *,
    readings: int,
    sigma: float,
    seed: int,
    header: str = "height_cm,thrust_g",
    heights_cm: np.ndarray = HEIGHTS_CM,
) -> Path:
    """A rig file in a scale's units (cm, grams of force), `readings` per height, noise `sigma` in F/F0."""
    rng = np.random.default_rng(seed)
    heights = np.repeat(heights_cm, readings)
    thrust_g = F0 * (np.repeat(ratio, readings) + rng.normal(0, sigma, heights.size)) / 9.80665e-3
    path.write_text(header + "\n" + "".join(f"{h:.1f},{f:.4f}\n" for h, f in zip(heights, thrust_g)))
    return path


def test_fit_rig_csv_recovers_eq_2_5_and_writes_model_and_report(runner: CliRunner, tmp_path: Path) -> None:
    x = HEIGHTS_CM / 100 / R
    data = rig_csv(tmp_path / "rig.csv", laws.piecewise_linear(x, *EQ_2_5), readings=60, sigma=0.0103, seed=5)
    out, report = tmp_path / "ge.json", tmp_path / "ge.html"
    result = runner.invoke(
        cli,
        [
            "ground-effect",
            "fit",
            str(data),
            "--rotor-radius",
            str(R),
            "-o",
            str(out),
            "--report",
            str(report),
            "--json",
            "-",
        ],
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert summary["best"] == "piecewise_linear"
    assert summary["f0_source"].startswith("mean of 180 rows with Z/R > 8")  # 18.5-20.5 cm: Z/R 8.2-9.1
    params = summary["models"]["piecewise_linear"]["params"]
    np.testing.assert_allclose([params["slope"], params["intercept"], params["breakpoint"]], EQ_2_5, rtol=0.05)
    for name in ("cheeseman_bennett", "corrected", "exponential", "piecewise_linear"):
        model = summary["models"][name]
        assert set(model) >= {"params", "ci", "rmse", "r2"} and set(model["ci"]) == set(model["params"])
    low, high = summary["models"]["corrected"]["ci"]["rho"]
    assert low < summary["models"]["corrected"]["params"]["rho"] < high
    model = read_ground_effect_model(out)
    assert model.model == "piecewise_linear" and model.params == pytest.approx(params)
    page = report.read_text()
    assert page.count("<svg") >= 2 and "chosen" in page
    assert not re.search(r"(src|href)=[\"']https?:", page)  # self-contained: no fetches


def test_fit_human_output_and_f0_given(runner: CliRunner, tmp_path: Path) -> None:
    x = HEIGHTS_CM[:8] / 100 / R  # all in ground effect: no rows above Z/R 8
    data = (
        rig_csv(
            tmp_path / "low.csv",
            laws.corrected(x, 3.315),
            readings=3,
            sigma=0.002,
            seed=1,
            header="Z (cm),F [g]",
            heights_cm=HEIGHTS_CM[:8],
        )
        .read_text()
        .replace(",", ";")
    )
    (tmp_path / "low.csv").write_text(data)
    args = [
        "ground-effect",
        "fit",
        str(tmp_path / "low.csv"),
        "--rotor-radius",
        str(R),
        "--columns",
        "height=Z (cm),thrust=F [g]",
    ]
    result = runner.invoke(cli, args)
    assert result.exit_code == 1
    assert "low.csv: no reading above Z/R = 8" in result.output and "--f0" in result.output
    result = runner.invoke(cli, [*args, "--f0", str(F0)])
    assert result.exit_code == 0, result.output
    assert "chosen: corrected" in result.stdout and "rho 3.3" in result.stdout


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (["--rotor-radius", "0.0225", "--models", "quartic"], 2, "quartic: choose from"),
        ([], 2, "Missing option '--rotor-radius'"),
        (["--rotor-radius", "0.0225", "--units", "height=cm,weight=g"], 2, "weight: only height= and thrust="),
    ],
)
def test_fit_usage_errors(runner: CliRunner, tmp_path: Path, args: list[str], code: int, message: str) -> None:
    data = rig_csv(tmp_path / "rig.csv", np.ones(HEIGHTS_CM.size), readings=1, sigma=0.0, seed=0)
    result = runner.invoke(cli, ["ground-effect", "fit", str(data), *args])
    assert result.exit_code == code
    assert message in result.output


def test_fit_bad_rig_file_names_the_line(runner: CliRunner, tmp_path: Path) -> None:
    data = tmp_path / "rig.csv"
    data.write_text("height_m,thrust_n\n0.03,0.41\n0.04,n/a\n")
    result = runner.invoke(cli, ["ground-effect", "fit", str(data), "--rotor-radius", "0.0225", "--f0", "0.4"])
    assert result.exit_code == 1
    assert "rig.csv, line 3: column 'thrust_n' has no value" in result.output
    assert "Traceback" not in result.output


def test_spacing_finds_the_transition_and_writes_the_report(runner: CliRunner, tmp_path: Path) -> None:
    x = HEIGHTS_CM / 100 / R
    files = []
    for i, w in enumerate(
        [1.0, 0.9, 0.8, 0.2, 0.1, 0.0]
    ):  # see tests/sysid/groundeffect/test_fitting.py: spacing_series
        ratio = w * laws.piecewise_linear(x, *EQ_2_5) + (1 - w) * laws.corrected(x, 3.0)
        files.append(str(rig_csv(tmp_path / f"rig_{10 * i}mm.csv", ratio, readings=3, sigma=0.0103, seed=40 + i)))
    report = tmp_path / "spacing.html"
    result = runner.invoke(
        cli,
        [
            "ground-effect",
            "spacing",
            *files,
            "--spacing",
            "0,10,20,30,40,50",
            "--rotor-radius",
            str(R),
            "--report",
            str(report),
            "--json",
            "-",
        ],
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert summary["transition_mm"] == pytest.approx(30.0)
    assert summary["chosen"] == ["piecewise_linear"] * 3 + ["corrected"] * 3
    assert [s["source"] for s in summary["sets"]] == [Path(f).name for f in files]
    assert "30 mm" in report.read_text()
    human = runner.invoke(
        cli, ["ground-effect", "spacing", *files, "--spacing", "0,10,20,30,40,50", "--rotor-radius", str(R)]
    )
    assert "transition piecewise_linear -> corrected: at 30 mm" in human.stdout


def test_spacing_needs_one_spacing_per_file(runner: CliRunner, tmp_path: Path) -> None:
    data = rig_csv(tmp_path / "rig.csv", np.ones(HEIGHTS_CM.size), readings=1, sigma=0.0, seed=0)
    result = runner.invoke(
        cli, ["ground-effect", "spacing", str(data), str(data), "--spacing", "0", "--rotor-radius", "0.0225"]
    )
    assert result.exit_code == 2 and "2 files but 1 spacings" in result.output
    result = runner.invoke(cli, ["ground-effect", "spacing", str(data), "--spacing", "0,x", "--rotor-radius", "1"])
    assert result.exit_code == 2 and "not a comma-separated list" in result.output


def test_help_has_examples(runner: CliRunner) -> None:
    for command in (["ground-effect"], ["ground-effect", "fit"], ["ground-effect", "spacing"]):
        result = runner.invoke(cli, [*command, "--help"])
        assert result.exit_code == 0 and "Examples:" in result.output
