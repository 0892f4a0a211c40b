"""Wind: drag and hub moments on the measured wind, ``∝ T wind`` on ax, ay, p_dot, q_dot, and the yaw of that drag.

A rotor that thrusts more than the others (to roll or pitch the vehicle) drags more, off the CG: a yaw
acceleration of the wind times the roll or pitch acceleration the commands make (``r_dot += n w p_dot_cmd``).

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
    lon = averaged(series, series["wind_lon"], _WIND_AVERAGE_S)
    lat = averaged(series, series["wind_lat"], _WIND_AVERAGE_S)
    along, across = thrust * lon, thrust * lat
    # the drag of a rotor thrusting more than the others acts at its hub, off the CG: a yaw moment of the wind
    # times the roll and pitch moments the commands make (the vehicle's own, holding against the wind's)
    parts = context.command_parts
    yaw = [lon * parts["delta_lat"]["p_dot"], lat * parts["delta_lon"]["q_dot"]]
    columns = {"ax": [along], "ay": [across], "p_dot": [across], "q_dot": [along], "r_dot": yaw}
    keys = ("d_x_s_m", "d_y_s_m", "l_wind_rad_m", "m_wind_rad_m", "n_roll_s_m", "n_pitch_s_m")
    return linear("wind", columns, keys, "wind_speed")


def _what(finding: Finding) -> str:
    p = parameter(finding, "drag_x")
    size = f" (a drag of specific thrust × wind × {pm(p.value, p.uncertainty)} s/m along the nose)" if p else ""
    return f"Forces and moments follow the wind the real vehicle flew in{size}; the simulation flew in a calm"


TERM = Term(
    effect="wind",
    summary="drag and hub moments of the measured wind",
    outputs=("ax", "ay", "p_dot", "q_dot", "r_dot"),
    regime="wind_speed",
    make=_make,
    what=_what,
    coefficients=(
        Coefficient(key="d_x_s_m", name="drag_x", unit="s/m"),
        Coefficient(key="d_y_s_m", name="drag_y", unit="s/m"),
        Coefficient(key="l_wind_rad_m", name="roll_moment_per_wind", unit="rad/m"),
        Coefficient(key="m_wind_rad_m", name="pitch_moment_per_wind", unit="rad/m"),
        Coefficient(key="n_roll_s_m", name="yaw_per_wind_and_roll_moment", unit="s/m"),
        Coefficient(key="n_pitch_s_m", name="yaw_per_wind_and_pitch_moment", unit="s/m"),
    ),
    separated_by="the same manoeuvres in a calm and in wind",
)
