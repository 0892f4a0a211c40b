"""Modes: the SI eigenvalues of Table 3.3 (tables.md), analytic second-order systems, labels."""

from __future__ import annotations

import math

import control
import numpy as np
import pytest

from sysid.model import load_structure, structure_model
from sysid.model.modes import modes
from sysid.model.statespace import DelayedStateSpace

#: Table 3.3, calm wind (per % of mixer input).
TABLE_3_3_CALM = {
    "X_u": -0.3172,
    "M_u": 0.7690,
    "X_lon": -0.0985,
    "M_lon": 0.5251,
    "Y_v": -0.2787,
    "L_v": -0.7406,
    "Y_lat": 0.1185,
    "L_lat": 0.6226,
    "N_yaw": 0.0744,
    "Z_thr": -0.8712,
    "T_a": 0.0458,
    "tau_lat": 0.0194,
    "tau_lon": 0.0201,
    "tau_yaw": 0.0133,
}


def _by_mode(found):
    out: dict[str, list] = {}
    for m in found:
        out.setdefault(m.mode, []).append(m)
    return out


def test_calm_table_3_3_gives_the_si_eigenvalues_of_tables_md() -> None:
    """tables.md: longitudinal 0.878 +- 1.694i and -2.073, lateral 0.8778 +- 1.674i and -2.034, actuator -21.83,
    time to double 0.79 s (g = 9.81 m/s^2, not Table 3.7's ft/s^2 figures)."""
    model, unset = structure_model(load_structure("hover"), TABLE_3_3_CALM)
    assert set(unset) == {"N_r", "Z_w", "tau_thr"}
    found = _by_mode(modes(model))
    pitch = sorted(found["pitch"], key=lambda m: -m.real)
    roll = sorted(found["roll"], key=lambda m: -m.real)
    assert (pitch[0].real, pitch[0].imag) == (pytest.approx(0.878, abs=5e-4), pytest.approx(1.694, abs=5e-4))
    assert pitch[1].real == pytest.approx(-2.073, abs=5e-4) and pitch[1].imag == 0.0
    assert (roll[0].real, roll[0].imag) == (pytest.approx(0.8778, abs=5e-5), pytest.approx(1.674, abs=5e-4))
    assert roll[1].real == pytest.approx(-2.034, abs=5e-4)
    assert [m.real for m in found["actuator"]] == pytest.approx([-21.83] * 3, abs=5e-3)
    assert pitch[0].stability == "unstable" and pitch[0].time_to_double_s == pytest.approx(0.79, abs=5e-3)
    assert pitch[1].time_to_half_s == pytest.approx(math.log(2) / 2.073, rel=1e-3)
    assert {m.stability for m in found["yaw"] + found["heave"]} == {"neutral"}


def test_repeated_zero_eigenvalues_keep_every_motion() -> None:
    """Issue 14: with no speed damping or stability (X_u = M_u = Y_v = L_v = 0) and no Z_w, N_r the hover model
    has eight zero eigenvalues; a whole-matrix eigenvector basis mixed them and labelled five "pitch", losing
    roll, heave and yaw. Each motion keeps its own: pitch 3, roll 3, heave 1, yaw 1, actuator 3."""
    values = {**TABLE_3_3_CALM, "X_u": 0.0, "M_u": 0.0, "Y_v": 0.0, "L_v": 0.0}
    model, _ = structure_model(load_structure("hover"), values)
    found = _by_mode(modes(model))
    counts = {mode: sum(2 if m.oscillatory else 1 for m in group) for mode, group in found.items()}
    assert counts == {"pitch": 3, "roll": 3, "heave": 1, "yaw": 1, "actuator": 3}
    assert all(m.real == 0.0 and m.stability == "neutral" for m in found["pitch"] + found["roll"])
    assert [m.real for m in found["actuator"]] == pytest.approx([-1 / 0.0458] * 3)


def test_second_order_damping_and_frequency_are_analytic() -> None:
    zeta, omega_n = 0.3, 4.0
    a = np.array([[0.0, 1.0], [-(omega_n**2), -2 * zeta * omega_n]])
    model = DelayedStateSpace(
        a=a,
        b=np.array([[0.0], [1.0]]),
        c=np.eye(2),
        d=np.zeros((2, 1)),
        states=("theta", "q"),
        inputs=("delta_lon",),
        outputs=("theta", "q"),
        input_delays_s=np.zeros(1),
    )
    (mode,) = modes(model)
    assert mode.damping == pytest.approx(zeta) and mode.natural_frequency_rad_s == pytest.approx(omega_n)
    assert mode.imag == pytest.approx(omega_n * math.sqrt(1 - zeta**2)) and mode.oscillatory
    assert mode.time_to_half_s == pytest.approx(math.log(2) / (zeta * omega_n)) and mode.mode == "pitch"
    assert mode.time_to_double_s == math.inf


def test_labels_do_not_depend_on_state_units() -> None:
    """Participation factors are unchanged by scaling a state (per % or per normalised input alike)."""
    model, _ = structure_model(load_structure("hover"), TABLE_3_3_CALM)
    scale = np.diag([100.0 if s.startswith("d_") else 1.0 for s in model.states])
    scaled = DelayedStateSpace(
        a=scale @ model.a @ np.linalg.inv(scale),
        b=scale @ model.b,
        c=model.c @ np.linalg.inv(scale),
        d=model.d,
        states=model.states,
        inputs=model.inputs,
        outputs=model.outputs,
        input_delays_s=model.input_delays_s,
    )
    assert [(m.mode, round(m.real, 6)) for m in modes(scaled)] == [(m.mode, round(m.real, 6)) for m in modes(model)]


def test_modes_of_a_python_control_system() -> None:
    system = control.ss([[-1.0, 0.0], [0.0, 2.0]], [[1.0], [1.0]], [[1.0, 1.0]], [[0.0]], states=["r", "w"])
    found = {m.mode: m for m in modes(system)}
    assert found["yaw"].real == pytest.approx(-1.0) and found["heave"].stability == "unstable"
    with pytest.raises(TypeError):
        modes("model.json")
