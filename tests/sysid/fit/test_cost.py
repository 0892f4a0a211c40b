"""The cost of eq. 3.9, its residuals and Jacobian, against hand-computed values."""

from __future__ import annotations

import math

import numpy as np
import pytest

from flightlogs.errors import FitError
from simulator.vehicle.identified import CALM_HOVER
from sysid.fit import CostWeights, ResponseModel, fit_points, synthetic_responses
from sysid.model import Assembler, load_structure, parse_structure, structure_model

FIRST_ORDER = """
name = "first-order"
states = ["p"]
outputs = ["p"]
[[inputs]]
name = "delta_lat"
delay = "tau"
[parameters]
K = { value = 2.0 }
a = { value = -1.0 }
tau = { value = 0.0, bounds = [0.0, 1.0] }
[F]
p = { p = "a" }
[G_u]
p = { delta_lat = "K" }
"""
PAIRS = [
    "v/delta_lat",
    "p/delta_lat",
    "ay/delta_lat",
    "u/delta_lon",
    "q/delta_lon",
    "ax/delta_lon",
    "r/delta_yaw",
    "az/delta_thr",
]


def _w_gamma(gamma2: float) -> float:
    return (1.58 * (1.0 - math.exp(-gamma2))) ** 2


def _first_order(measured_gain: complex = 1.0, *, coherence: float = 1.0, delay: float = 0.0):
    s = parse_structure(FIRST_ORDER)
    truth, _ = structure_model(s, {"K": 2.0, "a": -1.0, "tau": delay})
    omega = np.geomspace(0.5, 50.0, 20)
    (fr,) = synthetic_responses(truth, ["p/delta_lat"], omega=omega, fit_range=(0.5, 50.0), coherence=coherence)
    fr = type(fr)(**{**{f: getattr(fr, f) for f in fr.__dataclass_fields__}, "response": fr.response * measured_gain})
    values = {"K": 2.0, "a": -1.0, "tau": delay}
    model = ResponseModel(
        Assembler(s, free=["K", "a", "tau"], fixed=values, constants={}, include_wind=False), fit_points([fr])
    )
    return model, np.array([2.0, -1.0, delay])


def test_exact_response_costs_nothing_even_beyond_a_turn_of_delay_phase() -> None:
    model, theta = _first_order(delay=0.2)  # 0.2 s at 50 rad/s is 573 deg of phase
    assert model.cost(theta).average == pytest.approx(0.0, abs=1e-18)


def test_one_db_everywhere_costs_twenty_w_gamma() -> None:
    model, theta = _first_order(10 ** (1 / 20), coherence=1.0)
    assert model.cost(theta).average == pytest.approx(20.0 * _w_gamma(1.0) * 1.0, rel=1e-9)


@pytest.mark.parametrize("degrees", [10.0, -10.0, 350.0])
def test_phase_error_costs_w_p_per_deg2_and_is_wrapped(degrees: float) -> None:
    model, theta = _first_order(np.exp(1j * math.radians(degrees)), coherence=0.5)
    wrapped = (degrees + 180.0) % 360.0 - 180.0
    assert model.cost(theta).average == pytest.approx(20.0 * _w_gamma(0.5) * 0.01745 * wrapped**2, rel=1e-9)


def test_weights_follow_the_options() -> None:
    s = parse_structure(FIRST_ORDER)
    truth, _ = structure_model(s, {"K": 2.0, "a": -1.0})
    grid = np.geomspace(0.5, 20.0, 160)  # 100 points a decade: one near each of 40 targets over 1-10 rad/s
    responses = synthetic_responses(truth, ["p/delta_lat"], omega=grid, fit_range=(1.0, 10.0), coherence=1.0)
    points = fit_points(responses, weights=CostWeights(n_points=40))
    targets = np.geomspace(points.omega[0], points.omega[-1], 40)
    half_step = np.log(grid[1] / grid[0]) / 2
    assert points.omega.size == 40 and np.all(np.abs(np.log(points.omega / targets)) <= half_step)
    assert points.weight == pytest.approx(np.full(40, 20.0 / 40 * _w_gamma(1.0)))
    few = fit_points(
        synthetic_responses(truth, ["p/delta_lat"], omega=np.geomspace(1.0, 10.0, 5), fit_range=(1.0, 10.0))
    )
    assert few.omega.size == 5 and few.weight.sum() == pytest.approx(20.0 * _w_gamma(0.95))  # n = 5 distinct points


def test_jacobian_matches_central_differences_with_trim_terms() -> None:
    hover = load_structure("hover")
    truth, _ = structure_model(hover, dict(CALM_HOVER))
    responses = synthetic_responses(truth, PAIRS, noise_db=1.0, noise_deg=5.0)
    free = [n for n in hover.parameter_names if n != "tau_thr"]
    consts = hover.default_constants() | {"U0": 2.2, "W0": -0.1, "theta0": -0.04}
    model = ResponseModel(
        Assembler(hover, free=free, fixed=hover.values(), constants=consts, include_wind=False), fit_points(responses)
    )
    theta = np.array([hover.values()[n] for n in free]) * 1.1 + 0.003
    jac = model.jacobian(theta)
    for k in range(theta.size):
        step = 1e-6 * max(1.0, abs(theta[k]))
        up, down = theta.copy(), theta.copy()
        up[k] += step
        down[k] -= step
        numeric = (model.residuals(up) - model.residuals(down)) / (2 * step)
        assert np.allclose(jac[:, k], numeric, rtol=1e-5, atol=1e-5 * np.abs(numeric).max()), free[k]


def test_unstable_airframe_has_a_finite_cost() -> None:
    """The calm hover has a pitch pair at +0.878 rad/s: the response is evaluated directly, never simulated."""
    hover = load_structure("hover")
    truth, _ = structure_model(hover, dict(CALM_HOVER))
    assert np.max(np.linalg.eigvals(truth.a).real) > 0.8
    responses = synthetic_responses(truth, PAIRS, omega=np.geomspace(1.0, 40.0, 20), fit_range=(1.0, 40.0))
    model = ResponseModel(
        Assembler(
            hover, free=["M_u"], fixed=truth_values(hover), constants=hover.default_constants(), include_wind=False
        ),
        fit_points(responses),
    )
    assert model.cost(np.array([CALM_HOVER["M_u"]])).average == pytest.approx(0.0, abs=1e-15)
    assert np.isfinite(model.cost(np.array([5.0])).average)


def truth_values(structure) -> dict[str, float]:
    return structure.values(dict(CALM_HOVER) | {"N_r": 0.0, "Z_w": 0.0})


def test_responses_the_model_cannot_produce_are_refused() -> None:
    s = parse_structure(FIRST_ORDER)
    truth, _ = structure_model(s, {"K": 2.0, "a": -1.0})
    (fr,) = synthetic_responses(truth, ["p/delta_lat"])
    hover = load_structure("hover")
    points = fit_points([type(fr)(**{**{f: getattr(fr, f) for f in fr.__dataclass_fields__}, "output": "psi"})])
    with pytest.raises(FitError, match="no output psi"):
        ResponseModel(
            Assembler(
                hover,
                free=[],
                fixed=hover.values(),
                constants={"g": 9.81, "U0": 0, "V0": 0, "W0": 0, "phi0": 0, "theta0": 0},
            ),
            points,
        )
    ungated = type(fr)(**{**{f: getattr(fr, f) for f in fr.__dataclass_fields__}, "fit_range": None})
    with pytest.raises(FitError, match="no fit range"):
        fit_points([ungated])
