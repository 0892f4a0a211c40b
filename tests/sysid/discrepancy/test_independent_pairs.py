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

import pytest
from independent_sim.pairs import PLANT, Changes, delayed, scaled

from sysid.discrepancy import DiscrepancyResult

from builders import discover_independent_pairs

pytestmark = [
    pytest.mark.slow,
    pytest.mark.timeout(900),
    pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning"),
]

#: Pair name -> (the effect concealed, the REAL vehicle's plant changes). The 8 and 15 ms delays are
#: those the hand-made pysindy baseline of the issue split between "delay" and "lag".
PAIRS: dict[str, tuple[str, Changes]] = {
    "none": ("none", ()),
    "time_delay": ("time_delay", delayed(0.030)),
    "time_delay_15ms": ("time_delay", delayed(0.015)),
    "time_delay_8ms": ("time_delay", delayed(0.008)),
    "actuator_lag": ("actuator_lag", scaled(1.6, "T_a")),
    "rotor_drag": ("rotor_drag", scaled(2.0, "X_u", "Y_v")),
}


@pytest.fixture(scope="module", name="results")
def results_fixture(tmp_path_factory: pytest.TempPathFactory) -> dict[str, DiscrepancyResult]:
    plants = {name: entry[1] for name, entry in PAIRS.items()}
    return discover_independent_pairs(tmp_path_factory.mktemp("independent-pairs"), 501, 601, plants)


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
    assert value == pytest.approx(-PLANT.X_u / 9.81, rel=0.05)


def test_the_lag_lies_between_the_added_and_the_whole_actuator_lag(results: dict[str, DiscrepancyResult]) -> None:
    value, _ = _value(results["actuator_lag"], "time_constant_s")
    assert 0.6 * PLANT.T_a <= value <= 1.6 * PLANT.T_a
