"""Inflow: thrust that changes with the climb (axial) rate, ``az += -T (k V_c + k2 V_c² + a)``.

The thrust ratio ``1 + k V_c + k2 V_c²``, ``V_c`` the climb rate along the rotor axis (m/s, up: ``-w``,
the body's vertical speed relative to the air; ``-vd`` in level flight; a speed along the nose while
pitched also flows through the discs). Momentum theory gives ``k < 0``: a climbing rotor sees more inflow and makes less thrust
per command; the square term holds the difference between climb and descent (the induced velocity
does not fall as fast as the climb rate grows).
"""

from __future__ import annotations

from sysid.discrepancy.catalogue._air import air_velocity
from sysid.discrepancy.catalogue._term import (
    THRUST_GAIN,
    Candidate,
    Coefficient,
    FlightContext,
    Term,
    linear,
    parameter,
    pm,
)
from sysid.discrepancy.result import Finding

__all__ = ["TERM"]


def _make(context: FlightContext) -> Candidate | None:
    air = air_velocity(context.series)
    if air is None:
        return None
    climb = -air[2]  # the air's speed along the rotor axis, up: what the discs' inflow feels (-vd in level flight)
    thrust = context.thrust
    columns = {"az": [-thrust * climb, -thrust * climb**2, -thrust]}
    return linear("inflow", columns, ("k_climb_s_m", "k_climb2_s2_m2", "gain"), "climb_rate")


def _what(finding: Finding) -> str:
    p = parameter(finding, "thrust_change_per_climb_rate")
    size = f" by {pm(p.value, p.uncertainty, 100.0, sign=True)} % per m/s of climb" if p is not None else ""
    return f"The real thrust changes with the climb rate{size} (rotor inflow); the simulation's does not"


TERM = Term(
    effect="inflow",
    summary="thrust that changes with the climb rate (rotor inflow)",
    outputs=("az",),
    regime="climb_rate",
    make=_make,
    what=_what,
    coefficients=(
        Coefficient(key="k_climb_s_m", name="thrust_change_per_climb_rate", unit="s/m"),
        Coefficient(key="k_climb2_s2_m2", name="thrust_change_per_climb_rate_squared", unit="s^2/m^2"),
        THRUST_GAIN,
    ),
    separated_by="climbs and descents at several rates",
)
