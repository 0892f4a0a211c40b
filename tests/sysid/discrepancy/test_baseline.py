"""The simulation's model: its lagged inputs, taken as strided views, against a column at a time; its squares."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from sysid.discrepancy.baseline import _curvature_share, _lagged, fit_baseline
from sysid.discrepancy.catalogue._term import delayed, first_order
from sysid.discrepancy.series import COMMANDS, FlightSeries

from builders import synthetic_series


def _column_at_a_time(spans: list[slice], x: np.ndarray, lags: np.ndarray) -> np.ndarray:
    """x(t - lag) per lag, each piece padded with its first value: the definition, one slice per column."""
    out = np.empty((x.size, lags.size))
    longest = int(lags[-1])
    for rows in spans:
        piece = x[rows]
        padded = np.concatenate([np.full(longest, piece[0]), piece])
        for j, lag in enumerate(lags.tolist()):
            out[rows, j] = padded[longest - lag : longest - lag + piece.size]
    return out


@pytest.mark.parametrize(
    "lags",
    [np.arange(16), np.arange(0, 16, 5), np.arange(0, 13, 4), np.array([0]), np.array([0, 1, 4, 9])],
    ids=["every-sample", "step-5", "step-4", "none", "uneven"],
)
@pytest.mark.parametrize(
    "spans", [[slice(0, 600)], [slice(0, 2), slice(2, 300), slice(300, 600)]], ids=["one-piece", "short-first-piece"]
)
def test_the_lagged_inputs_are_the_definitions_columns(lags: np.ndarray, spans: list[slice]) -> None:
    """Equal, bit for bit: no lag reaches across a gap, a piece shorter than the lags holds its first value."""
    x = np.random.default_rng(7).normal(size=600)
    assert np.array_equal(_lagged(spans, x, lags), _column_at_a_time(spans, x, lags))


def _with_thrust(flight: FlightSeries, thrust: np.ndarray) -> FlightSeries:
    return FlightSeries(
        name=flight.name,
        time_s=flight.time_s,
        piece=flight.piece,
        signals={**flight.signals, "delta_thr": thrust},
        rate_hz=flight.rate_hz,
    )


@pytest.mark.parametrize(
    ("shift", "outside", "squared"),
    [(0.0, (0.0, 0.01), True), (0.03, (0.03, 0.08), True), (0.06, (0.2, 0.5), False), (0.20, (1.0, 1.0), False)],
    ids=["same-hover", "a-few-peaks-outside", "a-third-outside", "all-outside"],
)
def test_a_thrust_square_is_left_out_where_real_hovers_outside_the_simulations_range(
    shift: float, outside: tuple[float, float], squared: bool
) -> None:
    """The square stays while at most a tenth of REAL's thrust commands leave SIM's range; the other inputs' stay."""
    sim = synthetic_series(seed=1)
    thrust = 0.45 + 4.0 * (sim["delta_thr"] - 0.45)  # a curvature SIM informs: 4 % of the square's spread
    sim = _with_thrust(sim, thrust)
    real = synthetic_series(seed=2)
    moved = 0.45 + 4.0 * (real["delta_thr"] - 0.45) + shift
    share = float(np.mean((moved < thrust.min()) | (moved > thrust.max())))
    assert outside[0] <= share <= outside[1]  # the case is what its name says
    assert _curvature_share(thrust) > 0.03 and "delta_thr" in fit_baseline(sim).squared  # SIM alone informs it
    model = fit_baseline(sim, read_on=_with_thrust(real, moved))
    assert ("delta_thr" in model.squared) is squared
    assert {"delta_lat", "delta_lon", "delta_yaw"} <= set(model.squared)


@pytest.mark.parametrize(
    ("change", "values"),
    [(delayed, (0.0025, 0.02, 0.0375, 0.15)), (first_order, (0.005, 0.04, 0.3))],
    ids=["delay", "first-order-lag"],
)
def test_a_change_applied_to_the_outputs_parts_is_the_change_applied_to_every_input(
    change: Callable[[FlightSeries, np.ndarray, float], np.ndarray], values: tuple[float, ...]
) -> None:
    """A delay or a lag commutes with the model's impulse responses: the same prediction, to rounding, in two pieces."""
    flight = synthetic_series(seed=3)
    flight = FlightSeries(
        name=flight.name,
        time_s=flight.time_s,
        piece=(np.arange(flight.n) >= 1100).astype(int),  # a gap: no lag or change reaches across it
        signals=flight.signals,
        rate_hz=flight.rate_hz,
    )
    model = fit_baseline(flight)
    assert len(flight.spans()) == 2 and model.squared  # the squares' part is there to be changed too
    changed = model.changed(flight)
    for value in values:
        direct = model.predict(flight, {c: change(flight, flight[c], value) for c in COMMANDS})
        commuted = changed(lambda x, value=value: change(flight, x, value))
        for o in direct:
            scale = float(np.max(np.abs(direct[o])))
            np.testing.assert_allclose(commuted[o], direct[o], rtol=0, atol=1e-12 * scale, err_msg=f"{o} {value}")
