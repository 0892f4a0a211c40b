"""Ground-effect fitting (chapter 2): the laws, recovery of eqs. 2.4-2.5, Table 2.2, selection, intervals, spacing.

Synthetic rig data follow chapter 2's rig: heights 2.5-20.5 cm in 1 cm steps
(section 2.4.1: "adjusted at an increment of 1 cm ... until 20 cm", Z/R
slightly above 1 at the lowest) on the Crazyflie's R = 22.5 mm, several
readings per height, Gaussian noise at the RMSE the dissertation reports.
Tolerances follow from the standard errors the design implies, s (J^T J)^-1/2
at the truth, computed here from the formulas, not from the code under test.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from flightlogs.errors import DataError, FitError, FitWarning, ModelError
from simulator.world.environment import thrust_ratio
from sysid.groundeffect import (
    FitConfig,
    ThrustRatioData,
    fit_ground_effect,
    fit_model,
    read_ground_effect_model,
    rig_thrust_ratio,
    spacing_study,
    write_ground_effect_model,
)
from sysid.groundeffect import formulas as laws

R = 0.0225  # Crazyflie propeller radius, m
HEIGHTS_M = np.arange(0.025, 0.2051, 0.01)  # 19 heights
EQ_2_5 = np.array([laws.FITTED_4ROTOR_SLOPE, laws.FITTED_4ROTOR_INTERCEPT, laws.FITTED_4ROTOR_BREAKPOINT])
# Table 2.2, two rotors: rho, RMSE, R^2 per spacing increment 0-50 mm
TABLE_2_2 = [
    (3.315, 0.0151, 0.8893),
    (3.166, 0.0161, 0.8740),
    (2.977, 0.0115, 0.9143),
    (3.097, 0.0130, 0.9221),
    (2.829, 0.0116, 0.9204),
    (2.788, 0.0136, 0.8889),
]


def _design(readings: int) -> np.ndarray:
    return np.repeat(HEIGHTS_M / R, readings)


def _stderr(jacobian: np.ndarray, sigma: float) -> np.ndarray:
    """Standard errors of least squares at the truth: sigma sqrt(diag((J^T J)^-1))."""
    return sigma * np.sqrt(np.diag(np.linalg.inv(jacobian.T @ jacobian)))


# --------------------------------------------------------------------------- the laws


def test_laws_against_the_dissertation_formulas() -> None:
    x = np.array([1.0, 2.0, 4.0, 5.0])
    np.testing.assert_allclose(laws.cheeseman_bennett(x), 1 / (1 - (1 / (4 * x)) ** 2), rtol=1e-15)  # eq. 2.1
    assert float(laws.cheeseman_bennett(np.array(1.0))) == pytest.approx(16 / 15, rel=1e-15)
    np.testing.assert_allclose(laws.corrected(x, 1.0), laws.cheeseman_bennett(x), rtol=1e-15)  # rho = 1 is 2.1
    assert float(laws.corrected(np.array(2.0), 3.315)) == pytest.approx(1.0546, abs=1e-4)  # "5 % at 2 R"
    np.testing.assert_allclose(laws.exponential(x, 0.7, 1.5), 0.7 * np.exp(-x / 1.5) + 1)  # eq. 2.3
    np.testing.assert_allclose(laws.piecewise_linear(x, *EQ_2_5), [1.1278, 1.0905, 1.0159, 1.0], atol=1e-12)


@pytest.mark.parametrize(
    ("model", "family"),
    [
        ("cheeseman_bennett", laws.cheeseman_bennett),
        ("fitted_2rotor", lambda x: laws.corrected(x, 3.315)),
        ("fitted_4rotor", lambda x: laws.piecewise_linear(x, *EQ_2_5)),
    ],
)
def test_the_simulator_flies_the_same_laws(model: Any, family: Any) -> None:
    x = np.linspace(1.0, 10.0, 50)
    np.testing.assert_array_equal(thrust_ratio(x, model), family(x))


# --------------------------------------------------------------------------- recovery and selection


def test_four_rotor_data_of_eq_2_5_pick_piecewise_linear_and_recover_it_within_5_percent() -> None:
    sigma = 0.0103  # Table 2.3, 0 mm, piecewise-linear RMSE
    x = _design(60)  # a scale logged for a few seconds at each height
    slope, bp = EQ_2_5[0], EQ_2_5[2]
    jacobian = np.column_stack([np.minimum(x - bp, 0), np.where(x < bp, -slope, 0)])
    se_slope, se_bp = _stderr(jacobian, sigma)
    se_intercept = sigma * np.sqrt(np.array([-bp, -slope]) @ np.linalg.inv(jacobian.T @ jacobian) @ [-bp, -slope])
    se = np.array([se_slope, se_intercept, se_bp])
    assert np.all(4 * se <= 0.05 * np.abs(EQ_2_5)), "design: 5 % must be at least 4 standard errors"
    rng = np.random.default_rng(25)
    fit = fit_ground_effect(
        ThrustRatioData(
            height_ratio=x,
            thrust_ratio=laws.piecewise_linear(x, *EQ_2_5) + rng.normal(0, sigma, x.size),
            rotor_radius_m=R,
        )
    )
    assert fit.best == "piecewise_linear"
    pl = fit.model("piecewise_linear")
    np.testing.assert_allclose(pl.values, EQ_2_5, rtol=0.05)
    assert np.all(np.abs(pl.values - EQ_2_5) <= 4 * se)
    np.testing.assert_allclose(pl.stderr, se, rtol=0.25)  # the covariance agrees with the design's
    assert pl.values[1] + pl.values[0] * pl.values[2] == pytest.approx(1.0, abs=1e-12)  # continuous by construction
    assert pl.rmse == pytest.approx(sigma, rel=4 / np.sqrt(2 * (x.size - 2)))  # chi distribution, 4 sd


def test_two_rotor_data_of_eq_2_4_pick_the_corrected_law_and_recover_rho_within_5_percent() -> None:
    sigma, rho = 0.0151, laws.FITTED_2ROTOR_RHO  # Table 2.2, 0 mm
    x = _design(20)
    (se_rho,) = _stderr((laws.corrected(x, rho) ** 2 / (16 * x * x))[:, None], sigma)
    assert 4 * se_rho <= 0.05 * rho
    rng = np.random.default_rng(24)
    fit = fit_ground_effect(
        ThrustRatioData(
            height_ratio=x, thrust_ratio=laws.corrected(x, rho) + rng.normal(0, sigma, x.size), rotor_radius_m=R
        )
    )
    assert fit.best == "corrected"
    assert fit.model("corrected").params["rho"] == pytest.approx(rho, rel=0.05)
    assert fit.model("corrected").stderr[0] == pytest.approx(se_rho, rel=0.25)


def test_table_2_2_rho_series_is_recovered_by_the_two_rotor_spacing_study() -> None:
    x = _design(30)
    rng = np.random.default_rng(22)
    datasets = [
        ThrustRatioData(
            height_ratio=x,
            thrust_ratio=laws.corrected(x, rho) + rng.normal(0, rmse, x.size),
            rotor_radius_m=R,
            source=f"{10 * i} mm",
        )
        for i, (rho, rmse, _) in enumerate(TABLE_2_2)
    ]
    study = spacing_study(datasets, np.arange(6) * 0.010, rotors=2)
    rho_hat, low, high = study.parameter("corrected", "rho")
    for (rho, rmse, r2), value, fit in zip(TABLE_2_2, rho_hat, study.fits):
        (se_rho,) = _stderr((laws.corrected(x, rho) ** 2 / (16 * x * x))[:, None], rmse)
        assert 4 * se_rho <= 0.05 * rho
        assert value == pytest.approx(rho, rel=0.05)
        model = fit.model("corrected")
        assert model.rmse == pytest.approx(rmse, rel=4 / np.sqrt(2 * (x.size - 1)))
        # the same heights give the table's R^2: it carries the sampling error of ~19 readings (sd ~0.02)
        assert model.r2 == pytest.approx(r2, abs=0.05)
    assert study.chosen == ("corrected",) * 6 and study.transition_m is None
    assert np.all((low < rho_hat) & (rho_hat < high))


@pytest.mark.parametrize(
    ("model", "truth", "sigma"),
    [
        ("corrected", np.array([3.315]), 0.0151),
        ("exponential", np.array([0.30, 1.6]), 0.0103),
        ("piecewise_linear", EQ_2_5 * [1, 0, 1] + [0, 1 - EQ_2_5[0] * EQ_2_5[2], 0], 0.0103),
    ],
)
def test_confidence_intervals_cover_the_truth_at_their_level(model: str, truth: np.ndarray, sigma: float) -> None:
    x = _design(5)
    clean = {
        "corrected": lambda: laws.corrected(x, *truth),
        "exponential": lambda: laws.exponential(x, *truth),
        "piecewise_linear": lambda: laws.piecewise_linear(x, *truth),
    }[model]()
    rng = np.random.default_rng(95)
    trials = 200
    covered = np.array(
        [
            (lambda f: (f.ci_low <= truth) & (truth <= f.ci_high))(
                fit_model(model, x, clean + rng.normal(0, sigma, x.size))
            )
            for _ in range(trials)
        ]
    )
    # binomial: 95 % coverage, 4 standard deviations of a 200-trial proportion
    assert np.all(covered.mean(axis=0) >= 0.95 - 4 * np.sqrt(0.95 * 0.05 / trials))


def test_selection_counts_parameters_bic_and_aicc() -> None:
    x = _design(3)
    rng = np.random.default_rng(3)
    y = laws.corrected(x, 1.0) + rng.normal(0, 0.002, x.size)  # eq. 2.1 exactly: rho = 1 adds nothing
    for criterion in ("aicc", "bic"):
        data = ThrustRatioData(height_ratio=x, thrust_ratio=y, rotor_radius_m=R)
        fit = fit_ground_effect(data, FitConfig(criterion=criterion))  # type: ignore[arg-type]
        assert fit.best == "cheeseman_bennett"
        assert fit.model("corrected").rss <= fit.model("cheeseman_bennett").rss  # fits better, yet not chosen
        assert fit.delta("cheeseman_bennett") == 0.0
    m = fit.model("corrected")
    n, k = x.size, 2
    assert m.aicc == pytest.approx(n * np.log(m.rss / n) + 2 * k + 2 * k * (k + 1) / (n - k - 1), rel=1e-12)
    assert m.bic == pytest.approx(n * np.log(m.rss / n) + k * np.log(n), rel=1e-12)
    assert m.r2 == pytest.approx(1 - m.rss / np.sum((y - y.mean()) ** 2), rel=1e-12)


def test_too_few_points_and_an_unreachable_breakpoint_are_reported() -> None:
    with pytest.raises(FitError, match="at least 3"):
        fit_ground_effect(
            ThrustRatioData(height_ratio=np.array([1.5, 3.0]), thrust_ratio=np.array([1.1, 1.0]), rotor_radius_m=R)
        )
    x = np.linspace(1.2, 3.0, 12)  # all inside ground effect: no plateau, the breakpoint is extrapolated
    with pytest.warns(FitWarning, match="breakpoint 4.5 lies past the largest Z/R 3: extrapolated"):
        fit = fit_model("piecewise_linear", x, laws.piecewise_linear(x, -0.04, 1.18, 4.5))
    np.testing.assert_allclose(fit.values, [-0.04, 1.18, 4.5], rtol=1e-6)
    assert fit.notes and "extrapolated" in fit.notes[0]
    with pytest.warns(FitWarning, match="not identified by the data"):
        fit = fit_model("piecewise_linear", x, laws.piecewise_linear(x, -0.04, 1.2, 1.25))  # one point below it
    assert fit.notes and "not identified" in fit.notes[0]


def test_only_the_chosen_familys_notes_are_raised_and_named() -> None:
    x = np.linspace(1.2, 3.0, 15)  # no plateau in the data: piecewise_linear extrapolates its breakpoint
    wiggle = 0.002 * np.sin(7 * x)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing raised: the corrected law is chosen, without a note
        fit = fit_ground_effect(
            ThrustRatioData(height_ratio=x, thrust_ratio=laws.corrected(x, 3.3) + wiggle, rotor_radius_m=R)
        )
    assert fit.best == "corrected" and not fit.model("corrected").notes
    assert "extrapolated" in fit.model("piecewise_linear").notes[0]  # kept in that family's fit
    data = ThrustRatioData(
        height_ratio=x, thrust_ratio=laws.piecewise_linear(x, -0.04, 1.18, 4.5) + wiggle, rotor_radius_m=R
    )
    with pytest.warns(
        FitWarning, match=r"^piecewise_linear: breakpoint 4\.\d+ lies past the largest Z/R 3: extrapolated"
    ):
        fit = fit_ground_effect(data)
    assert fit.best == "piecewise_linear" and "extrapolated" in fit.model("piecewise_linear").notes[0]


# --------------------------------------------------------------------------- inputs and outputs


def test_rig_f0_from_the_rows_out_of_ground_effect() -> None:
    f0 = 0.374
    height = np.array([0.03, 0.05, 0.10, 0.19, 0.20])
    thrust = f0 * laws.piecewise_linear(height / R, *EQ_2_5)
    data = rig_thrust_ratio(height, thrust, rotor_radius_m=R)
    assert data.f0_n == pytest.approx(f0, rel=1e-12) and "2 rows with Z/R > 8" in data.f0_source
    np.testing.assert_allclose(data.thrust_ratio, laws.piecewise_linear(height / R, *EQ_2_5), rtol=1e-12)
    assert rig_thrust_ratio(height, thrust, rotor_radius_m=R, f0_n=0.5).f0_source == "given"
    with pytest.raises(DataError, match="no reading above Z/R = 8"):
        rig_thrust_ratio(height[:3], thrust[:3], rotor_radius_m=R, source="rig.csv")


def test_model_file_round_trips_and_rejects_foreign_files(tmp_path: Path) -> None:
    x = _design(2)
    rng = np.random.default_rng(7)
    fit = fit_ground_effect(
        ThrustRatioData(
            height_ratio=x,
            thrust_ratio=laws.piecewise_linear(x, *EQ_2_5) + rng.normal(0, 0.005, x.size),
            rotor_radius_m=R,
        )
    )
    path = write_ground_effect_model(fit, tmp_path / "ge.json")
    model = read_ground_effect_model(path)
    assert model.model == fit.best and model.rotor_radius_m == R
    grid = np.linspace(x.min(), 12, 50)
    np.testing.assert_allclose(model.ratio(grid), fit.ratio(grid), rtol=1e-15)
    assert model.ratio(np.array(0.2)) == model.ratio(np.array(x.min()))  # clamped below the data
    (tmp_path / "other.json").write_text('{"format": "something else"}')
    with pytest.raises(ModelError, match="not a ground-effect model"):
        read_ground_effect_model(tmp_path / "other.json")
    (tmp_path / "bad.json").write_text(path.read_text().replace('"piecewise_linear"', '"quartic"', 1))
    with pytest.raises(ModelError, match="unknown ground-effect model 'quartic'"):
        read_ground_effect_model(tmp_path / "bad.json")


# --------------------------------------------------------------------------- rotor spacing, four rotors


def spacing_series(seed: int, *, readings: int = 3) -> tuple[list[ThrustRatioData], np.ndarray, np.ndarray]:
    """Table 2.3 in synthetic form: four-rotor data mixing eq. 2.5 and eq. 2.2 (rho = 3) by spacing.

    The interaction that makes eq. 2.5 linear fades as the rotors move apart:
    the weight of eq. 2.5 is 1, 0.9, 0.8 below 30 mm and 0.2, 0.1, 0 from it;
    noise at Table 2.3's RMSE (0.0103).
    """
    x = _design(readings)
    weights = np.array([1.0, 0.9, 0.8, 0.2, 0.1, 0.0])
    rng = np.random.default_rng(seed)
    datasets = [
        ThrustRatioData(
            height_ratio=x,
            thrust_ratio=w * laws.piecewise_linear(x, *EQ_2_5)
            + (1 - w) * laws.corrected(x, 3.0)
            + rng.normal(0, 0.0103, x.size),
            rotor_radius_m=R,
            source=f"rig_{10 * i}mm.csv",
        )
        for i, w in enumerate(weights)
    ]
    return datasets, np.arange(6) * 0.010, weights


def test_four_rotor_spacing_study_finds_the_linear_to_quadratic_transition_at_30_mm() -> None:
    datasets, spacings, weights = spacing_series(23)
    # noise-free, each mixture is fitted better by the family that dominates it
    for w, data in zip(weights, datasets):
        clean = w * laws.piecewise_linear(data.height_ratio, *EQ_2_5) + (1 - w) * laws.corrected(data.height_ratio, 3.0)
        rss = {m: fit_model(m, data.height_ratio, clean).rss for m in ("piecewise_linear", "corrected")}
        assert (rss["piecewise_linear"] < rss["corrected"]) == (w > 0.5)
    study = spacing_study(list(reversed(datasets)), spacings[::-1], rotors=4)  # order does not matter
    np.testing.assert_array_equal(study.spacings_m, spacings)
    assert study.chosen == ("piecewise_linear",) * 3 + ("corrected",) * 3
    assert study.transition_m == pytest.approx(0.030)
    # as in Table 2.3: R^2 of the chosen family is the larger one at every spacing
    r2_pl, r2_quad = study.r2("piecewise_linear"), study.r2("corrected")
    assert np.all((r2_pl > r2_quad) == (spacings < 0.030))


def test_spacing_study_needs_one_spacing_per_data_set() -> None:
    datasets, spacings, _ = spacing_series(1, readings=1)
    with pytest.raises(DataError, match="6 data sets but 5 spacings"):
        spacing_study(datasets, spacings[:5])
    with pytest.raises(DataError, match="distinct spacings"):
        spacing_study(datasets[:2], [0.0, 0.0])
