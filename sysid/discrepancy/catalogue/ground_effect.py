"""Ground effect: thrust grows near the ground, ``az += -T (c / (h + d)² + a)``.

The thrust ratio ``1 + c / (h + d)²`` (d: the rotor plane's height over the logged height, the grid), with a
thrust gain ``a`` beside it (the real thrust per input may differ by a constant factor).
"""

from __future__ import annotations

from functools import cache

import numpy as np

from sysid.discrepancy.catalogue._term import (
    THRUST_GAIN,
    Candidate,
    Coefficient,
    Derivation,
    FlightContext,
    Regressors,
    Term,
    parameter,
)
from sysid.discrepancy.result import Finding, FittedParameter

__all__ = ["TERM"]

_ROTOR_ABOVE_M = tuple(np.round(np.arange(0.0, 0.501, 0.05), 3))  # rotor plane above the logged height, m
_MIN_HEIGHT_M = 0.05
_END = 0.01  # the ground effect "ends" where the thrust gain falls below 1 %


def _make(context: FlightContext) -> Candidate | None:
    series, thrust = context.series, context.thrust
    if "height_agl" not in series:
        return None
    h = np.maximum(series["height_agl"], _MIN_HEIGHT_M)

    @cache
    def build(rotor_above_m: float) -> Regressors:
        return {"az": np.column_stack([-thrust / (h + rotor_above_m) ** 2, -thrust])}

    return Candidate(
        effect="ground_effect",
        outputs=("az",),
        kind="linear",
        grid=_ROTOR_ABOVE_M,
        grid_parameter="rotor_above_height_m",
        build=build,
        coefficients=("c_m2", "gain"),
        regime="height_agl",
    )


def _derive(out: list[FittedParameter], context: Derivation) -> list[FittedParameter]:
    if len(out) < 2:
        return out
    rotors_above, c = out[0], out[1]
    plane = np.sqrt(max(c.value, 0.0) / _END)  # rotor-plane height where the gain falls to 1 %
    spread = 0.5 * plane * c.uncertainty / c.value if c.value > 0 else float("nan")
    ends = plane - rotors_above.value
    out = [*out, FittedParameter(name="ends_at_height", value=float(ends), uncertainty=float(spread), unit="m")]
    if context.rotor_radius_m is not None:
        radius = context.rotor_radius_m
        out.append(
            FittedParameter(
                name="ends_at_height_over_radius",
                value=float(plane / radius),
                uncertainty=float(spread / radius),
                unit="1",
            )
        )
    return out


def _what(finding: Finding) -> str:
    p = parameter(finding, "ends_at_height")
    ratio = parameter(finding, "ends_at_height_over_radius")
    where = f" (rotor plane at Z/R = {ratio.value:.1f})" if ratio is not None else ""
    up_to = f", up to about {p.value:.2f} m{where}" if p is not None else ""
    return f"The real vehicle gains thrust near the ground{up_to}; the simulation has no ground effect"


TERM = Term(
    effect="ground_effect",
    summary="thrust that grows near the ground (inverse square of the rotor plane's height)",
    outputs=("az",),
    regime="height_agl",
    make=_make,
    what=_what,
    coefficients=(
        Coefficient(key="c_m2", name="coefficient", unit="m^2"),
        THRUST_GAIN,
    ),
    derive=_derive,
    separated_by="a hover stepped down to within a rotor diameter of the ground",
)
