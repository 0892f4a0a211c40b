"""Control effectiveness: the moment per axis, or the thrust, per unit command differs from the simulation's.

Worn motors or propellers, another inertia: the part of each output the simulation's model makes from
its own axis' command (:meth:`~sysid.discrepancy.baseline.BaselineModel.command_part`, its lags and
square) is scaled, ``p_dot += k_roll P_lat``, ``q_dot += k_pitch P_lon``, ``r_dot += k_yaw P_yaw``,
``az += k_thrust (P_thr - mean)``. Each ``k`` is the fractional change (−0.25: a quarter less moment or
thrust per command). The thrust's mean is the trim the search fits before any term; what is left to
this term is the thrust's change per change of command.
"""

from __future__ import annotations

import numpy as np

from sysid.discrepancy.catalogue._term import (
    Candidate,
    Coefficient,
    FlightContext,
    Term,
    linear,
    pm,
)
from sysid.discrepancy.result import Finding

__all__ = ["TERM"]

_AXES = (  # (output, command, key, reported name)
    ("p_dot", "delta_lat", "k_roll", "roll_effectiveness_change"),
    ("q_dot", "delta_lon", "k_pitch", "pitch_effectiveness_change"),
    ("r_dot", "delta_yaw", "k_yaw", "yaw_effectiveness_change"),
    ("az", "delta_thr", "k_thrust", "thrust_effectiveness_change"),
)
_MIN_SHARE = 0.01  # an axis whose command part is under this share of its output's spread is not tried


def _make(context: FlightContext) -> Candidate | None:
    series, parts = context.series, context.command_parts
    columns, keys = {}, []
    for output, command, key, _ in _AXES:
        part = parts[command][output] - float(np.mean(parts[command][output]))
        if np.std(part) <= _MIN_SHARE * max(float(np.std(series[output])), 1e-12):
            continue  # the simulation's model makes nothing of this command here: no change of it to measure
        columns[output] = [part]
        keys.append(key)
    if not columns:
        return None
    return linear("control_effectiveness", columns, tuple(keys), None)


def _what(finding: Finding) -> str:
    changes = [
        f"{name.split('_')[0]} {pm(p.value, p.uncertainty, 100.0, sign=True)} %"
        for _, _, _, name in _AXES
        for p in finding.parameters
        if p.name == name and abs(p.value) > 2.0 * p.uncertainty
    ]
    which = ", ".join(changes) if changes else "within its uncertainty on every axis"
    return (
        f"The real vehicle makes another moment or thrust per unit command than the simulation ({which}): "
        "worn motors or propellers, or another inertia"
    )


TERM = Term(
    effect="control_effectiveness",
    summary="moment or thrust per unit command changed (worn motors or props, another inertia)",
    outputs=("p_dot", "q_dot", "r_dot", "az"),
    regime=None,
    make=_make,
    what=_what,
    coefficients=tuple(Coefficient(key=key, name=name, unit="1") for _, _, key, name in _AXES),
    separated_by="sweeps of each axis at two amplitudes, away from the ground",
    rivals=("time_delay", "actuator_lag"),
)
