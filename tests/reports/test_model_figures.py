"""Figures of the model report: model overlays on the responses, correlation heat map, pole map."""

from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.text import Text

from reports.model_figures import correlation_figure, pair_response, plain_text, pole_map_figure, response_figures
from reports.svg import figure_svg
from sysid.fit import IdentifiedModel
from sysid.model.modes import Mode, modes
from sysid.model.statespace import DelayedStateSpace

import builders


def _first_order(delay_s: float = 0.0) -> DelayedStateSpace:
    return DelayedStateSpace(
        a=np.array([[-2.0]]),
        b=np.array([[2.0]]),
        c=np.array([[1.0]]),
        d=np.zeros((1, 1)),
        states=("p",),
        inputs=("delta_lat",),
        outputs=("p",),
        input_delays_s=np.array([delay_s]),
    )


def test_pair_response_is_the_analytic_lag_with_its_delay() -> None:
    omega = np.geomspace(0.1, 100.0, 30)
    expected = 2.0 / (1j * omega + 2.0) * np.exp(-1j * omega * 0.02)  # 2/(s+2) e^(-0.02 s)
    np.testing.assert_allclose(pair_response(_first_order(0.02), "p", "delta_lat", omega), expected, rtol=1e-12)
    with pytest.raises(KeyError):
        pair_response(_first_order(), "q", "delta_lat", omega)


def test_a_signal_entering_twice_is_summed() -> None:
    """A wind signal with two delays (u and w) acts as one input: its response is the sum of both paths."""
    model = DelayedStateSpace(
        a=-np.eye(2),
        b=np.eye(2),
        c=np.ones((1, 2)),
        d=np.zeros((1, 2)),
        states=("u", "w"),
        inputs=("wind_lon", "wind_lon"),
        outputs=("ax",),
        input_delays_s=np.array([0.0, 0.1]),
    )
    omega = np.array([1.0, 3.0])
    expected = 1.0 / (1j * omega + 1.0) * (1.0 + np.exp(-0.1j * omega))
    np.testing.assert_allclose(pair_response(model, "ax", "wind_lon", omega), expected, rtol=1e-12)


def _model_line(figure, kind: str):  # type: ignore[no-untyped-def]
    for ax in figure.axes:
        if ax.get_visible() and ax.get_ylabel().startswith(kind):
            dashed = [line for line in ax.get_lines() if line.get_linestyle() == "--"]
            if dashed:
                return ax, ax.get_lines()[0], dashed[0]
    raise AssertionError(f"no model line on a {kind} panel")


def test_the_overlay_is_the_model_and_the_phase_sits_on_the_data_branch(small_model: IdentifiedModel) -> None:
    figures = response_figures(small_model, min_coherence=0.5)
    assert [caption.split()[2] for _, caption in figures] == ["delta_lon", "delta_lat", "delta_thr"]
    figure = figures[0][0]
    response = small_model.responses[0]
    exact = pair_response(small_model.linear_model(), response.output, response.input, response.omega)
    _, _, magnitude = _model_line(figure, "magnitude")
    np.testing.assert_allclose(magnitude.get_ydata(), 20 * np.log10(np.abs(exact)), rtol=1e-12)
    _, data, phase = _model_line(figure, "phase")
    gap = np.asarray(phase.get_ydata()) - np.asarray(data.get_ydata())
    assert np.max(np.abs(gap)) < 180.0  # 3 deg noise: never a whole turn apart
    offset = (np.asarray(phase.get_ydata()) - np.degrees(np.unwrap(np.angle(exact)))) / 360.0
    np.testing.assert_allclose(offset, np.round(offset), atol=1e-9)  # moved by whole turns only


def test_each_column_is_labelled_once_with_plain_frequency_ticks(small_model: IdentifiedModel) -> None:
    figure = response_figures(small_model)[0][0]
    figure.canvas.draw()
    labelled = [ax for ax in figure.axes if ax.get_visible() and any(t.get_text() for t in ax.get_xticklabels())]
    assert len(labelled) == 2 and all(ax.get_xlabel() == "frequency, rad/s" for ax in labelled)


def test_correlation_cells_beyond_the_threshold_are_written_in() -> None:
    names = ["X_u", "M_u", "X_lon"]
    matrix = np.array([[1.0, -0.95, 0.3], [-0.95, 1.0, 0.91], [0.3, 0.91, 1.0]])
    figure = correlation_figure(names, matrix, threshold=0.9)
    ax = figure.axes[0]
    written = sorted(t.get_text() for t in ax.texts if isinstance(t, Text))
    assert written == ["-.95", "-.95", ".91", ".91"]
    assert [t.get_text() for t in ax.get_xticklabels()] == names
    with pytest.raises(ValueError):
        correlation_figure(names, np.eye(2))


def test_a_dollar_in_a_name_is_drawn_as_it_is() -> None:
    figure = correlation_figure(["$X$", "M_u"], np.eye(2))
    assert plain_text("$X$") == r"\$X\$"
    assert "$X$" in figure_svg(figure)


def _mode(real: float, imag: float, label: str) -> Mode:
    omega_n = math.hypot(real, imag)
    stability = "unstable" if real > 0 else "stable"
    return Mode(
        real=real,
        imag=imag,
        damping=-real / omega_n,
        natural_frequency_rad_s=omega_n,
        time_to_double_s=math.inf,
        time_to_half_s=math.inf,
        mode=label,
        stability=stability,  # type: ignore[arg-type]
    )


def test_pole_map_draws_conjugates_and_zooms_past_fast_actuators() -> None:
    found = [_mode(-22.9, 0.0, "actuator"), _mode(0.9, 1.7, "pitch"), _mode(-2.1, 0.0, "pitch")]
    figure = pole_map_figure(found)
    assert len(figure.axes) == 2  # all poles, and near the origin
    points = [
        (float(x), float(y))
        for line in figure.axes[0].get_lines()
        if line.get_marker() not in ("None", "")
        for x, y in zip(np.asarray(line.get_xdata()), np.asarray(line.get_ydata()))
    ]
    assert sorted(points) == sorted([(-22.9, 0.0), (0.9, 1.7), (0.9, -1.7), (-2.1, 0.0)])
    low, high = figure.axes[1].get_xlim()
    assert low < -2.1 and 0.9 < high < 5.0
    assert len(pole_map_figure(found[1:]).axes) == 1  # nothing fast: one panel
    with pytest.raises(ValueError):
        pole_map_figure([])


def test_pole_map_of_an_identified_model_has_every_mode(small_model: IdentifiedModel) -> None:
    found = modes(small_model.linear_model())
    figure = pole_map_figure(found)
    drawn = sum(
        np.asarray(line.get_xdata()).size
        for line in figure.axes[0].get_lines()
        if line.get_marker() not in ("None", "")
    )
    assert drawn == sum(2 if m.imag > 0 else 1 for m in found)


@pytest.fixture(scope="module")
def small_model() -> IdentifiedModel:
    """Two longitudinal, one lateral and one heave response of a hover model, with 3 deg phase noise."""
    model: IdentifiedModel = builders.small_model()
    assert [r.pair for r in model.responses] == list(builders.PAIRS)
    return model
