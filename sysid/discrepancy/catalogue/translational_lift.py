"""Translational lift: thrust that grows with horizontal airspeed, ``az += -T (k V_h² + a)``: ratio ``1 + k V_h²``.

``V_h`` is the horizontal speed relative to the air (m/s; the ground speed less the wind where one is
logged). At the low speeds of a multirotor's manoeuvres the gain grows with its square.
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
    u, v, _ = air
    thrust = context.thrust
    columns = {"az": [-thrust * (u**2 + v**2), -thrust]}
    return linear("translational_lift", columns, ("k_speed_s2_m2", "gain"), "airspeed")


def _what(finding: Finding) -> str:
    p = parameter(finding, "thrust_change_per_speed_squared")
    size = f" ({pm(p.value, p.uncertainty, 100.0, sign=True)} % per (m/s)²)" if p is not None else ""
    return f"The real thrust grows with horizontal airspeed{size} (translational lift); the simulation's does not"


TERM = Term(
    effect="translational_lift",
    summary="thrust that grows with horizontal airspeed (translational lift)",
    outputs=("az",),
    regime="airspeed",
    make=_make,
    what=_what,
    coefficients=(
        Coefficient(key="k_speed_s2_m2", name="thrust_change_per_speed_squared", unit="s^2/m^2"),
        THRUST_GAIN,
    ),
    separated_by="level passes at several airspeeds",
)
