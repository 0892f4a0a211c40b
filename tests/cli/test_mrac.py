"""``sysid mrac compare`` end to end: JSON summary, results file, report, fitted ground effect, errors."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sysid_cli.main import cli

SHORT = ["--trials", "2", "--pid-phase", "4", "--mrac-phase", "4", "-q"]


def test_compare_writes_summary_results_and_report(runner: CliRunner, tmp_path: Path) -> None:
    report, results = tmp_path / "mrac.html", tmp_path / "results.json"
    result = runner.invoke(
        cli,
        [
            "mrac",
            "compare",
            "--height-ratio",
            "4,3",
            "--height-ratio",
            "22",
            *SHORT,
            "--report",
            str(report),
            "-o",
            str(results),
            "--json",
            "-",
        ],
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert summary["height_ratios"] == [4.0, 3.0, 22.0] and summary["trials"] == 2
    for name in ("pid", "mrac_linear", "mrac_rbf"):
        stats = summary["controllers"][name]
        assert set(stats) == {"rise_time_s", "steady_state_error_m", "mse_m2", "overshoot_percent", "settling_time_s"}
        assert set(stats["mse_m2"]) == {"mean", "std", "n"} and stats["mse_m2"]["n"] == 3 * 2 * 2
    stored = json.loads(results.read_text())
    assert len(stored["cases"][0]["phases"]["takeoff"]["trials"]["mrac_rbf"]) == 2
    assert stored["controllers"] == summary["controllers"]
    page = report.read_text()
    assert page.count("<svg") >= 1 + 2 * 3 and not re.search(r'(src|href)\s*=\s*"(https?:)?//', page)
    assert "MRAC, RBF" in page and "Z/R ≈ 22" in page


def test_compare_defaults_to_the_dissertation_cases_and_prints_rise_times(runner: CliRunner) -> None:
    result = runner.invoke(cli, ["mrac", "compare", "--trials", "1", "--pid-phase", "4", "--mrac-phase", "4"])
    assert result.exit_code == 0, result.output
    lines = [line for line in result.output.splitlines() if line.startswith("Z/R")]
    assert [line.split()[1] for line in lines] == ["4", "4", "3", "3", "2", "2"]


def test_a_fitted_ground_effect_model_drives_the_vehicle(runner: CliRunner, tmp_path: Path) -> None:
    """The loop from data to controller: eq. 2.5 sampled, fitted, saved, and flown; same result as eq. 2.5 itself."""
    from simulator.world.environment import thrust_ratio
    from sysid.groundeffect import ThrustRatioData, fit_ground_effect, write_ground_effect_model

    x = np.linspace(1.1, 8.0, 40)
    fit = fit_ground_effect(
        ThrustRatioData(height_ratio=x, thrust_ratio=thrust_ratio(x, "fitted_4rotor"), rotor_radius_m=0.0225)
    )
    model = write_ground_effect_model(fit, tmp_path / "ge.json")
    args = [
        "mrac",
        "compare",
        "--height-ratio",
        "3",
        "--trials",
        "1",
        "--pid-phase",
        "6",
        "--mrac-phase",
        "6",
        "-q",
        "--json",
        "-",
    ]
    fitted = runner.invoke(cli, [*args, "--ground-effect", str(model)])
    plain = runner.invoke(cli, args)
    assert fitted.exit_code == 0 and plain.exit_code == 0, fitted.output + plain.output
    with_fit, with_law = json.loads(fitted.stdout), json.loads(plain.stdout)
    assert "ge.json" in with_fit["ground_effect"] and "eq. 2.5" in with_law["ground_effect"]
    for name in ("pid", "mrac_rbf"):
        a = with_fit["controllers"][name]["mse_m2"]["mean"]
        b = with_law["controllers"][name]["mse_m2"]["mean"]
        assert a == pytest.approx(b, rel=0.05)  # the fit reproduces eq. 2.5 to its RMSE


@pytest.mark.parametrize(
    ("args", "code", "fragment"),
    [
        (["--height-ratio", "four"], 2, "is not a number"),
        (["--height-ratio", "-1"], 2, "must be > 0"),
        (["--trials", "0"], 2, "--trials"),
        (["--height-ratio", "1"], 1, "below the rotors' height on the ground"),
    ],
)
def test_bad_options_are_usage_or_data_errors(runner: CliRunner, args: list[str], code: int, fragment: str) -> None:
    result = runner.invoke(cli, ["mrac", "compare", *args, "-q"])
    assert result.exit_code == code
    assert fragment in result.stderr and "Traceback" not in result.output


def test_a_file_that_is_not_a_model_is_exit_1(runner: CliRunner, tmp_path: Path) -> None:
    bogus = tmp_path / "ge.json"
    bogus.write_text("{}")
    out = tmp_path / "results.json"
    result = runner.invoke(cli, ["mrac", "compare", "--ground-effect", str(bogus), "-o", str(out), "-q"])
    assert result.exit_code == 1 and "not a ground-effect model" in result.stderr
    assert not out.exists()
