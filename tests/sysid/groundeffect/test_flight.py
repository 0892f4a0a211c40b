"""Ground effect from a flight log's hover steps (chapter 2's flight test, eq. 2.6).

A synthetic log checks the step detection and the eq. 2.6 arithmetic
exactly; the simulated chapter-2 flight (slow) checks the whole path against
the eq. 2.5 truth the simulator flies.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from flightlogs.errors import DataError, MissingSignalError
from flightlogs.flightlog import FlightLog, Signal
from sysid.groundeffect import GroundEffectDataConfig, fit_ground_effect, flight_thrust_ratio, plateaus
from sysid.groundeffect import formulas as laws

R = 0.0225  # Crazyflie propeller radius, m
MASS, G, KF, FULL = 0.03812, 9.81, 2.083e-6, 65535.0  # Table 2.1 (mass read as 0.03812 kg), 16-bit PWM
EQ_2_5 = (laws.FITTED_4ROTOR_SLOPE, laws.FITTED_4ROTOR_INTERCEPT, laws.FITTED_4ROTOR_BREAKPOINT)
# the scenario's steps (simulator/campaign/builtin/chapter2-ground-effect.toml), 10 s each
HEIGHTS_M = (0.230, 0.184, 0.161, 0.138, 0.115, 0.092, 0.069, 0.058, 0.046, 0.035)
HEIGHT_NOISE_M, MOTOR_NOISE = 0.005, 0.005


def synthetic_log(*, ground_s: float = 6.0, seed: int = 0, motors: bool = True) -> FlightLog:
    """On the ground (motors idle), take off, then 10 s hover steps with 1.5 s cosine transitions.

    The thrust is m (g + z'') throughout; F0 = F / (F/F0 of eq. 2.5) at the
    true height; 100 Hz, white noise on height (5 mm) and on each motor (0.5 %).
    """
    rate, hold, ramp = 100.0, 10.0, 1.5
    levels = (0.005,) + HEIGHTS_M
    starts = [0.0] + [ground_s + hold * k for k in range(len(HEIGHTS_M))]
    time_s = np.arange(0.0, starts[-1] + hold, 1 / rate)
    height = np.full_like(time_s, levels[0])
    for k in range(1, len(levels)):
        phase = np.clip((time_s - starts[k]) / ramp, 0.0, 1.0)
        height += (levels[k] - levels[k - 1]) * (1 - np.cos(np.pi * phase)) / 2
    accel = np.gradient(np.gradient(height, time_s), time_s)
    f0 = MASS * (G + accel) / laws.piecewise_linear(height / R, *EQ_2_5)
    f0[time_s < ground_s] = 0.02  # idling on the ground
    rng = np.random.default_rng(seed)
    signals = {
        "height_agl": Signal(
            name="height_agl",
            time_s=time_s,
            values=height + rng.normal(0, HEIGHT_NOISE_M, time_s.size),
            unit="m",
            source="vehicle_local_position[0].dist_bottom",
        )
    }
    for i in range(1, 5 if motors else 1):
        command = f0 / 4 / (KF * FULL) * (1 + rng.normal(0, MOTOR_NOISE, time_s.size))
        signals[f"motor_{i}"] = Signal(
            name=f"motor_{i}",
            time_s=time_s,
            values=command,
            unit="normalised",
            source=f"actuator_motors[0].control[{i - 1}]",
        )
    return FlightLog(path=Path("synthetic.ulg"), log_format="ulog", autopilot="px4", signals=signals)


def test_plateaus_split_a_staircase_at_its_steps() -> None:
    rng = np.random.default_rng(1)
    staircase = np.repeat([0.2, 0.15, 0.12, 0.1], 20) + rng.normal(0, 0.002, 80)
    assert plateaus(staircase, min_length=8) == [(0, 20), (20, 40), (40, 60), (60, 80)]
    assert plateaus(np.zeros(30), min_length=8) == [(0, 30)]


def test_hover_steps_give_eq_2_6_ratios_at_the_step_heights() -> None:
    config = GroundEffectDataConfig(rotor_radius_m=R, mass_kg=MASS, kf_n_per_count=KF, gravity_m_s2=G)
    data = flight_thrust_ratio(synthetic_log(), config)
    steps = data.steps
    assert steps is not None and len(steps.steps) == len(HEIGHTS_M)
    assert any("implausible" in note for note in steps.dropped)  # the time idling on the ground
    # each steady half: >= 450 samples, so the means carry 5 standard errors of at most
    n = min(s.samples for s in steps.steps)
    assert n >= 450
    tol_height = 5 * HEIGHT_NOISE_M / np.sqrt(n)
    tol_ratio = 5 * MOTOR_NOISE / 2 / np.sqrt(n) * 1.1  # four motors average the noise; F/F0 <= 1.1
    for step, truth in zip(steps.steps, HEIGHTS_M):
        assert step.height_m == pytest.approx(truth, abs=tol_height)
        assert step.thrust_ratio == pytest.approx(
            float(laws.piecewise_linear(np.array(truth / R), *EQ_2_5)), abs=tol_ratio + abs(EQ_2_5[0]) * tol_height / R
        )
        assert step.steady_start_s == pytest.approx((step.start_s + step.end_s) / 2)
    fit = fit_ground_effect(data)
    assert fit.best == "piecewise_linear"
    np.testing.assert_allclose(fit.model("piecewise_linear").values, EQ_2_5, rtol=0.05)


def test_without_mass_the_steps_out_of_ground_effect_give_the_weight() -> None:
    log = synthetic_log(seed=2)
    with_mass = flight_thrust_ratio(log, GroundEffectDataConfig(rotor_radius_m=R, mass_kg=MASS, gravity_m_s2=G))
    without = flight_thrust_ratio(log, GroundEffectDataConfig(rotor_radius_m=R))
    assert "2 step(s) above Z/R = 8" in without.f0_source  # 0.230 and 0.184 m: Z/R 10.2 and 8.2
    n = min(s.samples for s in without.steps.steps)  # type: ignore[union-attr]
    np.testing.assert_allclose(without.thrust_ratio, with_mass.thrust_ratio, atol=5 * MOTOR_NOISE / 2 / np.sqrt(n))
    with pytest.raises(DataError, match="no hover step above Z/R = 12"):
        flight_thrust_ratio(log, GroundEffectDataConfig(rotor_radius_m=R, reference_height_ratio=12.0))


def test_a_log_without_motors_is_refused() -> None:
    with pytest.raises(MissingSignalError, match="no motor signals"):
        flight_thrust_ratio(synthetic_log(motors=False), GroundEffectDataConfig(rotor_radius_m=R, mass_kg=MASS))


# --------------------------------------------------------------------------- the simulated flight test


@pytest.fixture(scope="module")
def chapter2_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from simulator.campaign.fly import run_scenario
    from simulator.campaign.scenario import load_builtin

    folder = tmp_path_factory.mktemp("chapter2")
    written = run_scenario(load_builtin("chapter2-ground-effect"), folder)
    return written[0].logs[0]


@pytest.mark.slow
def test_simulated_flight_recovers_the_eq_2_5_truth(chapter2_log: Path) -> None:
    from flightlogs.readers.dispatch import read_log

    # The simulator logs motors normalised 0..1 with thrust = k_f 65535 u per rotor (the crazyflie preset),
    # so eq. 2.6 with Table 2.1's k_f and 65535 counts is its F0 exactly.
    data = flight_thrust_ratio(read_log(chapter2_log), GroundEffectDataConfig(rotor_radius_m=R, mass_kg=MASS))
    assert data.n_points >= len(HEIGHTS_M)
    fit = fit_ground_effect(data)
    assert fit.best == "piecewise_linear"
    pl = fit.model("piecewise_linear")
    np.testing.assert_allclose(pl.values, EQ_2_5, rtol=0.05)
    # Noise per point: height 10 mm per sample (SensorNoise) over >= 200 samples is 0.7 mm, 0.031 in Z/R,
    # 0.0012 in F/F0 through eq. 2.5's slope; motor commands (0.7 % per sample) add 0.0005: 3 sigma = 0.004.
    assert min(s.samples for s in data.steps.steps) >= 200  # type: ignore[union-attr]
    x = np.linspace(data.height_ratio.min(), 8.0, 300)
    assert np.max(np.abs(fit.ratio(x) - laws.piecewise_linear(x, *EQ_2_5))) <= 0.004


@pytest.mark.slow
def test_cli_fits_the_simulated_flight_and_writes_a_model_the_controller_can_read(
    chapter2_log: Path, tmp_path: Path
) -> None:
    from sysid.groundeffect import read_ground_effect_model
    from sysid_cli.main import cli

    out, report = tmp_path / "ge.json", tmp_path / "ge.html"
    result = CliRunner().invoke(
        cli,
        [
            "ground-effect",
            "fit",
            str(chapter2_log),
            "--rotor-radius",
            str(R),
            "--mass",
            str(MASS),
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
    assert summary["best"] == "piecewise_linear" and len(summary["steps"]) == summary["n_points"]
    model = read_ground_effect_model(out)
    x = np.linspace(2.0, 8.0, 50)
    assert np.max(np.abs(model.ratio(x) - laws.piecewise_linear(x, *EQ_2_5))) <= 0.004
    assert "Hover steps" in report.read_text()
