"""Bode and coherence figures."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from matplotlib.patches import Polygon, Rectangle

from reports.bode import _nearest_branch, bode_figure, write_bode_svg
from reports.svg import figure_svg
from sysid.freqresp import FrequencyResponse

OMEGA = np.geomspace(0.5, 50.0, 60)


def _lag(output: str = "q", *, fit_range: tuple[float, float] | None = None, delay_s: float = 0.0) -> FrequencyResponse:
    h = np.exp(-1j * OMEGA * delay_s) / (1j * OMEGA * 0.2 + 1)
    n = OMEGA.size
    return FrequencyResponse(
        input="delta_lon",
        output=output,
        omega=OMEGA,
        response=h,
        coherence=np.full(n, 0.9),
        random_error=np.full(n, 0.02),
        input_autospectrum=np.ones(n),
        output_autospectrum=np.ones(n),
        cross_spectrum=np.ones(n, complex),
        windows_s=(2.0, 8.0),
        input_unit="%",
        output_unit="rad/s",
        fit_range=fit_range,
    )


def _y(line: Any) -> np.ndarray:
    return np.asarray(line.get_ydata(), dtype=float)


def _visible(figure: Any) -> list[Any]:
    return [ax for ax in figure.axes if ax.get_visible()]


def test_three_panels_per_response_with_data_in_db_and_degrees() -> None:
    response = _lag(delay_s=0.05)
    figure = bode_figure([response])
    magnitude, phase, coherence = figure.axes
    np.testing.assert_allclose(_y(magnitude.lines[0]), response.magnitude_db)
    np.testing.assert_allclose(_y(phase.lines[0]), response.phase_deg)
    np.testing.assert_allclose(_y(coherence.lines[0]), response.coherence)
    assert magnitude.get_xscale() == "log" and coherence.get_xlabel() == "frequency, rad/s"
    assert magnitude.get_title() == "q/delta_lon"


def test_blocks_fill_two_columns_and_unused_panels_are_hidden() -> None:
    figure = bode_figure([_lag("q"), _lag("ax"), _lag("theta")])
    assert len(figure.axes) == 12 and len(_visible(figure)) == 9
    assert [ax.get_title() for ax in _visible(figure) if ax.get_title()] == [
        "q/delta_lon",
        "ax/delta_lon",
        "theta/delta_lon",
    ]
    assert len(bode_figure([_lag("q"), _lag("ax")], n_cols=1).axes) == 6


def test_fit_range_is_shaded_on_every_panel() -> None:
    figure = bode_figure([_lag(fit_range=(1.0, 20.0))])
    for ax in figure.axes:
        spans = [p for p in ax.patches if isinstance(p, (Polygon, Rectangle))]
        assert len(spans) == 1
        xs = spans[0].get_xy()[:, 0] if isinstance(spans[0], Polygon) else [spans[0].get_x()]
        assert min(xs) == pytest.approx(1.0)
    assert all(not ax.patches for ax in bode_figure([_lag()]).axes)


def test_model_overlay_from_an_array_or_a_function_on_the_data_phase_branch() -> None:
    response = _lag()
    exact = 1 / (1j * OMEGA * 0.2 + 1)
    for model in (exact, lambda w: 1 / (1j * w * 0.2 + 1)):
        magnitude, phase, _ = bode_figure([response], models={"q/delta_lon": model}).axes
        assert len(magnitude.lines) == 2 and magnitude.get_legend() is not None
        np.testing.assert_allclose(_y(phase.lines[1]), _y(phase.lines[0]), atol=1e-9)
    shifted = dataclasses.replace(response, response=response.response * np.exp(2j * np.pi))  # same phase
    _, phase, _ = bode_figure([shifted], models={"q/delta_lon": exact}).axes
    assert abs(_y(phase.lines[1])[0] - _y(phase.lines[0])[0]) < 1e-6
    assert len(bode_figure([response], models={"ax/delta_lon": exact}).axes[0].lines) == 1


def test_bad_arguments_are_refused() -> None:
    with pytest.raises(ValueError, match="no response"):
        bode_figure([])
    with pytest.raises(ValueError, match="shape"):
        bode_figure([_lag()], models={"q/delta_lon": np.ones(3)})


def test_standalone_svg_file(tmp_path: Path) -> None:
    target = tmp_path / "fr.svg"
    write_bode_svg(target, [_lag(fit_range=(1.0, 20.0)), _lag("ax")], min_coherence=0.6)
    text = target.read_text()
    assert text.startswith("<?xml") and "<svg" in text and "q/delta_lon" in text and "ax/delta_lon" in text
    assert figure_svg(bode_figure([_lag()])) == figure_svg(bode_figure([_lag()]))  # deterministic


def test_the_model_phase_follows_the_data_branch_through_a_wrap() -> None:
    """Data that wraps +180 at a zero while the model wraps -180: the model is moved a whole turn after it."""
    model = np.concatenate([np.linspace(-100, -170, 20), np.linspace(-190, -260, 20)])
    data = np.concatenate([model[:20] + 2.0, model[20:] + 360.0 - 3.0])
    np.testing.assert_allclose(_nearest_branch(data, model), np.concatenate([model[:20], model[20:] + 360.0]))
    noisy = data.copy()
    noisy[5] += 360.0  # one wrapped noise point does not move the model
    np.testing.assert_allclose(_nearest_branch(noisy, model)[:20], model[:20])


def _tick_texts(ax: Any) -> list[str]:
    """Tick labels inside the frequency range shown."""
    low, high = ax.get_xlim()
    return [t.get_text() for t, x in zip(ax.get_xticklabels(), ax.get_xticks()) if t.get_text() and low <= x <= high]


def test_frequency_ticks_are_plain_numbers_labelled_once_per_column() -> None:
    """Five blocks in two columns: only the last block of each column carries tick labels and the axis title."""
    figure = bode_figure(
        [_lag(name) for name in ("q", "ax", "theta", "u", "w")], models={"q/delta_lon": 1 / (1j * OMEGA * 0.2 + 1)}
    )
    figure.canvas.draw()
    shown = _visible(figure)
    labelled = [ax for ax in shown if _tick_texts(ax)]
    assert len(labelled) == 2
    assert [ax.get_xlabel() for ax in labelled] == ["frequency, rad/s"] * 2
    assert sum(bool(ax.get_xlabel()) for ax in shown) == 2
    for ax in labelled:
        assert set(_tick_texts(ax)) <= {"0.5", "1", "2", "5", "10", "20", "50"} and "10" in _tick_texts(ax)
    assert sum(ax.get_legend() is not None for ax in shown) == 1  # one legend per figure
    left, right = sorted(labelled, key=lambda ax: ax.get_position().x0)
    assert left.get_position().y0 < right.get_position().y0  # left column: 3 blocks, right: 2


def _text_overlaps(figure: Any) -> list[tuple[str, str]]:
    """Pairs of the figure's visible titles, axis labels and tick labels whose boxes overlap, as drawn."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(figure)
    canvas.draw()
    renderer = canvas.get_renderer()
    boxes = []
    for ax in figure.axes:
        if not ax.get_visible():
            continue
        texts = [ax.title, ax.yaxis.label, ax.xaxis.label, *ax.get_yticklabels(), *ax.get_xticklabels(), *ax.texts]
        boxes += [(t.get_text(), t.get_window_extent(renderer)) for t in texts if t.get_text() and t.get_visible()]
    return [(a, b) for k, (a, box) in enumerate(boxes) for b, other in boxes[k + 1 :] if box.overlaps(other)]


@pytest.mark.parametrize("n", [1, 2, 5])
def test_no_label_runs_into_another(n: int) -> None:
    """Issue 33: the y-labels overlapped (a magnitude label with its units ran an inch and a half along a panel an
    inch tall; each panel's lowest tick label met the top one of the panel below). Units, long as they are,
    now sit inside the magnitude panel."""
    long_units = [dataclasses.replace(_lag(o), input_unit="normalised (-1..1)", output_unit="m/s^2") for o in "qwu"]
    responses = [*long_units, _lag("theta"), _lag("ax")][:n]
    assert _text_overlaps(bode_figure(responses)) == []
