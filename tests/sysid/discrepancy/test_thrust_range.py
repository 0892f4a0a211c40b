"""A REAL vehicle that hovers outside SIM's thrust range, and a thrust ceiling fitted the other way round (issue 30).

Found on another generator's flights (SIM 7200, now a tuning flight): the worn motors' 30 % thrust
loss hovers at a command of 0.50 where SIM flew 0.44-0.46; the simulation's model, its thrust square's
lag coefficients read 8 of SIM's standard deviations away, left az at 2.8 times its floor after the
trim (``unexplained``, 0.0 % cut), and two REAL flights of the same vehicle were named
``thrust_saturation`` with a lost share of -0.27: more thrust above the "ceiling", the thrust's
curvature, not a saturation. With the square left out where REAL leaves SIM's range and a coefficient
on the side its physics rules out ruling its term out, the worn motors are named and the nulls are none.

The benchmark's null pair (``benchmarks/bench_discrepancy_pair.py --effect none``, another plan) was
named ``thrust_saturation`` on p_dot alone: half the roll moment per command "lost" above a command of
0.454, with no thrust lost (0.8 % cut). A ceiling's own mark is the thrust that stops growing: the
term must now remove a share of az by itself (``shown_on``).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from independent_sim.corpus import write_case
from independent_sim.open_world import NAMED, open_world_cases
from independent_sim.pairs import open_pair_case, physics_pair_case

from sysid.discrepancy import DiscrepancyResult, discover

from builders import discrepancy_series

pytestmark = pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning")

SIM_SEED = 7200  # a tuning flight: the rules below were found on it
CASES = ("none", "none-1", "worn_motors_thrust")


@pytest.fixture(scope="module", name="outcomes")
def outcomes_fixture(tmp_path_factory: pytest.TempPathFactory) -> dict[str, DiscrepancyResult]:
    folder: Path = tmp_path_factory.mktemp("thrust-range")
    sim = discrepancy_series(write_case(open_pair_case("sim", SIM_SEED), folder).log)
    out = {}
    for k, (name, (effects, changes)) in enumerate(open_world_cases(3, ceiling=False).items()):
        if name in CASES:  # the seeds the rates test gives them
            case = open_pair_case(f"real-{k}", SIM_SEED + 1 + k, effects=effects, changes=changes)  # type: ignore[arg-type]
            out[name] = discover([sim], [discrepancy_series(write_case(case, folder).log)])
    return out


def test_worn_motors_that_hover_outside_the_simulations_thrust_range_are_named(
    outcomes: dict[str, DiscrepancyResult],
) -> None:
    result = outcomes["worn_motors_thrust"]
    assert [f.effect for f in result.findings] == [NAMED["worn_motors_thrust"][0]]
    (change,) = [p for p in result.findings[0].parameters if p.name == "thrust_effectiveness_change"]
    assert change.value == pytest.approx(-0.30, abs=0.05)
    assert result.findings[0].improvement_percent > 90.0
    assert result.unexplained["az"] < 1.5  # az at its floor with the thrust's change modelled (was 2.8)


@pytest.mark.parametrize("name", ["none", "none-1"])
def test_flights_of_the_same_vehicle_find_no_ceiling(outcomes: dict[str, DiscrepancyResult], name: str) -> None:
    result = outcomes[name]
    assert result.verdict == "none" and not result.findings, [(f.effect, f.parameters) for f in result.findings]
    saturation = [s for s in result.screened if s.effect == "thrust_saturation"]
    assert saturation  # it was tried


def test_the_benchmarks_null_pair_finds_no_ceiling(tmp_path: Path) -> None:
    sim, real = (
        write_case(physics_pair_case(name, seed), tmp_path).log for name, seed in (("sim", 3301), ("real", 3302))
    )
    result = discover([discrepancy_series(sim)], [discrepancy_series(real)])
    assert result.verdict == "none" and not result.findings, [(f.effect, f.outputs) for f in result.findings]
