"""Battery sag: thrust follows the pack's voltage, ``az += -T (n (V - V̄) / V̄ + a)``: thrust ``∝ V^n``.

The moments sag with the thrust, but as a regressor their sag (the voltage times each axis' command
moment) took up the error of an actuator lag's shape on another generator's flights; what the moments at
the pack's mean voltage differ by is a control effectiveness (without the voltage the simulation assumed,
the two are one), a term of its own.
"""

from __future__ import annotations

import numpy as np

from sysid.discrepancy.catalogue._term import (
    THRUST_GAIN,
    Candidate,
    Coefficient,
    Derivation,
    FlightContext,
    Term,
    linear,
    parameter,
    pm,
)
from sysid.discrepancy.result import Finding, FittedParameter

__all__ = ["TERM"]


def _make(context: FlightContext) -> Candidate | None:
    series, thrust = context.series, context.thrust
    if "battery_v" not in series or np.ptp(series["battery_v"]) <= 0:
        return None
    volts = series["battery_v"]
    relative = (volts - volts.mean()) / volts.mean()
    columns = {"az": [-thrust * relative, -thrust]}
    return linear(
        "battery_sag",
        columns,
        ("exponent", "gain"),
        "battery_v",
    )


def _derive(out: list[FittedParameter], context: Derivation) -> list[FittedParameter]:
    """The exponent is the log-derivative of thrust against voltage: its coefficient over the whole thrust level."""
    if len(out) < 2:
        return out
    exponent, gain, *rest = out
    level = context.thrust_scale + gain.value
    scaled = FittedParameter(
        name="exponent", value=exponent.value / level, uncertainty=exponent.uncertainty / level, unit="1"
    )
    return [scaled, gain, *rest]


def _what(finding: Finding) -> str:
    p = parameter(finding, "exponent")
    n = f" (thrust ∝ V^n, n = {pm(p.value, p.uncertainty)})" if p is not None else ""
    return f"Thrust follows the battery voltage{n}; the simulation keeps it constant"


TERM = Term(
    effect="battery_sag",
    summary="thrust that follows the battery voltage",
    outputs=("az",),
    regime="battery_v",
    make=_make,
    what=_what,
    coefficients=(
        Coefficient(key="exponent", name="exponent", unit="1"),
        THRUST_GAIN,
    ),
    derive=_derive,
    separated_by="a long hover from a full to a nearly empty pack",
)
