"""Scenarios flown end to end: files on disk that read back, and truth the conditioning recovers."""

from __future__ import annotations

import json
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from flightlogs.conditioning.condition import ConditioningOptions, condition_flight
from flightlogs.geo import local_north_east
from flightlogs.readers.anemometer import read_anemometer_csv
from flightlogs.readers.dispatch import read_log
from simulator.campaign.fly import plan_trials, run_scenario
from simulator.campaign.scenario import load_builtin, read_scenario
from sysid_cli.main import cli

ONE_SAMPLE_S = 0.01 + 1e-9


@pytest.fixture(scope="module")
def strong_trials(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list]:
    """Two strong-wind trials of the chapter 3 campaign (nonlinear octocopter): a lon sweep and a lat doublet."""
    scenario = load_builtin("chapter3-campaign")
    plans = plan_trials(scenario)
    picked = [p.index for p in plans if p.name in ("strong-lon-sweep-1", "strong-lat-doublet-1")]
    out = tmp_path_factory.mktemp("campaign")
    return out, run_scenario(scenario, out, trials=picked)


def test_the_campaign_plan_is_ordered_and_seeded() -> None:
    plans = plan_trials(load_builtin("chapter3-campaign"))
    assert len(plans) == 120 and len({p.seed for p in plans}) == 120 and len({p.name for p in plans}) == 120
    assert all(b.utc_start > a.utc_start for a, b in zip(plans, plans[1:]))
    sweep = next(p for p in plans if p.spec.kind == "sweep")
    assert sweep.duration_s == pytest.approx(34.0 + 2 * 3.0)


def test_trials_read_back_with_every_canonical_signal(strong_trials: tuple[Path, list]) -> None:
    out, written = strong_trials
    index = json.loads((out / "campaign.json").read_text())
    assert [t["name"] for t in index["trials"]] == [t.plan.name for t in written]
    for trial in written:
        log = read_log(trial.logs[0])
        assert log.autopilot == "ardupilot" and not log.warnings
        assert set(log.missing) == set(), log.missing
        assert log["az"].values.mean() == pytest.approx(-9.81, abs=0.3)  # hover: specific force -g
        assert any(name.startswith("motor_8") for name in log.signals)  # octocopter


def test_conditioning_recovers_the_simulated_transport_delay(strong_trials: tuple[Path, list]) -> None:
    """The nonlinear simulator advects a frozen field; correlation finds its delay within one sample.

    The delay is to where the vehicle actually hovered: in strong wind its position hold leaves it
    a few centimetres from the set point, which the truth's effective delay accounts for.
    """
    _, written = strong_trials
    trial = next(t for t in written if t.plan.spec.kind == "sweep")
    truth = json.loads(trial.truth.read_text())["anemometer"]
    flight = condition_flight(
        read_log(trial.logs[0]),
        read_anemometer_csv(trial.wind_csv),
        ConditioningOptions(wind_offset_s=truth["clock_offset_s"], estimate_transport_delay=True),
    )
    assert flight.wind is not None and flight.wind.transport.source == "correlation"
    assert abs(flight.wind.transport.delay_s - truth["effective_transport_delay_s"]) < ONE_SAMPLE_S
    (sweep,) = [s for s in flight.segments if s.kind == "sweep"]
    assert (sweep.axis, sweep.source) == ("lon", "sids")


def test_conditioning_recovers_the_anemometer_clock_offset(strong_trials: tuple[Path, list]) -> None:
    """Within two samples in strong wind (measured 11.6 ms; within one sample for the linear model,
    tests/flightlogs/conditioning/test_condition.py): the vehicle wanders ±0.33 m (1 sigma) along the wind, so the
    true delay varies by ±60 ms over the trial and one clock offset fits it only to about a sample."""
    _, written = strong_trials
    trial = next(t for t in written if t.plan.spec.kind == "sweep")
    truth = json.loads(trial.truth.read_text())["anemometer"]
    flight = condition_flight(
        read_log(trial.logs[0]),
        read_anemometer_csv(trial.wind_csv),
        ConditioningOptions(transport_delay_s=truth["effective_transport_delay_s"], estimate_wind_offset=True),
    )
    assert flight.wind is not None and flight.wind.clock_offset_source == "estimated"
    assert abs(flight.wind.clock_offset_s - truth["clock_offset_s"]) < 2 * ONE_SAMPLE_S


@pytest.fixture(scope="module")
def doublet_trials(tmp_path_factory: pytest.TempPathFactory) -> list:
    """One doublet per axis per wind (12 logs of 8 s) and one sweep per axis in light wind (4 logs of 40 s)."""
    scenario = load_builtin("chapter3-campaign")
    picked = [
        p.index
        for p in plan_trials(scenario)
        if p.name.endswith("-doublet-1") or (p.name.startswith("light-") and p.name.endswith("-sweep-1"))
    ]
    return run_scenario(scenario, tmp_path_factory.mktemp("doublets"), trials=picked)


@pytest.mark.slow  # about 20 s, most of it simulating the 16 trials
@pytest.mark.filterwarnings("ignore:no wind given:flightlogs.errors.DataQualityWarning")  # u v w are not used here
def test_every_doublet_and_sweep_is_found_once_with_its_axis_and_bounds(doublet_trials: list) -> None:
    """Segmentation of the nonlinear campaign's logs against the plan's maneuver timing (truth JSON).

    The doublets (3 s hover, 2 s doublet, 3 s hover: too little hover to fit
    the feedback alone) are found by the joint fit of feedback and doublet
    (flightlogs.maneuvers.excitation_recovery). Their edges are steps of the logged mixer
    input, so each is placed to the sample: the segment runs from the first
    to the last sample of the doublet, within one sample (10 ms) of the
    truth's start and end. Sweeps come from the SIDS messages, exactly.
    Measured on all 120 logs of the campaign: 60/60 doublets and 60/60
    sweeps, nothing else found.
    """
    assert len(doublet_trials) == 16
    for trial in doublet_trials:
        (truth,) = json.loads(trial.truth.read_text())["maneuvers"]
        found = [s for s in condition_flight(read_log(trial.logs[0])).segments if s.kind != "hover"]
        assert len(found) == 1, (trial.plan.name, found)
        (segment,) = found
        source = "sids" if truth["kind"] == "sweep" else "detected"
        assert (segment.axis, segment.kind, segment.source) == (truth["axis"], truth["kind"], source), trial.plan.name
        assert abs(segment.start_s - truth["start_s"]) <= ONE_SAMPLE_S, (trial.plan.name, segment)
        assert abs(segment.end_s - truth["end_s"]) <= ONE_SAMPLE_S, (trial.plan.name, segment)


def test_the_logged_gps_is_the_path_flown(tmp_path: Path) -> None:
    """The nonlinear simulator knows where the vehicle is: its GPS logs that, to the 1e-7 deg of Lat/Lng (1.1 cm)."""
    from simulator.flights.nonlinear import Trial, simulate_flights
    from simulator.output.ardupilot import VEHICLE_POSITION_DEG, write_ardupilot_log
    from simulator.world.environment import Environment
    from simulator.world.wind_field import Dryden, Wind

    wind = Wind(mean_speed_m_s=5.4, direction_from_deg=300.0, turbulence=Dryden.low_altitude(4.6, 5.4))
    (flight,) = simulate_flights([Trial(duration_s=10.0, environment=Environment(wind=wind), seed=3)])
    utc_start = datetime(2024, 5, 1, tzinfo=UTC)
    log = read_log(write_ardupilot_log(flight, tmp_path / "gps.bin", utc_start=utc_start))
    lat0, lon0 = np.radians(VEHICLE_POSITION_DEG)
    north, east = local_north_east(log["latitude"].values, log["longitude"].values, lat0, lon0)
    at = np.round((log["latitude"].time_s - log["latitude"].time_s[0]) * 100.0).astype(int)  # every 20th 100 Hz sample
    assert np.ptp(flight.truth["pn"]) > 0.05  # it does move in strong wind
    assert np.max(np.abs(north - flight.truth["pn"][at])) < 0.012
    assert np.max(np.abs(east - flight.truth["pe"][at])) < 0.012


def test_the_linear_model_refuses_maneuvers_it_cannot_fly(tmp_path: Path) -> None:
    from flightlogs.errors import DataError

    path = tmp_path / "s.toml"
    path.write_text(
        '[scenario]\nvehicle = "linear-octo"\n[[condition]]\nname = "calm"\nmean_speed_m_s = 0.0\n'
        '[[maneuver]]\naxis = "lon"\nkind = "3211"\namplitude = 5.0\nduration_s = 7.0\n'
    )
    with pytest.raises(DataError, match="sweeps and doublets only"):
        run_scenario(read_scenario(path), tmp_path / "out")


def test_simulate_command_lists_and_flies(tmp_path: Path) -> None:
    runner = CliRunner()
    listing = runner.invoke(cli, ["simulate", "--list"])
    assert listing.exit_code == 0
    assert {"chapter3-campaign", "chapter2-ground-effect", "sitl-nominal"} <= {
        line.split()[0] for line in listing.output.splitlines()
    }
    result = runner.invoke(cli, ["simulate", "sitl-nominal", "-o", str(tmp_path), "--json", "-", "-q"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert len(summary["trials"]) == 2
    for trial in summary["trials"]:
        formats = {Path(p).suffix for p in trial["logs"]}
        assert formats == {".ulg", ".bin"}
        for path in trial["logs"]:
            assert {"p", "q", "r", "vn", "delta_lat"} <= set(read_log(path).signals)
    assert runner.invoke(cli, ["simulate"]).exit_code == 2
    assert runner.invoke(cli, ["simulate", "no-such-scenario", "-o", str(tmp_path)]).exit_code == 1
