"""Scenarios flown end to end: files on disk that read back, and truth the conditioning recovers."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from flightlogs.anemometer import read_anemometer_csv
from flightlogs.condition import ConditioningOptions, condition_flight
from flightlogs.reader import read_log
from sysid.sim.campaign import plan_trials, run_scenario
from sysid.sim.scenario import load_builtin, read_scenario
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
    flight = condition_flight(read_log(trial.logs[0]), read_anemometer_csv(trial.wind_csv),
                              ConditioningOptions(wind_offset_s=truth["clock_offset_s"], estimate_transport_delay=True))
    assert flight.wind is not None and flight.wind.transport.source == "correlation"
    assert abs(flight.wind.transport.delay_s - truth["effective_transport_delay_s"]) < ONE_SAMPLE_S
    (sweep,) = [s for s in flight.segments if s.kind == "sweep"]
    assert (sweep.axis, sweep.source) == ("lon", "sids")


def test_conditioning_recovers_the_anemometer_clock_offset(strong_trials: tuple[Path, list]) -> None:
    """Within two samples in strong wind (measured 11.6 ms; within one sample for the linear model,
    tests/flightlogs/test_condition.py): the vehicle wanders ±0.33 m (1 sigma) along the wind, so the
    true delay varies by ±60 ms over the trial and one clock offset fits it only to about a sample."""
    _, written = strong_trials
    trial = next(t for t in written if t.plan.spec.kind == "sweep")
    truth = json.loads(trial.truth.read_text())["anemometer"]
    flight = condition_flight(read_log(trial.logs[0]), read_anemometer_csv(trial.wind_csv),
                              ConditioningOptions(transport_delay_s=truth["effective_transport_delay_s"], estimate_wind_offset=True))
    assert flight.wind is not None and flight.wind.clock_offset_source == "estimated"
    assert abs(flight.wind.clock_offset_s - truth["clock_offset_s"]) < 2 * ONE_SAMPLE_S


def test_the_linear_model_refuses_maneuvers_it_cannot_fly(tmp_path: Path) -> None:
    from flightlogs.errors import DataError

    path = tmp_path / "s.toml"
    path.write_text('[scenario]\nvehicle = "linear-octo"\n[[condition]]\nname = "calm"\nmean_speed_m_s = 0.0\n'
                    '[[maneuver]]\naxis = "lon"\nkind = "3211"\namplitude = 5.0\nduration_s = 7.0\n')
    with pytest.raises(DataError, match="sweeps and doublets only"):
        run_scenario(read_scenario(path), tmp_path / "out")


def test_simulate_command_lists_and_flies(tmp_path: Path) -> None:
    runner = CliRunner()
    listing = runner.invoke(cli, ["simulate", "--list"])
    assert listing.exit_code == 0
    assert {"chapter3-campaign", "chapter2-ground-effect", "sitl-nominal"} <= {line.split()[0] for line in listing.output.splitlines()}
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
