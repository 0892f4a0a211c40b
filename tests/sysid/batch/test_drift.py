"""Drift detection on parameter series from a generator of this test's own (not the simulator).

Each series is a vehicle's flights: values drawn around a truth with a scatter
that is a chosen multiple of the Cramér–Rao bound the fit reports (the
simulated fleet's healthy vehicles show 0.2-3x, up to 5x for the speed
derivatives, see sysid.batch.drift), with a step or a ramp where a part wears.
The rule's numbers (3 combined bounds of 2x CR, confirmed by the next flight)
were chosen on the simulated fleet; here they are held against series it did
not produce.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sysid.batch import DriftOptions, GroupFit, find_drifts
from sysid.fit.result import ParameterEstimate


def _series(
    values: np.ndarray, cr_percent: float | np.ndarray, *, vehicle: str = "V1", costs: np.ndarray | None = None
) -> list[GroupFit]:
    """A vehicle's groups, one a day, holding one parameter ``K`` with these values and bounds."""
    cr = np.broadcast_to(np.asarray(cr_percent, dtype=float), values.shape)
    costs = np.full(values.size, 40.0) if costs is None else costs
    return [
        GroupFit(
            key=f"{vehicle} d{k:02d}",
            vehicle=vehicle,
            date=f"2024-07-{k + 1:02d}",
            logs=(f"{vehicle}_{k}.bin",),
            parameters=(ParameterEstimate(name="K", value=float(v), cr_percent=float(c)),),
            cost_average=float(j),
        )
        for k, (v, c, j) in enumerate(zip(values, cr, costs))
    ]


def _noisy(rng: np.random.Generator, truth: np.ndarray, cr_percent: float, scatter: float) -> np.ndarray:
    """Estimates of `truth` scattering by `scatter` times the bound the fit reports."""
    return truth + rng.normal(size=truth.size) * scatter * np.abs(truth) * cr_percent / 100.0


@pytest.mark.parametrize("scatter", [0.3, 1.0, 2.0])
def test_healthy_vehicles_scattering_up_to_twice_their_bounds_are_almost_never_flagged(scatter: float) -> None:
    rng = np.random.default_rng(11)
    groups = []
    for v in range(2000):  # 2000 vehicle-parameter series of 10 flights
        groups += _series(_noisy(rng, np.full(10, -90.0), 3.0, scatter), 3.0, vehicle=f"V{v}")
    confirmed = [d for d in find_drifts(groups) if d.confirmed]
    # a two-sided 3-sigma excess on two flights in a row, at worst (scatter = the scaled bound): ~1e-5 a flight
    assert len(confirmed) <= {0.3: 0, 1.0: 0, 2.0: 1}[scatter], [d.after for d in confirmed][:5]


def test_where_the_scatter_is_three_times_the_bound_a_few_percent_of_healthy_series_are_flagged() -> None:
    """The rule's limit, stated: the speed derivatives of a closed-loop hover scatter up to 3-5x their bounds."""
    rng = np.random.default_rng(12)
    groups = []
    for v in range(2000):
        groups += _series(_noisy(rng, np.full(10, 0.77), 4.0, 3.0), 4.0, vehicle=f"V{v}")
    rate = sum(d.confirmed for d in find_drifts(groups)) / 2000
    assert 0.005 < rate < 0.05


def test_a_step_of_five_combined_bounds_is_flagged_at_its_flight_with_the_one_before() -> None:
    rng = np.random.default_rng(5)
    hits, changes = 0, []
    for trial in range(200):
        truth = np.full(10, 50.0)
        onset = 3 + trial % 7  # the 4th to the 10th flight
        truth[onset:] *= 1.25  # 2x CR 2 % combined with the baseline's: about 5 bounds
        found = find_drifts(_series(_noisy(rng, truth, 2.0, 1.0), 2.0))
        assert len(found) == 1 and found[0].parameter == "K"
        d = found[0]
        hits += d.after == f"V1 d{onset:02d}" and d.before == f"V1 d{onset - 1:02d}"
        assert d.confirmed == (onset < 9)  # the last flight alone is reported, unconfirmed
        changes.append(d.change_percent)
    assert hits >= 196  # the right flight, but for the rare noise draw
    # each change measured with the noise of one flight and the baseline's: 2.3 % (1 sigma)
    assert np.mean(changes) == pytest.approx(25.0, abs=0.5) and np.std(changes) < 3.0
    loss = find_drifts(_series(np.r_[np.full(5, -90.0), np.full(5, -67.5)], 2.0))[0]
    assert loss.change_percent == pytest.approx(-25.0) and loss.sigmas > 0  # the magnitude lost; z follows the value


def test_a_ramp_is_flagged_once_it_has_grown_past_the_bounds_not_before() -> None:
    truth = -90.0 * (1.0 - np.r_[np.zeros(4), 0.02 * np.arange(1, 7)])  # 2 % more lost each flight from the 5th
    found = find_drifts(_series(truth, 1.5))  # noise-free: the threshold decides alone
    bounds = 2.0 * 0.015 * np.abs(truth)  # 2x CR, the bound shrinking with the value
    baseline_bound = bounds[0] / math.sqrt(3)
    first = next(k for k in range(4, 10) if abs(truth[k] + 90.0) > 3.0 * math.hypot(bounds[k], baseline_bound))
    assert [d.after for d in found] == [f"V1 d{first:02d}"]


def test_one_outlying_flight_is_not_a_drift() -> None:
    values = np.full(10, 10.0)
    values[5] = 13.0  # 30 %, 6 combined bounds, then back
    assert find_drifts(_series(values, 2.0)) == ()


def test_fits_beyond_the_cost_guideline_are_not_trended() -> None:
    values = np.full(10, 10.0)
    values[5:7] = 13.0  # two poor fits in a row, far off
    costs = np.full(10, 40.0)
    costs[5:7] = 400.0
    assert find_drifts(_series(values, 2.0, costs=costs)) == ()
    assert len(find_drifts(_series(values, 2.0, costs=costs), DriftOptions(max_cost_average=1000.0))) == 1


def test_vehicles_unknown_or_mixed_and_short_series_are_not_trended() -> None:
    step = np.r_[np.full(5, 10.0), np.full(5, 14.0)]
    assert len(find_drifts(_series(step, 2.0))) == 1
    assert find_drifts(_series(step, 2.0, vehicle="unknown")) == ()
    assert find_drifts(_series(step, 2.0, vehicle="mixed")) == ()
    assert find_drifts(_series(step[:3], 2.0)) == ()  # the baseline only
    no_bound = _series(step, math.nan)  # no Cramér-Rao bound: nothing to judge against
    assert find_drifts(no_bound) == ()
