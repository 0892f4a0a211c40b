"""The model report: sections, verdict against DESIGN.md's guidelines, escaping, figures, determinism.

(It is rendered in Chromium by ``test_browser.py``.)

The models are built directly (the hover structure with Table 3.3's values and
synthetic responses), not fitted: the report is judged on what it is given.
"""

from __future__ import annotations

import dataclasses
import math
import re

import pytest

from reports.model_report import model_report_html
from sysid.fit import IdentifiedModel, model_verdict
from sysid.verify import Verification

from builders import STAMP, sample_verification, small_model, with_unidentified

HOSTILE = '<script>alert("x")</script><img src=x onerror=alert(1)>'


@pytest.fixture(scope="module")
def hostile_page() -> tuple[str, IdentifiedModel, Verification]:
    """A full report where every string from a log or a file is hostile."""
    model = small_model(files=(f"flight{HOSTILE}.bin", "anemometer.csv"), notes=(f"note {HOSTILE}",))
    model = dataclasses.replace(
        model, provenance=dataclasses.replace(model.provenance, options={"min_coherence": 0.5, "kind": HOSTILE})
    )
    sample = sample_verification()
    records = tuple(dataclasses.replace(r, label=f"{r.label} {HOSTILE}") for r in sample.records)
    verification = dataclasses.replace(sample, records=records)
    page = model_report_html(
        model,
        verification=verification,
        logs_summary={"vehicle": HOSTILE},
        verification_options={"initial_state": HOSTILE},
        generated_utc=STAMP,
    )
    return page, model, verification


def _section_ids(page: str) -> list[str]:
    return re.findall(r'<h2 id="([a-z]+)"', page)


def test_every_section_is_there_in_order(hostile_page: tuple[str, IdentifiedModel, Verification]) -> None:
    page, _, _ = hostile_page
    assert _section_ids(page) == [
        "responses",
        "parameters",
        "costs",
        "correlation",
        "modes",
        "verification",
        "reduction",
        "provenance",
    ]
    assert 'id="summary"' in page and "With and without the wind term" in page
    for heading in ("Bias and reference shift per record", "Options of the identification", "Software"):
        assert heading in page


def test_the_verification_section_is_optional() -> None:
    page = model_report_html(small_model(responses=False), generated_utc=STAMP)
    assert "verification" not in _section_ids(page)
    assert "not yet verified on doublets" in page
    assert "The model file holds no frequency responses." in page


def test_strings_from_logs_and_files_are_escaped(hostile_page: tuple[str, IdentifiedModel, Verification]) -> None:
    page, _, _ = hostile_page
    assert "<script" not in page.lower() and "<img" not in page.lower()
    escaped = "&lt;script&gt;alert(&#34;x&#34;)&lt;/script&gt;"
    assert page.count(escaped) >= 6  # vehicle, data, file table, note, option, verification option, record labels
    svg_text = '&lt;script&gt;alert("x")&lt;/script&gt;'  # matplotlib's own escaping of text inside figures
    assert svg_text in page


def test_one_figure_per_input_plus_correlation_poles_and_verification(
    hostile_page: tuple[str, IdentifiedModel, Verification],
) -> None:
    page, model, verification = hostile_page
    inputs = {r.input for r in model.responses}
    n_verification = len(verification.records) + (1 if verification.wind_correction else 0)
    assert page.count("<svg ") == len(inputs) + 1 + 1 + n_verification
    assert page.count('class="figure"') == page.count("<svg ")


def test_the_report_is_deterministic(hostile_page: tuple[str, IdentifiedModel, Verification]) -> None:
    page, model, verification = hostile_page
    again = model_report_html(
        model,
        verification=verification,
        logs_summary={"vehicle": HOSTILE},
        verification_options={"initial_state": HOSTILE},
        generated_utc=STAMP,
    )
    assert again == page


def _row(page: str, first_cell: str) -> str:
    match = re.search(rf'<tr><td class="mono">{re.escape(first_cell)}</td>.*?</tr>', page)
    assert match is not None, first_cell
    return match.group(0)


def test_parameters_beyond_the_guidelines_are_flagged() -> None:
    model = small_model(
        responses=False,
        accuracy={
            "X_u": (20.1, 3.0),  # Tischler's limits: CR% <= 20, I% <= 10
            "M_u": (4.0, 10.1),
            "Y_v": (20.0, 10.0),
        },
    )
    page = model_report_html(model, generated_utc=STAMP)
    assert re.search(r'<td class="flag">20\.1</td><td>3</td>', _row(page, "X_u"))
    assert re.search(r'<td>4</td><td class="flag">10\.1</td>', _row(page, "M_u"))
    assert 'class="flag"' not in _row(page, "Y_v")  # on the limit is within it
    assert 'class="flag"' not in _row(page, "N_r")  # dropped: no accuracy to judge


def test_response_costs_beyond_200_are_flagged() -> None:
    costs = {
        "q/delta_lon": 201.0,  # Tischler's limit: J <= 200 for each response
        "u/delta_lon": 200.0,
        "p/delta_lat": 10.0,
        "az/delta_thr": 5.0,
    }
    page = model_report_html(small_model(average=90.0, costs=costs), generated_utc=STAMP)
    assert '<td class="flag">201</td>' in _row(page, "q/delta_lon")
    assert 'class="flag"' not in _row(page, "u/delta_lon")


def test_correlated_pairs_beyond_0_9_are_listed() -> None:
    page = model_report_html(small_model(responses=False), generated_utc=STAMP)
    assert re.search(
        r"<td class=\"mono\">X_u</td><td class=\"mono left\">M_u</td><td class=\"warn\">-0\.950</td>", page
    )
    assert page.count('<td class="warn">') == 1  # the 0.5 pair is not listed


def test_the_verdict_is_one_coloured_sentence_in_the_card() -> None:
    model = small_model(average=200.0, responses=False)  # J_ave beyond 150: poor
    page = model_report_html(model, generated_utc=STAMP)
    verdict = model_verdict(model)
    assert verdict.grade == "poor"
    assert f'<p class="verdict bad">{verdict.sentence}</p>' in page
    assert verdict.sentence.count(". ") == 0 and verdict.sentence.endswith(".")


def _fitted_with(max_cr_percent: float) -> IdentifiedModel:
    """The small model with X_u at CR 25 %, as if ``sysid fit --max-cr`` had been given `max_cr_percent`."""
    model = small_model(responses=False, accuracy={"X_u": (25.0, 3.0)})
    options = {"fit": {"max_cr_percent": max_cr_percent, "max_insensitivity_percent": 10.0}}
    return dataclasses.replace(model, provenance=dataclasses.replace(model.provenance, options=options))


def test_the_report_judges_by_the_max_cr_the_model_was_fitted_with() -> None:
    """Issue 13: the verdict used its own 20 % whatever ``--max-cr`` the fit was run with."""
    strict = model_report_html(_fitted_with(20.0), generated_utc=STAMP)
    lenient = model_report_html(_fitted_with(30.0), generated_utc=STAMP)
    assert (
        '<p class="verdict warn">Acceptable model: 1 of 14 estimated parameters miss CR ≤ 20 % or I ≤ 10 % (X_u); not yet verified on doublets.</p>'
        in strict
    )
    assert '<p class="verdict good">Good model by Tischler&#39;s guidelines: ' in lenient
    assert "all 14 estimated parameters within CR ≤ 30 % and I ≤ 10 %" in lenient
    assert re.search(r'<td class="flag">25</td><td>3</td>', _row(strict, "X_u"))
    assert 'class="flag"' not in _row(lenient, "X_u")
    assert "guidelines CR ≤ 30 % and I ≤ 10 %" in lenient and "guidelines CR ≤ 20 % and I ≤ 10 %" in strict


def test_the_wind_of_the_trim_is_shown_as_speed_and_direction_from() -> None:
    model = small_model(responses=False)
    # air moving towards the south-east at 2.7 m/s: the wind comes from 315 deg (north-west)
    model = dataclasses.replace(model, trim={"wind_n": -2.7 / math.sqrt(2), "wind_e": 2.7 / math.sqrt(2)})
    page = model_report_html(model, generated_utc=STAMP)
    assert "mean 2.7 m/s from 315°" in page


def test_unidentified_parameters_show_no_value_flagged_and_the_missing_axis() -> None:
    """Issue 14: a parameter no response informed is "—" and flagged, its axis named in the card and the verdict."""
    pitch = {"X_u", "M_u", "X_lon", "M_lon", "tau_lon"}
    model = with_unidentified(small_model(responses=False), pitch, {"lon": "no sweep found in 3 logs"})
    page = model_report_html(model, generated_utc=STAMP)
    row = _row(page, "M_lon")
    assert '<td class="flag">—</td>' in row and '<td class="left flag">unidentified</td>' in row
    assert "unidentified, so not simulated: lon (no sweep found in 3 logs)" in page
    assert "5 unidentified (no value)" in page
    assert (
        '<p class="verdict warn">Acceptable model: lon unidentified (no sweep found in 3 logs): a model of lat, yaw, thr only'
        in page
    )


def test_a_reduction_step_refused_for_its_cost_is_shown_kept_with_the_reason() -> None:
    model = small_model(responses=False)
    kept = dataclasses.replace(
        model.reduction[0],
        parameter="tau_yaw",
        action="kept",
        reason="I% = 11.2 > 10; removing it, the cost of r/delta_yaw rose from 2.8 to 83 (allowed: up to 4.8), so it stays",
    )
    page = model_report_html(dataclasses.replace(model, reduction=(kept,)), generated_utc=STAMP)
    assert '<td class="left warn">kept</td>' in page
    assert "the cost of r/delta_yaw rose from 2.8 to 83 (allowed: up to 4.8), so it stays" in page
    assert "by more than 2 %, or the cost of any one response by more than 20 %" in page
