"""Wind: drag and hub moments on the measured wind, ``∝ T wind`` on ax, ay, p_dot, q_dot.

The anemometer's wind is averaged over 1 s before it is a regressor: the rotors feel the air over their
discs, and a gust measured at a point metres upstream reaches them smeared; the faster part of its record is
measurement noise for the drag, and noise in a regressor shrinks its coefficient (at 2.7 m/s, the wind's own
moment then came out 30 % short, and the constant rest was named a CG offset on another generator's flights).
"""

from __future__ import annotations

from sysid.discrepancy.catalogue._term import (
    Candidate,
    Coefficient,
    FlightContext,
    Term,
    averaged,
    linear,
    parameter,
    pm,
)
from sysid.discrepancy.result import Finding

__all__ = ["TERM"]

_WIND_AVERAGE_S = 1.0


def _make(context: FlightContext) -> Candidate | None:
    series, thrust = context.series, context.thrust
    if not series.windy:
        return None  # no wind logged, or a calm: its drag is below anything the search can tell from noise
    along = thrust * averaged(series, series["wind_lon"], _WIND_AVERAGE_S)
    across = thrust * averaged(series, series["wind_lat"], _WIND_AVERAGE_S)
    columns = {"ax": [along], "ay": [across], "p_dot": [across], "q_dot": [along]}
    return linear("wind", columns, ("d_x_s_m", "d_y_s_m", "l_wind_rad_m", "m_wind_rad_m"), "wind_speed")


def _what(finding: Finding) -> str:
    p = parameter(finding, "drag_x")
    size = f" (a drag of specific thrust × wind × {pm(p.value, p.uncertainty)} s/m along the nose)" if p else ""
    return f"Forces and moments follow the wind the real vehicle flew in{size}; the simulation flew in a calm"


TERM = Term(
    effect="wind",
    summary="drag and hub moments of the measured wind",
    outputs=("ax", "ay", "p_dot", "q_dot"),
    regime="wind_speed",
    make=_make,
    what=_what,
    coefficients=(
        Coefficient(key="d_x_s_m", name="drag_x", unit="s/m"),
        Coefficient(key="d_y_s_m", name="drag_y", unit="s/m"),
        Coefficient(key="l_wind_rad_m", name="roll_moment_per_wind", unit="rad/m"),
        Coefficient(key="m_wind_rad_m", name="pitch_moment_per_wind", unit="rad/m"),
    ),
    separated_by="the same manoeuvres in a calm and in wind",
)
