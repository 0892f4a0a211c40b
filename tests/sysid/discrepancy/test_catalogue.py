"""The catalogue of terms: one module per effect, one registry line each, and what each term builds on a flight."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from sysid.discrepancy.baseline import fit_baseline
from sysid.discrepancy.catalogue import CATALOGUE, EFFECTS, FlightContext, candidate_terms, term_of
from sysid.discrepancy.selection import narrowed
from sysid.discrepancy.series import FlightSeries

from builders import synthetic_series

NEW_TERMS = (
    "control_effectiveness",
    "parasitic_drag",
    "inflow",
    "translational_lift",
    "thrust_saturation",
    "sensor_scale",
)


@pytest.fixture(scope="module", name="context")
def context_fixture() -> FlightContext:
    flight = synthetic_series()
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
    calibrated = {t.effect for t in CATALOGUE if t.calibrate is not None}  # a sensor's, measured before any model
    assert calibrated == {"sensor_scale"}
    assert set(candidates) == set(EFFECTS) - {"wind"} - calibrated  # no wind logged
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


def test_a_rotor_drag_narrowed_to_its_force_keeps_its_force_columns_and_names(context: FlightContext) -> None:
    """The search drops a companion output (the hub moment) where it removes nothing: the rest is untouched."""
    whole = term_of("rotor_drag").make(context)
    assert whole is not None
    assert whole.outputs == ("ax", "ay", "p_dot", "q_dot") and term_of("rotor_drag").shown_on == ("ax", "ay")
    force = narrowed(whole, ("ax", "ay"))
    assert force.outputs == ("ax", "ay") and force.coefficients == ("d_x_s_m", "d_y_s_m")
    built, full = force.build(force.grid[0]), whole.build(whole.grid[0])
    assert set(built) == {"ax", "ay"}
    for o in built:
        np.testing.assert_array_equal(built[o], full[o])
    moment = narrowed(whole, ("ax", "q_dot"))
    assert moment.coefficients == ("d_x_s_m", "m_u_rad_m")


def test_a_coefficient_on_the_side_its_physics_rules_out_rules_its_term_out() -> None:
    """A saturation's lost thrust share is positive and its lost moments negative; beyond 2 sigma the other way, no."""
    saturation = term_of("thrust_saturation")
    assert saturation.against_physics([("share", -0.265, 0.019)])  # more thrust above the "ceiling": curvature
    assert not saturation.against_physics([("share", -0.03, 0.019)])  # within 2 sigma of zero: not ruled out
    assert not saturation.against_physics([("share", 0.9, 0.05), ("roll_share", -0.5, 0.14)])
    assert saturation.against_physics([("share", 0.9, 0.05), ("pitch_share", 0.5, 0.14)])
    signed = {t.effect for t in CATALOGUE if any(c.sign for c in t.coefficients)}
    assert signed == {"thrust_saturation"}  # the others' signs are not yet checked on tuning seeds
    for term in CATALOGUE:
        if term.effect not in signed:  # any of its own coefficients, far from zero either way, rules nothing out
            for value in (-5.0, 5.0):
                assert not term.against_physics([(c.key, value, 0.01) for c in term.coefficients]), term.effect
