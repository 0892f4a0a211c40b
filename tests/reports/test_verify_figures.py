"""Figures and the HTML page of a verification (drawn from a small simulated one)."""

from __future__ import annotations

import importlib.util
import re
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from reports.validate_report import render_validate_report
from reports.verify_figures import display_scale, record_figure, verification_figures, wind_correction_figure
from sysid.verify import WindCorrection

_HELPER = importlib.util.spec_from_file_location("_report_browser", Path(__file__).with_name("browser.py"))
assert _HELPER is not None and _HELPER.loader is not None
browser = sys.modules.setdefault(_HELPER.name, importlib.util.module_from_spec(_HELPER))
_HELPER.loader.exec_module(browser)


@pytest.fixture(scope="module")
def verification():  # type: ignore[no-untyped-def]
    return browser.sample_verification()


def test_display_scale_shows_radians_as_degrees() -> None:
    assert display_scale("rad") == (pytest.approx(180 / np.pi), "deg")
    assert display_scale("rad/s")[1] == "deg/s"
    assert display_scale("m/s^2") == (1.0, "m/s^2")


def test_record_figure_draws_every_output_with_and_without_wind(verification) -> None:  # type: ignore[no-untyped-def]
    record, without = verification.records[0], verification.without_wind[0]
    svg = record_figure(record, without_wind=without)
    assert svg.startswith("<svg") and 'class="figure"' in svg
    for output in record.outputs:
        assert f"{output.name} [{display_scale(output.unit)[1]}]" in svg
        assert f"TIC {output.tic:.2f}" in svg
    assert "without" in svg
    alone = record_figure(record)
    assert "without" not in alone and "model" in alone


def test_unstable_records_say_so_in_the_title(verification) -> None:  # type: ignore[no-untyped-def]
    record = replace(verification.records[0], unstable=True, growth=21.4, notice="grows")
    assert "unstable open loop: grows 21-fold" in record_figure(record)


def test_wind_correction_figure_annotates_the_reduction() -> None:
    svg = wind_correction_figure([WindCorrection("ax", "m/s^2", 0.4129, 0.3480),
                                  WindCorrection("p", "rad/s", 0.1, 0.1)])
    assert "−16 %" in svg  # Table 3.6, strong wind: 0.4129 -> 0.3480
    assert ">p<" not in svg  # an output the wind term does not touch is left out


def test_report_has_a_figure_per_record_and_the_tables(verification) -> None:  # type: ignore[no-untyped-def]
    page = render_validate_report(verification, model_name="<model>.json", logs=[Path("/x/doublets.ulg")])
    assert page.count('<svg') == len(verification_figures(verification)) == len(verification.records) + 1
    assert "&lt;model&gt;.json" in page and "<model>" not in page
    assert not re.search(r"""(src|href|url)\s*[=(]\s*["']?(https?:)?//""", page)  # namespaces are not fetches
    for summary in verification.summary:
        assert re.search(rf"<td>{summary.name}</td>", page)
    assert "Wind correction" in page and "%" in page
    assert "Good predictive accuracy" in page


def test_report_without_wind_has_no_wind_section(verification) -> None:  # type: ignore[no-untyped-def]
    plain = replace(verification, without_wind=(), wind_correction=())
    page = render_validate_report(plain, model_name="m.json")
    assert "Wind correction" not in page
    assert page.count("<svg") == len(verification.records)
