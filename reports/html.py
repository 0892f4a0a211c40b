"""Render the Jinja2 templates of ``reports/templates`` into one self-contained HTML file."""

from __future__ import annotations

import datetime as _dt
import importlib.metadata
import math
import platform
from pathlib import Path
from typing import Any

import jinja2
from markupsafe import Markup

from flightlogs.writers.atomic import atomic_output

__all__ = ["render_html", "write_html", "software_versions"]

_ENVIRONMENT = jinja2.Environment(
    loader=jinja2.PackageLoader("reports", "templates"),
    autoescape=True,  # everything from a log (vehicle names, parameters, messages) is escaped
    undefined=jinja2.StrictUndefined,
    trim_blocks=True,
    lstrip_blocks=True,
)


def _number(value: Any, digits: int = 4) -> str:
    """A number for a table: `digits` significant figures, '—' for missing or NaN."""
    if value is None:
        return "—"
    number = float(value)
    if math.isnan(number):
        return "—"
    if math.isinf(number):
        return "∞" if number > 0 else "−∞"
    return f"{number:.{digits}g}"


_ENVIRONMENT.filters["num"] = _number
_ENVIRONMENT.filters["svg"] = Markup  # our own figure_svg output only: never log text


def render_html(template: str, **context: Any) -> str:
    """Render a report template to HTML text.

    Parameters
    ----------
    template : str
        Template file name in ``reports/templates`` (for example ``"freqresp.html"``).
    **context
        Template variables. Strings are escaped; figures must be passed through
        the ``svg`` filter, which marks only our own SVG markup as safe.

    Returns
    -------
    str
        One HTML document with inline CSS and SVG: no network fetches.
    """
    context.setdefault("generated_utc", _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"))
    context.setdefault("versions", software_versions())
    return _ENVIRONMENT.get_template(template).render(**context)


def write_html(path: str | Path, text: str) -> Path:
    """Write an HTML report atomically (never a half-written or clobbered file).

    Parameters
    ----------
    path : str or Path
        Destination; its folder must exist.
    text : str
        The document from `render_html`.

    Returns
    -------
    Path
        The path written.
    """
    path = Path(path)
    with atomic_output(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def software_versions() -> dict[str, str]:
    """Versions of Python and the packages a result depends on, for provenance.

    Returns
    -------
    dict of str to str
        Package name to version (``"not installed"`` when absent).
    """
    versions = {"python": platform.python_version()}
    for name in ("flight-sysid", "numpy", "scipy", "control", "pyulog", "pymavlink", "h5py", "matplotlib", "jinja2"):
        try:
            versions[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            versions[name] = "not installed"
    return versions
