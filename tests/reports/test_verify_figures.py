"""Figures of a verification (drawn from a small simulated one) and the verification section of the model report."""

from __future__ import annotations

import re
from dataclasses import replace

import numpy as np
import pytest
from matplotlib.transforms import Bbox

from reports.model_report import model_report_html
from reports.verify_figures import display_scale, record_figure, verification_figures, wind_correction_figure
from sysid.verify import Verification, WindCorrection

import builders


@pytest.fixture(scope="module")
def verification() -> Verification:
    result: Verification = builders.sample_verification()
    return result


def test_display_scale_shows_radians_as_degrees() -> None:
    assert display_scale("rad") == (pytest.approx(180 / np.pi), "deg")
    assert display_scale("rad/s")[1] == "deg/s"
    assert display_scale("m/s^2") == (1.0, "m/s^2")


def test_record_figure_stacks_the_judged_outputs_and_shows_the_others_small(verification: Verification) -> None:
    record, without = verification.records[0], verification.without_wind[0]
    assert record.off_axis == ("p",) and [o.name for o in record.judged] == ["q", "theta", "ax"]
    svg = record_figure(record, without_wind=without)
    assert svg.startswith("<svg") and 'class="figure"' in svg
    for output in record.judged:
        assert f"{output.name} [{display_scale(output.unit)[1]}]" in svg
        assert f"TIC {output.tic:.2f} with" in svg
    assert "off-axis outputs, for information only" in svg and "delta_lon" in svg
    assert f"TIC {record.output('p').tic:.2f}" in svg and "p [deg/s]" in svg
    alone = record_figure(replace(record, off_axis=()))
    assert "off-axis" not in alone and "without" not in alone and "model" in alone


def test_unstable_records_say_so_in_the_title(verification: Verification) -> None:
    record = replace(verification.records[0], unstable=True, growth=21.4, notice="grows", unstable_modes=("pitch",))
    assert "pitch mode unstable: grows 21-fold" in record_figure(record)


def test_a_dollar_in_a_record_label_is_drawn_as_it_is(verification: Verification) -> None:
    """A label from a log is text, not mathtext: ``$x^2$`` is drawn with its dollars."""
    record = replace(verification.records[0], label="flight $x^2$.ulg lon doublet")
    svg = record_figure(record)
    assert "flight $x^2$.ulg lon doublet" in svg


def test_wind_correction_figure_annotates_the_change() -> None:
    svg = wind_correction_figure(
        [
            WindCorrection(name="ax", unit="m/s^2", rmse_without=0.4129, rmse_with=0.3480),
            WindCorrection(name="p", unit="rad/s", rmse_without=0.1, rmse_with=0.1),
            WindCorrection(name="az", unit="m/s^2", rmse_without=0.187, rmse_with=0.295),
        ]
    )
    assert "−16 %" in svg and "+58 %" in svg  # Table 3.6, strong wind: 0.4129 -> 0.3480; a worse az
    assert "−-" not in svg and "−+" not in svg
    assert ">p<" not in svg  # an output the wind term does not change is left out


def _wind_axes(corrections: list[WindCorrection]):  # type: ignore[no-untyped-def]
    """The bar chart's axes, drawn, and the renderer to measure it with."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from reports.verify_figures import _wind_figure

    canvas = FigureCanvasAgg(_wind_figure(corrections))
    canvas.draw()
    return canvas.figure.axes[0], canvas.get_renderer()


def test_the_legend_never_covers_a_bar_even_beyond_the_old_axis_limit() -> None:
    """An output made 58 % worse (ratio 1.58 > 1.2) still fits, and the legend sits outside every bar."""
    ax, renderer = _wind_axes(
        [
            WindCorrection(name="ax", unit="m/s^2", rmse_without=0.0675, rmse_with=0.0585),
            WindCorrection(name="az", unit="m/s^2", rmse_without=0.187, rmse_with=0.295),
            WindCorrection(name="w", unit="m/s", rmse_without=0.135, rmse_with=0.141),
        ]
    )
    assert ax.get_ylim()[1] > 0.295 / 0.187
    legend: Bbox = ax.get_legend().get_window_extent(renderer)
    for bar in ax.patches:
        assert not legend.overlaps(bar.get_window_extent(renderer))
    for text in ax.texts:  # the change labels stay inside the axes
        assert ax.get_window_extent(renderer).contains(*text.get_window_extent(renderer).get_points()[1])


def test_figures_are_the_wind_bars_then_one_per_record(verification: Verification) -> None:
    figures = verification_figures(verification)
    assert len(figures) == len(verification.records) + 1
    assert "on-axis" in figures[0][1]
    assert "judged on q, theta, ax" in figures[1][1]
    plain = replace(verification, without_wind=(), wind_correction=())
    assert len(verification_figures(plain)) == len(verification.records)


def test_the_report_tables_judge_on_axis_outputs_and_list_the_others(verification: Verification) -> None:
    page = model_report_html(
        builders.small_model(responses=False), verification=verification, generated_utc=builders.STAMP
    )
    section = page[page.index('id="verification"') : page.index('id="reduction"')]
    judged, informative = section.split("Off-axis outputs", 1)
    for summary in verification.summary:
        assert re.search(rf"<tr><td>{summary.name}</td>.*?<td class=\"mono left\">delta_lon</td></tr>", judged)
    assert "<tr><td>p</td>" not in judged and "<tr><td>p</td>" in informative
    assert "With and without the wind term" in section and "−13 to −16 %" in section
    assert section.count("<svg ") == len(verification.records) + 1
