"""The model report as a reader's browser shows it: loads clean, every figure drawn, nothing fetched.

Headless Chromium is Debian's package (``.ci/run`` installs it). Without it the
test is skipped locally and fails in CI (``CI`` set), so a missing install
cannot pass silently. The screenshot is kept in ``tests/artifacts/``.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from reports.model_report import write_model_report

import browser
import builders

ARTIFACTS = Path(__file__).resolve().parents[1] / "artifacts"


@pytest.fixture(scope="module")
def chromium() -> Path:
    try:
        return browser.chromium_path()
    except browser.BrowserUnavailable as err:
        if os.environ.get("CI"):
            pytest.fail(f"CI must render reports in a browser: {err}")
        pytest.skip(str(err))


def test_model_report_renders_in_chromium(chromium: Path, tmp_path: Path) -> None:
    """What ``sysid validate --report`` and ``sysid report`` write: the model with its verification."""
    model = builders.small_model(files=("flight.bin", "anemometer.csv"))
    verification = builders.sample_verification()
    page = write_model_report(
        tmp_path / "model.html",
        model,
        verification=verification,
        logs_summary={"vehicle": "linear octocopter"},
        generated_utc=builders.STAMP,
    )
    shot = ARTIFACTS / "model_report.png"
    seen = browser.render_in_browser(page, shot)
    assert seen.console_errors == ()
    assert seen.external_requests == ()
    inputs = {r.input for r in model.responses}
    # Bode per input, correlation, poles, the wind-correction bars and one per record
    assert seen.n_figures == page.read_text().count("<svg ") == len(inputs) + 2 + 1 + len(verification.records)
    for (width, height), marks in zip(seen.figure_sizes, seen.figure_marks):
        assert width > 250 and height > 150
        assert marks > 20
    assert seen.screenshot_nonblank
    assert shot.stat().st_size > 50_000


def test_a_blank_page_is_seen_as_blank(chromium: Path, tmp_path: Path) -> None:
    """The helper itself: an empty page has no figures and no ink; a broken script and a fetch are reported."""
    page = tmp_path / "blank.html"
    page.write_text(
        "<!DOCTYPE html><html><body><script>undefinedFunction()</script>"
        '<img src="http://127.0.0.1:9/pixel.png" alt=""></body></html>'
    )  # loopback discard port
    seen = browser.render_in_browser(page, tmp_path / "blank.png")
    assert seen.n_figures == 0 and not seen.screenshot_nonblank
    assert any("undefinedFunction" in error for error in seen.console_errors)
    assert seen.external_requests == ("http://127.0.0.1:9/pixel.png",)
