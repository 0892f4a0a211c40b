"""The fleet's worn motors (issue 30): each flight of a vehicle against its own first flight.

``simulator.campaign.fleet`` flies one vehicle whose collective control derivative ``Z_thr`` shrinks from
a given flight on (25 % lost, then 5 % more a flight), every flight in its own light gusty wind, logged.
``sysid batch --against`` runs exactly :func:`~sysid.discrepancy.discover` on each log (``tests/cli/test_batch``
holds that equality); here the search itself, on a plan that was not looked at while the search was
changed for it (the simulation's model reading u and v on the air of a reference flown in wind was tried
on fleet seed 0; these assertions run on seed 7).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from simulator.campaign.fleet import FleetPlan, fleet_log_name, write_fleet
from sysid.discrepancy import DiscrepancyResult, discover

from builders import discrepancy_series

pytestmark = [
    pytest.mark.long,
    pytest.mark.timeout(1200),
    pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning"),
]

PLAN = FleetPlan(vehicles=2, flights=7, degrading_vehicle=2, degradation_starts=5, corrupted=None, seed=7)
WORN, HEALTHY = (5, 7), (2, 3)


@pytest.fixture(scope="module", name="results")
def results_fixture(tmp_path_factory: pytest.TempPathFactory) -> dict[int, DiscrepancyResult]:
    folder = tmp_path_factory.mktemp("fleet-wear")
    write_fleet(folder, PLAN)
    vehicle = PLAN.degrading_vehicle

    def log(flight: int) -> Path:
        return folder / f"V{vehicle:02d}" / fleet_log_name(vehicle, flight)

    reference = discrepancy_series(log(1))
    return {f: discover([reference], [discrepancy_series(log(f))]) for f in (*WORN, *HEALTHY)}


def _thrust_change(result: DiscrepancyResult) -> float:
    (value,) = [
        p.value
        for f in result.findings
        if f.effect == "control_effectiveness"
        for p in f.parameters
        if p.name == "thrust_effectiveness_change"
    ]
    return value


@pytest.mark.parametrize("flight", WORN)
def test_a_worn_flight_is_control_effectiveness_with_the_thrust_lost(
    results: dict[int, DiscrepancyResult], flight: int
) -> None:
    """The verdict is the thrust per command, and the fraction lost is the plan's within 5 points."""
    result = results[flight]
    assert result.verdict == "control_effectiveness", result.summary
    loss = PLAN.thrust_loss(PLAN.degrading_vehicle, flight)
    assert loss > 0.0
    assert _thrust_change(result) == pytest.approx(-loss, abs=0.05)


@pytest.mark.xfail(
    strict=False,
    reason="open (issue 30): on fleet seed 0 the healthy flights against the first kept one small finding each "
    "(wind 18 %, cg_offset 10.5 %, cg_offset 12.4 % held-out cut; a worn one a wind beside its control "
    "effectiveness), down from 83 % and 30 % before the simulation's model read u and v on the air; "
    "not yet analysed",
)
@pytest.mark.parametrize("flight", HEALTHY)
def test_a_healthy_flight_finds_nothing(results: dict[int, DiscrepancyResult], flight: int) -> None:
    assert results[flight].findings == (), results[flight].summary
