"""Render a report in headless Chromium (Debian's package, driven by Playwright) and say what a reader would see.

Also builds a small simulated verification to render, for the report tests.
"""

from __future__ import annotations

import io
import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: Flags that work on the shared machine and CI: no sandbox (root), no GPU, nothing phoning home.
CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
)


class BrowserUnavailable(RuntimeError):
    """Chromium or Playwright is not installed."""


@dataclass(frozen=True, slots=True)
class BrowserResult:
    """What the browser saw.

    Parameters
    ----------
    console_errors : tuple of str
        Console messages of type error, and uncaught page errors.
    n_figures : int
        ``<svg class="figure">`` elements on the page.
    figure_sizes : tuple of (float, float)
        Rendered width and height of each, CSS px.
    figure_marks : tuple of int
        Drawn elements (path, line, text, use) inside each figure.
    screenshot_nonblank : bool
        The full-page screenshot has ink: pixel variance and enough non-white pixels.
    external_requests : tuple of str
        URLs requested other than the page itself and inline data.
    """

    console_errors: tuple[str, ...]
    n_figures: int
    figure_sizes: tuple[tuple[float, float], ...]
    figure_marks: tuple[int, ...]
    screenshot_nonblank: bool
    external_requests: tuple[str, ...]


def chromium_path() -> Path:
    """The Chromium executable (``$CHROMIUM``, else Debian's ``/usr/bin/chromium``), or BrowserUnavailable."""
    candidate = os.environ.get("CHROMIUM") or shutil.which("chromium") or "/usr/bin/chromium"
    if not Path(candidate).is_file():
        raise BrowserUnavailable(f"no Chromium at {candidate} (apt-get install chromium)")
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError as err:
        raise BrowserUnavailable("Playwright for Python is not installed (pip install playwright)") from err
    return Path(candidate)


def _nonblank(png: bytes) -> bool:
    from matplotlib import image

    pixels = image.imread(io.BytesIO(png), format="png")[..., :3].mean(axis=-1)
    inked = float(np.mean(pixels < 0.9))
    return bool(pixels.std() > 0.02 and inked > 0.005)


def render_in_browser(html_path: Path, screenshot_path: Path, *, width: int = 1100, height: int = 900) -> BrowserResult:
    """Open `html_path` in headless Chromium, wait for it to load, inspect it and save a full-page screenshot.

    Parameters
    ----------
    html_path : Path
        The report.
    screenshot_path : Path
        Where the PNG goes (its folder is created).
    width, height : int, optional
        Viewport, CSS px.
    """
    from playwright.sync_api import sync_playwright

    executable = chromium_path()
    page_url = Path(html_path).resolve().as_uri()
    errors: list[str] = []
    requests: list[str] = []
    screenshot_path.parent.mkdir(parents=True, exist_ok=True)
    with sync_playwright() as driver, tempfile.TemporaryDirectory(prefix="chromium-profile-") as profile:
        context = driver.chromium.launch_persistent_context(
            profile,
            executable_path=str(executable),
            headless=True,
            args=list(CHROMIUM_FLAGS),
            viewport={"width": width, "height": height},
        )
        try:
            page = context.new_page()
            page.on("console", lambda message: errors.append(message.text) if message.type == "error" else None)
            page.on("pageerror", lambda error: errors.append(str(error)))
            page.on("request", lambda request: requests.append(request.url))
            page.goto(page_url, wait_until="load")
            box = "e => [e.getBoundingClientRect().width, e.getBoundingClientRect().height]"
            sizes = page.eval_on_selector_all("svg.figure", f"els => els.map({box})")
            marks = page.eval_on_selector_all(
                "svg.figure", "els => els.map(e => e.querySelectorAll('path, line, text, use').length)"
            )
            png = page.screenshot(path=str(screenshot_path), full_page=True)
        finally:
            context.close()
    external = tuple(url for url in requests if url != page_url and not url.startswith(("data:", "about:")))
    return BrowserResult(
        tuple(errors),
        len(sizes),
        tuple((float(w), float(h)) for w, h in sizes),
        tuple(int(n) for n in marks),
        _nonblank(png),
        external,
    )
