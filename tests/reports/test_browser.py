"""The validation report as a reader's browser shows it: loads clean, every figure drawn, nothing fetched.

Headless Chromium is Debian's package (``.ci/run`` installs it). Without it the
test is skipped locally and fails in CI (``CI`` set), so a missing install
cannot pass silently. The screenshot is kept in ``tests/artifacts/``.
"""

from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path

import pytest

from reports.validate_report import write_validate_report

_HELPER = importlib.util.spec_from_file_location("_report_browser", Path(__file__).with_name("browser.py"))
assert _HELPER is not None and _HELPER.loader is not None
browser = sys.modules.setdefault(_HELPER.name, importlib.util.module_from_spec(_HELPER))
_HELPER.loader.exec_module(browser)

ARTIFACTS = Path(__file__).resolve().parents[1] / "artifacts"


@pytest.fixture(scope="module")
def chromium() -> Path:
    try:
        return browser.chromium_path()
    except browser.BrowserUnavailable as err:
        if os.environ.get("CI"):
            pytest.fail(f"CI must render reports in a browser: {err}")
        pytest.skip(str(err))


def test_validate_report_renders_in_chromium(chromium: Path, tmp_path: Path) -> None:
    verification = browser.sample_verification()
    page = write_validate_report(tmp_path / "validate.html", verification, model_name="hover-wind.json",
                                 logs=["doublets.ulg"])
    shot = ARTIFACTS / "validate.png"
    seen = browser.render_in_browser(page, shot)
    assert seen.console_errors == ()
    assert seen.external_requests == ()
    assert seen.n_figures == len(verification.records) + 1  # the wind-correction bars and one per record
    for (width, height), marks in zip(seen.figure_sizes, seen.figure_marks):
        assert width > 300 and height > 100
        assert marks > 20
    assert seen.screenshot_nonblank
    assert shot.stat().st_size > 10_000


def test_a_blank_page_is_seen_as_blank(chromium: Path, tmp_path: Path) -> None:
    """The helper itself: an empty page has no figures and no ink; a broken script and a fetch are reported."""
    page = tmp_path / "blank.html"
    page.write_text('<!DOCTYPE html><html><body><script>undefinedFunction()</script>'
                    '<img src="http://127.0.0.1:9/pixel.png" alt=""></body></html>')  # loopback discard port
    seen = browser.render_in_browser(page, tmp_path / "blank.png")
    assert seen.n_figures == 0 and not seen.screenshot_nonblank
    assert any("undefinedFunction" in error for error in seen.console_errors)
    assert seen.external_requests == ("http://127.0.0.1:9/pixel.png",)
