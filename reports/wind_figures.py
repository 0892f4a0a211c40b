"""Figures of the wind step: the residual of eq. 3.14 against the anemometer's clock offset, and the wind's timing."""

from __future__ import annotations

from typing import cast

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from sysid.fit.result import WindClockOffset, WindTrace

from .svg import new_figure

__all__ = ["clock_offset_figure", "wind_trace_figure"]


def clock_offset_figure(clock: WindClockOffset) -> Figure:
    """The wind step's residual against the anemometer clock offset, with the minimum and the offset in use.

    Parameters
    ----------
    clock : WindClockOffset
        The scan (offsets in s; costs as weighted residual per sample).

    Returns
    -------
    Figure
        One panel: cost (relative to its median over the scan) against the clock offset, s; the offset
        found with its ±2 sigma band when measured, the offset the conditioning used dashed.

    Examples
    --------
    >>> import numpy as np
    >>> shift = np.linspace(-5, 5, 101)
    >>> clock = WindClockOffset(shift_s=shift, cost=1 + (shift + 1.5) ** 2, cost_without_wind=30.0,
    ...     best_shift_s=-1.5, sigma_s=0.01, used_clock_offset_s=0.0, transport_delay_s=0.85, measured=True, reason="", samples=1000)
    >>> len(clock_offset_figure(clock).axes)
    1
    """
    figure, created = new_figure(1, 1, width_in=5.5, height_in=2.8)
    ax = cast(Axes, created)
    offset = clock.used_clock_offset_s - clock.shift_s
    order = np.argsort(offset)
    relative = clock.cost / float(np.median(clock.cost))
    ax.plot(offset[order], relative[order], color="C0", lw=1.2, label="residual after G_w")
    ax.axvline(clock.used_clock_offset_s, color="0.4", ls="--", lw=1.0, label="offset in use")
    if clock.measured:
        band = 2 * clock.sigma_s
        ax.axvspan(clock.clock_offset_s - band, clock.clock_offset_s + band, color="C2", alpha=0.25, lw=0)
        ax.axvline(
            clock.clock_offset_s, color="C2", lw=1.2, label=f"found {clock.clock_offset_s:+.2f} ± {clock.sigma_s:.2f} s"
        )
    ax.set_xlabel("anemometer clock offset, s")
    ax.set_ylabel("residual / median")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    figure.tight_layout()
    return figure


def wind_trace_figure(trace: WindTrace) -> Figure:
    """One record's along-nose wind at the anemometer, where the vehicle met it, and as its accelerations felt it.

    Parameters
    ----------
    trace : WindTrace
        The record's winds (m/s, less their mean) against the log's clock (s).

    Returns
    -------
    Figure
        One panel: the anemometer's reading (thin, grey), the same air at the vehicle after the transport
        delay, and the accelerometer's residual of eq. 3.14 read as wind through the G_w gain; the
        correlation of each reading with the accelerations in the legend.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 30.0, 0.1)
    >>> air = np.sin(0.7 * t) + 0.3 * np.sin(2.1 * t)
    >>> trace = WindTrace(record="lon sweep", time_s=t, at_anemometer_m_s=np.roll(air, -9), at_vehicle_m_s=air,
    ...     from_accelerations_m_s=air + 0.05, output="ax", gain=-0.36, transport_delay_s=0.9, smoothing_hz=2.0)
    >>> len(wind_trace_figure(trace).axes)
    1
    """
    figure, created = new_figure(1, 1, width_in=7.0, height_in=2.8)
    ax = cast(Axes, created)
    felt = trace.from_accelerations_m_s

    def agreement(wind: np.ndarray) -> str:
        return f"r = {float(np.corrcoef(wind, felt)[0, 1]):.2f}"

    lines = (
        (trace.at_anemometer_m_s, f"at the anemometer ({agreement(trace.at_anemometer_m_s)})", "0.6", 0.9, "-"),
        (
            trace.at_vehicle_m_s,
            f"at the vehicle, {trace.transport_delay_s:.2f} s later ({agreement(trace.at_vehicle_m_s)})",
            "C0",
            1.2,
            "-",
        ),
        (felt, f"from {trace.output}: residual / G_w {trace.gain:.3g} 1/s", "C3", 1.0, "--"),
    )
    for wind, label, color, width, style in lines:
        ax.plot(trace.time_s, wind, color=color, lw=width, ls=style, label=label)
    ax.set_xlabel(f"log time, s ({trace.record})")
    ax.set_ylabel("along-nose wind less mean, m/s")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    figure.tight_layout()
    return figure
