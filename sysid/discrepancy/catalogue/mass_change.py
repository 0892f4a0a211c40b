"""Mass change: a step of mass at ``t0``, ``az += T ((Δm/(m + Δm)) H(t - t0) - a)``; reported also as Δm/m."""

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
    pm,
)
from sysid.discrepancy.result import Finding, FittedParameter

__all__ = ["TERM"]

_STEP_EDGE = 0.1  # a mass step lies within the middle 80 % of the flight
_STEP_GRID_S = 0.25  # times tried for it


def _make(context: FlightContext) -> Candidate:
    clock, thrust = context.series["t_flight"], context.thrust
    span = clock[-1] - clock[0]
    times = np.arange(clock[0] + _STEP_EDGE * span, clock[-1] - _STEP_EDGE * span, _STEP_GRID_S)

    @cache
    def build(t0: float) -> Regressors:
        return {"az": np.column_stack([thrust * (clock >= t0), -thrust])}

    return Candidate(
        effect="mass_change",
        outputs=("az",),
        kind="linear",
        grid=tuple(float(t) for t in times),
        grid_parameter="time_s",
        build=build,
        coefficients=("mass_ratio", "gain"),
        regime="t_flight",
    )


def _derive(out: list[FittedParameter], _context: Derivation) -> list[FittedParameter]:
    """The specific force per thrust drops by dm / (m + dm): the mass grew by ratio / (1 - ratio)."""
    if len(out) < 2:
        return out
    ratio = out[1]
    fraction = FittedParameter(
        name="mass_change_fraction",
        value=ratio.value / (1.0 - ratio.value),
        uncertainty=ratio.uncertainty / (1.0 - ratio.value) ** 2,
        unit="1",
    )
    return [*out[:2], fraction, *out[2:]]


def _what(finding: Finding) -> str:
    p = parameter(finding, "mass_change_fraction")
    t = parameter(finding, "time_s")
    when = f" at t = {pm(t.value, t.uncertainty)} s of flight" if t is not None else ""
    size = f" by {pm(p.value, p.uncertainty, 100.0, sign=True)} %" if p is not None else ""
    return f"The mass changes{size}{when}, and the thrust needed to hover with it"


TERM = Term(
    effect="mass_change",
    summary="a step of mass in flight (a payload picked up or dropped)",
    outputs=("az",),
    regime="t_flight",
    make=_make,
    what=_what,
    coefficients=(
        Coefficient(key="mass_ratio", name="mass_ratio", unit="1"),
        THRUST_GAIN,
    ),
    derive=_derive,
    separated_by="hovers before and after the suspected change of mass",
)
