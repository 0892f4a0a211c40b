"""Time delay: every mixer input reaches the real vehicle ``tau`` later (a transform of the model's prediction)."""

from __future__ import annotations

import numpy as np

from sysid.discrepancy.catalogue._term import (
    FASTER_SWEEPS,
    Candidate,
    FlightContext,
    Term,
    delayed,
    input_transform,
    parameter,
    pm,
)
from sysid.discrepancy.result import Finding
from sysid.discrepancy.series import OUTPUTS

__all__ = ["TERM"]

_DELAYS_S = tuple(float(d) for d in np.round(np.arange(0.0025, 0.1501, 0.0025), 4))


def _make(context: FlightContext) -> Candidate:
    return input_transform(context, "time_delay", _DELAYS_S, "delay_s", delayed)


def _what(finding: Finding) -> str:
    p = parameter(finding, "delay_s")
    late = f" {pm(p.value, p.uncertainty, 1e3)} ms" if p is not None else ""
    return f"The real vehicle responds{late} later than the simulation"


TERM = Term(
    effect="time_delay",
    summary="a longer transport delay from command to response",
    outputs=OUTPUTS,
    regime=None,
    make=_make,
    what=_what,
    rivals=("actuator_lag", "control_effectiveness"),
    separated_by=FASTER_SWEEPS,
)
