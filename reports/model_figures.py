"""Figures of an identified model: responses against the model, correlation heat map, pole map."""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from sysid.fit import IdentifiedModel
from sysid.freqresp import FrequencyResponse
from sysid.model.modes import Mode
from sysid.model.statespace import DelayedStateSpace

from .bode import bode_figure
from .svg import new_figure

__all__ = ["pair_response", "response_figures", "correlation_figure", "pole_map_figure", "plain_text"]

#: What each mixer input commands, for captions.
INPUT_AXES = {
    "delta_lat": "roll (lateral)",
    "delta_lon": "pitch (longitudinal)",
    "delta_yaw": "yaw",
    "delta_thr": "thrust (heave)",
}
#: Colour and marker of each mode: markers differ too, so coinciding poles stay apart in grey print.
_MODE_STYLES = {
    "roll": ("#0969da", "x"),
    "pitch": ("#c0392b", "+"),
    "yaw": ("#2e8b57", "o"),
    "heave": ("#8250df", "s"),
    "actuator": ("#6e7781", "D"),
}
_OTHER_STYLES = (("#b35900", "^"), ("#1b7c83", "v"), ("#953800", "<"), ("#5a32a3", ">"))


def plain_text(text: str) -> str:
    """Text for a matplotlib label, drawn as given: ``$`` does not start mathtext.

    Parameters
    ----------
    text : str
        A name or label, possibly from a log or a user's structure file.

    Returns
    -------
    str

    Examples
    --------
    >>> plain_text("cost $5$")
    'cost \\\\$5\\\\$'
    """
    return text.replace("$", r"\$")


def pair_response(model: DelayedStateSpace, output: str, signal: str, omega: np.ndarray) -> np.ndarray:
    """The model's response of `output` to input signal `signal`, delays included.

    A signal that enters through several model inputs (a wind signal with two
    delays) is their sum, as a measured response of that signal would be.

    Parameters
    ----------
    model : DelayedStateSpace
        The identified model.
    output : str
        Output name (``q``).
    signal : str
        Input signal name (``delta_lon``).
    omega : ndarray, shape (n_freq,)
        Frequencies, rad/s.

    Returns
    -------
    ndarray of complex, shape (n_freq,)

    Raises
    ------
    KeyError
        If the model has no such output or input.

    Examples
    --------
    >>> m = DelayedStateSpace(a=np.array([[-2.0]]), b=np.array([[2.0]]), c=np.array([[1.0]]), d=np.zeros((1, 1)),
    ...                       states=("p",), inputs=("delta_lat",), outputs=("p",), input_delays_s=np.array([0.0]))
    >>> np.round(np.abs(pair_response(m, "p", "delta_lat", np.array([2.0]))), 3)
    array([0.707])
    """
    columns = [k for k, name in enumerate(model.inputs) if name == signal]
    if output not in model.outputs or not columns:
        raise KeyError(f"the model has no output {output!r} or no input {signal!r}")
    full = model.frequency_response(np.asarray(omega, dtype=float))
    return np.asarray(full[:, model.outputs.index(output), columns].sum(axis=1))


def response_figures(model: IdentifiedModel, *, min_coherence: float | None = None) -> list[tuple[Figure, str]]:
    """Bode and coherence of every fitted response, one figure per input, with the model overlaid.

    Parameters
    ----------
    model : IdentifiedModel
        The model and the responses it was fitted to.
    min_coherence : float, optional
        Gating threshold gamma^2 to draw on the coherence panels.

    Returns
    -------
    list of (Figure, str)
        Each figure with its caption, inputs in the order the responses come.
    """
    if not model.responses:
        return []
    linear = model.linear_model(include_wind=True)
    by_input: dict[str, list[FrequencyResponse]] = {}
    for response in model.responses:
        by_input.setdefault(response.input, []).append(response)
    found = []
    for signal, responses in by_input.items():
        overlays = {}
        for r in responses:
            if r.output in linear.outputs and signal in linear.inputs:
                overlays[r.pair] = pair_response(linear, r.output, signal, r.omega)
        figure = bode_figure(responses, models=overlays, min_coherence=min_coherence)
        axis = INPUT_AXES.get(signal, signal)
        conditioned = sorted({name for r in responses for name in r.conditioned_on})
        caption = (
            f"Responses to {signal} ({axis} mixer input): flight data (solid) and identified model "
            f"(dashed); the fit range is shaded"
        )
        if min_coherence is not None:
            caption += f", dotted line γ² = {min_coherence:g}"
        if conditioned:
            caption += f"; conditioned on {', '.join(conditioned)} (partial coherence)"
        missing = [r.pair for r in responses if r.pair not in overlays]
        if missing:
            caption += f"; no model overlay for {', '.join(missing)}"
        found.append((figure, caption + "."))
    return found


def correlation_figure(names: Sequence[str], correlation: np.ndarray, *, threshold: float = 0.9) -> Figure:
    """Heat map of the parameter correlation matrix, cells beyond `threshold` annotated.

    Parameters
    ----------
    names : sequence of str
        Parameter names, in matrix order (the estimated ones).
    correlation : ndarray, shape (n_params, n_params)
        Correlation coefficients, -1..1; NaN where none was estimated (drawn grey).
    threshold : float, optional
        Off-diagonal cells with ``|r| > threshold`` get their value written in.

    Returns
    -------
    Figure

    Raises
    ------
    ValueError
        If the matrix is not square with one row per name.
    """
    matrix = np.asarray(correlation, dtype=float)
    n = len(names)
    if matrix.shape != (n, n) or n == 0:
        raise ValueError(f"correlation has shape {matrix.shape}, expected ({n}, {n}) with n >= 1")
    side = float(np.clip(1.6 + 0.22 * n, 2.6, 5.4))
    figure, created = new_figure(width_in=side + 1.2, height_in=side)
    ax = cast(Axes, created)
    colours = colormaps["RdBu_r"].with_extremes(bad="#d0d7de")  # not estimated together: grey
    image = ax.imshow(np.ma.masked_invalid(matrix), cmap=colours, vmin=-1.0, vmax=1.0, interpolation="nearest")
    ax.grid(False)
    labels = [plain_text(name) for name in names]
    ax.set_xticks(range(n), labels, rotation=90, fontsize=8)
    ax.set_yticks(range(n), labels, fontsize=8)
    ax.tick_params(length=0)
    for spine in ax.spines.values():
        spine.set_visible(False)
    for i in range(n):
        for j in range(n):
            value = matrix[i, j]
            if i != j and np.isfinite(value) and abs(value) > threshold:
                ax.text(
                    j,
                    i,
                    f"{value:.2f}".replace("0.", "."),
                    ha="center",
                    va="center",
                    fontsize=6.5,
                    color="white" if abs(value) > 0.6 else "black",
                )
    bar = figure.colorbar(image, ax=ax, fraction=0.046, pad=0.03)
    bar.set_label("correlation coefficient r")
    return figure


def _style(label: str, others: dict[str, tuple[str, str]]) -> tuple[str, str]:
    if label in _MODE_STYLES:
        return _MODE_STYLES[label]
    return others.setdefault(label, _OTHER_STYLES[len(others) % len(_OTHER_STYLES)])


def _draw_poles(ax: Axes, found: Sequence[Mode], others: dict[str, tuple[str, str]], *, legend: bool) -> None:
    seen: set[str] = set()
    for mode in found:
        colour, marker = _style(mode.mode, others)
        imag = [mode.imag, -mode.imag] if mode.imag > 0 else [0.0]
        ax.plot(
            [mode.real] * len(imag),
            imag,
            ls="none",
            marker=marker,
            ms=8 if marker in "x+" else 7,
            mew=1.6,
            color=colour,
            mfc="none",
            label=plain_text(mode.mode) if mode.mode not in seen else None,
        )
        seen.add(mode.mode)
    ax.axvline(0.0, color="0.25", lw=0.8)
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_xlabel("real part σ, 1/s")
    ax.set_ylabel("imaginary part ω, rad/s")
    if legend:
        ax.legend(loc="upper left", fontsize=7.5, frameon=True, framealpha=0.85, edgecolor="none")


def _limits(found: Sequence[Mode]) -> tuple[float, float, float]:
    """x from, x to, and |y| limit that show every pole with a margin."""
    real = [m.real for m in found] + [0.0]
    imag = [m.imag for m in found] + [0.0]
    span = max(max(real) - min(real), 2.0 * max(imag), 1e-3)
    margin = 0.12 * span
    return min(real) - margin, max(real) + margin, max(max(imag) + margin, 0.25 * span)


def _shade_unstable(ax: Axes, x_high: float, y_limit: float) -> None:
    if x_high > 0:
        ax.axvspan(0.0, x_high, color="#cf222e", alpha=0.07, lw=0)
        ax.text(x_high, y_limit, "unstable ", ha="right", va="top", fontsize=7.5, color="#cf222e")


def pole_map_figure(found: Sequence[Mode]) -> Figure:
    """The model's eigenvalues in the s-plane, by mode; a second panel zooms in when fast poles crowd the rest.

    Parameters
    ----------
    found : sequence of Mode
        Modes from :func:`sysid.model.modes.modes` (a complex pair is drawn with its conjugate).

    Returns
    -------
    Figure

    Raises
    ------
    ValueError
        If there is no mode.

    Examples
    --------
    >>> from sysid.model.modes import Mode
    >>> mode = Mode(real=-1.0, imag=2.0, damping=0.45, natural_frequency_rad_s=2.24,
    ...             time_to_double_s=float("inf"), time_to_half_s=0.69, mode="pitch", stability="stable")
    >>> fig = pole_map_figure([mode])
    >>> len(fig.axes)
    1
    """
    if not found:
        raise ValueError("no mode to draw")
    slow = [m for m in found if m.mode != "actuator"]
    fastest = max(abs(m.eigenvalue) for m in found)
    zoom = bool(slow) and len(slow) < len(found) and 1.3 * max(abs(m.eigenvalue) for m in slow) < 0.35 * fastest
    figure, created = new_figure(1, 2 if zoom else 1, width_in=7.5 if zoom else 5.0, height_in=3.0)
    axes = list(np.atleast_1d(np.asarray(created, dtype=object)))
    others: dict[str, tuple[str, str]] = {}
    groups = [found, slow] if zoom else [found]
    for k, (ax, shown) in enumerate(zip(axes, groups)):
        ax = cast(Axes, ax)
        _draw_poles(ax, found, others, legend=k == 0)
        x_low, x_high, y_limit = _limits(shown)
        _shade_unstable(ax, x_high, y_limit)
        ax.set_xlim(x_low, x_high)
        ax.set_ylim(-y_limit, y_limit)
        ax.set_title("all poles" if zoom and k == 0 else "near the origin" if zoom else "poles", fontsize=9, loc="left")
    figure.tight_layout(w_pad=1.5)
    return figure
