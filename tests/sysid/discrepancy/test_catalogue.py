"""The catalogue of terms: one module per effect, one registry line each, and what each term builds on a flight."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from sysid.discrepancy.baseline import fit_baseline
from sysid.discrepancy.catalogue import CATALOGUE, EFFECTS, FlightContext, candidate_terms, term_of
from sysid.discrepancy.series import COMMANDS, FlightSeries

NEW_TERMS = ("control_effectiveness", "parasitic_drag", "inflow", "translational_lift", "thrust_saturation")


def _flight(n: int = 3000, seed: int = 0) -> FlightSeries:
    """A synthetic flight: smooth random commands, states and a voltage, outputs linear in them."""
    rng = np.random.default_rng(seed)

    def smooth(scale: float) -> np.ndarray:
        return scale * np.convolve(rng.normal(size=n + 49), np.ones(50) / 50.0, mode="valid")

    signals = {c: smooth(0.05) for c in COMMANDS}
    signals["delta_thr"] = signals["delta_thr"] + 0.45
    for name, scale in (("u", 3.0), ("v", 3.0), ("w", 0.5), ("p", 0.2), ("q", 0.2), ("r", 0.2), ("vd", 0.5)):
        signals[name] = smooth(scale)
    signals["height_agl"] = 2.0 + np.abs(smooth(5.0))
    signals["battery_v"] = 25.0 - np.linspace(0.0, 1.0, n) + smooth(0.05)
    signals["t_flight"] = np.arange(n) / 50.0
    signals["ax"] = -0.3 * signals["u"] + 2.0 * signals["delta_lon"] + rng.normal(0, 0.05, n)
    signals["ay"] = -0.3 * signals["v"] + 2.0 * signals["delta_lat"] + rng.normal(0, 0.05, n)
    signals["az"] = -9.81 - 20.0 * (signals["delta_thr"] - 0.45) + rng.normal(0, 0.05, n)
    for axis, command in (("p_dot", "delta_lat"), ("q_dot", "delta_lon"), ("r_dot", "delta_yaw")):
        signals[axis] = 50.0 * signals[command] + rng.normal(0, 0.1, n)
    return FlightSeries(
        name="synthetic", time_s=np.arange(n) / 50.0, piece=np.zeros(n, int), signals=signals, rate_hz=50.0
    )


@pytest.fixture(scope="module", name="context")
def context_fixture() -> FlightContext:
    flight = _flight()
    baseline = fit_baseline(flight)
    return FlightContext(series=flight, baseline=baseline, thrust=-baseline.predict(flight)["az"])


def test_every_term_is_one_module_with_its_term_and_one_registry_line() -> None:
    assert len(set(EFFECTS)) == len(CATALOGUE)
    assert set(NEW_TERMS) <= set(EFFECTS)
    for term in CATALOGUE:
        module = importlib.import_module(f"sysid.discrepancy.catalogue.{term.effect}")
        assert module.TERM is term and term_of(term.effect) is term
        assert term.summary and term.separated_by, term.effect
        keys = [c.key for c in term.coefficients]
        assert len(keys) == len(set(keys)), term.effect
        assert all(r in EFFECTS for r in term.rivals)
    with pytest.raises(KeyError, match="no term 'sensor_drift' in the catalogue"):
        term_of("sensor_drift")


def test_each_terms_candidate_acts_on_its_outputs_with_its_named_coefficients(context: FlightContext) -> None:
    candidates = {c.effect: c for c in candidate_terms(context)}
    assert set(candidates) == set(EFFECTS) - {"wind"}  # no wind logged
    for effect, candidate in candidates.items():
        term = term_of(effect)
        assert set(candidate.outputs) <= set(term.outputs), effect
        built = candidate.build(candidate.grid[0])
        if candidate.kind == "linear":
            assert set(candidate.coefficients) <= {c.key for c in term.coefficients}, effect
            assert sum(built[o].shape[1] for o in candidate.outputs) == len(candidate.coefficients), effect
        for o in candidate.outputs:
            assert built[o].shape[0] == context.series.n and np.all(np.isfinite(built[o])), (effect, o)


def test_the_control_effectiveness_regressor_is_the_models_own_command_moment(context: FlightContext) -> None:
    """Scaling the simulation's roll moment per command by 0.8 is its coefficient -0.2, exactly (no noise)."""
    (candidate,) = [c for c in candidate_terms(context) if c.effect == "control_effectiveness"]
    part = context.baseline.command_part(context.series, "delta_lat")["p_dot"]
    column = candidate.build(float("nan"))["p_dot"][:, 0]
    residual = -0.2 * (part - part.mean())
    assert np.dot(column, residual) / np.dot(column, column) == pytest.approx(-0.2, rel=1e-12)


def test_a_baseline_recentred_on_the_thrust_reads_the_thrust_about_the_real_hover(context: FlightContext) -> None:
    """Moving the thrust command by s and recentring by s leaves every output but az as it was (exact)."""
    flight, baseline = context.series, context.baseline
    moved = FlightSeries(
        name="moved",
        time_s=flight.time_s,
        piece=flight.piece,
        signals={**flight.signals, "delta_thr": flight["delta_thr"] + 0.05},
        rate_hz=flight.rate_hz,
    )
    before, after = baseline.predict(flight), baseline.recentred(0.05).predict(moved)
    for o in before:
        if o != "az":
            np.testing.assert_allclose(after[o], before[o], atol=1e-10)
    np.testing.assert_allclose(after["az"], baseline.predict(moved)["az"], atol=1e-12)
