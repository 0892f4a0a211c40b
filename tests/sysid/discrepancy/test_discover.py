"""Discrepancy discovery on SIM / REAL pairs with one concealed effect (issue 15), through PX4 logs.

The pairs come from our simulator (:mod:`simulator.campaign.discrepancy_pairs`): one mission, the REAL flight with
the effect, another noise seed and its events moved by 2 %. The thresholds (a held-out score of 0.05,
and three times the term's score on held-out simulated flight) and the terms' shapes were set on seeds
1, 2, 3 and 5; these tests assert on seed 11. The truth is the simulator's own constants.

Measured on seed 11 (see the closing note of the commit for the other seeds): every verdict right,
the delay 30.0 ms (truth 30), the mass step +5.4 % at 70.0 s (truth 0.4 kg on 7.0 kg at 70 s), the CG
moment -0.348 rad/m (truth -m dx / I_yy = -0.350), the ground effect (eq. 2.3, exponential) acting up to
1.4 m and cutting the az residual by 72 %, about 2 s per pair after reading the logs. Open: the battery
exponent reads 2.22 (truth 2); the 1/(h + d)^2 shape puts the rotors 0.20 m above the logged height
(truth 0.08), d taking up the difference between the shapes.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from flightlogs.conditioning.condition import condition_flight
from flightlogs.readers import read_log
from simulator.campaign.discrepancy_pairs import write_pairs
from simulator.vehicle.presets import OCTO_S1000
from sysid.discrepancy import DiscrepancyResult, discover, flight_series
from sysid_cli.main import cli

pytestmark = [pytest.mark.slow, pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning")]

SEED = 11  # held out: the search was tuned on seeds 1, 2, 3 and 5
EFFECTS = ["none", "ground_effect", "battery_sag", "mass_change", "cg_offset", "time_delay", "actuator_lag"]


def _series(path: Path):  # type: ignore[no-untyped-def]
    return flight_series(path.name, condition_flight(read_log(path)).records)


@pytest.fixture(scope="module", name="pairs")
def pairs_fixture(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Path]]:
    return write_pairs(EFFECTS, tmp_path_factory.mktemp("discrepancy"), SEED)


@pytest.fixture(scope="module", name="results")
def results_fixture(pairs: tuple[Path, dict[str, Path]]) -> dict[str, DiscrepancyResult]:
    sim, reals = pairs
    simulated = _series(sim)
    return {effect: discover([simulated], [_series(path)]) for effect, path in reals.items()}


@pytest.mark.parametrize("effect", EFFECTS)
def test_the_verdict_names_the_concealed_effect_and_only_it(results: dict[str, DiscrepancyResult], effect: str) -> None:
    result = results[effect]
    assert result.verdict == effect, result.summary
    assert [f.effect for f in result.findings] == ([] if effect == "none" else [effect])
    for finding in result.findings:
        assert finding.improvement_percent > 0.0
        assert all(finding.rmse_after[o] < finding.rmse_before[o] for o in finding.outputs)


def test_nothing_missing_is_said_in_words(results: dict[str, DiscrepancyResult]) -> None:
    assert results["none"].summary.startswith("Nothing is missing")
    assert results["none"].to_dict()["findings"] == []


def _parameter(result: DiscrepancyResult, name: str) -> tuple[float, float]:
    (p,) = [p for p in result.findings[0].parameters if p.name == name]
    return p.value, p.uncertainty


def test_the_delay_is_the_one_added(results: dict[str, DiscrepancyResult]) -> None:
    """30 ms added to every input; the grid is 2.5 ms, so within a grid step and within 3 sigma."""
    value, sigma = _parameter(results["time_delay"], "delay_s")
    assert abs(value - 0.030) <= 0.0025 and abs(value - 0.030) <= 3 * sigma + 1e-9


def test_the_mass_step_has_its_size_and_time(results: dict[str, DiscrepancyResult]) -> None:
    """0.4 kg picked up at 70 s by a 7.0 kg vehicle: the specific force per thrust drops by 0.4 / 7.4."""
    ratio, _ = _parameter(results["mass_change"], "mass_ratio")
    time_s, time_sigma = _parameter(results["mass_change"], "time_s")
    assert ratio == pytest.approx(0.4 / 7.4, rel=0.05)
    assert abs(time_s - 70.0) <= max(0.5, 3 * time_sigma)
    assert results["mass_change"].findings[0].regime.variable == "time"


def test_the_cg_moment_is_mass_times_offset_over_inertia(results: dict[str, DiscrepancyResult]) -> None:
    """The CG 2 cm forward: pitch acceleration per specific thrust -m dx / I_yy (nose down)."""
    moment, _ = _parameter(results["cg_offset"], "pitch_moment_per_thrust")
    truth = -OCTO_S1000.mass_kg * 0.02 / OCTO_S1000.inertia_kg_m2[1]
    assert moment == pytest.approx(truth, rel=0.05)
    roll, _ = _parameter(results["cg_offset"], "roll_moment_per_thrust")
    assert abs(roll) < 0.05 * abs(truth)


@pytest.mark.xfail(
    strict=True,
    reason="open (issue 15): through the PX4 log the exponent reads 2.22 +- 0.016 on seeds 11-13 (1.9 on the "
    "simulator's own signals), 11 % high with a standard deviation that does not cover it",
)
def test_the_battery_exponent_is_that_of_thrust_on_rotor_speed(results: dict[str, DiscrepancyResult]) -> None:
    """Thrust grows with the rotor speed squared (thrust_expo 1) and the speed with the voltage: exponent 2."""
    assert OCTO_S1000.thrust_expo == 1.0
    exponent, _ = _parameter(results["battery_sag"], "exponent")
    assert exponent == pytest.approx(2.0, rel=0.1)


def test_the_lag_lies_between_the_added_and_the_whole_motor_lag(results: dict[str, DiscrepancyResult]) -> None:
    """Motors of 73 ms against 46 ms simulated: one extra first-order lag between their difference and the whole."""
    value, _ = _parameter(results["actuator_lag"], "time_constant_s")
    real = OCTO_S1000.motor_time_constant_s * 1.6
    assert real - OCTO_S1000.motor_time_constant_s <= value <= real


def test_the_ground_effect_is_located_near_the_ground(results: dict[str, DiscrepancyResult]) -> None:
    finding = results["ground_effect"].findings[0]
    assert finding.regime.variable == "height_agl" and finding.regime.high <= 1.2


def test_the_command_writes_json_and_report(pairs: tuple[Path, dict[str, Path]], tmp_path: Path) -> None:
    sim, reals = pairs
    out, report = tmp_path / "gap.json", tmp_path / "gap.html"
    result = CliRunner().invoke(
        cli, ["discrepancy", str(sim), str(reals["time_delay"]), "-o", str(out), "--report", str(report), "-q"]
    )
    assert result.exit_code == 0, result.output
    saved = json.loads(out.read_text())
    assert saved["verdict"] == "time_delay"
    finding = saved["findings"][0]
    for key in (
        "effect",
        "outputs",
        "band_rad_s",
        "regime",
        "explained_variance",
        "parameters",
        "rmse_before",
        "rmse_after",
        "improvement_percent",
        "evidence",
    ):
        assert key in finding
    assert finding["parameters"]["delay_s"]["unit"] == "s"
    page = report.read_text()
    assert "time_delay" in page and page.count("<svg") >= 1


def test_bad_input_is_one_sentence_and_exit_1(
    pairs: tuple[Path, dict[str, Path]], tmp_path: Path, real_data: Path
) -> None:
    sim, reals = pairs
    model = tmp_path / "model.json"
    model.write_text("{}")
    runner = CliRunner()
    result = runner.invoke(cli, ["discrepancy", str(model), str(reals["none"])])
    assert result.exit_code == 1 and "a fitted model as SIM is not supported yet" in result.output
    no_inputs = real_data / "kd0aij-impulse-response/log1.ulg"  # rates and setpoints only, no mixer input
    result = runner.invoke(cli, ["discrepancy", str(sim), str(no_inputs), "-o", str(tmp_path / "x.json")])
    assert result.exit_code == 1 and "not logged; the discrepancy search needs them" in result.output
    assert "Traceback" not in result.output and not (tmp_path / "x.json").exists()
    result = runner.invoke(cli, ["discrepancy", str(sim)])
    assert result.exit_code == 2
