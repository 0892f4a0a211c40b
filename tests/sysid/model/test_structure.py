"""Model structures: the safe evaluator, the TOML format, the built-ins against the simulator's truth."""

from __future__ import annotations

import math

import numpy as np
import pytest

from flightlogs.errors import ModelError
from simulator.flights.linear import _axis_models
from simulator.vehicle.identified import CALM_HOVER, G
from sysid.model import Assembler, load_structure, parse_expression, parse_structure, structure_model

ROLL = """
name = "roll"
states = ["p", "phi"]
outputs = ["p", "phi", "ay"]
[constants]
g = 9.81
[[inputs]]
name = "delta_lat"
delay = "tau_lat"
[parameters]
L_p = { value = -2.0, bounds = [-20.0, 20.0] }
L_lat = { value = 50.0, input = "delta_lat" }
tau_lat = { value = 0.01, bounds = [0.0, 0.2] }
[F]
p = { p = "L_p" }
phi = { p = 1.0 }
[G_u]
p = { delta_lat = "L_lat" }
[H0]
ay = { phi = "-g" }
[H1]
ay = { p = "L_p/L_p" }
"""


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("1/T_a", 20.0),
        ("-g*cos(theta0)", -9.81),
        ("X_u**2 - 3", -2.75),
        ("+U0 - -W0", 3.0),
        ("sqrt(g*g)", 9.81),
        ("exp(0) + tan(0) + sin(0)", 1.0),
        (2, 2.0),
        (-0.5, -0.5),
    ],
)
def test_expressions_evaluate(text: str | float, expected: float) -> None:
    values = {"T_a": 0.05, "g": 9.81, "theta0": 0.0, "X_u": -0.5, "U0": 1.0, "W0": 2.0}
    assert float(np.real(parse_expression(text)(values))) == pytest.approx(expected)


@pytest.mark.parametrize(
    "text",
    [
        "__import__('os').system('true')",
        "X_u.real",
        "values['g']",
        "lambda: 1",
        "open('x')",
        "[1, 2]",
        "X_u if g else 0",
        "g < 1",
        "'text'",
        "True",
        "abs(X_u)",
        "cos(g, g)",
        "f(x)",
        "",
        "1 +",
        "x" * 300,
    ],
)
def test_expressions_refuse_anything_but_arithmetic(text: str) -> None:
    with pytest.raises(ModelError):
        parse_expression(text, where="F[u, u]")


def test_expression_reports_unknown_name_and_division_by_zero() -> None:
    with pytest.raises(ModelError, match="Y_v"):
        parse_expression("Y_v + 1")({})
    with pytest.raises(ModelError, match="1/T_a"):
        parse_expression("1/T_a")({"T_a": 0.0})


def test_complex_step_of_an_expression_is_its_derivative() -> None:
    expression = parse_expression("-g*cos(theta0)/T_a")
    h = 1e-30
    step = expression({"g": 9.81, "theta0": 0.1, "T_a": 0.05 + 1j * h})
    assert np.imag(step) / h == pytest.approx(9.81 * math.cos(0.1) / 0.05**2, rel=1e-12)


def test_toml_structure_assembles_with_h1_substitution() -> None:
    s = parse_structure(ROLL)
    asm = Assembler(s, free=["L_p"], fixed=s.values(), constants=s.default_constants())
    m = asm.matrices(np.array([-3.0]))
    # ay = p' - g phi = L_p p + L_lat delta - g phi (H1 substitution)
    assert m.c[2].tolist() == pytest.approx([-3.0, -9.81])
    assert m.d[2, 0] == pytest.approx(50.0)
    assert m.delays.tolist() == [0.01]
    d = asm.derivatives(np.array([-3.0]))
    assert d.a[0, 0, 0] == pytest.approx(1.0) and d.c[0, 2, 0] == pytest.approx(1.0)


def test_derivatives_match_finite_differences_on_the_hover_structure() -> None:
    s = load_structure("hover-wind")
    free = ["X_u", "M_u", "T_a", "tau_lon", "M_lon", "Z_w", "X_w_lon", "tau_w_thr"]
    consts = s.default_constants() | {"U0": 2.0, "W0": -0.2, "theta0": -0.07}
    asm = Assembler(s, free=free, fixed=s.values(), constants=consts)
    theta = np.array([s.values()[n] for n in free])
    d = asm.derivatives(theta)
    for k in range(len(free)):
        step = 1e-6 * max(1.0, abs(theta[k]))
        up, down = theta.copy(), theta.copy()
        up[k] += step
        down[k] -= step
        hi, lo = asm.matrices(up), asm.matrices(down)
        for name in ("a", "b", "c", "d", "delays"):
            numeric = (getattr(hi, name) - getattr(lo, name)) / (2 * step)
            assert np.allclose(getattr(d, name)[k], numeric, atol=1e-6 * (1 + np.abs(numeric).max())), (free[k], name)


def test_mass_matrix_is_inverted() -> None:
    text = ROLL.replace("[F]", "[M]\np = { p = 2.0 }\n[F]")
    s = parse_structure(text)
    m = Assembler(s, free=[], fixed=s.values(), constants=s.default_constants()).matrices(np.zeros(0))
    assert m.a[0, 0] == pytest.approx(-1.0) and m.b[0, 0] == pytest.approx(25.0)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (('p = { p = "L_p" }', 'p = { p = "L_q" }'), "unknown name 'L_q'"),
        (('p = { p = "L_p" }', 'q = { p = "L_p" }'), "row 'q'"),
        (("phi = { p = 1.0 }", "phi = { r = 1.0 }"), "column 'r'"),
        (('outputs = ["p", "phi", "ay"]', 'outputs = ["p", "phi", "ay", "az"]'), "output 'az' is not a state"),
        (
            ("L_p = { value = -2.0, bounds = [-20.0, 20.0] }", "L_p = { value = -30.0, bounds = [-20.0, 20.0] }"),
            "outside its bounds",
        ),
        (('input = "delta_lat"', 'input = "delta_lon"'), "delta_lon"),
        (("[F]", "[G]"), "unknown key 'G'"),
        (('p = { p = "L_p" }', 'p = { p = "L_p(1)" }'), "not a call of L_p"),
        (('name = "roll"', "name = roll"), "not valid TOML"),
    ],
)
def test_structure_errors_name_the_fault(edit: tuple[str, str], message: str) -> None:
    with pytest.raises(ModelError, match=message):
        parse_structure(ROLL.replace(*edit), source="roll.toml")


def test_builtins_load_by_name_and_unknown_names_are_refused(tmp_path) -> None:
    assert load_structure("hover").name == "hover"
    wind = load_structure("hover-wind")
    assert wind.wind_parameters == ("X_w_lon", "Z_w_lon", "tau_w_lon", "tau_w_thr")
    assert [c.signal for c in wind.wind_inputs] == ["wind_lon", "wind_lon"]
    path = tmp_path / "roll.toml"
    path.write_text(ROLL)
    assert load_structure(path).name == "roll"
    with pytest.raises(ModelError, match="neither a built-in"):
        load_structure("hovre")


def test_hover_names_follow_the_dissertation() -> None:
    names = set(load_structure("hover-wind").parameter_names)
    assert names == set(
        "X_u M_u X_lon M_lon Y_v L_v Y_lat L_lat N_r N_yaw Z_w Z_thr T_a tau_lat tau_lon tau_yaw "
        "tau_thr X_w_lon Z_w_lon tau_w_lon tau_w_thr".split()
    )


def test_hover_at_zero_trim_is_the_simulators_truth() -> None:
    """Same sign conventions as simulator.flights.linear (eqs. 3.10-3.13 with the actuator lag)."""
    hover = load_structure("hover")
    model, _ = structure_model(hover, dict(CALM_HOVER), constants={"g": G})
    truth = _axis_models(CALM_HOVER)
    order = {
        "lat": ["v", "p", "phi", "d_lat"],
        "lon": ["u", "q", "theta", "d_lon"],
        "yaw": ["r"],
        "thr": ["w", "d_thr"],
    }
    rows = {"lat": [0, 1, 2, 3], "lon": [0, 1, 2, 3], "yaw": [0], "thr": [0, 2]}
    for axis, states in order.items():
        index = [hover.states.index(s) for s in states]
        a, b = truth[axis]
        assert np.allclose(model.a[np.ix_(index, index)], a[np.ix_(rows[axis], rows[axis])]), axis
        column = model.inputs.index(f"delta_{axis}")
        assert np.allclose(model.b[index, column], b[rows[axis], 0]), axis
    # accelerometers, eq. 3.7 at zero trim: ax = u' + g theta, ay = v' - g phi, az = w'
    ax = model.outputs.index("ax")
    u, q, theta = (hover.states.index(s) for s in ("u", "q", "theta"))
    assert model.c[ax, u] == pytest.approx(CALM_HOVER["X_u"]) and model.c[ax, theta] == pytest.approx(0.0)
    assert model.input_delays_s.tolist() == [CALM_HOVER[f"tau_{a}"] for a in ("lat", "lon", "yaw", "thr")]


def test_trim_constants_enter_eq_3_5() -> None:
    hover = load_structure("hover")
    consts = hover.constants_from_trim({"u": 4.12, "w": -0.22, "theta": math.radians(-4.36), "v": 0.0, "phi": 0.0})
    model, _ = structure_model(hover, dict(CALM_HOVER), constants=consts)
    w, q, theta, v, r = (hover.states.index(s) for s in ("w", "q", "theta", "v", "r"))
    assert model.a[w, q] == pytest.approx(4.12)  # Z_q + U0
    assert model.a[v, r] == pytest.approx(-4.12)  # Y_r - U0
    assert model.a[w, theta] == pytest.approx(-9.81 * math.sin(math.radians(-4.36)))
    az = model.outputs.index("az")
    assert model.c[az, q] == pytest.approx(0.0)  # w' has +U0 q, az = w' - U0 q
