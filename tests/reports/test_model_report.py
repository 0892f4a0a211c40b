"""The model report: sections, verdict against DESIGN.md's guidelines, escaping, figures, determinism.

(It is rendered in Chromium by ``test_browser.py``.)

The models are built directly (the hover structure with Table 3.3's values and
synthetic responses), not fitted: the report is judged on what it is given.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Mapping

import pytest

from reports.model_report import (
    CR_MAX_PERCENT,
    INSENSITIVITY_MAX_PERCENT,
    J_AVE_ACCEPTABLE,
    J_AVE_GOOD,
    J_RESPONSE_MAX,
    TIC_ACCEPTABLE,
    TIC_GOOD,
    model_report_html,
    model_verdict,
)
from sysid.fit import IdentifiedModel
from sysid.verify import OutputSummary, Verification

from builders import STAMP, sample_verification, small_model

HOSTILE = '<script>alert("x")</script><img src=x onerror=alert(1)>'


def verification_with(tics: Mapping[str, float]) -> Verification:
    """A verification whose pooled outputs have these TICs (no records: for the verdict only)."""
    summary = tuple(
        OutputSummary(name=name, unit="rad/s", rmse=0.1, tic=tic, n_records=1, n_samples=100)
        for name, tic in tics.items()
    )
    return Verification(records=(), summary=summary, rmse=1.0, tic=max(tics.values()))


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
            "X_u": (CR_MAX_PERCENT + 0.1, 3.0),
            "M_u": (4.0, INSENSITIVITY_MAX_PERCENT + 0.1),
            "Y_v": (CR_MAX_PERCENT, INSENSITIVITY_MAX_PERCENT),
        },
    )
    page = model_report_html(model, generated_utc=STAMP)
    assert re.search(r'<td class="flag">20\.1</td><td>3</td>', _row(page, "X_u"))
    assert re.search(r'<td>4</td><td class="flag">10\.1</td>', _row(page, "M_u"))
    assert 'class="flag"' not in _row(page, "Y_v")  # on the limit is within it
    assert 'class="flag"' not in _row(page, "N_r")  # dropped: no accuracy to judge


def test_response_costs_beyond_200_are_flagged() -> None:
    costs = {
        "q/delta_lon": J_RESPONSE_MAX + 1.0,
        "u/delta_lon": J_RESPONSE_MAX,
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


@pytest.mark.parametrize(
    ("average", "grade"),
    [
        (J_AVE_GOOD, "good"),
        (J_AVE_GOOD + 0.01, "acceptable"),
        (J_AVE_ACCEPTABLE, "acceptable"),
        (J_AVE_ACCEPTABLE + 0.01, "poor"),
        (math.nan, "poor"),
    ],
)
def test_verdict_on_the_average_cost(average: float, grade: str) -> None:
    verdict = model_verdict(small_model(average=average, costs={"q/delta_lon": 10.0}, responses=False))
    assert verdict.grade == grade
    assert verdict.checks[0].grade == grade


@pytest.mark.parametrize(
    ("costs", "accuracy", "grade"),
    [
        ({"q/delta_lon": J_RESPONSE_MAX}, {}, "good"),
        ({"q/delta_lon": J_RESPONSE_MAX + 0.1}, {}, "acceptable"),  # a few single responses may pass 200
        ({"q/delta_lon": 10.0}, {"X_u": (CR_MAX_PERCENT + 0.5, 1.0)}, "acceptable"),
        ({"q/delta_lon": 10.0}, {"X_u": (1.0, INSENSITIVITY_MAX_PERCENT + 0.5)}, "acceptable"),
        ({"q/delta_lon": 10.0}, {"X_u": (CR_MAX_PERCENT, INSENSITIVITY_MAX_PERCENT)}, "good"),
    ],
)
def test_verdict_on_responses_and_parameters(
    costs: dict[str, float], accuracy: dict[str, tuple[float, float]], grade: str
) -> None:
    verdict = model_verdict(small_model(average=50.0, costs=costs, accuracy=accuracy, responses=False))
    assert verdict.grade == grade
    if grade != "good":
        assert verdict.sentence.startswith("Acceptable model:")
        assert "X_u" in verdict.sentence or "q/delta_lon" in verdict.sentence


@pytest.mark.parametrize(
    ("worst", "grade"),
    [
        (TIC_GOOD, "good"),
        (TIC_GOOD + 0.01, "acceptable"),
        (TIC_ACCEPTABLE, "acceptable"),
        (TIC_ACCEPTABLE + 0.01, "poor"),
    ],
)
def test_verdict_on_the_prediction_of_doublets(worst: float, grade: str) -> None:
    model = small_model(average=50.0, costs={"q/delta_lon": 10.0}, responses=False)
    verdict = model_verdict(model, verification_with({"q": 0.05, "theta": worst}))
    assert verdict.grade == grade
    assert verdict.checks[-1].value.endswith("(theta)")
    if grade == "good":
        assert verdict.sentence.startswith("Good model") and "not yet verified" not in verdict.sentence
    else:
        assert "although the fit meets the guidelines" in verdict.sentence  # the fit itself is fine


def test_the_verdict_is_one_coloured_sentence_in_the_card() -> None:
    model = small_model(average=J_AVE_ACCEPTABLE + 50.0, responses=False)
    page = model_report_html(model, generated_utc=STAMP)
    verdict = model_verdict(model)
    assert verdict.grade == "poor"
    assert f'<p class="verdict bad">{verdict.sentence}</p>' in page
    assert verdict.sentence.count(". ") == 0 and verdict.sentence.endswith(".")


def test_the_wind_of_the_trim_is_shown_as_speed_and_direction_from() -> None:
    model = small_model(responses=False)
    # air moving towards the south-east at 2.7 m/s: the wind comes from 315 deg (north-west)
    model = dataclasses.replace(model, trim={"wind_n": -2.7 / math.sqrt(2), "wind_e": 2.7 / math.sqrt(2)})
    page = model_report_html(model, generated_utc=STAMP)
    assert "mean 2.7 m/s from 315°" in page
