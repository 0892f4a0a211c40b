"""Tables 2.6-2.8 in the simulator with eq. 2.5: the chapter's ordering in ground effect, alike out of it."""

from __future__ import annotations

import numpy as np
import pytest

from flightlogs.errors import DataError
from simulator.flights.altitude import CRAZYFLIE_ALTITUDE
from simulator.mrac import (
    FLOWN_RISE_TIMES,
    REFERENCE_EQ_2_20,
    CompareConfig,
    MracComparison,
    Regressor,
    StepMetrics,
    compare_controllers,
    comparison_json,
    flown_rise_time,
    step_case,
    step_metrics,
)

IN_GROUND_EFFECT = (4.0, 3.0, 2.0)
PHASES = ("takeoff", "landing")


@pytest.fixture(scope="module")
def comparison() -> MracComparison:
    """Chapter 2's experiment: three trials per controller at Z/R 4, 3, 2 and 22 (PID 40 s, MRAC 20 s phases)."""
    return compare_controllers(CompareConfig(height_ratios=(*IN_GROUND_EFFECT, 22.0), trials=3))


def _rise(comparison: MracComparison, name: str, ratio: float, phase: str) -> float:
    stats = comparison.statistics(name, height_ratio=ratio, phase=phase).rise_time_s  # type: ignore[arg-type]
    assert stats.n == stats.total == 3, f"{name} at Z/R {ratio} {phase}: 90 % not reached in every trial"
    return stats.mean


@pytest.mark.parametrize("ratio", IN_GROUND_EFFECT)
@pytest.mark.parametrize("phase", PHASES)
def test_rbf_tracks_the_reference_model_better_than_linear(
    comparison: MracComparison, ratio: float, phase: str
) -> None:
    """Done-when: RBF has a lower MSE to the reference model than linear (chapter 2: at least 45 % lower)."""
    linear = comparison.statistics("mrac_linear", height_ratio=ratio, phase=phase).mse_m2.mean  # type: ignore[arg-type]
    rbf = comparison.statistics("mrac_rbf", height_ratio=ratio, phase=phase).mse_m2.mean  # type: ignore[arg-type]
    assert rbf <= 0.55 * linear


@pytest.mark.parametrize("ratio", IN_GROUND_EFFECT)
@pytest.mark.parametrize("phase", PHASES)
def test_rise_time_ordering_pid_then_linear_then_rbf(comparison: MracComparison, ratio: float, phase: str) -> None:
    """PID >> MRAC linear > MRAC RBF. Each MRAC at least halves the PID's rise time: its bias estimate adds
    Gamma p12 / m = 0.24 N/(m s) of integral action, 3.5 times the PID's Ki n k_f = 0.069 N/(m s), to the
    integrator that alone moves the vehicle against the ground-effect spring; RBF adapts faster
    (|Phi|^2 about 2 near the ground against 1), chapter 2: 15 % shorter rise than linear."""
    pid, linear, rbf = (_rise(comparison, n, ratio, phase) for n in ("pid", "mrac_linear", "mrac_rbf"))
    assert rbf <= 0.85 * linear
    assert linear <= 0.5 * pid


#: Issue 17's decision: a faithful build of chapter 2 (eqs. 2.14-2.26, A.4, Tables 2.1, 2.5, eq. 2.5: B = [0, 1/m],
#: Gamma = 1e-3, e = x - x_ref, steps 6.2/4.2/2.2 cm) cuts the PID's rise time by 67-74 % (linear) and 77-81 % (RBF),
#: not the flights' 80 % or more; the faithful figure is accepted. The MRAC's integral action Gamma p12 |Phi|^2 / m is
#: 3.5 |Phi|^2 times the PID's Ki n k_f, so to first order the linear MRAC rises in 1 / 4.5 = 22 % of the PID's time
#: plus the reference model's own lag; the flown PID was slower than this one (its 40-s errors 0.26-1.03 cm against
#: 0.03-0.16 cm here; test_mrac.py::test_eq_2_20_is_table_2_5s_pd_loop_with_a_lower_pwm_gain).
FAITHFUL_CUT_PERCENT = {"mrac_linear": (67, 74), "mrac_rbf": (77, 81)}  # whole percents, as the issue states them


@pytest.mark.parametrize("name", ["mrac_linear", "mrac_rbf"])
def test_mrac_cuts_the_rise_time_as_the_faithful_build_does(comparison: MracComparison, name: str) -> None:
    """In ground effect, take-off and landing at Z/R 4, 3, 2: the cut the decision accepted, each case inside it."""
    low, high = FAITHFUL_CUT_PERCENT[name]
    for ratio in IN_GROUND_EFFECT:
        for phase in PHASES:
            cut = 100.0 * (1.0 - _rise(comparison, name, ratio, phase) / _rise(comparison, "pid", ratio, phase))
            assert low <= round(cut) <= high, f"{name} at Z/R {ratio} {phase}: cut {cut:.1f} %"


def test_the_flown_figures_are_the_chapters() -> None:
    """Tables 2.6-2.8 as transcribed: every MRAC rise time flown is under 20 % of the PID's (the chapter's "at least
    80 %"), RBF under linear in every case, and the PID's landing at Z/R 2 has no figure (it never touched down)."""
    assert {(f.height_ratio, f.phase) for f in FLOWN_RISE_TIMES} == {(r, p) for r in IN_GROUND_EFFECT for p in PHASES}
    cuts = [f.cut(n) for f in FLOWN_RISE_TIMES for n in ("mrac_linear", "mrac_rbf")]
    assert all(c <= 0.21 for c in cuts if c is not None)  # 4.53 / 22.40 = 0.202 at Z/R 4: "at least 80 %" rounded
    assert all(f.rbf_s < f.linear_s for f in FLOWN_RISE_TIMES if f.rbf_s and f.linear_s)
    assert flown_rise_time(2.0, "landing").pid_s is None and flown_rise_time(22.0, "takeoff") is None


@pytest.mark.parametrize("phase", PHASES)
def test_out_of_ground_effect_the_three_behave_alike(comparison: MracComparison, phase: str) -> None:
    """At Z/R = 22 the MRAC has only the mismatch between the PID loop and the reference model identified from
    it to correct: each MRAC's response stays between the two (rise time, RMS height difference), while in
    ground effect it departs from the PID by far more than that mismatch."""
    t_ref = np.arange(0.0, 20.0, 0.005)
    reference = REFERENCE_EQ_2_20.response(t_ref, np.ones_like(t_ref))[:, 0]
    reference_rise = step_metrics(t_ref, reference, reference, before_m=0.0, after_m=1.0).rise_time_s
    pid_rise = _rise(comparison, "pid", 22.0, phase)
    for name in ("mrac_linear", "mrac_rbf"):
        rise = _rise(comparison, name, 22.0, phase)
        assert min(pid_rise, reference_rise) * 0.95 <= rise <= max(pid_rise, reference_rise) * 1.05
    spread = {}
    for ratio in (22.0, 4.0):
        pid = comparison.result(ratio, "pid")
        step = pid.case.high_m - pid.case.low_m
        n = int(round(comparison.config.mrac_phase_s * comparison.config.rate_hz))
        first = 0 if phase == "takeoff" else n
        pid_first = 0 if phase == "takeoff" else pid.run.time_s.size // 2
        z_pid = pid.run.height_m[pid_first : pid_first + n].mean(axis=1)
        z_ref = pid.reference_m[pid_first : pid_first + n]
        mismatch = np.sqrt(np.mean((z_ref - z_pid) ** 2)) / step
        for name in ("mrac_linear", "mrac_rbf"):
            z = comparison.result(ratio, name).run.height_m[first : first + n].mean(axis=1)
            spread[ratio, name] = np.sqrt(np.mean((z - z_pid) ** 2)) / step
            if ratio == 22.0:
                assert spread[ratio, name] <= mismatch
        if ratio == 22.0:
            assert mismatch < 0.1  # the PID loop out of ground effect is close to eq. 2.20
    for name in ("mrac_linear", "mrac_rbf"):
        assert spread[4.0, name] > 2 * spread[22.0, name]
    result = comparison.result(22.0, "pid")
    stats = comparison.statistics("pid", height_ratio=22.0, phase=phase)  # type: ignore[arg-type]
    sse = stats.steady_state_error_m.mean
    assert sse < 0.02 * (result.case.high_m - result.case.low_m)  # the MRACs' offset: next test


@pytest.mark.parametrize("ratio", (*IN_GROUND_EFFECT, 22.0))
@pytest.mark.parametrize("name", ["mrac_linear", "mrac_rbf"])
def test_mrac_settles_where_eqs_2_20_and_a4_put_it(comparison: MracComparison, ratio: float, name: str) -> None:
    """e = x - x_ref (eq. A.4) with eq. 2.20's states: held at a step s, x_ref -> [1.0097 s, 0.1145 s] while the
    vehicle's v_z -> 0, so the MRAC integrates towards z = z_ref + (p22/p12) 0.1145 s and the PID towards s. With
    constant thrust, Ki n k_f (s - z) = k_a (z - 1.0097 s - (p22/p12) 0.1145 s), k_a = Gamma p12 |Phi|^2 / m, puts
    the vehicle about 2 % of the step above the command after take-off and on the command after landing (the
    tables' take-off steady-state errors, 0.15-0.27 cm, exceed the landing ones, 0.09-0.12 cm). Tolerance: the
    1-s final mean scatters by about 0.3 mm per trial with the sensor noise; 0.5 mm is three standard errors of
    the mean of three trials."""
    result = comparison.result(ratio, name)
    vehicle, case = CRAZYFLIE_ALTITUDE, result.case
    step = case.high_m - case.low_m
    p = REFERENCE_EQ_2_20.lyapunov(np.diag([100.0, 1.0]))
    phi = Regressor("linear" if name == "mrac_linear" else "rbf")(np.array([case.high_m]))[0]
    k_a = 1e-3 * p[0, 1] * float(phi @ phi) / vehicle.mass_kg
    k_i = 8219.7 * vehicle.thrust_per_pwm_n
    dc = REFERENCE_EQ_2_20.dc_gain()
    offset = step * k_a * (dc[0] - 1.0 + p[1, 1] / p[0, 1] * dc[1]) / (k_i + k_a)
    assert 0.019 * step < offset < 0.025 * step
    n = result.run.time_s.size // 2
    final = result.run.height_m[n - 200 : n].mean(axis=0)  # the last second of the take-off, at 200 Hz
    assert np.mean(final) - case.high_m == pytest.approx(offset, abs=5e-4)
    assert np.mean(result.run.height_m[-200:]) - case.low_m == pytest.approx(0.0, abs=5e-4)


def test_adaptive_histories_are_kept(comparison: MracComparison) -> None:
    result = comparison.result(4.0, "mrac_rbf")
    assert result.adaptive is not None
    assert result.adaptive.theta.shape == (result.run.time_s.size, 3, 7)
    np.testing.assert_array_equal(result.adaptive.theta[0], 0.0)
    # the estimates take over part of the ground-effect thrust near the ground: below the weight, not nothing
    share = np.max(np.abs(result.adaptive.adaptive_thrust_n)) / (CRAZYFLIE_ALTITUDE.mass_kg * 9.81)
    assert 0.01 < share < 0.2
    assert comparison.result(4.0, "pid").adaptive is None


def test_the_json_summary_has_the_documented_shape(comparison: MracComparison) -> None:
    summary = comparison_json(comparison)
    for name in ("pid", "mrac_linear", "mrac_rbf"):
        for index in StepMetrics.__dataclass_fields__:
            assert set(summary["controllers"][name][index]) == {"mean", "std", "n"}
    case = summary["cases"][0]
    assert case["height_ratio"] == 4.0 and case["in_ground_effect"]
    assert set(case["phases"]["takeoff"]["rise_time_over_pid"]) == {"mrac_linear", "mrac_rbf"}
    assert case["phases"]["takeoff"]["flown_rise_time_over_pid"] == {
        "mrac_linear": 4.53 / 22.40,
        "mrac_rbf": 2.99 / 22.40,
    }
    assert summary["cases"][2]["phases"]["landing"]["flown_rise_time_over_pid"] == {
        "mrac_linear": None,
        "mrac_rbf": None,
    }
    assert "flown_rise_time_over_pid" not in summary["cases"][3]["phases"]["takeoff"]  # Z/R 22: not flown
    assert "trials" not in case["phases"]["landing"]
    trials = comparison_json(comparison, per_trial=True)["cases"][3]["phases"]["landing"]["trials"]
    assert len(trials["mrac_rbf"]) == 3 and set(trials["pid"][0]) == set(StepMetrics.__dataclass_fields__)


def test_step_cases_follow_the_dissertation() -> None:
    """Section 2.7: "6.2cm (Z/R ≈ 4), 4.2cm (Z/R ≈ 3) and 2.2cm (Z/R ≈ 2) above the ground"; other ratios put the
    rotors (gear 25.5 mm above the ground, R = 22.5 mm) at Z/R."""
    assert [step_case(r).high_m for r in IN_GROUND_EFFECT] == [0.062, 0.042, 0.022]
    case = step_case(2.0, table_heights=False)
    assert case.low_m == 0.0 and case.high_m == pytest.approx(2 * 0.0225 - 0.0255)
    assert step_case(2.5).high_m == pytest.approx(2.5 * 0.0225 - 0.0255)
    out = step_case(22.0)
    assert not out.in_ground_effect and out.low_m == pytest.approx(22 * 0.0225 - 0.0255)
    with pytest.raises(DataError, match="below the rotors' height on the ground"):
        step_case(1.0)


def test_step_metrics_on_a_first_order_response() -> None:
    """Rise 10-90 % of 1 - exp(-t/T) is T ln 9; settling (2 %) T ln 50; no overshoot; MSE of a 1 cm offset."""
    t = np.arange(0.0, 40.0, 0.005)
    height = 0.05 * (1 - np.exp(-t / 2.0))
    metrics = step_metrics(t, height, height + 0.01, before_m=0.0, after_m=0.05, smoothing_s=0.0)
    assert metrics.rise_time_s == pytest.approx(2.0 * np.log(9.0), abs=0.005)
    assert metrics.settling_time_s == pytest.approx(2.0 * np.log(50.0), abs=0.01)
    assert metrics.overshoot_percent == 0.0 and metrics.mse_m2 == pytest.approx(1e-4)
    landing = step_metrics(t, 0.05 * np.exp(-t / 2.0), np.zeros_like(t), before_m=0.05, after_m=0.0)
    assert landing.rise_time_s == pytest.approx(2.0 * np.log(9.0), abs=0.01)
    slow = step_metrics(t, 0.05 * (1 - np.exp(-t / 30.0)), height, before_m=0.0, after_m=0.05)
    assert np.isnan(slow.rise_time_s) and np.isnan(slow.settling_time_s)  # never 90 %, still moving at the end
    assert slow.steady_state_error_m == pytest.approx(0.05 * np.exp(-39.5 / 30.0), rel=0.01)
