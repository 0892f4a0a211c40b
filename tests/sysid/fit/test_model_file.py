"""Identified models on disk (JSON, .mat) and the python-control adapter, round-tripped."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from scipy import io as sio

from flightlogs.errors import ModelError
from simulator.vehicle.identified import CALM_HOVER
from sysid.fit import (
    FitOptions,
    IdentifiedModel,
    Provenance,
    WindFit,
    fit_frequency_responses,
    fit_summary,
    from_control_layout,
    from_statespace,
    model_from_fit,
    read_model,
    synthetic_responses,
    to_control_layout,
    to_statespace,
    write_mat,
    write_model,
)
from sysid.fit.result import WindClockOffset, WindTrace
from sysid.model import load_structure, structure_model
from sysid.model.statespace import DelayedStateSpace

from builders import with_unidentified

PAIRS = ["p/delta_lat", "ay/delta_lat", "q/delta_lon", "ax/delta_lon", "r/delta_yaw", "az/delta_thr"]


@pytest.fixture(scope="module")
def model() -> IdentifiedModel:
    structure = load_structure("hover-wind")
    truth, _ = structure_model(structure, dict(CALM_HOVER) | {"X_w_lon": -0.356, "Z_w_lon": 1.323})
    responses = synthetic_responses(truth, PAIRS, noise_db=0.5, noise_deg=3.0, fit_range=(0.8, 50.0))
    fit = fit_frequency_responses(structure, responses, options=FitOptions(max_steps=2))
    return model_from_fit(
        fit,
        trim={"u": 2.2, "theta": -0.04},
        provenance=Provenance(
            files=("a.bin",),
            sha256={"a.bin": "0" * 64},
            options={"starts": 1},
            versions={"numpy": "2"},
            created_utc="now",
        ),
        notes=("u/delta_lon: dropped by gating",),
    )


def test_json_round_trip_keeps_everything(model: IdentifiedModel, tmp_path) -> None:
    path = write_model(tmp_path / "model.json", model)
    back = read_model(path)
    assert back.parameters == model.parameters
    assert back.cost == model.cost and back.reduction == model.reduction and back.notes == model.notes
    assert back.correlation_names == model.correlation_names
    assert np.array_equal(np.isnan(back.correlation), np.isnan(model.correlation))
    assert np.allclose(np.nan_to_num(back.correlation), np.nan_to_num(model.correlation), rtol=0, atol=0)
    assert back.provenance == model.provenance and dict(back.trim) == dict(model.trim)
    for a, b in zip(back.responses, model.responses):
        assert a.pair == b.pair and a.fit_range == b.fit_range
        assert np.array_equal(a.response, b.response) and np.array_equal(a.coherence, b.coherence)
    one, two = back.linear_model(), model.linear_model()
    assert np.array_equal(one.a, two.a) and np.array_equal(one.d, two.d) and one.inputs == two.inputs
    doc = json.loads(path.read_text())
    assert doc["schema_version"] == 1 and doc["parameters"]["X_w_lon"]["status"] == "dropped"
    assert doc["parameters"]["N_r"]["cr_percent"] is None  # NaN is written as null


def test_the_wind_steps_clock_scan_and_trace_round_trip(model: IdentifiedModel, tmp_path) -> None:
    shift, t = np.linspace(-5.0, 5.0, 101), np.arange(0.0, 20.0, 0.1)
    clock = WindClockOffset(
        shift_s=shift,
        cost=1.0 + (shift + 1.5) ** 2,
        cost_without_wind=30.0,
        best_shift_s=-1.5,
        sigma_s=0.02,
        used_clock_offset_s=0.0,
        transport_delay_s=0.85,
        measured=True,
        reason="",
        samples=1000,
    )
    trace = WindTrace(
        record="a.bin lon sweep 10.00-30.00 s",
        time_s=t,
        at_anemometer_m_s=np.sin(t + 0.85),
        at_vehicle_m_s=np.sin(t),
        from_accelerations_m_s=np.sin(t) + 0.01 * np.cos(7 * t),
        output="ax",
        gain=-0.356,
        transport_delay_s=0.85,
        smoothing_hz=2.0,
    )
    wind = WindFit(outputs=("ax", "az"), rms_before=(0.3, 0.4), rms_after=(0.1, 0.2), samples=1000)
    windy = dataclasses.replace(model, wind=dataclasses.replace(wind, clock_offset=clock, trace=trace))
    back = read_model(write_model(tmp_path / "model.json", windy)).wind
    assert back is not None and back.clock_offset is not None and back.trace is not None
    assert back.clock_offset.clock_offset_s == clock.clock_offset_s == 1.5
    assert np.array_equal(back.clock_offset.cost, clock.cost)
    for name in ("time_s", "at_anemometer_m_s", "at_vehicle_m_s", "from_accelerations_m_s"):
        assert np.array_equal(getattr(back.trace, name), getattr(trace, name)), name
    assert (back.trace.record, back.trace.gain, back.trace.transport_delay_s) == (trace.record, -0.356, 0.85)


def test_how_each_response_was_computed_is_kept(model: IdentifiedModel, tmp_path) -> None:
    first = dataclasses.replace(model.responses[0], reference="excitation", whole_record=True)
    changed = dataclasses.replace(model, responses=(first, *model.responses[1:]))
    back = read_model(write_model(tmp_path / "model.json", changed))
    assert [(r.reference, r.whole_record) for r in back.responses] == [
        (r.reference, r.whole_record) for r in changed.responses
    ]
    assert (back.responses[0].reference, back.responses[0].whole_record) == ("excitation", True)


def test_wind_parameters_without_a_wind_step_are_dropped_and_logged(model: IdentifiedModel) -> None:
    assert model.parameter("X_w_lon").dropped and model.parameter("X_w_lon").stage == "wind"
    assert any(s.parameter == "tau_w_thr" and "no wind record" in s.reason for s in model.reduction)
    assert model.linear_model(include_wind=False).inputs == ("delta_lat", "delta_lon", "delta_yaw", "delta_thr")
    assert model.linear_model().inputs[-2:] == ("wind_lon", "wind_lon")


def test_bad_model_files_are_refused(model: IdentifiedModel, tmp_path) -> None:
    path = write_model(tmp_path / "model.json", model)
    doc = json.loads(path.read_text())
    for change, message in (
        ({"schema_version": 99}, "version 99"),
        ({"schema": "x"}, "not a flight-sysid model"),
        ({"cost": {}}, "cost has no average"),
    ):
        (tmp_path / "bad.json").write_text(json.dumps(doc | change))
        with pytest.raises(ModelError, match=message):
            read_model(tmp_path / "bad.json")
    (tmp_path / "text.json").write_text("{not json")
    with pytest.raises(ModelError, match="text.json"):
        read_model(tmp_path / "text.json")


def test_a_file_without_the_fit_limits_reads_with_tischlers(model: IdentifiedModel, tmp_path) -> None:
    """Model files written before the limits were read from the options (and files without provenance) still read."""
    doc = json.loads(write_model(tmp_path / "model.json", model).read_text())
    assert "fit" not in doc["provenance"]["options"]  # this model was assembled without the fit's options
    del doc["provenance"]
    (tmp_path / "old.json").write_text(json.dumps(doc))
    old = read_model(tmp_path / "old.json")
    assert old.parameters == model.parameters
    assert (old.guidelines.max_cr_percent, old.guidelines.max_insensitivity_percent) == (20.0, 10.0)


def test_the_fit_limits_travel_with_the_model(model: IdentifiedModel, tmp_path) -> None:
    options = {"fit": {"max_cr_percent": 30.0, "max_insensitivity_percent": 12.5}}
    fitted = dataclasses.replace(model, provenance=dataclasses.replace(model.provenance, options=options))
    back = read_model(write_model(tmp_path / "model.json", fitted))
    assert (back.guidelines.max_cr_percent, back.guidelines.max_insensitivity_percent) == (30.0, 12.5)


@pytest.mark.parametrize(
    ("limits", "message"),
    [
        ({"max_cr_percent": "20"}, "provenance: options fit.max_cr_percent is '20', not a number"),
        ({"max_insensitivity_percent": 0}, "provenance: max_insensitivity_percent=0.0 must be a positive number"),
    ],
)
def test_bad_fit_limits_are_refused(model: IdentifiedModel, tmp_path, limits: dict[str, object], message: str) -> None:
    doc = json.loads(write_model(tmp_path / "model.json", model).read_text())
    doc["provenance"]["options"] = {"fit": limits}
    (tmp_path / "bad.json").write_text(json.dumps(doc))
    with pytest.raises(ModelError, match=f"bad.json: {message}"):
        read_model(tmp_path / "bad.json")


def test_mat_file_holds_the_matrices(model: IdentifiedModel, tmp_path) -> None:
    content = sio.loadmat(write_mat(tmp_path / "model.mat", model))
    linear = model.linear_model()
    assert np.array_equal(content["A"], linear.a) and np.array_equal(content["D"], linear.d)
    assert [str(s[0]) for s in content["states"].ravel()] == list(linear.states)
    names = [str(s[0]) for s in content["parameter_names"].ravel()]
    assert content["parameter_values"].ravel()[names.index("X_u")] == model.parameter("X_u").value


def test_summary_has_the_fields_scripts_use(model: IdentifiedModel) -> None:
    summary = fit_summary(model)
    assert set(summary["parameters"]["X_u"]) >= {"value", "cr_percent", "insensitivity_percent"}
    assert summary["cost"]["average"] == model.cost.average and set(summary["cost"]["responses"]) == set(
        model.cost.responses
    )
    assert {"real", "imag", "damping", "natural_frequency_rad_s", "mode"} <= set(summary["eigenvalues"][0])
    assert set(summary["dropped"]) >= {"X_w_lon", "Z_w_lon"}
    json.dumps(summary, allow_nan=False)  # NaN-free


def test_layout_adapter_round_trips() -> None:
    response = np.random.default_rng(0).normal(size=(7, 3, 2)) + 0j
    assert to_control_layout(response).shape == (3, 2, 7)
    assert np.array_equal(from_control_layout(to_control_layout(response)), response)


def test_control_statespace_reproduces_the_response(model: IdentifiedModel) -> None:
    linear = model.linear_model(include_wind=False)
    omega = np.geomspace(0.5, 30.0, 25)
    undelayed = DelayedStateSpace(
        a=linear.a,
        b=linear.b,
        c=linear.c,
        d=linear.d,
        states=linear.states,
        inputs=linear.inputs,
        outputs=linear.outputs,
        input_delays_s=np.zeros(len(linear.inputs)),
    )
    system = to_statespace(undelayed)
    ours = from_control_layout(system.frequency_response(omega).complex)
    assert np.allclose(ours, undelayed.frequency_response(omega), rtol=1e-9, atol=1e-12)
    back = from_statespace(system, linear.input_delays_s)
    assert np.allclose(back.frequency_response(omega), linear.frequency_response(omega), rtol=1e-9, atol=1e-12)
    # Pade: phase error of a 3rd-order approximant of exp(-s tau) is below 1e-3 rad for omega tau < 1
    pade = from_control_layout(to_statespace(linear, delays="pade", pade_order=3).frequency_response(omega).complex)
    assert np.allclose(pade, linear.frequency_response(omega), rtol=2e-3, atol=1e-9)


def test_control_names_are_unique_for_a_signal_entering_twice(model: IdentifiedModel) -> None:
    system = to_statespace(model)
    assert system.input_labels[-2:] == ["wind_lon", "wind_lon_2"]
    with pytest.raises(TypeError):
        to_statespace(object())
    assert math.isfinite(model.cost.average)


@pytest.fixture(scope="module")
def partial() -> IdentifiedModel:
    """Pitch and roll responses only: the yaw and heave axes are unidentified."""
    structure = load_structure("hover-wind")
    truth, _ = structure_model(structure, dict(CALM_HOVER))
    responses = synthetic_responses(truth, PAIRS[:4], noise_db=0.5, noise_deg=3.0, fit_range=(0.8, 50.0))
    return model_from_fit(fit_frequency_responses(structure, responses, options=FitOptions(max_steps=2)))


def test_a_partial_model_has_no_value_for_what_was_not_measured(partial: IdentifiedModel, tmp_path) -> None:
    assert [a.axis for a in partial.unidentified_axes] == ["yaw", "thr"]
    for name in ("N_yaw", "tau_yaw", "Z_thr", "tau_thr", "Z_w", "N_r"):
        p = partial.parameter(name)
        assert p.unidentified and math.isnan(p.value) and math.isnan(p.cr_percent), name
    path = write_model(tmp_path / "partial.json", partial)
    doc = json.loads(path.read_text())
    assert doc["parameters"]["N_yaw"]["value"] is None and doc["parameters"]["N_yaw"]["status"] == "unidentified"
    assert {a["axis"]: a["status"] for a in doc["axes"]} == {
        "lat": "identified",
        "lon": "identified",
        "yaw": "unidentified",
        "thr": "unidentified",
    }
    assert doc["axes"][2]["reason"] == "no gated response of delta_yaw was fitted"
    assert doc["linear_model"]["inputs"] == ["delta_lat", "delta_lon", "wind_lon", "wind_lon"]
    assert "r" not in doc["linear_model"]["states"] and "az" not in doc["linear_model"]["outputs"]
    back = read_model(path)
    assert back.axes == partial.axes
    assert [(p.name, p.status) for p in back.parameters] == [(p.name, p.status) for p in partial.parameters]
    summary = fit_summary(partial)
    assert summary["parameters"]["N_yaw"]["value"] is None and "N_yaw" in summary["unidentified"]
    json.dumps(summary, allow_nan=False)


def test_a_partial_model_is_simulated_on_its_identified_axes_only(partial: IdentifiedModel, tmp_path) -> None:
    """linear_model, the .mat file and python-control get the lat and lon parts, equal to the whole model's there."""
    linear = partial.linear_model(include_wind=False)
    assert linear.inputs == ("delta_lat", "delta_lon")
    assert linear.states == ("u", "v", "p", "q", "phi", "theta", "d_lat", "d_lon")
    assert linear.outputs == ("u", "v", "p", "q", "phi", "theta", "ax", "ay")
    omega = np.geomspace(0.5, 30.0, 7)
    whole = dataclasses.replace(
        partial,
        parameters=tuple(
            dataclasses.replace(p, status="fixed", value=1.0) if p.unidentified else p for p in partial.parameters
        ),
        axes=(),
    ).linear_model(include_wind=False)
    pick = [whole.outputs.index(o) for o in linear.outputs]
    assert np.allclose(linear.frequency_response(omega), whole.frequency_response(omega)[:, pick, :2])
    content = sio.loadmat(write_mat(tmp_path / "partial.mat", partial))
    assert content["A"].shape == (8, 8)
    names = [str(s[0]) for s in content["parameter_names"].ravel()]
    assert np.isnan(content["parameter_values"].ravel()[names.index("N_yaw")])
    assert to_statespace(partial).ninputs == 4  # delta_lat, delta_lon and the two wind channels


def test_nothing_builds_matrices_from_an_unidentified_parameter(partial: IdentifiedModel) -> None:
    with pytest.raises(ModelError, match="N_yaw has no value"):
        structure_model(load_structure("hover"), {"N_yaw": math.nan})
    nothing = with_unidentified(partial, {p.name for p in partial.parameters})
    with pytest.raises(ModelError, match="no identified axis"):
        nothing.linear_model()


def test_an_old_file_without_axes_reads_with_them_derived(model: IdentifiedModel, tmp_path) -> None:
    doc = json.loads(write_model(tmp_path / "model.json", model).read_text())
    del doc["axes"]
    for step in doc["reduction"]:
        del step["cost_responses"], step["cost_responses_after"]
    (tmp_path / "old.json").write_text(json.dumps(doc))
    old = read_model(tmp_path / "old.json")
    assert old.axes == () and all(a.identified for a in old.axis_status) and len(old.axis_status) == 4
    assert old.reduction[0].cost_responses == {}


def test_a_kept_reduction_step_round_trips(model: IdentifiedModel, tmp_path) -> None:
    kept = dataclasses.replace(
        model.reduction[0],
        action="kept",
        reason="I% = 11.2 > 10; removing it, the cost of r/delta_yaw rose from 2.8 to 83 (allowed: up to 4.8), so it stays",
        cost_responses={"r/delta_yaw": 2.8},
        cost_responses_after={"r/delta_yaw": 83.0},
    )
    back = read_model(write_model(tmp_path / "model.json", dataclasses.replace(model, reduction=(kept,))))
    assert back.reduction == (kept,)
