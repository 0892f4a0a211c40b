"""CG offset: a roll and pitch moment that follows the thrust, ``p_dot, q_dot += k T``."""

from __future__ import annotations

from sysid.discrepancy.catalogue._term import Candidate, Coefficient, FlightContext, Term, linear
from sysid.discrepancy.result import Finding

__all__ = ["TERM"]


def _make(context: FlightContext) -> Candidate:
    thrust = context.thrust
    return linear("cg_offset", {"p_dot": [thrust], "q_dot": [thrust]}, ("l_rad_m", "m_rad_m"), "delta_thr")


def _what(_finding: Finding) -> str:
    return "A constant moment follows the thrust: the centre of gravity is off the thrust axis"


TERM = Term(
    effect="cg_offset",
    summary="a moment that follows the thrust (centre of gravity off the thrust axis)",
    outputs=("p_dot", "q_dot"),
    regime="delta_thr",
    make=_make,
    what=_what,
    coefficients=(
        Coefficient(key="l_rad_m", name="roll_moment_per_thrust", unit="rad/m"),
        Coefficient(key="m_rad_m", name="pitch_moment_per_thrust", unit="rad/m"),
    ),
    separated_by="hovers at two thrust levels (a payload on and off)",
)
