"""The MRAC report: one self-contained page with heights, metrics and the adaptive parameters."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from reports.mrac_report import height_figure, render_mrac_report, theta_figure, write_mrac_report
from simulator.mrac import CompareConfig, MracComparison, compare_controllers


@pytest.fixture(scope="module")
def comparison() -> MracComparison:
    return compare_controllers(CompareConfig(height_ratios=(3.0, 22.0), trials=2, pid_phase_s=6.0, mrac_phase_s=4.0))


def test_the_page_has_every_case_table_and_figure(comparison: MracComparison, tmp_path: Path) -> None:
    path = write_mrac_report(tmp_path / "r.html", comparison)
    page = path.read_text()
    assert not re.search(r'(src|href)\s*=\s*"(https?:)?//', page) and "<script" not in page  # nothing fetched
    # rise-time chart + per case: heights and Theta_hat
    assert page.count("<svg") == 1 + 2 * 2
    assert page.count("<h3>take-off</h3>") == 2 and page.count("<h3>landing</h3>") == 2
    assert "θ[rbf(0 m)]" in page and "θ[z]" in page
    assert "eq. 2.5" in page and "Γ = 0.001·I" in page


def test_figures_have_two_phases_and_one_panel_per_mrac(comparison: MracComparison) -> None:
    heights = height_figure(comparison, 3.0)
    assert [ax.get_title() for ax in heights.axes] == ["take-off", "landing"]
    labels = [line.get_label() for line in heights.axes[0].get_lines()]
    assert {"PID", "MRAC, linear", "MRAC, RBF", "reference (2.20)", "command"} <= set(labels)
    theta = theta_figure(comparison, 3.0)
    assert theta is not None and [ax.get_title() for ax in theta.axes] == ["MRAC, linear", "MRAC, RBF"]
    assert len(theta.axes[1].get_lines()) == 7 + 1  # seven estimates and the landing marker


def test_a_pid_only_comparison_renders_without_theta(tmp_path: Path) -> None:
    config = CompareConfig(height_ratios=(4.0,), trials=1, pid_phase_s=4.0, controllers=("pid",))
    comparison = compare_controllers(config)
    assert theta_figure(comparison, 4.0) is None
    page = render_mrac_report(comparison)
    assert page.count("<svg") == 2


def test_the_flown_rise_times_stand_beside_the_simulated(comparison: MracComparison) -> None:
    """Z/R 3 (Table 2.7): flown linear/PID 4.58/25.86 = 0.177 at take-off and 5.23/27.62 = 0.189 at landing, RBF
    3.15/25.86 = 0.122 and 3.53/27.62 = 0.128; Z/R 22 was not flown (a dash in both flown columns)."""
    page = render_mrac_report(comparison)
    claims = page[page.index("Against the dissertation") : page.index("All cases")]
    rows = re.findall(r"<tr><td>([^<]*)</td><td>([^<]*)</td>(.*?)</tr>", claims, flags=re.S)
    cells = {(z, phase): re.findall(r"<td[^>]*>([^<]*)</td>", rest) for z, phase, rest in rows}
    assert [cells["3", "take-off"][k] for k in (1, 3)] == ["0.177", "0.122"]
    assert [cells["3", "landing"][k] for k in (1, 3)] == ["0.189", "0.128"]
    assert [cells["22 (out)", "take-off"][k] for k in (1, 3)] == ["—", "—"]
    assert "flight tests (Tables 2.6–2.8" in claims and "67–74 %" in claims
