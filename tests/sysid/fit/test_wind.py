"""The wind step (eq. 3.14) on simulated strong-wind flights with the Table 3.5 terms."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from flightlogs.errors import FitError, FitWarning
from flightlogs.record import Record
from simulator.autopilot.excitation import Maneuver
from simulator.flights.linear import WindField, simulate_hover
from simulator.vehicle.identified import CALM_HOVER, STRONG_WIND_TERMS
from sysid.fit import FrequencyFit, fit_frequency_responses, fit_wind, model_from_fit, synthetic_responses
from sysid.fit.wind import (
    _gains_problem,
    _Joint,
    _lagged_wind,
    _prediction_data,
    _projected,
    _with_wind_defaults,
    sharing_delayed_winds,
    speed_derivatives,
    unfitted_wind,
)
from sysid.model import ModelStructure, load_structure, structure_model

CONTROLS = ("X_lon", "M_lon", "Y_lat", "L_lat", "N_yaw", "Z_thr")
UNITS = {
    "u": "m/s",
    "w": "m/s",
    "q": "rad/s",
    "theta": "rad",
    "ax": "m/s^2",
    "az": "m/s^2",
    "wind_lon": "m/s",
    "delta_lat": "%",
    "delta_lon": "%",
    "delta_yaw": "%",
    "delta_thr": "%",
}


def _record(axis: str, seed: int) -> Record:
    """A sweep flown in strong wind, as conditioning leaves it: air-relative u from the noisy velocity."""
    sweep = Maneuver(axis=axis, kind="sweep", start_s=3.0, amplitude=8.0 if axis == "lon" else 4.0, duration_s=34.0)  # type: ignore[arg-type]
    flight = simulate_hover(
        40.0,
        (sweep,),
        wind=WindField(mean_speed_m_s=5.4, direction_from_deg=0.0, turbulence_ratio=0.2),
        wind_terms=STRONG_WIND_TERMS,
        seed=seed,
    )
    s, wind = flight.signals, flight.wind_at_vehicle
    table = pd.DataFrame(
        {
            "u": s["vn"] - wind[:, 0],
            "w": s["vd"],
            "q": s["q"],
            "theta": s["theta"],
            "ax": s["ax"],
            "az": s["az"],
            "wind_lon": wind[:, 0],
        }
        | {f"delta_{a}": s[f"delta_{a}"] for a in ("lat", "lon", "yaw", "thr")},
        index=flight.time_s,
    )
    trim = table.mean()
    return Record.from_table(
        table - trim, units=UNITS, trim=trim.to_dict(), source=Path(f"{axis}.bin"), label=f"{axis} sweep"
    )


@pytest.fixture(scope="module")
def records() -> list[Record]:
    return [_record("lon", 3), _record("thr", 4)]


def test_wind_terms_come_back_from_the_residual(records: list[Record]) -> None:
    structure = load_structure("hover-wind")
    values = structure.values(dict(CALM_HOVER) | {"N_r": 0.0, "Z_w": 0.0})  # step 1 exact: per %, as logged here
    result = fit_wind(structure, values, structure.default_constants(), records)
    for name in ("X_w_lon", "Z_w_lon"):
        assert result.status[name] == "estimated"
        k = result.accuracy.names.index(name)
        error = abs(result.values[name] - STRONG_WIND_TERMS[name])
        assert error <= max(3 * result.accuracy.cramer_rao[k], 0.02 * abs(STRONG_WIND_TERMS[name])), name
    assert all(after < 0.5 * before for before, after in zip(result.fit.rms_before, result.fit.rms_after))
    # a_x is left with its sensor noise (0.03 m/s^2); a_z also with the error of rebuilding the lagged throttle
    # from its 100 Hz log of a 500 Hz simulation (about 1 ms at up to 10 Hz, times Z_thr)
    assert 0.03 <= result.fit.rms_after[0] < 0.06
    for name in ("tau_w_lon", "tau_w_thr"):
        assert 0.0 <= result.values[name] <= 0.5


def test_unresolved_wind_delays_are_dropped_to_zero(records: list[Record]) -> None:
    """The gusts roll off above 0.3 Hz: a 13 ms delay barely moves them, so its I% fails and it becomes 0."""
    structure = load_structure("hover-wind")
    values = structure.values(dict(CALM_HOVER) | {"N_r": 0.0, "Z_w": 0.0})
    result = fit_wind(structure, values, structure.default_constants(), records)
    assert {step.parameter for step in result.reduction} == {"tau_w_lon", "tau_w_thr"}
    assert all(step.action == "dropped" and result.values[step.parameter] == 0.0 for step in result.reduction)
    assert np.all(result.accuracy.insensitivity_percent <= 10)


def test_fits_of_the_same_records_share_their_delayed_winds_and_give_what_each_gives_alone(
    records: list[Record],
) -> None:
    """Inside :func:`sharing_delayed_winds` the fits reuse one set of delayed winds; the values are bitwise the same."""
    structure = load_structure("hover-wind")
    values = structure.values(dict(CALM_HOVER) | {"N_r": 0.0, "Z_w": 0.0})
    constants = structure.default_constants()
    alone = fit_wind(structure, values, constants, records)

    def data(of: list[Record]):  # type: ignore[no-untyped-def]
        return _prediction_data(structure, values, constants, of, ["ax", "az"])

    assert data(records).delayed is not data(records).delayed  # outside: each fit its own
    with sharing_delayed_winds():
        shared = data(records).delayed
        assert data(records).delayed is shared
        moved = [replace(records[0], columns=dict(records[0].columns) | {"wind_lon": records[0]["wind_lon"] + 0.1})]
        assert data(moved).delayed is not shared  # another wind array: not the same winds
        twice = [fit_wind(structure, values, constants, records) for _ in range(2)]
        delayed = shared.stacked("wind_lon", 0.013)
    assert all(dict(fit.values) == dict(alone.values) for fit in twice)
    assert all(fit.accuracy.cramer_rao.tolist() == alone.accuracy.cramer_rao.tolist() for fit in twice)
    t, wind = records[0].time_s, records[0]["wind_lon"]
    expected = np.interp(t - 0.013, t, wind)
    np.testing.assert_allclose(delayed[: t.size], expected - expected.mean(), rtol=0, atol=1e-12)  # the blend's
    assert not delayed.flags.writeable
    assert data(records).delayed is not shared  # freed on leaving


def test_the_scans_solutions_from_whole_lag_products_are_those_of_the_delayed_winds(records: list[Record]) -> None:
    """The delay scans solve the gains (and the speed derivatives beside them) from products at whole lags
    (:class:`~sysid.fit.wind._LagProducts`): at any delays, the solutions of the delayed winds themselves."""
    structure = load_structure("hover-wind")
    values = _with_wind_defaults(structure, structure.values(dict(CALM_HOVER) | {"N_r": 0.0, "Z_w": 0.0}))
    constants = structure.default_constants()
    data = _prediction_data(structure, values, constants, records, ["ax", "az"])
    problem, normal, delay_index, _ = _gains_problem(structure, values, constants, data)
    u = np.concatenate([r["u"] - r["u"].mean() for r in records])
    speeds = [np.column_stack([u, 0.3 * u])]
    joint = _Joint(normal, data, speeds, [_projected(c, _lagged_wind(problem)) for c in speeds])
    assert len(delay_index) == 2
    for taus in ((0.0, 0.0), (0.013, 0.2371), (0.5, 0.0049), (0.999, 0.61)):
        theta = problem.start.copy()
        theta[delay_index] = taus
        delays, winds = problem.wind_delays(theta), problem.winds(theta)
        gains, cost = normal.solve(theta)
        expected_gains, expected_cost = normal.solve_for(theta, winds, normal.residual)
        np.testing.assert_allclose(gains, expected_gains, rtol=1e-10, atol=0)
        assert abs(cost - expected_cost) <= 1e-10 * expected_cost
        joint_cost, solution = joint.solve_at(delays)
        expected_joint_cost, expected_solution = joint.solve(winds)
        np.testing.assert_allclose(solution, expected_solution, rtol=1e-9, atol=0)
        assert abs(joint_cost - expected_joint_cost) <= 1e-10 * expected_joint_cost


def test_records_without_wind_are_refused(records: list[Record]) -> None:
    structure = load_structure("hover-wind")
    bare = [
        Record.from_table(r.table.drop(columns="wind_lon"), units=r.units, trim=r.trim, source=r.source)
        for r in records
    ]
    with pytest.raises(FitError, match="wind_lon"):
        fit_wind(structure, structure.values(), structure.default_constants(), bare)
    with pytest.raises(FitError, match="no wind parameters"):
        fit_wind(load_structure("hover"), structure.values(), structure.default_constants(), records)


def test_unfitted_wind_leaves_every_term_unidentified_with_the_reason() -> None:
    structure = load_structure("hover-wind")
    with pytest.warns(FitWarning, match="wind terms X_w_lon, Z_w_lon, tau_w_lon, tau_w_thr not identified: why"):
        result = unfitted_wind(structure, "why")
    assert set(result.status.values()) == {"unidentified"} and all(np.isnan(v) for v in result.values.values())
    model = model_from_fit(_fit_without_wind(structure), result)
    assert model.parameter("X_w_lon").unidentified and model.wind is None
    assert model.linear_model().inputs == ("delta_lat", "delta_lon", "delta_yaw", "delta_thr")  # no unmeasured G_w


def _fit_without_wind(structure: ModelStructure) -> FrequencyFit:
    truth, _ = structure_model(structure, dict(CALM_HOVER))
    pairs = ["p/delta_lat", "q/delta_lon", "ax/delta_lon", "r/delta_yaw", "az/delta_thr"]
    return fit_frequency_responses(structure, synthetic_responses(truth, pairs, fit_range=(0.8, 50.0)))


def test_the_wind_step_of_a_partial_model_fits_the_identified_axes_outputs(records: list[Record]) -> None:
    """Pitch unidentified: ax has no residual to fit, so X_w_lon and tau_w_lon are unidentified; Z_w_lon comes back."""
    structure = load_structure("hover-wind")
    truth = structure.values(dict(CALM_HOVER) | {"N_r": 0.0, "Z_w": 0.0})  # per %, as logged here
    values = truth | dict.fromkeys(("X_u", "M_u", "X_lon", "M_lon", "tau_lon"), float("nan"))
    result = fit_wind(structure, values, structure.default_constants(), records)
    assert result.status["X_w_lon"] == result.status["tau_w_lon"] == "unidentified"
    assert np.isnan(result.values["X_w_lon"]) and result.fit is not None and result.fit.outputs == ("az",)
    assert result.status["Z_w_lon"] == "estimated"
    assert abs(result.values["Z_w_lon"] - STRONG_WIND_TERMS["Z_w_lon"]) <= 0.1 * STRONG_WIND_TERMS["Z_w_lon"]


@pytest.mark.parametrize("phi", [0.5, 0.9, 0.999, -0.3])
def test_the_first_order_recursion_is_lfilter_with_its_initial_state(phi: float) -> None:
    from scipy import signal as sps

    from sysid.fit.wind import _first_order

    f = np.random.default_rng(4).standard_normal(4000)
    b, den = np.array([0.3, -0.1]), np.array([1.0, -phi])
    expected = sps.lfilter(b, den, f[1:], zi=sps.lfiltic(b, den, y=[0.7], x=[f[0]]))[0]
    np.testing.assert_allclose(_first_order(phi, 0.3, -0.1, f, 0.7), np.r_[0.7, expected], rtol=0, atol=1e-12)


def test_the_speed_derivatives_without_bounds_are_those_with_them(records: list[Record]) -> None:
    """The step 1 spreads want the values alone: the same values, every bound infinite, no correlation."""
    structure = load_structure("hover-wind")
    values = structure.values(dict(CALM_HOVER) | {"N_r": 0.0, "Z_w": 0.0})
    estimated = [n for n in structure.parameter_names if n not in structure.wind_parameters]
    constants = structure.default_constants()
    delays = {"tau_w_lon": 0.1, "tau_w_thr": 0.1}
    flown = [  # the speed regressors need every air-relative velocity: v, still, beside u and w
        replace(r, columns=dict(r.columns) | {"v": np.zeros(r.time_s.size)}, units=dict(r.units) | {"v": "m/s"})
        for r in records
    ]
    with_bounds = speed_derivatives(structure, values, constants, flown, estimated, delays=delays)
    alone = speed_derivatives(structure, values, constants, flown, estimated, delays=delays, with_accuracy=False)
    assert alone[0] == with_bounds[0] and {"X_u", "Z_w"} <= set(alone[0])
    assert alone[1].names == with_bounds[1].names and len(alone[1].names) > 2
    np.testing.assert_array_equal(alone[1].values, with_bounds[1].values)
    assert np.all(np.isfinite(with_bounds[1].cramer_rao)) and np.all(np.isinf(alone[1].cramer_rao))


def test_the_wind_steps_fits_simulate_the_missing_states_again_only_when_their_rows_change(
    records: list[Record], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Inside sharing_delayed_winds, a move of X_lon (the u row: u is recorded) reuses the actuator lags simulated;
    a move of T_a (the lags' own rows) simulates them again; the residuals are those computed without sharing."""
    import sysid.fit.wind as wind_module

    structure = load_structure("hover-wind")
    constants = structure.default_constants()
    values = structure.values(dict(CALM_HOVER) | {"N_r": 0.0, "Z_w": 0.0})
    moves = [values, values | {"X_lon": values["X_lon"] * 1.1}, values | {"T_a": values["T_a"] * 1.1}]
    alone = [_prediction_data(structure, v, constants, records, ["ax", "az"]).residual for v in moves]
    simulated = wind_module._states
    calls: list[str] = []

    def counted(record: Record, *args: object) -> tuple[np.ndarray, np.ndarray]:
        calls.append(record.label)
        return simulated(record, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(wind_module, "_states", counted)
    with sharing_delayed_winds():
        shared = []
        for v in moves:
            shared.append(_prediction_data(structure, v, constants, records, ["ax", "az"]).residual)
            calls.append("|")
    assert calls == ["lon sweep", "thr sweep", "|", "|", "lon sweep", "thr sweep", "|"]
    for before, after in zip(alone, shared):
        for a, b in zip(before, after):
            np.testing.assert_array_equal(a, b)
