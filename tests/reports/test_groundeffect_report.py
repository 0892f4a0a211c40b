"""Ground-effect reports: every model in the table and the figures, steps for flight data, the spacing study."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from reports.groundeffect_report import (
    fit_figure,
    render_groundeffect_report,
    render_spacing_report,
    residual_figure,
    write_groundeffect_report,
)
from sysid.groundeffect import HoverStep, HoverSteps, ThrustRatioData, fit_ground_effect, spacing_study
from sysid.groundeffect import formulas as laws

R = 0.0225
EQ_2_5 = (laws.FITTED_4ROTOR_SLOPE, laws.FITTED_4ROTOR_INTERCEPT, laws.FITTED_4ROTOR_BREAKPOINT)


def _data(seed: int, w: float = 1.0, source: str = "rig.csv", steps: HoverSteps | None = None) -> ThrustRatioData:
    x = np.repeat(np.arange(0.025, 0.2051, 0.01) / R, 2)
    rng = np.random.default_rng(seed)
    y = w * laws.piecewise_linear(x, *EQ_2_5) + (1 - w) * laws.corrected(x, 3.0) + rng.normal(0, 0.005, x.size)
    return ThrustRatioData(
        height_ratio=x, thrust_ratio=y, rotor_radius_m=R, source=source, f0_source="given", f0_n=0.374, steps=steps
    )


def _self_contained(page: str) -> bool:
    return not re.search(r"(src|href)=[\"']https?:", page)


def test_fit_report_has_every_model_its_parameters_and_the_choice(tmp_path: Path) -> None:
    fit = fit_ground_effect(_data(1, source="<script>alert(1)</script>.csv"))
    page = render_groundeffect_report(fit)
    for label in ("Cheeseman–Bennett (2.1)", "corrected ρ (2.2)", "exponential (2.3)", "piecewise linear (2.5)"):
        assert label in page
    for name in ("rho", "slope", "intercept", "breakpoint", "a = ", "b = "):
        assert name in page
    assert page.count("<svg") == 2 and "Hover steps" not in page
    assert "<script>" not in page and "&lt;script&gt;" in page  # the file name is escaped
    assert _self_contained(page)
    target = write_groundeffect_report(fit, tmp_path / "ge.html")
    assert target.read_text(encoding="utf-8").count("<svg") == 2


def test_flight_report_shows_the_hover_steps() -> None:
    step = HoverStep(
        start_s=10.0,
        end_s=20.0,
        steady_start_s=15.0,
        height_m=0.069,
        height_std_m=0.01,
        climb_rate_m_s=-0.001,
        f0_n=0.356,
        thrust_ratio=1.05,
        samples=500,
    )
    steps = HoverSteps(
        time_s=np.arange(0.0, 30.0, 0.5),
        height_m=np.full(60, 0.069),
        steps=(step,),
        dropped=("0.0-6.0 s: F/F0 = 5 implausible",),
    )
    page = render_groundeffect_report(fit_ground_effect(_data(2, steps=steps)))
    assert "Hover steps" in page and page.count("<svg") == 3
    assert "implausible" in page


def test_figures_draw_data_and_one_curve_per_model() -> None:
    fit = fit_ground_effect(_data(3))
    figure = fit_figure(fit)
    assert len(figure.axes[0].lines) == len(fit.models) + 1
    assert len(residual_figure(fit).axes) == len(fit.models)


@pytest.mark.parametrize("rotors", [2, 4])
def test_spacing_report_names_the_transition(rotors: int) -> None:
    weights = [1.0, 0.9, 0.8, 0.2, 0.1, 0.0]
    study = spacing_study(
        [_data(10 + i, w, f"rig_{10 * i}mm.csv") for i, w in enumerate(weights)], np.arange(6) * 0.010, rotors=rotors
    )
    page = render_spacing_report(study)
    assert page.count("<svg") == 2 and _self_contained(page)
    assert "rig_50mm.csv" in page
    if rotors == 4:
        assert study.transition_m == pytest.approx(0.030)
        assert "piecewise linear (2.5) → corrected ρ (2.2) at 30 mm" in page
    else:
        assert "none found" in page and "ρ of eq. 2.2" in page
