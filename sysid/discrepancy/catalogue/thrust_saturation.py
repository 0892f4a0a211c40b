"""Thrust saturation: thrust commands above a ceiling produce no more thrust.

``az += s (P_thr(min(δ, c)) - P_thr(δ))``: the part of az the simulation's model makes from the thrust
command (:meth:`~sysid.discrepancy.baseline.BaselineModel.command_part`) with the command clipped at the
ceiling ``c`` (the grid, over the upper range the flight commanded), less the unclipped part; ``s`` is
the share of the excess lost (1: a hard ceiling). Motors at their ceiling give no more of the moment
either: ``p_dot += s_p P_lat H(δ - c)``, ``q_dot += s_q P_lon H(δ - c)`` (the fraction of the roll and
pitch moment per command lost while the thrust command is above the ceiling, about -0.5 when half the
motors saturate).
"""

from __future__ import annotations

from functools import cache

import numpy as np

from sysid.discrepancy.catalogue._term import (
    Candidate,
    Coefficient,
    FlightContext,
    Regressors,
    Term,
    parameter,
    pm,
)
from sysid.discrepancy.result import Finding

__all__ = ["TERM"]

_PERCENTILES = (70.0, 80.0, 87.0, 92.0, 95.0, 97.0, 98.5, 99.5)  # ceilings tried: these percentiles of δ_thr


def _make(context: FlightContext) -> Candidate:
    series, baseline = context.series, context.baseline
    command = series["delta_thr"]
    whole = context.command_parts["delta_thr"]["az"]
    ceilings = tuple(sorted({float(np.percentile(command, p)) for p in _PERCENTILES}))

    parts = context.command_parts

    @cache
    def build(ceiling: float) -> Regressors:
        clipped = baseline.command_part(series, "delta_thr", np.minimum(command, ceiling))["az"]
        above = command > ceiling
        return {
            "az": (clipped - whole)[:, None],
            "p_dot": (parts["delta_lat"]["p_dot"] * above)[:, None],
            "q_dot": (parts["delta_lon"]["q_dot"] * above)[:, None],
        }

    return Candidate(
        effect="thrust_saturation",
        outputs=("az", "p_dot", "q_dot"),
        kind="linear",
        grid=ceilings,
        grid_parameter="ceiling_command_1",
        build=build,
        coefficients=("share", "roll_share", "pitch_share"),
        regime="delta_thr",
    )


def _what(finding: Finding) -> str:
    c = parameter(finding, "ceiling_command_1")
    at = f" above a command of {pm(c.value, c.uncertainty)} (as logged)" if c is not None else ""
    return f"The real vehicle's thrust stops growing{at}: its motors saturate where the simulation's do not"


TERM = Term(
    effect="thrust_saturation",
    summary="thrust that stops growing above a command ceiling (motors saturated)",
    outputs=("az", "p_dot", "q_dot"),
    regime="delta_thr",
    make=_make,
    what=_what,
    coefficients=(
        Coefficient(key="share", name="saturated_share", unit="1", sign=1),
        Coefficient(key="roll_share", name="roll_moment_change_above_ceiling", unit="1", sign=-1),
        Coefficient(key="pitch_share", name="pitch_moment_change_above_ceiling", unit="1", sign=-1),
    ),
    separated_by="thrust steps approaching full throttle",
    shown_on=("az",),  # motors at a ceiling stop adding thrust first: lost moments alone are no ceiling
)
