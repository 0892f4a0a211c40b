"""Actuator lag: every mixer input through an extra ``1 / (T_a s + 1)`` (a transform of the model's prediction)."""

from __future__ import annotations

import numpy as np

from sysid.discrepancy.catalogue._term import (
    FASTER_SWEEPS,
    Candidate,
    FlightContext,
    Term,
    first_order,
    input_transform,
    parameter,
    pm,
)
from sysid.discrepancy.result import Finding
from sysid.discrepancy.series import OUTPUTS

__all__ = ["TERM"]

_LAGS_S = tuple(float(d) for d in np.round(np.arange(0.0025, 0.1501, 0.0025), 4))


def _make(context: FlightContext) -> Candidate:
    return input_transform(context, "actuator_lag", _LAGS_S, "time_constant_s", first_order)


def _what(finding: Finding) -> str:
    p = parameter(finding, "time_constant_s")
    tau = f" of τ = {pm(p.value, p.uncertainty, 1e3)} ms" if p is not None else ""
    return (
        f"The real actuators lag: an extra first-order lag{tau} that the simulation lacks "
        "(the magnitude rolls off, not only the phase)"
    )


TERM = Term(
    effect="actuator_lag",
    summary="slower actuators (an extra first-order lag)",
    outputs=OUTPUTS,
    regime=None,
    make=_make,
    what=_what,
    rivals=("time_delay", "control_effectiveness"),
    separated_by=FASTER_SWEEPS,
)
