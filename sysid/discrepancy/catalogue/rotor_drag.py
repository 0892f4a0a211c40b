"""Rotor drag: a force in the rotor plane of specific thrust × ground speed, ``ax += -d_x T u``, ``ay += -d_y T v``.

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
    columns = {"ax": [-thrust * series["u"]], "ay": [-thrust * series["v"]]}
    return linear("rotor_drag", columns, ("d_x_s_m", "d_y_s_m"), "ground_speed")


def _what(finding: Finding) -> str:
    p = parameter(finding, "drag_x")
    size = f" of specific thrust × ground speed × {pm(p.value, p.uncertainty)} s/m along the nose" if p else ""
    return f"The real rotors drag more: a force in the rotor plane{size} that the simulation lacks"


TERM = Term(
    effect="rotor_drag",
    summary="rotor (induced) drag proportional to thrust and speed",
    outputs=("ax", "ay"),
    regime="ground_speed",
    make=_make,
    what=_what,
    coefficients=(
        Coefficient(key="d_x_s_m", name="drag_x", unit="s/m"),
        Coefficient(key="d_y_s_m", name="drag_y", unit="s/m"),
    ),
    separated_by="repositions at two speeds and two thrust levels",
)
