"""A fitted model in the simulation's place (issue 15): its outputs along a flight, against the analytic ones."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import savgol_filter

from flightlogs.errors import ModelError
from sysid.discrepancy import FlightSeries, model_flight, model_outputs
from sysid.discrepancy.series import OUTPUTS, smoothed_as_derivative
from sysid.model.statespace import DelayedStateSpace

RATE_HZ = 50.0
L_V, L_LAT, T_A, TAU = -0.6, 30.0, 0.06, 0.03  # rad/(m s), rad/s² per unit, s, s (1.5 samples: a fractional delay)
X_U, Y_LAT, Z_W, N_R, M_U = -0.3, 4.0, -0.8, -0.25, 0.5
STATES = ("u", "v", "w", "p", "q", "r", "d_lat")


def _model() -> DelayedStateSpace:
    """p' = L_v v + L_lat d_lat, q' = M_u u, r' = N_r r, d_lat' = (delta_lat(t - tau) - d_lat) / T_a."""
    i = {s: k for k, s in enumerate(STATES)}
    a = np.zeros((7, 7))
    a[i["p"], i["v"]], a[i["p"], i["d_lat"]] = L_V, L_LAT
    a[i["q"], i["u"]], a[i["r"], i["r"]] = M_U, N_R
    a[i["d_lat"], i["d_lat"]] = -1.0 / T_A
    b = np.zeros((7, 2))
    b[i["d_lat"], 0] = 1.0 / T_A
    c = np.zeros((3, 7))
    c[0, i["u"]], c[1, i["d_lat"]], c[2, i["w"]] = X_U, Y_LAT, Z_W
    return DelayedStateSpace(
        a=a,
        b=b,
        c=c,
        d=np.zeros((3, 2)),
        states=STATES,
        inputs=("delta_lat", "delta_thr"),
        outputs=("ax", "ay", "az"),
        input_delays_s=np.array([TAU, 0.0]),
    )


OMEGA = 8.0  # rad/s, of the lateral input


def _flight(seed: int = 3) -> FlightSeries:
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 20.0, 1.0 / RATE_HZ)
    signals = {s: rng.normal(0.0, 0.3, t.size) for s in ("u", "v", "w", "p", "q", "r", "delta_yaw", "delta_lon")}
    signals["delta_lat"] = 0.2 * np.sin(OMEGA * t)
    signals["delta_thr"] = np.full(t.size, 0.5)
    signals |= {o: rng.normal(0.0, 0.1, t.size) for o in OUTPUTS}
    signals["az"] -= 9.81
    return FlightSeries(name="sine.ulg", time_s=t, piece=np.zeros(t.size, dtype=int), signals=signals, rate_hz=RATE_HZ)


def test_the_outputs_are_the_models_rows_on_the_measured_states_with_its_own_lagged_delayed_actuator() -> None:
    flight = _flight()
    got = model_outputs(_model(), flight)
    t = flight.time_s
    # the actuator's steady response to 0.2 sin(w t), delayed 30 ms (1.5 samples) and lagged by T_a
    actuator = np.imag(0.2 * np.exp(1j * OMEGA * (t - TAU)) / (1.0 + 1j * OMEGA * T_A))
    actuator -= np.median(flight["delta_lat"])  # about the trim: the model file has none, the median stands in
    centred = {s: flight[s] - np.median(flight[s]) for s in ("u", "v", "w", "r")}
    settled = t > 1.0  # the start from rest has died out (T_a = 60 ms)
    tolerance = 0.005 * 0.2 * abs(L_LAT)  # 0.5 % of the input's amplitude: the samples are read as a line between them
    np.testing.assert_allclose(got["ay"][settled], Y_LAT * actuator[settled], atol=0.005 * 0.2 * Y_LAT)
    expected_p_dot = smoothed_as_derivative(flight, L_V * centred["v"] + L_LAT * actuator)
    np.testing.assert_allclose(got["p_dot"][settled], expected_p_dot[settled], atol=tolerance)
    # one sample of delay more or less would be 16 % of the amplitude off at 8 rad/s: the delay is read
    late = smoothed_as_derivative(flight, L_V * centred["v"] + L_LAT * np.roll(actuator, 1))
    assert np.max(np.abs(got["p_dot"] - late)[settled]) > 20 * tolerance
    np.testing.assert_allclose(got["q_dot"], smoothed_as_derivative(flight, M_U * centred["u"]), atol=1e-12)
    np.testing.assert_allclose(got["r_dot"], smoothed_as_derivative(flight, N_R * centred["r"]), atol=1e-12)
    np.testing.assert_allclose(got["ax"], X_U * centred["u"], atol=1e-12)
    np.testing.assert_allclose(got["az"], Z_W * centred["w"], atol=1e-12)


def test_a_models_accelerations_are_smoothed_as_the_logged_rates_derivatives_are() -> None:
    """A rate logged at 250 Hz, differentiated as flight_series does (0.1 s Savitzky-Golay, quadratic)."""
    omega, log_hz = 20.0, 250.0
    t_log = np.arange(0.0, 10.0, 1.0 / log_hz)
    logged = savgol_filter(np.sin(omega * t_log), 25, 2, deriv=1, delta=1.0 / log_hz)
    flight = _flight()
    t = flight.time_s[flight.time_s < 10.0]
    short = flight.subset(np.arange(t.size))
    derivative = np.interp(t, t_log, logged)
    exact = omega * np.cos(omega * t)
    inner = slice(10, -10)
    assert np.max(np.abs(derivative - exact)[inner]) > 0.05 * omega  # the smoothing matters at 20 rad/s
    assert np.max(np.abs(derivative - smoothed_as_derivative(short, exact))[inner]) < 0.015 * omega


def test_the_models_flight_keeps_the_samples_and_carries_noise_of_the_real_flights_size() -> None:
    flight = _flight()
    simulated = model_flight(_model(), flight, source="hover.json")
    outputs = model_outputs(_model(), flight)
    assert simulated.name == "hover.json on sine.ulg"
    np.testing.assert_array_equal(simulated.time_s, flight.time_s)
    np.testing.assert_array_equal(simulated["v"], flight["v"])
    for o in OUTPUTS:
        noise = simulated[o] - np.median(flight[o]) - outputs[o]
        # REAL's outputs here are white noise of 0.1 that no linear model explains: all of it is left
        assert 0.08 < np.std(noise) < 0.1
        assert abs(np.corrcoef(noise, flight[o])[0, 1]) < 0.1  # moved in time: not REAL's own noise sample by sample


def test_a_model_without_an_axis_or_with_an_input_the_flight_lacks_is_refused_by_name() -> None:
    model = _model()
    lateral_only = DelayedStateSpace(
        a=model.a[:5, :5],
        b=model.b[:5],
        c=model.c[:, :5],
        d=model.d,
        states=STATES[:5],
        inputs=model.inputs,
        outputs=model.outputs,
        input_delays_s=model.input_delays_s,
    )
    with pytest.raises(ModelError, match=r"hover\.json: no r in the model"):
        model_outputs(lateral_only, _flight(), source="hover.json")
    flight = _flight()
    without = flight.without(["delta_thr"])
    with pytest.raises(ModelError, match=r"input delta_thr is not logged by sine\.ulg"):
        model_outputs(model, without, source="hover.json")
