"""The report foundation: escaping, inline SVG, atomic writes."""

from __future__ import annotations

from pathlib import Path

import pytest

from reports.html import render_html, write_html
from reports.svg import figure_svg, new_figure


def test_log_text_is_escaped_and_only_figures_are_markup() -> None:
    fig, ax = new_figure()
    ax.plot([0, 1], [1, 0])
    svg = figure_svg(fig)
    from reports import html as module

    page = module._ENVIRONMENT.from_string(
        '{% import "_macros.html" as m %}{{ name }}{{ m.figure(svg, caption) }}'
    ).render(name="<script>alert(1)</script>", svg=svg, caption="<b>x</b>")
    assert "<script>" not in page
    assert "&lt;script&gt;" in page and "&lt;b&gt;x&lt;/b&gt;" in page
    assert page.count("<svg") == 1


def test_figures_are_deterministic_and_sized_by_css() -> None:
    def draw() -> str:
        fig, ax = new_figure()
        ax.plot([0, 1, 2], [0, 1, 4])
        return figure_svg(fig)

    first, second = draw(), draw()
    assert first == second
    head = first[: first.index(">")]
    assert 'width="' not in head and "viewBox" in head


def test_write_html_is_atomic(tmp_path: Path) -> None:
    target = tmp_path / "r.html"
    write_html(target, "<p>good</p>")
    with pytest.raises(KeyError):
        write_html(target, render_html("base.html", **{}) + str({}["missing"]))  # type: ignore[index]
    assert target.read_text() == "<p>good</p>"
    assert list(tmp_path.iterdir()) == [target]


def test_base_template_is_self_contained() -> None:
    page = render_html("base.html")
    assert "http://" not in page and "https://" not in page
    assert "flight-sysid" in page
