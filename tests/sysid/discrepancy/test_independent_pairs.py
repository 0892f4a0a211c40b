"""Discrepancy discovery on pairs from a generator that is not ours (issue 15): PX4 ULogs of ``independent_sim``.

That generator shares no code with ``simulator``: the Table 3.3 octocopter as a linear plant in PX4
units (normalised torque setpoints), PX4-like cascade gains at 250 Hz, log chirps injected at the
mixer, coloured gust disturbances, estimator drift, take-off and landing. A pair is two flights of
one plan (lon, lat and yaw sweeps, a 15 m reposition out and back), the REAL one with another seed
and one plant parameter changed (8, 15 and 30 ms more delay, a 1.6 times slower actuator, twice the speed
damping X_u and Y_v). The search's thresholds and terms were set on our simulator's pairs
(seeds 1, 2, 3 and 5); nothing here was tuned on: every case is held out.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from independent_sim.corpus import write_case
from independent_sim.maneuvers import Chirp, Maneuver
from independent_sim.plant import hover_plant
from independent_sim.scenario import Case, FlightPlan, Reposition

from flightlogs.conditioning.condition import ConditioningOptions, condition_flight
from flightlogs.readers import read_log
from sysid.discrepancy import DiscrepancyResult, discover, flight_series

pytestmark = [
    pytest.mark.slow,
    pytest.mark.timeout(900),
    pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning"),
]

_PLANT = hover_plant("calm")
_AXES = ("lat", "lon", "yaw", "thr")


def _delayed(extra_s: float) -> tuple[tuple[str, float], ...]:
    return tuple((f"tau_{a}", getattr(_PLANT, f"tau_{a}") + extra_s) for a in _AXES)


#: Pair name -> (the effect concealed, the REAL vehicle's plant changes). The 8 and 15 ms delays are
#: those the hand-made pysindy baseline of the issue split between "delay" and "lag".
PAIRS: dict[str, tuple[str, tuple[tuple[str, float], ...]]] = {
    "none": ("none", ()),
    "time_delay": ("time_delay", _delayed(0.030)),
    "time_delay_15ms": ("time_delay", _delayed(0.015)),
    "time_delay_8ms": ("time_delay", _delayed(0.008)),
    "actuator_lag": ("actuator_lag", (("T_a", 1.6 * _PLANT.T_a),)),
    "rotor_drag": ("rotor_drag", (("X_u", 2.0 * _PLANT.X_u), ("Y_v", 2.0 * _PLANT.Y_v))),
}


def _case(name: str, seed: int, changes: tuple[tuple[str, float], ...]) -> Case:
    sweep = Chirp(duration_s=40.0, f_min_hz=0.1, f_max_hz=6.0)
    maneuvers = tuple(
        Maneuver(axis=axis, design=sweep, start_s=start, amplitude=amplitude)  # type: ignore[arg-type]
        for axis, start, amplitude in (("lon", 10.0, 0.06), ("lat", 56.0, 0.07), ("yaw", 102.0, 0.08))
    )
    plan = FlightPlan(
        duration_s=200.0,
        repositions=(Reposition(start_s=150.0, north_m=15.0), Reposition(start_s=170.0, north_m=-15.0)),
    )
    return Case(name=name, fmt="ulog", plan=plan, maneuvers=maneuvers, seed=seed, plant_changes=changes)


def _series(path: Path):  # type: ignore[no-untyped-def]
    return flight_series(path.name, condition_flight(read_log(path), options=ConditioningOptions(segments=())).records)


@pytest.fixture(scope="module", name="results")
def results_fixture(tmp_path_factory: pytest.TempPathFactory) -> dict[str, DiscrepancyResult]:
    folder = tmp_path_factory.mktemp("independent-pairs")
    sim = _series(write_case(_case("sim", 501, ()), folder).log)
    return {
        name: discover([sim], [_series(write_case(_case(f"real-{k}", 601 + k, changes), folder).log)])
        for k, (name, (_, changes)) in enumerate(PAIRS.items())
    }


@pytest.mark.parametrize("name", list(PAIRS))
def test_the_verdict_names_the_effect_on_another_generators_logs(
    results: dict[str, DiscrepancyResult], name: str
) -> None:
    result, effect = results[name], PAIRS[name][0]
    assert result.verdict == effect, result.summary
    assert [f.effect for f in result.findings] == ([] if effect == "none" else [effect])
    if effect != "none":
        assert result.findings[0].improvement_percent > 0.0
        assert max(result.unexplained.values()) < 2.0  # the finding accounts for the difference


def _value(result: DiscrepancyResult, name: str) -> tuple[float, float]:
    (p,) = [p for p in result.findings[0].parameters if p.name == name]
    return p.value, p.uncertainty


@pytest.mark.parametrize(
    ("name", "extra_s"), [("time_delay", 0.030), ("time_delay_15ms", 0.015), ("time_delay_8ms", 0.008)]
)
def test_the_delay_is_measured_on_another_generators_logs(
    results: dict[str, DiscrepancyResult], name: str, extra_s: float
) -> None:
    """The delay added to every input, within a step of the search's grid (2.5 ms)."""
    value, _ = _value(results[name], "delay_s")
    assert abs(value - extra_s) <= 0.0025


def test_the_extra_drag_is_the_one_added(results: dict[str, DiscrepancyResult]) -> None:
    """X_u and Y_v doubled: the term's coefficient is the added -X_u / g (its sigma is optimistic: 5 % allowed)."""
    value, _ = _value(results["rotor_drag"], "drag_x")
    assert value == pytest.approx(-_PLANT.X_u / 9.81, rel=0.05)


def test_the_lag_lies_between_the_added_and_the_whole_actuator_lag(results: dict[str, DiscrepancyResult]) -> None:
    value, _ = _value(results["actuator_lag"], "time_constant_s")
    assert 0.6 * _PLANT.T_a <= value <= 1.6 * _PLANT.T_a
