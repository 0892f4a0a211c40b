"""The fleet's worn motors (issue 30): each flight of a vehicle against its own first flight.

``simulator.campaign.fleet`` flies one vehicle whose collective control derivative ``Z_thr`` shrinks from
a given flight on (25 % lost, then 5 % more a flight), every flight in its own light gusty wind, logged.
``sysid batch --against`` runs exactly :func:`~sysid.discrepancy.discover` on each log (``tests/cli/test_batch``
holds that equality); here the search itself, on every flight of two plans. Nothing in the search was
changed for them: the healthy flights' CG offsets (fleet seed 7, p_dot, 11 % cut; seed 0 before it) came from
the fleet's simulator, whose wind did not turn with the vehicle's heading
(``tests/simulator/flights/test_linear_heading``); seed 11 was first read with the simulator fixed.
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

WORN, HEALTHY = (5, 6, 7), (2, 3, 4)


@pytest.fixture(scope="module", name="plan", params=(7, 11))
def plan_fixture(request: pytest.FixtureRequest) -> FleetPlan:
    return FleetPlan(
        vehicles=2, flights=7, degrading_vehicle=2, degradation_starts=5, corrupted=None, seed=request.param
    )


@pytest.fixture(scope="module", name="results")
def results_fixture(plan: FleetPlan, tmp_path_factory: pytest.TempPathFactory) -> dict[int, DiscrepancyResult]:
    folder = tmp_path_factory.mktemp("fleet-wear")
    write_fleet(folder, plan)
    vehicle = plan.degrading_vehicle

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
    plan: FleetPlan, results: dict[int, DiscrepancyResult], flight: int
) -> None:
    """The thrust per command alone, and the fraction lost is the plan's within 5 points."""
    result = results[flight]
    assert [f.effect for f in result.findings] == ["control_effectiveness"], result.summary
    loss = plan.thrust_loss(plan.degrading_vehicle, flight)
    assert loss > 0.0
    assert _thrust_change(result) == pytest.approx(-loss, abs=0.05)


@pytest.mark.parametrize("flight", HEALTHY)
def test_a_healthy_flight_finds_nothing(results: dict[int, DiscrepancyResult], flight: int) -> None:
    """The same vehicle in another wind: no finding at all."""
    assert results[flight].findings == (), results[flight].summary
