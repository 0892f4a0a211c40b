"""Discrepancy discovery on SIM / REAL pairs with one concealed effect (issue 15), through PX4 logs.

The pairs come from our simulator (:mod:`simulator.campaign.discrepancy_pairs`): one 4-minute mission
(sweeps, legs, height steps), the REAL flight with the effect, another noise seed and its events moved
by 2 %, for the octocopter (every effect) and the quad (six). The thresholds (a held-out score of 0.05,
and three times the term's score on held-out simulated flight) and the terms' shapes were set on seeds
1, 2, 3 and 5 of the octocopter; these tests assert on seed 11. The truth is the simulator's own
constants: the delay added, the mass step, -m dx / I_yy of the CG offset, the rotors' drag coefficient
-X_u / g (which is also the drag per thrust on a wind), the motor lag. The benchmark
(``benchmarks/bench_discrepancy.py``) runs the whole matrix on other seeds. Open: the battery exponent
reads about 2.2 (truth 2).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from flightlogs.conditioning.condition import condition_flight
from flightlogs.readers import read_log
from simulator.campaign.discrepancy_pairs import VEHICLES, mission, write_pairs, write_sweep_flight
from simulator.vehicle.linearize import hover_derivatives, linearize_hover
from simulator.vehicle.multirotor import Vehicle
from simulator.world.environment import Environment
from sysid.discrepancy import DiscrepancyResult, compare_responses, discover, model_flight
from sysid.fit.model_file import read_model
from sysid_cli.main import cli

from builders import discrepancy_series

# the pairs fly 17 four-minute flights and search each: about 6 minutes of one core, a third of the suite;
# a `long` run (CI runs it after the suite); the independent generator's pairs stay in the default run
pytestmark = [
    pytest.mark.long,
    pytest.mark.timeout(1200),
    pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning"),
]

SEED = 11  # held out: the search was tuned on seeds 1, 2, 3 and 5
#: Per vehicle, the effects flown (the quad's a subset, for time: the benchmark flies all of them).
EFFECTS: dict[str, list[str]] = {
    "octo": [
        "none",
        "ground_effect",
        "rotor_drag",
        "wind",
        "battery_sag",
        "mass_change",
        "cg_offset",
        "time_delay",
        "actuator_lag",
    ],
    "quad": ["none", "ground_effect", "rotor_drag", "wind", "cg_offset", "actuator_lag"],
}
#: Cases the open-world search (issue 30) gets wrong on this simulator, as measured on 2026-11-28 (CI, seed as below):
#: the battery's sag leaves a thrust trim read as control_effectiveness. Issue 30 stays open on it.
_OPEN = {
    ("octo", "battery_sag"): "battery_sag and control_effectiveness (the trim beside the sag)",
}
CASES = [
    pytest.param(v, e, marks=pytest.mark.xfail(strict=False, reason=_OPEN[v, e])) if (v, e) in _OPEN else (v, e)
    for v, effects in EFFECTS.items()
    for e in effects
]


@pytest.fixture(scope="module", name="pairs")
def pairs_fixture(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, dict[str, Path]]]:
    return {
        v: write_pairs(e, tmp_path_factory.mktemp(f"discrepancy-{v}"), SEED, VEHICLES[v]) for v, e in EFFECTS.items()
    }


@pytest.fixture(scope="module", name="results")
def results_fixture(pairs: dict[str, tuple[Path, dict[str, Path]]]) -> dict[tuple[str, str], DiscrepancyResult]:
    out = {}
    for vehicle, (sim, reals) in pairs.items():
        simulated = discrepancy_series(sim)
        out |= {(vehicle, effect): discover([simulated], [discrepancy_series(path)]) for effect, path in reals.items()}
    return out


Results = dict[tuple[str, str], DiscrepancyResult]


@pytest.fixture(scope="module", name="models")
def models_fixture(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The hover model ``sysid fit`` makes of the octocopter's sweeps in SIM's air ("fitted"), and the same
    file with the simulator's own hover derivatives, its linearisation, in place of the fitted ones ("exact")."""
    folder = tmp_path_factory.mktemp("discrepancy-models")
    fitted = folder / "fitted.json"
    sweeps = write_sweep_flight(folder, SEED, VEHICLES["octo"])
    result = CliRunner().invoke(cli, ["fit", str(sweeps), "--model", "hover", "-o", str(fitted), "-q"])
    assert result.exit_code == 0, result.output
    truth = hover_derivatives(linearize_hover(VEHICLES["octo"]))
    document = json.loads(fitted.read_text())
    for name, entry in document["parameters"].items():  # control derivatives: per % of mixer input in the
        entry["value"] = truth[name] * (100.0 if " per " in entry["unit"] else 1.0)  # simulator, per unit logged
    exact = folder / "exact.json"
    exact.write_text(json.dumps(document))
    return {"fitted": fitted, "exact": exact}


MODEL_CASES = ("none", "time_delay", "cg_offset")


@pytest.fixture(scope="module", name="against_models")
def against_models_fixture(
    pairs: dict[str, tuple[Path, dict[str, Path]]], models: dict[str, Path]
) -> dict[tuple[str, str], DiscrepancyResult]:
    _, reals = pairs["octo"]
    out = {}
    for kind, path in models.items():
        model = read_model(path).linear_model(include_wind=False)
        for effect in MODEL_CASES:
            real = discrepancy_series(reals[effect])
            out[kind, effect] = discover([model_flight(model, real, source=path.name)], [real])
    return out


@pytest.mark.parametrize(("vehicle", "effect"), CASES)
def test_the_verdict_names_the_concealed_effect_and_only_it(results: Results, vehicle: str, effect: str) -> None:
    result = results[vehicle, effect]
    assert result.verdict == effect, result.summary
    assert [f.effect for f in result.findings] == ([] if effect == "none" else [effect])
    for finding in result.findings:
        assert finding.improvement_percent > 0.0
        assert all(finding.rmse_after[o] < finding.rmse_before[o] for o in finding.outputs)


def test_nothing_missing_is_said_in_words(results: Results) -> None:
    for vehicle in EFFECTS:
        assert results[vehicle, "none"].summary.startswith("Nothing is missing")
        assert results[vehicle, "none"].to_dict()["findings"] == []


def _parameter(result: DiscrepancyResult, name: str) -> tuple[float, float]:
    (p,) = [p for p in result.findings[0].parameters if p.name == name]
    return p.value, p.uncertainty


def test_the_delay_is_the_one_added(results: Results) -> None:
    """30 ms added to every input; the grid is 2.5 ms, so within a grid step and within 3 sigma."""
    value, sigma = _parameter(results["octo", "time_delay"], "delay_s")
    assert abs(value - 0.030) <= 0.0025 and abs(value - 0.030) <= 3 * sigma + 1e-9


def test_the_mass_step_has_its_size_and_time(results: Results) -> None:
    """5.7 % of the mass picked up at 70 s: the specific force per thrust drops by 0.057 / 1.057."""
    ratio, _ = _parameter(results["octo", "mass_change"], "mass_ratio")
    fraction, _ = _parameter(results["octo", "mass_change"], "mass_change_fraction")
    time_s, time_sigma = _parameter(results["octo", "mass_change"], "time_s")
    assert ratio == pytest.approx(0.057 / 1.057, rel=0.05)
    assert fraction == pytest.approx(0.057, rel=0.05) and fraction == pytest.approx(ratio / (1.0 - ratio), rel=1e-12)
    said = re.search(r"The mass changes by \+(\d+\.\d+) ± ", results["octo", "mass_change"].summary)
    assert said is not None and float(said.group(1)) == pytest.approx(100.0 * fraction, abs=0.01)
    assert abs(time_s - 70.0) <= max(0.5, 3 * time_sigma)
    assert results["octo", "mass_change"].findings[0].regime.variable == "time"


def _arm_m(vehicle: Vehicle) -> float:
    return float(np.max(np.hypot(*vehicle.rotor_positions_m[:, :2].T)))


@pytest.mark.parametrize("name", ["octo", "quad"])
def test_the_cg_moment_is_mass_times_offset_over_inertia(results: Results, name: str) -> None:
    """The CG 3.8 % of the arm forward: pitch acceleration per specific thrust -m dx / I_yy (nose down), no roll."""
    vehicle = VEHICLES[name]
    moment, _ = _parameter(results[name, "cg_offset"], "pitch_moment_per_thrust")
    truth = -vehicle.mass_kg * 0.038 * _arm_m(vehicle) / vehicle.inertia_kg_m2[1]
    assert moment == pytest.approx(truth, rel=0.05)
    # no roll moment is claimed: p_dot dropped as an output the term leaves at the floor, or a small one
    finding = results[name, "cg_offset"].findings[0]
    roll = [p.value for p in finding.parameters if p.name == "roll_moment_per_thrust"]
    assert ("p_dot" in finding.outputs) == bool(roll) and all(abs(r) < 0.05 * abs(truth) for r in roll), roll


@pytest.mark.parametrize("name", ["octo", "quad"])
@pytest.mark.parametrize(("effect", "variable"), [("rotor_drag", "ground_speed"), ("wind", "wind_speed")])
def test_the_drag_per_thrust_and_speed_is_the_rotors(results: Results, name: str, effect: str, variable: str) -> None:
    """Rotors dragging twice the simulated, or hovering in a wind the simulation lacked: either way the term's
    drag per specific thrust and speed is the rotors' own d = -X_u / g, located by the speed it follows."""
    finding = results[name, effect].findings[0]
    drag, _ = _parameter(results[name, effect], "drag_x")
    assert drag == pytest.approx(VEHICLES[name].drag_s_m[0], rel=0.05)
    assert finding.regime.variable == variable


@pytest.mark.parametrize("name", ["octo", "quad"])
def test_the_wind_pitches_at_the_hubs(results: Results, name: str) -> None:
    """The wind's drag acts at the hubs, above the CG, and flaps the discs back: per specific thrust and m/s of
    wind a pitch acceleration -m (d_x h + flapping_x) / I_yy, h the hubs' height (the simulator's constants)."""
    vehicle = VEHICLES[name]
    height_m = -float(np.mean(vehicle.rotor_positions_m[:, 2]))
    truth = vehicle.mass_kg * (vehicle.drag_s_m[0] * height_m + vehicle.flapping_s[0]) / vehicle.inertia_kg_m2[1]
    moment, _ = _parameter(results[name, "wind"], "pitch_moment_per_wind")
    assert moment == pytest.approx(-truth, rel=0.05)


@pytest.mark.xfail(
    strict=True,
    reason="open (issue 15): through the PX4 log the exponent reads 2.22 +- 0.016 on seeds 11-13 (1.9 on the "
    "simulator's own signals), 11 % high with a standard deviation that does not cover it",
)
def test_the_battery_exponent_is_that_of_thrust_on_rotor_speed(results: Results) -> None:
    """Thrust grows with the rotor speed squared (thrust_expo 1) and the speed with the voltage: exponent 2."""
    assert VEHICLES["octo"].thrust_expo == 1.0
    exponent, _ = _parameter(results["octo", "battery_sag"], "exponent")
    assert exponent == pytest.approx(2.0, rel=0.1)


@pytest.mark.parametrize("name", ["octo", "quad"])
def test_the_lag_lies_between_the_added_and_the_whole_motor_lag(results: Results, name: str) -> None:
    """Motors 1.6 times slower than simulated: one extra first-order lag between their difference and the whole."""
    vehicle = VEHICLES[name]
    value, _ = _parameter(results[name, "actuator_lag"], "time_constant_s")
    real = vehicle.motor_time_constant_s * 1.6
    assert real - vehicle.motor_time_constant_s <= value <= real


@pytest.mark.parametrize("name", ["octo", "quad"])
def test_the_ground_effect_is_located_near_the_ground(results: Results, name: str) -> None:
    """Located below the mission's second height step (6.7 rotor radii), where the thrust gain is under 0.1 %."""
    finding = results[name, "ground_effect"].findings[0]
    second_step = mission(Environment(), SEED, vehicle=VEHICLES[name]).height_steps.heights_m[1]  # type: ignore[union-attr]
    assert finding.regime.variable == "height_agl" and finding.regime.high <= second_step


def test_the_command_writes_json_and_report(pairs: dict[str, tuple[Path, dict[str, Path]]], tmp_path: Path) -> None:
    sim, reals = pairs["octo"]
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
    assert "time_delay" in page and page.count("<svg") >= 2  # the finding's residuals, the responses
    assert "Real against simulated frequency responses" in page and "p/delta_lat" in page


def test_against_the_simulators_own_model_only_the_concealed_effect_is_found(
    against_models: Results,
) -> None:
    """A model in SIM's place, evaluated along the real flight: with the simulator's exact hover derivatives
    nothing is missing from the null flight, and the delay and the CG moment are measured as from a log."""
    assert against_models["exact", "none"].verdict == "none", against_models["exact", "none"].summary
    for effect in ("time_delay", "cg_offset"):
        assert [f.effect for f in against_models["exact", effect].findings] == [effect]
    delay, sigma = _parameter(against_models["exact", "time_delay"], "delay_s")
    assert abs(delay - 0.030) <= 0.0025 and abs(delay - 0.030) <= 3 * sigma + 1e-9
    octo = VEHICLES["octo"]
    moment, _ = _parameter(against_models["exact", "cg_offset"], "pitch_moment_per_thrust")
    assert moment == pytest.approx(-octo.mass_kg * 0.038 * _arm_m(octo) / octo.inertia_kg_m2[1], rel=0.05)


def test_against_a_fitted_model_its_own_error_is_found_beside_the_concealed_effect(
    against_models: Results, models: dict[str, Path]
) -> None:
    """The fitted model's speed damping X_u, Y_v is short of the truth (closed-loop sweeps, issue 14); on the
    legs that shortfall is drag the model leaves out: rotor_drag, with d = (X_u fitted - X_u true) / g."""
    truth = hover_derivatives(linearize_hover(VEHICLES["octo"]))
    fitted = read_model(models["fitted"])
    shortfall = {
        axis: (fitted.parameter(name).value - truth[name]) / 9.81 for axis, name in (("x", "X_u"), ("y", "Y_v"))
    }
    assert min(shortfall.values()) > 0.003  # the model has at least a third less speed damping than the truth
    null = against_models["fitted", "none"]
    assert [f.effect for f in null.findings] == ["rotor_drag"], null.summary
    for axis, expected in shortfall.items():
        drag, _ = _parameter(null, f"drag_{axis}")
        assert drag == pytest.approx(expected, rel=0.1)
    for effect in ("time_delay", "cg_offset"):
        assert {f.effect for f in against_models["fitted", effect].findings} == {effect, "rotor_drag"}
    (delay,) = [p for f in against_models["fitted", "time_delay"].findings for p in f.parameters if p.name == "delay_s"]
    assert abs(delay.value - 0.030) <= 0.0025


def test_a_fitted_model_as_sim_through_the_command(
    pairs: dict[str, tuple[Path, dict[str, Path]]], models: dict[str, Path], tmp_path: Path
) -> None:
    _, reals = pairs["octo"]
    out, report = tmp_path / "gap.json", tmp_path / "gap.html"
    arguments = ["discrepancy", str(models["exact"]), str(reals["time_delay"]), "-o", str(out), "--report", str(report)]
    result = CliRunner().invoke(cli, [*arguments, "-q"])
    assert result.exit_code == 0, result.output
    assert json.loads(out.read_text())["verdict"] == "time_delay"
    page = report.read_text()
    assert "Real against simulated frequency responses" in page and "p/delta_lat" in page
    assert ">model</text>" in page  # the Bode legend names the model, not a simulated flight
    assert "exact.json</span>, a fitted model evaluated along each real flight" in page
    mixed = CliRunner().invoke(cli, ["discrepancy", str(models["exact"]), str(pairs["octo"][0]), "--real", str(out)])
    assert mixed.exit_code == 1 and "a fitted model is the whole simulation" in mixed.output


def test_a_model_beyond_the_j_guideline_is_not_close_enough_to_judge(
    pairs: dict[str, tuple[Path, dict[str, Path]]], models: dict[str, Path], tmp_path: Path
) -> None:
    """Issue 33: with the simulator's own model nothing is missing on the null flight; the same model in a file
    whose J_ave is 216 (beyond the 150 of an acceptable fit) is not judged: it cannot tell what it leaves out
    from its own misfit, and says so."""
    _, reals = pairs["octo"]
    document = json.loads(models["exact"].read_text())
    assert document["cost"]["average"] <= 150.0
    poor = tmp_path / "poor.json"
    poor.write_text(json.dumps(document | {"cost": document["cost"] | {"average": 216.0}}))
    verdicts = {}
    for model in (models["exact"], poor):
        result = CliRunner().invoke(cli, ["discrepancy", str(model), str(reals["none"]), "--json", "-", "-q"])
        assert result.exit_code == 0, result.output
        verdicts[model.name] = json.loads(result.stdout)
    assert verdicts["exact.json"]["verdict"] == "none"
    assert verdicts["exact.json"]["summary"].startswith("Nothing is missing")
    assert verdicts["poor.json"]["verdict"] == "not_judged" and verdicts["poor.json"]["findings"] == []
    assert verdicts["poor.json"]["summary"] == (
        "Not judged: poor.json fits its own responses with J_ave 216, beyond the 150 of an acceptable fit, so it is "
        "not close enough to its own flights to tell what it leaves out from its own misfit."
    )


def test_bad_input_is_one_sentence_and_exit_1(
    pairs: dict[str, tuple[Path, dict[str, Path]]], tmp_path: Path, real_data: Path
) -> None:
    sim, reals = pairs["octo"]
    model = tmp_path / "model.json"
    model.write_text("{}")
    runner = CliRunner()
    result = runner.invoke(cli, ["discrepancy", str(model), str(reals["none"])])
    assert result.exit_code == 1 and str(model) in result.output and "Traceback" not in result.output
    no_inputs = real_data / "kd0aij-impulse-response/log1.ulg"  # rates and setpoints only, no mixer input
    result = runner.invoke(cli, ["discrepancy", str(sim), str(no_inputs), "-o", str(tmp_path / "x.json")])
    assert result.exit_code == 1 and "not logged; the discrepancy search needs them" in result.output
    assert "Traceback" not in result.output and not (tmp_path / "x.json").exists()
    result = runner.invoke(cli, ["discrepancy", str(sim)])
    assert result.exit_code == 2


def test_a_rotor_radius_gives_the_ground_effect_end_in_rotor_radii(
    pairs: dict[str, tuple[Path, dict[str, Path]]],
) -> None:
    """``--rotor-radius``: the end of the ground effect also as the rotor plane's Z/R (its height plus d, over R)."""
    sim, reals = pairs["octo"]
    radius = VEHICLES["octo"].rotor_radius_m
    result = CliRunner().invoke(
        cli, ["discrepancy", str(sim), str(reals["ground_effect"]), "--rotor-radius", str(radius), "--json", "-", "-q"]
    )
    assert result.exit_code == 0, result.output
    parameters = json.loads(result.stdout)["findings"][0]["parameters"]
    plane = parameters["ends_at_height"]["value"] + parameters["rotor_above_height_m"]["value"]
    assert parameters["ends_at_height_over_radius"]["value"] == pytest.approx(plane / radius, rel=1e-9)
    assert parameters["ends_at_height_over_radius"]["unit"] == "1"


def test_the_delay_shows_in_the_responses_as_phase_growing_with_frequency(
    pairs: dict[str, tuple[Path, dict[str, Path]]],
) -> None:
    """30 ms more delay: the real response lags the simulated one by ω τ at equal magnitude (e^{-jωτ}).

    τ from the phase's slope (least squares through the origin over 2-15 rad/s where γ² >= 0.9) lies
    within one step (2.5 ms) of the search's grid of the truth; the median magnitude change within 1 dB.
    """
    sim, reals = pairs["octo"]
    comparisons = compare_responses(
        [condition_flight(read_log(sim))], [condition_flight(read_log(reals["time_delay"]))]
    )
    assert {c.pair for c in comparisons} == {"p/delta_lat", "q/delta_lon", "r/delta_yaw"}
    for comparison in comparisons:
        omega, simulated = comparison.real.omega, comparison.sim_on_real_omega
        band = (comparison.real.coherence >= 0.9) & (omega >= 2.0) & (omega <= 15.0) & np.isfinite(simulated)
        assert np.count_nonzero(band) >= 10, comparison.pair
        ratio = comparison.real.response[band] / simulated[band]
        lag = -np.unwrap(np.angle(ratio))
        tau = float(np.sum(omega[band] * lag) / np.sum(omega[band] ** 2))
        assert tau == pytest.approx(0.030, abs=0.0025), comparison.pair
        assert np.median(np.abs(20 * np.log10(np.abs(ratio)))) < 1.0, comparison.pair
