"""Time-domain verification against analytic responses and the chapter 3 simulator's truth.

The truth models are built here from the same Table 3.3 / 3.5 parameters the
simulator flies (`simulator.flights.linear._axis_models`): states lon
``[u, q, theta, d_lon]``, lat ``[v, p, phi, d_lat]``, yaw ``[r, psi]``, heave
``[w, height_agl, d_thr]``; ``ax = u' + g theta``, ``ay = v' - g phi``,
``az = w'`` (eq. 3.7 about trim); the wind enters ``u'`` through
``X_w_lon wind_lon(t - tau_w_lon)`` and ``w'`` through
``Z_w_lon wind_lon(t - tau_w_thr)``, the vehicle facing north.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from flightlogs.conditioning.condition import ConditionedFlight
from flightlogs.errors import DataError, ModelError
from flightlogs.frames import wind_to_body_axes
from flightlogs.maneuvers.segments import Segment
from flightlogs.record import Record
from simulator.autopilot.excitation import Maneuver
from simulator.flights.linear import SimulatedFlight, WindField, simulate_hover
from simulator.vehicle.identified import CALM_HOVER, STRONG_WIND_TERMS
from sysid.model.discrete import discretize, simulate
from sysid.model.statespace import DelayedStateSpace
from sysid.verify import (
    RecordVerification,
    VerificationOptions,
    axis_outputs,
    doublet_records,
    driven_part,
    theil_inequality,
    verify,
    verify_record,
)

G = 9.81
UNITS = {
    "u": "m/s",
    "v": "m/s",
    "w": "m/s",
    "p": "rad/s",
    "q": "rad/s",
    "r": "rad/s",
    "phi": "rad",
    "theta": "rad",
    "psi": "rad",
    "ax": "m/s^2",
    "ay": "m/s^2",
    "az": "m/s^2",
    "height_agl": "m",
    "wind_lon": "m/s",
    "wind_lat": "m/s",
    "delta_lat": "%",
    "delta_lon": "%",
    "delta_yaw": "%",
    "delta_thr": "%",
}


# ---------------------------------------------------------------------------------------------- truth models
def _with_wind(model: DelayedStateSpace, state: str, output: str, gain: float, delay_s: float) -> DelayedStateSpace:
    """Add input ``wind_lon`` entering the derivative of `state` (and `output`, an acceleration) with `gain`."""
    b = np.zeros((len(model.states), 1))
    b[model.states.index(state), 0] = gain
    d = np.zeros((len(model.outputs), 1))
    d[model.outputs.index(output), 0] = gain
    return DelayedStateSpace(
        a=model.a,
        b=np.hstack([model.b, b]),
        c=model.c,
        d=np.hstack([model.d, d]),
        states=model.states,
        inputs=(*model.inputs, "wind_lon"),
        outputs=model.outputs,
        input_delays_s=np.append(model.input_delays_s, delay_s),
    )


def flown(parameters: Mapping[str, float], step_s: float = 0.002) -> dict[str, float]:
    """The parameters as the simulator flies them: its delays are whole integration steps (500 Hz)."""
    return {k: round(v / step_s) * step_s if k.startswith("tau_") else v for k, v in parameters.items()}


def truth_models(
    p: Mapping[str, float] = flown(CALM_HOVER), wind: Mapping[str, float] | None = None
) -> dict[str, DelayedStateSpace]:
    """Per-axis truth of the simulator: lon, lat, yaw, thr (with G_w on lon and thr when `wind` is given)."""
    wind = flown(wind) if wind is not None else None
    lag = 1.0 / p["T_a"]
    lon = DelayedStateSpace(
        a=np.array([[p["X_u"], 0, -G, p["X_lon"]], [p["M_u"], 0, 0, p["M_lon"]], [0, 1, 0, 0], [0, 0, 0, -lag]]),
        b=np.array([[0], [0], [0], [lag]]),
        c=np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [p["X_u"], 0, 0, p["X_lon"]]]),
        d=np.zeros((4, 1)),
        states=("u", "q", "theta", "d_lon"),
        inputs=("delta_lon",),
        outputs=("u", "q", "theta", "ax"),
        input_delays_s=np.array([p["tau_lon"]]),
    )
    lat = DelayedStateSpace(
        a=np.array([[p["Y_v"], 0, G, p["Y_lat"]], [p["L_v"], 0, 0, p["L_lat"]], [0, 1, 0, 0], [0, 0, 0, -lag]]),
        b=np.array([[0], [0], [0], [lag]]),
        c=np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [p["Y_v"], 0, 0, p["Y_lat"]]]),
        d=np.zeros((4, 1)),
        states=("v", "p", "phi", "d_lat"),
        inputs=("delta_lat",),
        outputs=("v", "p", "phi", "ay"),
        input_delays_s=np.array([p["tau_lat"]]),
    )
    yaw = DelayedStateSpace(
        a=np.array([[0.0, 0], [1, 0]]),
        b=np.array([[p["N_yaw"]], [0]]),
        c=np.eye(2),
        d=np.zeros((2, 1)),
        states=("r", "psi"),
        inputs=("delta_yaw",),
        outputs=("r", "psi"),
        input_delays_s=np.array([p["tau_yaw"]]),
    )
    thr = DelayedStateSpace(
        a=np.array([[0, 0, p["Z_thr"]], [-1.0, 0, 0], [0, 0, -lag]]),
        b=np.array([[0], [0], [lag]]),
        c=np.array([[1, 0, 0], [0, 0, p["Z_thr"]]]),
        d=np.zeros((2, 1)),
        states=("w", "height_agl", "d_thr"),
        inputs=("delta_thr",),
        outputs=("w", "az"),
        input_delays_s=np.array([p["tau_thr"]]),
    )
    if wind is not None:
        lon = _with_wind(lon, "u", "ax", wind["X_w_lon"], wind["tau_w_lon"])
        thr = _with_wind(thr, "w", "az", wind["Z_w_lon"], wind["tau_w_thr"])
    return {"lon": lon, "lat": lat, "yaw": yaw, "thr": thr}


# ---------------------------------------------------------------------------------------------- simulated flights
DOUBLETS = (
    Maneuver(axis="lon", kind="doublet", start_s=5.0, amplitude=15.0, duration_s=2.0),
    Maneuver(axis="lat", kind="doublet", start_s=11.0, amplitude=15.0, duration_s=2.0),
    Maneuver(axis="yaw", kind="doublet", start_s=17.0, amplitude=15.0, duration_s=2.0),
    Maneuver(axis="thr", kind="doublet", start_s=23.0, amplitude=8.0, duration_s=2.0),
)
START_S = 1.0  # the simulator's own start transient is left out of the trim


def hover_mask(time_s: np.ndarray, maneuvers: tuple[Maneuver, ...]) -> np.ndarray:
    """Samples of hover, as conditioning's hover segments: after the start, away from every maneuver."""
    quiet = time_s >= START_S
    for m in maneuvers:
        quiet &= (time_s < m.start_s - 0.5) | (time_s > m.end_s + 3.0)
    return quiet


def conditioned(flight: SimulatedFlight, name: str) -> ConditionedFlight:
    """The simulated flight as conditioning leaves it: one record, trim removed, the doublets as segments.

    ``u v w`` are air-relative as the simulator defines them (ground velocity minus wind).
    """
    s = flight.signals
    wind_body = wind_to_body_axes(flight.wind_at_vehicle, s["psi"])
    columns = {
        n: s[n]
        for n in (
            "p",
            "q",
            "r",
            "phi",
            "theta",
            "psi",
            "ax",
            "ay",
            "az",
            "height_agl",
            "delta_lat",
            "delta_lon",
            "delta_yaw",
            "delta_thr",
        )
    }
    columns |= {
        "u": s["vn"] - flight.wind_at_vehicle[:, 0],
        "v": s["ve"] - flight.wind_at_vehicle[:, 1],
        "w": s["vd"],
        "wind_lon": wind_body[:, 0],
        "wind_lat": wind_body[:, 1],
    }
    table = pd.DataFrame(columns, index=pd.Index(flight.time_s, name="time_s"))
    trim = table[hover_mask(flight.time_s, flight.maneuvers)].mean()  # over the whole hover, as conditioning does
    trim_values = {str(k): float(v) for k, v in trim.items()}
    record = Record.from_table(
        table - trim, units=UNITS, trim=trim_values, source=Path(f"{name}.ulg"), label="piece 1 of 1"
    )
    segments = tuple(
        Segment(axis=m.axis, kind="doublet", start_s=m.start_s, end_s=m.end_s, source="user") for m in flight.maneuvers
    )
    return ConditionedFlight(source=Path(f"{name}.ulg"), records=(record,), segments=segments, rate_hz=100.0)


@pytest.fixture(scope="module")
def calm_flights() -> list[ConditionedFlight]:
    return [conditioned(simulate_hover(27.0, DOUBLETS, seed=seed), f"calm-{seed}") for seed in (1, 2, 3)]


@pytest.fixture(scope="module")
def strong_flights() -> list[ConditionedFlight]:
    wind = WindField(
        mean_speed_m_s=5.4, direction_from_deg=300.0, turbulence_ratio=0.2
    )  # the chapter 3 campaign's strong condition
    return [
        conditioned(
            simulate_hover(27.0, DOUBLETS, wind=wind, wind_terms=STRONG_WIND_TERMS, seed=seed), f"strong-{seed}"
        )
        for seed in (11, 12, 13)
    ]


def _block(models: Mapping[str, DelayedStateSpace]) -> DelayedStateSpace:
    """The per-axis models side by side, as an identified hover model holds them."""
    from scipy.linalg import block_diag

    ms = list(models.values())
    return DelayedStateSpace(
        a=block_diag(*[m.a for m in ms]),
        b=block_diag(*[m.b for m in ms]),
        c=block_diag(*[m.c for m in ms]),
        d=block_diag(*[m.d for m in ms]),
        states=sum((m.states for m in ms), ()),
        inputs=sum((m.inputs for m in ms), ()),
        outputs=sum((m.outputs for m in ms), ()),
        input_delays_s=np.concatenate([m.input_delays_s for m in ms]),
    )


def _record(columns: dict[str, np.ndarray], rate_hz: float = 100.0, units: Mapping[str, str] = UNITS) -> Record:
    n = len(next(iter(columns.values())))
    table = pd.DataFrame(columns, index=pd.Index(np.arange(n) / rate_hz, name="time_s"))
    return Record.from_table(
        table, units={c: units.get(c, "1") for c in columns}, trim={}, source=Path("test.ulg"), label="test"
    )


# ---------------------------------------------------------------------------------------------- analytic
@pytest.mark.parametrize("delay_samples", [0.0, 1.0, 2.37, 0.5, 4.99])
def test_held_step_through_a_delayed_lag_is_exact(delay_samples: float) -> None:
    """y = 1 - exp(-(t - t_step - tau) / T) after a held step: the modified z-transform is exact."""
    dt, lag_s = 0.01, 0.05
    model = DelayedStateSpace(
        a=np.array([[-1 / lag_s]]),
        b=np.array([[1 / lag_s]]),
        c=np.eye(1),
        d=np.zeros((1, 1)),
        states=("x",),
        inputs=("u",),
        outputs=("y",),
        input_delays_s=np.array([delay_samples * dt]),
    )
    t = np.arange(60) * dt
    u = (t >= 0.1).astype(float)
    y = simulate(discretize(model, dt), u[:, None], np.zeros(1))[:, 0]
    elapsed = t - 0.1 - delay_samples * dt
    np.testing.assert_allclose(y, np.where(elapsed > 0, 1 - np.exp(-elapsed / lag_s), 0.0), atol=1e-12)


def test_feedthrough_sees_the_delayed_held_input() -> None:
    """y = D u(t - tau): with a 1.5-sample delay the step shows two samples later."""
    model = DelayedStateSpace(
        a=np.zeros((0, 0)),
        b=np.zeros((0, 1)),
        c=np.zeros((1, 0)),
        d=np.ones((1, 1)),
        states=(),
        inputs=("u",),
        outputs=("y",),
        input_delays_s=np.array([0.015]),
    )
    u = (np.arange(10) >= 3).astype(float)
    y = simulate(discretize(model, 0.01), u[:, None], np.zeros(0))[:, 0]
    np.testing.assert_array_equal(y, (np.arange(10) >= 5).astype(float))


def _second_order() -> DelayedStateSpace:
    """A stable pitch-like pair driven by two inputs, outputs q and an acceleration with feedthrough."""
    return DelayedStateSpace(
        a=np.array([[-1.2, -4.0], [1.0, 0.0]]),
        b=np.array([[2.0, 0.0], [0.0, 0.5]]),
        c=np.array([[1.0, 0.0], [-0.3, 0.8]]),
        d=np.array([[0.0, 0.0], [0.4, 0.0]]),
        states=("q", "theta"),
        inputs=("delta_lon", "wind_lon"),
        outputs=("q", "ax"),
        input_delays_s=np.array([0.023, 0.011]),
    )


def test_bias_and_reference_shift_are_recovered() -> None:
    """y_meas = y_model(u + du) + b exactly: least squares finds du and b, leaving no error."""
    model, dt = _second_order(), 0.01
    t = np.arange(400) * dt
    u = np.column_stack(
        [np.where((t > 0.5) & (t < 1.5), 5.0, 0.0) - np.where((t >= 1.5) & (t < 2.5), 5.0, 0.0), 0.8 * np.sin(1.3 * t)]
    )
    shift, bias = np.array([0.7, -0.4]), np.array([0.02, -0.15])
    y = simulate(discretize(model, dt), u + shift, np.zeros(2)) + bias
    record = _record({"delta_lon": u[:, 0], "wind_lon": u[:, 1], "q": y[:, 0], "ax": y[:, 1]})
    result = verify_record(model, record, options=VerificationOptions(initial_state="zero"))
    np.testing.assert_allclose(
        [result.reference_shifts["delta_lon"], result.reference_shifts["wind_lon"]], shift, atol=1e-9
    )
    np.testing.assert_allclose([result.output("q").bias, result.output("ax").bias], bias, atol=1e-9)
    assert result.rmse < 1e-9 and result.tic < 1e-9
    assert not result.unstable and result.output("q").predicted is None


def test_measured_initial_state_and_rest_for_the_others() -> None:
    """theta is measured, q is not: q starts at rest given theta and the input, and the record is matched."""
    model, dt = _second_order(), 0.01
    x0 = np.array([0.0, 0.05])
    u = np.column_stack([np.full(300, 0.1), np.zeros(300)])  # at rest: q = 0, theta = 0.05 (2 * 0.1 = 4 * 0.05)
    y = simulate(discretize(model, dt), u, x0)
    theta = np.full(300, 0.05)
    record = _record({"delta_lon": u[:, 0], "wind_lon": u[:, 1], "ax": y[:, 1], "theta": theta})
    options = VerificationOptions(fit_bias=False, fit_reference_shift=False)
    assert verify_record(model, record, options=options).output("ax").rmse < 1e-12
    zero = verify_record(
        model, record, options=VerificationOptions(initial_state="zero", fit_bias=False, fit_reference_shift=False)
    )
    assert zero.output("ax").rmse > 1e-3


def test_unstable_model_is_flagged_and_predicted_one_step_ahead(calm_flights: list[ConditionedFlight]) -> None:
    """Over 10 s of closed-loop flight the open-loop pitch mode grows ~6000-fold: the simulation of a model
    10 % off in one derivative drifts away, while one step ahead, from the measured states, it stays at the
    sensor noise. (The exact truth itself tracks: the simulator holds its command over each log sample.)"""
    parameters = dict(flown(CALM_HOVER))
    parameters["M_u"] *= 1.1
    model = truth_models(parameters)["lon"]
    record = calm_flights[0].records[0].between(4.0, 14.0)
    result = verify_record(model, record)
    growth = np.exp(np.max(np.linalg.eigvals(model.a).real) * (record.end_s - record.start_s))
    assert result.unstable and result.growth == pytest.approx(growth)
    assert result.unstable_modes == ("pitch",) and "unstable open loop in its pitch mode" in result.notice
    q = result.output("q")
    assert q.tic > 0.5
    # q[k+1] predicted from the measured q[k]: error about sqrt(2) x the 0.005 rad/s gyro noise
    assert q.prediction_rmse is not None and q.prediction_rmse < 2 * np.sqrt(2) * 0.005
    quiet = verify_record(model, record, options=VerificationOptions(max_growth=1e6))
    assert not quiet.unstable and quiet.output("q").predicted is None


@pytest.mark.parametrize("trim_u", [0.0, 1.5])
def test_a_heave_record_names_the_pitch_mode_the_trim_couples_in(trim_u: float) -> None:
    """w' = Z_thr d + U0 q: at U0 = 0 heave is neutral and the record is not flagged; with U0 the judged w
    depends on the unstable pitch pair (0.878 +- 1.694i, Table 3.3), which the notice names."""
    a = np.array([[-0.3172, 0.0, -9.81, 0.0], [0.769, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, trim_u, 0.0, 0.0]])
    model = DelayedStateSpace(
        a=a,
        b=np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [0.0, -5.0]]),
        c=np.eye(4)[3:],
        d=np.zeros((1, 2)),
        states=("u", "q", "theta", "w"),
        inputs=("delta_lon", "delta_thr"),
        outputs=("w",),
        input_delays_s=np.zeros(2),
    )
    t = np.arange(500) * 0.01
    result = verify_record(
        model, _record({"delta_lon": np.zeros(500), "delta_thr": np.sin(2 * t), "w": -5 * (1 - np.cos(2 * t)) / 2})
    )
    if trim_u == 0:
        assert result.growth == 1.0 and result.unstable_modes == () and not result.unstable
    else:
        assert 79 < result.growth == pytest.approx(np.exp(np.max(np.linalg.eigvals(a).real) * 4.99), rel=1e-9)
        assert result.unstable_modes == ("pitch",)
        assert result.notice.startswith("the model is unstable open loop in its pitch mode, which w depends on")


def test_an_off_axis_output_cannot_move_the_on_axis_verdict() -> None:
    """The trim couples q into w (w' = U0 q): a heave record judged on w must come out the same whether the
    off-axis q is logged well or with a drift the model cannot explain."""
    a = np.array([[-2.0, 0.0], [1.5, 0.0]])  # q' = -2 q + 4 delta_lon, w' = 1.5 q - 5 delta_thr
    model = DelayedStateSpace(
        a=a,
        b=np.array([[4.0, 0.0], [0.0, -5.0]]),
        c=np.eye(2),
        d=np.zeros((2, 2)),
        states=("q", "w"),
        inputs=("delta_lon", "delta_thr"),
        outputs=("q", "w"),
        input_delays_s=np.zeros(2),
    )
    t = np.arange(600) * 0.01
    u = np.column_stack([0.02 + 0.1 * np.sin(1.3 * t), 0.2 * np.sign(np.sin(2.0 * t))])
    y = simulate(discretize(model, 0.01), u, np.zeros(2))
    base = {"delta_lon": u[:, 0] - 0.02, "delta_thr": u[:, 1], "w": y[:, 1]}  # delta_lon logged 0.02 low: a shift
    zero = VerificationOptions(initial_state="zero")  # as simulated: the shift is then exact
    results = [
        verify_record(model, _record(base | extra), on_axis=("w",), options=zero)
        for extra in ({"q": y[:, 0]}, {"q": y[:, 0] + 0.3 * t})
    ]
    np.testing.assert_allclose(results[1].output("w").simulated, results[0].output("w").simulated, atol=1e-12)
    assert results[1].reference_shifts == pytest.approx(results[0].reference_shifts, abs=1e-12)
    assert results[0].reference_shifts["delta_lon"] == pytest.approx(0.02, abs=1e-9)
    assert results[0].output("w").rmse < 1e-9
    assert results[1].output("q").tic > 0.1  # the drifting q is shown, badly predicted, as off-axis
    assert results[1].off_axis == ("q",)


def test_driven_part_keeps_one_axis_and_its_wind() -> None:
    model = _block(truth_models(wind=STRONG_WIND_TERMS))
    lon = driven_part(model, "delta_lon")
    assert lon.states == ("u", "q", "theta", "d_lon") and lon.inputs == ("delta_lon", "wind_lon")
    assert lon.outputs == ("u", "q", "theta", "ax")
    thr = driven_part(model, "delta_thr")
    assert thr.states == ("w", "height_agl", "d_thr") and thr.outputs == ("w", "az")
    assert thr.inputs == ("delta_thr", "wind_lon")
    np.testing.assert_allclose(thr.input_delays_s, [0.0, flown(STRONG_WIND_TERMS)["tau_w_thr"]])
    with pytest.raises(ModelError, match="delta_roll"):
        driven_part(model, "delta_roll")


def test_every_measured_input_drives_the_simulation() -> None:
    """A pitch doublet while the autopilot also moves the thrust, which reaches q: simulated exactly only with
    both inputs (the old excited-input-only simulation left delta_thr out)."""
    model = DelayedStateSpace(
        a=np.array([[-1.2, -4.0], [1.0, 0.0]]),
        b=np.array([[2.0, 0.6], [0.0, 0.0]]),
        c=np.eye(2),
        d=np.zeros((2, 2)),
        states=("q", "theta"),
        inputs=("delta_lon", "delta_thr"),
        outputs=("q", "theta"),
        input_delays_s=np.array([0.02, 0.01]),
    )
    t = np.arange(300) * 0.01
    u = np.column_stack(
        [np.where((t > 0.5) & (t < 1.5), 1.0, 0.0) - np.where((t >= 1.5) & (t < 2.5), 1.0, 0.0), 0.8 * np.sin(2.1 * t)]
    )
    y = simulate(discretize(model, 0.01), u, np.zeros(2))
    record = _record({"delta_lon": u[:, 0], "delta_thr": u[:, 1], "q": y[:, 0], "theta": y[:, 1]})
    result = verify(
        model,
        [record],
        excited=["delta_lon"],
        axes={"delta_lon": ("q",)},
        options=VerificationOptions(initial_state="zero"),
    )
    (checked,) = result.records
    assert checked.inputs == ("delta_lon", "delta_thr") and checked.excited == "delta_lon"
    assert checked.off_axis == ("theta",) and [s.name for s in result.summary] == ["q"]
    assert [s.name for s in result.off_axis] == ["theta"]
    assert checked.output("q").tic < 1e-9 and result.tic < 1e-9
    alone = DelayedStateSpace(
        a=model.a,
        b=model.b[:, :1],
        c=model.c,
        d=model.d[:, :1],
        states=model.states,
        inputs=("delta_lon",),
        outputs=model.outputs,
        input_delays_s=model.input_delays_s[:1],
    )
    bare = VerificationOptions(initial_state="zero", fit_bias=False, fit_reference_shift=False)
    thrust_part = simulate(discretize(model, 0.01), u * [0.0, 1.0], np.zeros(2))[:, 0]
    left_out = verify(alone, [record], options=bare).output("q")
    assert left_out.rmse == pytest.approx(np.sqrt(np.mean(thrust_part**2)), rel=1e-9)  # exactly what is missing


def _coupled_hover(constants: Mapping[str, float]):  # type: ignore[no-untyped-def]
    """The hover structure at the simulator's values, built with the given trim constants."""
    from importlib import resources

    from sysid.fit import CostSummary, IdentifiedModel, ParameterEstimate
    from sysid.model import parse_structure

    text = (resources.files("sysid.model") / "builtin" / "hover.toml").read_text()
    values = dict(flown(CALM_HOVER)) | {"N_r": 0.0, "Z_w": 0.0}
    parameters = tuple(ParameterEstimate(name=p.name, value=values[p.name]) for p in parse_structure(text).parameters)
    return IdentifiedModel(
        structure_name="hover",
        structure_text=text,
        parameters=parameters,
        correlation_names=(),
        correlation=np.zeros((0, 0)),
        cost=CostSummary(average=1.0),
        constants={"g": G, "phi0": 0.0, "theta0": 0.0} | dict(constants),
    )


def test_axes_come_from_the_structure_not_from_the_trim_coupling(calm_flights: list[ConditionedFlight]) -> None:
    """With 1.5 m/s of trim airspeed the yaw rate reaches the other axes through U0 and V0 (eq. 3.5): judged on
    driven_part, a yaw doublet would be judged on nearly every output; the structure says r alone."""
    identified = _coupled_hover({"U0": 1.2, "V0": -0.9, "W0": 0.1})
    coupled = identified.linear_model()
    assert {"r", "u", "q", "theta", "v", "p", "phi", "w"} <= set(driven_part(coupled, "delta_yaw").outputs)
    axes = axis_outputs(identified)
    assert axes == {
        "delta_lat": ("v", "p", "phi", "ay"),
        "delta_lon": ("u", "q", "theta", "ax"),
        "delta_yaw": ("r",),
        "delta_thr": ("w", "az"),
    }
    assert axis_outputs(_coupled_hover({"U0": 0.0, "V0": 0.0, "W0": 0.0})) == axes  # the trim does not matter
    cut = doublet_records(calm_flights[:1])
    result = verify(coupled, cut.records, excited=cut.excited, axes=axes)
    for record, excited in zip(result.records, cut.excited):
        assert record.inputs == coupled.inputs and record.excited == excited
        assert tuple(o.name for o in record.judged) == axes[excited]
        assert set(record.off_axis) == set(coupled.outputs) - set(axes[excited])
    # r' = N_yaw delta_yaw alone: the yaw doublet is not flagged although the airframe is unstable in pitch
    assert [r.unstable for r in result.records] == [True, True, False, True]
    assert {s.name for s in result.summary} == {n for names in axes.values() for n in names}


def _verified(time_s: np.ndarray, excited: str, output: Any, *, off_axis: tuple[str, ...] = ()) -> RecordVerification:
    """A record's verification made by hand: one output, nothing else measured."""
    return RecordVerification(
        label="r",
        source=Path("f.bin"),
        time_s=time_s,
        inputs=(excited,),
        outputs=(output,),
        reference_shifts={},
        rmse=0.0,
        tic=0.0,
        growth=1.0,
        unstable=False,
        off_axis=off_axis,
    )


def test_off_axis_names_some_outputs_of_the_record() -> None:
    from sysid.verify import OutputVerification

    out = OutputVerification(
        name="q", unit="rad/s", measured=np.zeros(3), simulated=np.zeros(3), bias=0.0, rmse=0.0, tic=0.0
    )
    make = lambda off: _verified(np.arange(3.0), "delta_lon", out, off_axis=off)
    with pytest.raises(ValueError, match="some, not all"):
        make(("q",))
    with pytest.raises(ValueError, match="some, not all"):
        make(("p",))


def test_missing_signals_are_named() -> None:
    model = _second_order()
    with pytest.raises(DataError, match="wind_lon"):
        verify_record(model, _record({"delta_lon": np.zeros(10), "q": np.zeros(10)}))
    with pytest.raises(DataError, match="none of the model outputs"):
        verify_record(model, _record({"delta_lon": np.zeros(10), "wind_lon": np.zeros(10)}))
    with pytest.raises(DataError, match="no records"):
        verify(model, [])
    with pytest.raises(ModelError, match="delta_yaw"):
        verify(
            model,
            [_record({"delta_lon": np.zeros(10), "wind_lon": np.zeros(10), "q": np.zeros(10)})],
            excited=["delta_yaw"],
        )


def test_excited_inputs_not_one_per_record_are_a_data_error() -> None:
    """A project error (a SysidError, so the CLI says it in one sentence), still a ValueError for callers."""
    record = _record({"delta_lon": np.zeros(10), "wind_lon": np.zeros(10), "q": np.zeros(10)})
    with pytest.raises(DataError, match="excited has 2 entries for 1 records") as caught:
        verify(_second_order(), [record], excited=["delta_lon", "delta_lon"])
    assert isinstance(caught.value, ValueError)


def test_theil_inequality_bounds() -> None:
    y = np.sin(np.linspace(0, 6, 50))
    assert theil_inequality(y, y) == 0.0
    assert theil_inequality(y, -y) == pytest.approx(1.0)
    assert theil_inequality(y, np.zeros_like(y)) == pytest.approx(1.0)
    assert np.isnan(theil_inequality(np.zeros(3), np.zeros(3)))


# ---------------------------------------------------------------------------------------------- simulator truth
def test_doublet_records_cut_each_doublet_with_margins(calm_flights: list[ConditionedFlight]) -> None:
    cut = doublet_records(calm_flights[:1], before_s=0.5, after_s=1.0)
    assert cut.excited == ("delta_lon", "delta_lat", "delta_yaw", "delta_thr")
    for record, maneuver in zip(cut.records, DOUBLETS):
        assert record.start_s == pytest.approx(maneuver.start_s - 0.5)
        assert record.end_s == pytest.approx(maneuver.end_s + 1.0)
        assert maneuver.axis in record.label


def test_calm_doublets_are_predicted_by_the_truth(calm_flights: list[ConditionedFlight]) -> None:
    """Issue 7: TIC <= 0.25 on every on-axis output of the calm truth's doublets (simulated from all inputs)."""
    cut = doublet_records(calm_flights)
    result = verify(_block(truth_models()), cut.records, excited=cut.excited)
    on_axis = {"u", "q", "theta", "ax", "v", "p", "phi", "ay", "r", "psi", "w", "az"}
    assert {s.name for s in result.summary} == on_axis == {s.name for s in result.off_axis}
    assert all(len(r.inputs) == 4 and len(r.judged) + len(r.off_axis) == 12 for r in result.records)
    for summary in result.summary:
        assert summary.n_records == 3
        assert summary.tic <= 0.25, summary
    # pitch and roll double in ~0.8 s: the 3 s records are flagged and also predicted one step ahead
    flagged = {r.label.split()[1] for r in result.records if r.unstable}
    assert flagged == {"lon", "lat"}
    assert result.output("q").prediction_tic is not None and result.output("r").prediction_tic is None


def test_wind_term_reduces_the_error_on_strong_wind_doublets(strong_flights: list[ConditionedFlight]) -> None:
    """Issue 7 / Table 3.6: G_w cuts the a_x and a_z RMS error by at least 13 % and 7 %."""
    cut = doublet_records(strong_flights)
    result = verify(
        _block(truth_models()),
        cut.records,
        excited=cut.excited,
        wind_model=_block(truth_models(wind=STRONG_WIND_TERMS)),
    )
    # Table 3.6 is per output over the doublets of its axis: a_x on the lon doublets, a_z on the heave ones
    assert result.output("ax").n_records == result.output("az").n_records == 3
    assert result.correction("ax").reduction_percent >= 13.0
    assert result.correction("az").reduction_percent >= 7.0
    assert result.correction("ay").reduction_percent == pytest.approx(0.0)  # no lateral wind term in the truth
    for name in ("ax", "az"):  # G_w predicts below the wind's low-pass only: there it cuts more (ax 89.7 -> 94.5 %,
        correction = result.correction(name)  # az 90.9 -> 96.5 %: the error it leaves is the sensors' noise)
        assert correction.band_hz == 2.0 and correction.reduction_in_band_percent > correction.reduction_percent
    for name in ("u", "q", "theta", "ax", "w", "az"):
        assert result.output(name).tic <= 0.25
    assert len(result.without_wind) == len(result.records) == 12


def test_with_exactly_held_inputs_the_residual_is_the_sensor_noise() -> None:
    """Logged at the integration rate the truth is exact: the a_z error is the simulator's noise (sigma 0.05).

    Bias and shift take 2 of N samples' degrees of freedom; an RMS over N samples scatters by 1/sqrt(2N).
    """
    records, n = [], 0
    for seed in (21, 22):
        flight = simulate_hover(27.0, DOUBLETS, seed=seed, rate_hz=500.0, substeps=1)
        cut = doublet_records([conditioned(flight, f"fine-{seed}")])
        records.append(cut.records[cut.excited.index("delta_thr")])
        n += records[-1].time_s.size
    result = verify(truth_models()["thr"], records)
    ratio = result.output("az").rmse / 0.05
    assert abs(ratio - np.sqrt(1 - 2 / n)) < 4 / np.sqrt(2 * n)


def test_the_error_in_the_winds_band_is_the_error_low_passed_as_the_wind_is() -> None:
    """An error of a 0.3 Hz sine (the wind's band) and a 7 Hz one (a thrust response's): in the band, the first alone.

    The wind step's low-pass (4th-order Butterworth at 2 Hz, zero phase) passes 0.3 Hz with a gain of
    1 - 1e-7 and 7 Hz with 4e-5: the pooled in-band RMS is the slow sine's, a / sqrt(2), within the
    filter's edge transients over 20 s; records at 100 and 400 Hz pool by their samples.
    """
    from sysid.verify import OutputVerification
    from sysid.verify.engine import _pooled_in_wind_band

    def record(rate_hz: float, slow: float, fast: float) -> RecordVerification:
        t = np.arange(0.0, 20.0, 1.0 / rate_hz)
        error = slow * np.sin(2 * np.pi * 0.3 * t) + fast * np.sin(2 * np.pi * 7.0 * t)
        out = OutputVerification(
            name="az", unit="m/s^2", measured=error, simulated=np.zeros(t.size), bias=0.0, rmse=0.0, tic=0.0
        )
        return _verified(t, "delta_thr", out)

    (rms,) = _pooled_in_wind_band([record(100.0, 0.4, 0.3)]).values()
    assert rms == pytest.approx(0.4 / np.sqrt(2), rel=2e-3)
    pooled = _pooled_in_wind_band([record(100.0, 0.4, 0.3), record(400.0, 0.2, 0.5)])["az"]
    assert pooled == pytest.approx(np.sqrt((2000 * 0.4**2 + 8000 * 0.2**2) / 2 / 10000), rel=2e-3)


def test_the_wind_correction_round_trips_with_its_band() -> None:
    from sysid.verify import WindCorrection

    correction = WindCorrection(
        name="az",
        unit="m/s^2",
        rmse_without=0.29,
        rmse_with=0.243,
        band_hz=2.0,
        rmse_without_in_band=0.27,
        rmse_with_in_band=0.135,
    )
    assert correction.reduction_in_band_percent == pytest.approx(50.0)
    assert WindCorrection.from_dict(correction.to_dict()) == correction
    older = {"name": "az", "unit": "m/s^2", "rmse_without": 0.29, "rmse_with": 0.243}  # a file from before the band
    assert np.isnan(WindCorrection.from_dict(older).reduction_in_band_percent)
    assert WindCorrection.from_dict(older).to_dict()["reduction_in_band_percent"] is None


def test_a_given_doublet_outside_every_record_names_its_line(calm_flights: list[ConditionedFlight], tmp_path) -> None:  # type: ignore[no-untyped-def]
    """``sysid validate --segments``: a doublet no record reaches is one sentence with the file's line."""
    from flightlogs.readers.segments_file import read_segments_file
    from sysid.verify import check_given_doublets

    inside = calm_flights[0].segments[0]
    path = tmp_path / "doublets.csv"
    path.write_text(f"start_s,end_s,axis,kind\n{inside.start_s},{inside.end_s},lon,doublet\n500,503,lon,doublet\n")
    given = read_segments_file(path)
    check_given_doublets(path, given[:1], calm_flights)  # inside: nothing said
    with pytest.raises(DataError, match=rf"^{path} line 3: the lon doublet at 500-503 s starts outside every log's "):
        check_given_doublets(path, given, calm_flights)
