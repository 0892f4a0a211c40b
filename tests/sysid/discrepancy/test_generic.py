"""The model of the unknown: a sparse combination of the flight's own regressors, chosen on held-out blocks."""

from __future__ import annotations

import numpy as np
import pytest

from sysid.discrepancy.baseline import fit_baseline
from sysid.discrepancy.catalogue import FlightContext
from sysid.discrepancy.generic import MAX_REGRESSORS, fit_generic, generic_library
from sysid.discrepancy.series import OUTPUTS

from builders import synthetic_series as _flight


@pytest.fixture(scope="module", name="context")
def context_fixture() -> FlightContext:
    flight = _flight(n=6000, seed=4)
    baseline = fit_baseline(flight)
    return FlightContext(series=flight, baseline=baseline, thrust=-baseline.predict(flight)["az"])


def _fit(context: FlightContext, extra: dict[str, np.ndarray]) -> tuple[object, dict[str, np.ndarray]]:
    n = context.series.n
    rng = np.random.default_rng(9)
    current = {o: np.zeros(n) for o in OUTPUTS}
    y = {o: extra.get(o, np.zeros(n)) + rng.normal(0.0, 0.05, n) for o in OUTPUTS}
    scale = {o: 0.05**2 for o in OUTPUTS}
    return fit_generic(context, y, current, scale), y


def test_a_pitch_moment_that_follows_the_speed_is_found_on_q_dot_alone(context: FlightContext) -> None:
    """q_dot residual 0.2 u (a hub moment): u chosen first on q_dot and nowhere else.

    Its held-out score is what the signal's share of the residual allows (analytic: var(0.2 u) over that plus the
    noise's 0.05²), within 0.03.
    """
    signal = 0.2 * context.series["u"]
    fit, _ = _fit(context, {"q_dot": signal})
    assert fit.outputs == ("q_dot",)
    assert [r.key for r in fit.chosen["q_dot"]][0] == "u"
    share = float(np.var(signal)) / (float(np.var(signal)) + 0.05**2)
    assert fit.output_scores["q_dot"] == pytest.approx(share, abs=0.03)


def test_a_roll_command_acting_on_pitch_is_named_by_the_models_own_roll_moment(context: FlightContext) -> None:
    part = context.command_parts["delta_lat"]["p_dot"]
    fit, _ = _fit(context, {"q_dot": 0.15 * (part - part.mean())})
    assert "P_delta_lat" in [r.key for r in fit.chosen["q_dot"]]


def test_a_sensors_constant_bias_is_a_nuisance_not_a_model(context: FlightContext) -> None:
    """ay 0.4 m/s² off (an accelerometer bias, 8 times the noise): nothing modelled."""
    fit, _ = _fit(context, {"ay": np.full(context.series.n, 0.4)})
    assert fit.chosen == {} and fit.score <= 0.0


def test_noise_alone_is_left_alone(context: FlightContext) -> None:
    fit, _ = _fit(context, {})
    assert fit.chosen == {}


def test_the_library_holds_named_regressors_in_units_and_the_model_keeps_few(context: FlightContext) -> None:
    library = generic_library(context)
    keys = [r.key for r in library]
    assert len(keys) == len(set(keys)) >= 20
    assert {"T*climb", "u|u|", "P_delta_lat", "p*q"} <= set(keys)
    assert all(r.unit and r.words for r in library)
    fit, _ = _fit(context, {"az": 0.3 * context.series["u"] + 0.3 * context.series["v"] + 0.3 * context.series["w"]})
    assert 1 <= len(fit.chosen["az"]) <= MAX_REGRESSORS
