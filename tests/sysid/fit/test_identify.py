"""``identify_logs`` end to end on simulator logs of the Table 3.3 model: the Done-when of issue 6.

Five 34 s sweeps per axis, flown closed loop by the linear simulator with sensor noise, written as
ArduPilot logs with a ground anemometer 4.6 m upstream, read, conditioned, fitted.
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from pathlib import Path

import pytest

from flightlogs.conditioning.condition import ConditioningOptions
from flightlogs.errors import FitWarning
from simulator.campaign.fly import run_scenario
from simulator.campaign.scenario import WindCondition, load_builtin
from simulator.vehicle.identified import CALM_HOVER, STRONG_WIND_TERMS
from sysid.fit import IdentifiedModel, identify_logs

CONTROLS = ("X_lon", "M_lon", "Y_lat", "L_lat", "N_yaw", "Z_thr")
STEP_S = 1.0 / 500.0  # the simulator integrates at 5 x 100 Hz


def _effective_delay(tau: float) -> float:
    """The simulator delays by whole integration steps (its logged command is a centred average: no lag)."""
    return round(tau / STEP_S) * STEP_S


#: Truth as the logs carry it: mixer inputs are logged normalised (-1..1), Table 3.3 is per %.
TRUTH = {k: v * 100.0 if k in CONTROLS else v for k, v in CALM_HOVER.items()} | {
    k: _effective_delay(v) for k, v in CALM_HOVER.items() if k.startswith("tau") and v > 0
}


def _identify(folder: Path, name: str, speed: float, seed: int, structure: str) -> IdentifiedModel:
    scenario = replace(
        load_builtin("linear-sweeps"),
        seed=seed,
        conditions=(WindCondition(name=name, mean_speed_m_s=speed, direction_from_deg=300.0, turbulence_ratio=0.2),),
    )
    written = run_scenario(scenario, folder / name)
    logs = [log for trial in written for log in trial.logs]
    return identify_logs(
        logs, structure, wind_paths=[folder / name], conditioning=ConditioningOptions(wind_distance_m=4.6)
    )


@pytest.mark.slow
def test_calm_logs_give_back_table_3_3(tmp_path: Path) -> None:
    model = _identify(tmp_path, "calm", 0.9, 11, "hover")
    assert model.cost.average <= 100
    # zero in Table 3.3 (no heave delay either)
    assert {p.name for p in model.parameters if p.dropped} == {"N_r", "Z_w", "tau_thr"}
    estimated = [p for p in model.parameters if p.status == "estimated"]
    assert {p.name for p in estimated} == set(TRUTH) - {"tau_thr"}
    for p in estimated:
        truth = TRUTH[p.name]
        assert p.cr_percent <= 20 and p.insensitivity_percent <= 10, p
        assert abs(p.value - truth) <= 0.10 * abs(truth), p
        assert abs(p.value - truth) <= 2 * p.cramer_rao, p
    assert model.parameter("M_lon").unit == "rad/s^2 per normalised (-1..1)"
    assert len(model.provenance.sha256) == 40  # 20 logs and their anemometer files


@pytest.mark.slow
def test_strong_wind_logs_give_back_the_wind_terms(tmp_path: Path) -> None:
    model = _identify(tmp_path, "strong", 5.4, 21, "hover-wind")
    for name in ("X_w_lon", "Z_w_lon"):
        p = model.parameter(name)
        assert p.status == "estimated" and p.stage == "wind"
        assert abs(p.value - STRONG_WIND_TERMS[name]) <= 0.20 * abs(STRONG_WIND_TERMS[name]), p
    p = model.parameter("tau_w_thr")  # measured +11.2 % of the delay flown
    flown = _effective_delay(STRONG_WIND_TERMS["tau_w_thr"])
    assert p.status == "estimated" and abs(p.value - flown) <= 0.20 * flown, p
    # u carries the wind undelayed, so tau_w_lon shares one split with X_u (13.3 ms at the true X_u, 0.55 ms
    # more per 0.001 of X_u): judged by calibration, as the closed-loop speed derivatives are, its bound
    # carrying X_u's (measured 17.6 ms, CR 14.9 %, where 14 ms was flown; the bound held at X_u said 4.6 %)
    p = model.parameter("tau_w_lon")
    flown = _effective_delay(STRONG_WIND_TERMS["tau_w_lon"])
    assert p.status == "estimated" and abs(p.value - flown) <= 2 * p.cramer_rao, p
    p = model.parameter("X_u")  # measured +3.6 %, CR 2.0 %
    assert abs(p.value - TRUTH["X_u"]) <= 2 * p.cramer_rao, p
    # with the logged excitation as reference the F, G_u step is as good as in calm air (M_u was +17 % without)
    for name in ("X_u", "M_u", "M_lon", "L_v"):
        p = model.parameter(name)
        assert abs(p.value - TRUTH[name]) <= 0.10 * abs(TRUTH[name]), p
    assert model.wind is not None and model.wind.rms_after[0] < model.wind.rms_before[0]


@pytest.fixture(scope="module")
def clock_off(tmp_path_factory: pytest.TempPathFactory) -> tuple[list[Path], Path]:
    """Sweeps on every axis in strong wind, the anemometer's clock 1.5 s off UTC: the logs and their folder."""
    base = load_builtin("linear-sweeps")
    assert base.anemometer is not None
    scenario = replace(
        base,
        seed=21,
        trials=2,
        anemometer=replace(base.anemometer, clock_offset_s=1.5),
        conditions=(WindCondition(name="strong", mean_speed_m_s=5.4, direction_from_deg=300.0, turbulence_ratio=0.2),),
    )
    folder = tmp_path_factory.mktemp("clock-off")
    return [log for trial in run_scenario(scenario, folder) for log in trial.logs], folder


@pytest.mark.slow
def test_an_anemometer_clock_off_by_seconds_is_measured_from_the_wind_steps_residual(
    clock_off: tuple[list[Path], Path],
) -> None:
    """Issue 14, then issue 31: the chapter 3 campaign's anemometer clock runs 1.5 s off UTC. The offset is
    scanned for the wind that best explains eq. 3.14's residual, applied, and Table 3.5 comes back; given the
    true offset nothing is said, given a wrong one the warning names the one measured and keeps the one given."""
    logs, folder = clock_off

    def fit(**given: float) -> IdentifiedModel:
        options = ConditioningOptions(wind_distance_m=4.6, **given)
        return identify_logs(logs, "hover-wind", wind_paths=[folder], conditioning=options)

    with warnings.catch_warnings():
        warnings.simplefilter("error", FitWarning)
        found, given = fit(), fit(wind_offset_s=1.5)
    for model in (found, given):
        assert model.wind is not None and model.wind.clock_offset is not None
        clock = model.wind.clock_offset
        assert clock.measured and abs(clock.clock_offset_s - 1.5) <= max(0.05, 2 * clock.sigma_s), clock.clock_offset_s
        for name in ("X_w_lon", "Z_w_lon"):  # Table 3.5, strong wind: -0.3560 and 1.323
            p = model.parameter(name)
            assert p.status == "estimated" and abs(p.value - STRONG_WIND_TERMS[name]) <= 0.05 * abs(
                STRONG_WIND_TERMS[name]
            ), (name, p.value)
    assert found.wind is not None and found.wind.clock_offset is not None
    assert found.wind.clock_offset.used_clock_offset_s == 0.0  # GPS time: the anemometer's own clock, then moved
    assert any("anemometer clock offset +1.50" in note for note in found.notes)
    with pytest.warns(FitWarning, match=r"offset given, \+0\.00 s, is 1\.5\d s from the \+1\.5\d ± 0\.0\d s"):
        wrong = fit(wind_offset_s=0.0)
    assert wrong.parameter("Z_w_lon").status != "estimated"  # fitted where the user said, and found wanting


@pytest.mark.slow
def test_the_clock_is_scanned_on_the_wind_axes_alone_as_on_every_axis(
    clock_off: tuple[list[Path], Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The offset is scanned on F and G_u fitted to the wind axes' responses alone, before the roll and yaw
    responses are computed, which the moved wind would make the fit compute again (roll and yaw computed once).

    That fit's lon and thr values differ from the fit of every axis by up to 0.2 % here (X_lon, M_lon, Z_thr,
    under a tenth of their bounds), so the offset is not the same to the bit: it must be the same within a
    quarter of its sigma (measured 0.10: 1.4987 against 1.4992 s, sigma 4.7 ms; 0.003 on the 60-sweep
    campaign), and every parameter within half its bound (measured 0.26 for tau_w_thr, which trades with the
    offset one for one, 0.007 at most for the others)."""
    import sysid.fit.identify as identify

    logs, folder = clock_off
    options = ConditioningOptions(wind_distance_m=4.6)
    monkeypatch.setenv("FLIGHT_SYSID_THREADS", "1")  # the responses in this process, where they are counted
    counted: list[str] = []
    responses = identify._axis_responses

    def counting(structure, records, axis, *args, **kwargs):  # type: ignore[no-untyped-def]
        counted.append(axis)
        return responses(structure, records, axis, *args, **kwargs)

    monkeypatch.setattr(identify, "_axis_responses", counting)
    scouted = identify_logs(logs, "hover-wind", wind_paths=[folder], conditioning=options)
    assert sorted(counted) == ["lat", "lon", "lon", "thr", "thr", "yaw"], counted
    monkeypatch.setattr(identify, "_measures_clock", lambda *_: False)
    whole = identify_logs(logs, "hover-wind", wind_paths=[folder], conditioning=options)
    assert scouted.wind is not None and scouted.wind.clock_offset is not None
    assert whole.wind is not None and whole.wind.clock_offset is not None
    found, full = scouted.wind.clock_offset, whole.wind.clock_offset
    assert found.measured and abs(found.clock_offset_s - full.clock_offset_s) <= 0.25 * full.sigma_s
    for p in whole.parameters:
        if p.status == "estimated":
            assert abs(scouted.parameter(p.name).value - p.value) <= 0.5 * p.cramer_rao, p.name
