"""Parasitic drag: airframe drag growing with the square of the air-relative speed.

``ax += -c_x |V| u_a``, ``ay += -c_y |V| v_a`` (1/m: ½ ρ C_D S / m), with ``u_a v_a w_a`` the body
velocities relative to the air (the ground velocities less the wind where one is logged) and ``|V|``
their magnitude. Rotor drag, linear in speed and in thrust, is a term of its own.
"""

from __future__ import annotations

import numpy as np

from sysid.discrepancy.catalogue._air import air_velocity
from sysid.discrepancy.catalogue._term import Candidate, Coefficient, FlightContext, Term, linear, parameter, pm
from sysid.discrepancy.result import Finding

__all__ = ["TERM"]


def _make(context: FlightContext) -> Candidate | None:
    air = air_velocity(context.series)
    if air is None:
        return None
    u, v, w = air
    speed = np.sqrt(u**2 + v**2 + w**2)
    return linear("parasitic_drag", {"ax": [-speed * u], "ay": [-speed * v]}, ("c_x_1_m", "c_y_1_m"), "airspeed")


def _what(finding: Finding) -> str:
    p = parameter(finding, "drag_coefficient_x")
    size = f" (½ρC_D S/m = {pm(p.value, p.uncertainty)} 1/m along the nose)" if p is not None else ""
    return f"The real airframe drags with the square of its airspeed{size}; the simulation lacks it"


TERM = Term(
    effect="parasitic_drag",
    summary="airframe drag growing with the square of the airspeed",
    outputs=("ax", "ay"),
    regime="airspeed",
    make=_make,
    what=_what,
    coefficients=(
        Coefficient(key="c_x_1_m", name="drag_coefficient_x", unit="1/m"),
        Coefficient(key="c_y_1_m", name="drag_coefficient_y", unit="1/m"),
    ),
    separated_by="repositions at two speeds (drag with the square of speed, not with speed)",
)
