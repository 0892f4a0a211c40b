"""Flights integrated together are the flights integrated one by one."""

from __future__ import annotations

import numpy as np

from simulator.autopilot.excitation import Maneuver
from simulator.flights.linear import HoverSetup, WindField, simulate_hover, simulate_hovers
from simulator.vehicle.identified import CALM_HOVER, LIGHT_WIND_TERMS


def test_each_flight_of_a_batch_is_the_flight_flown_alone() -> None:
    maneuvers = (
        Maneuver(axis="lon", kind="sweep", start_s=1.0, amplitude=8.0, duration_s=12.0),
        Maneuver(axis="thr", kind="doublet", start_s=14.0, amplitude=5.0, duration_s=2.0),
    )
    slow = dict(CALM_HOVER) | {"Z_thr": -0.6, "tau_lon": 0.05, "T_a": 0.08}  # other delays: other history indices
    setups = [
        HoverSetup(seed=1),
        HoverSetup(parameters=slow, wind=WindField(mean_speed_m_s=4.0, direction_from_deg=40.0), seed=2),
        HoverSetup(wind=WindField(), wind_terms=LIGHT_WIND_TERMS, seed=3),
    ]
    together = simulate_hovers(18.0, maneuvers, setups)
    for setup, flight in zip(setups, together):
        alone = simulate_hover(
            18.0, maneuvers, parameters=setup.parameters, wind=setup.wind, wind_terms=setup.wind_terms, seed=setup.seed
        )
        assert list(flight.signals) == list(alone.signals)
        for name, values in alone.signals.items():
            np.testing.assert_allclose(flight.signals[name], values, rtol=0, atol=1e-12 * (1 + np.abs(values).max()))
        np.testing.assert_array_equal(flight.wind_at_vehicle, alone.wind_at_vehicle)
        assert dict(flight.parameters) == dict(alone.parameters)
    # the setups differ, so do the flights: the batch does not mix them up
    assert not np.allclose(together[0].signals["w"], together[1].signals["w"])
    assert np.ptp(together[1].signals["delta_thr"]) > np.ptp(together[0].signals["delta_thr"])
