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
import pandas as pd

from flightlogs.record import Record
from sysid.model.statespace import DelayedStateSpace
from sysid.verify import Verification, verify
from sysid.verify._discrete import discretize, simulate

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


def sample_verification(*, seed: int = 0) -> Verification:
    """A small verification to render: a pitch-like model with and without a wind term on two noisy doublets.

    A weakly coupled roll rate ``p`` (driven by the pitch rate and its own input) is an off-axis output of the
    ``delta_lon`` doublets, shown for information.
    """
    a = np.array([[-1.5, -6.0, 1.2, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -20.0, 0.0], [0.3, 0.0, 0.0, -3.0]])
    b = np.array([[0.0, 0.0, 0.3], [0.0, 0.0, 0.0], [20.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    c = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [-0.4, 0.0, 0.3, 0.0], [0.0, 0.0, 0.0, 1.0]])
    d = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.5], [0.0, 0.0, 0.0]])
    with_wind = DelayedStateSpace(
        a,
        b,
        c,
        d,
        ("q", "theta", "d_lon", "p"),
        ("delta_lon", "delta_lat", "wind_lon"),
        ("q", "theta", "ax", "p"),
        np.array([0.02, 0.02, 0.015]),
    )
    without = DelayedStateSpace(
        a,
        b[:, :2],
        c,
        d[:, :2],
        with_wind.states,
        with_wind.inputs[:2],
        with_wind.outputs,
        with_wind.input_delays_s[:2],
    )
    rng = np.random.default_rng(seed)
    t = np.arange(400) * 0.01
    records = []
    for k in range(2):
        doublet = np.where((t >= 0.5) & (t < 1.5), 0.4, 0.0) - np.where((t >= 1.5) & (t < 2.5), 0.4, 0.0)
        wind = np.cumsum(rng.normal(scale=0.02, size=t.size))
        inputs = np.column_stack([doublet, 0.05 * np.sin(2.0 * t), wind - wind.mean()])
        y = simulate(discretize(with_wind, 0.01), inputs, np.zeros(4))
        y += rng.normal(scale=[0.005, 0.001, 0.03, 0.005], size=y.shape)
        table = pd.DataFrame(
            {
                "delta_lon": inputs[:, 0],
                "delta_lat": inputs[:, 1],
                "wind_lon": inputs[:, 2],
                "q": y[:, 0],
                "theta": y[:, 1],
                "ax": y[:, 2],
                "p": y[:, 3],
            },
            index=pd.Index(20.0 * k + 5.0 + t, name="time_s"),
        )
        units = {
            "delta_lon": "%",
            "delta_lat": "%",
            "wind_lon": "m/s",
            "q": "rad/s",
            "theta": "rad",
            "ax": "m/s^2",
            "p": "rad/s",
        }
        records.append(Record(table, units, {}, Path("doublets.ulg"), f"doublets.ulg lon doublet {k + 1}"))
    return verify(
        without,
        records,
        wind_model=with_wind,
        excited=["delta_lon", "delta_lon"],
        axes={"delta_lon": ("q", "theta", "ax")},
    )
