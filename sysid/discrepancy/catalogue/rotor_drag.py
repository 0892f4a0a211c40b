"""Rotor drag: a force in the rotor plane of specific thrust × ground speed, and its moment about the CG.

``ax += -d_x T u``, ``ay += -d_y T v``: each rotor's drag in its disc's plane. It acts at the hubs,
above the centre of gravity, and the discs flap back from the flow: both pitch the nose up in forward
flight and roll away from a sideslip, ``q_dot += m_u T u``, ``p_dot += l_v T v`` (rad/m per unit
specific thrust). A real rotor that drags more than simulated does both more.
The velocities are ground-relative: drag on the wind is the wind term's.
"""

from __future__ import annotations

from sysid.discrepancy.catalogue._term import Candidate, Coefficient, FlightContext, Term, linear, parameter, pm
from sysid.discrepancy.result import Finding

__all__ = ["TERM"]


def _make(context: FlightContext) -> Candidate | None:
    series, thrust = context.series, context.thrust
    if "u" not in series or "v" not in series:
        return None
    along, across = thrust * series["u"], thrust * series["v"]
    columns = {"ax": [-along], "ay": [-across], "p_dot": [across], "q_dot": [along]}
    return linear("rotor_drag", columns, ("d_x_s_m", "d_y_s_m", "l_v_rad_m", "m_u_rad_m"), "ground_speed")


def _what(finding: Finding) -> str:
    p = parameter(finding, "drag_x")
    size = f" of specific thrust × ground speed × {pm(p.value, p.uncertainty)} s/m along the nose" if p else ""
    return f"The real rotors drag more: a force in the rotor plane{size}, and its moment, that the simulation lacks"


TERM = Term(
    effect="rotor_drag",
    summary="rotor (induced) drag proportional to thrust and speed, and its hub moment",
    outputs=("ax", "ay", "p_dot", "q_dot"),
    regime="ground_speed",
    make=_make,
    what=_what,
    coefficients=(
        Coefficient(key="d_x_s_m", name="drag_x", unit="s/m"),
        Coefficient(key="d_y_s_m", name="drag_y", unit="s/m"),
        Coefficient(key="l_v_rad_m", name="roll_moment_per_speed", unit="rad/m"),
        Coefficient(key="m_u_rad_m", name="pitch_moment_per_speed", unit="rad/m"),
    ),
    separated_by="repositions at two speeds and two thrust levels",
    shown_on=("ax", "ay"),
)
