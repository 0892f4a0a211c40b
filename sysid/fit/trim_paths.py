"""Responses a linear structure reaches only through a trim smaller than the flight's own swings about it.

Eq. 3.5 keeps the trim velocities' kinematic terms: body w answers the pitch
rate through ``U0 q``, v the roll rate through ``W0 p``. In still air the
trim velocities are near zero and that path is gone, but body w still moves
with the pitch sweep through the products the linearisation leaves out
(``θ u``, ``q u`` with u the velocity the sweep itself drives): a response
of middling coherence (0.5-0.6 on the 200-log fleet) that no parameter of
the structure can reproduce, and fitting it drags the axis' other
parameters (issue 33: J_ave 149-635 with it, 9-16 without, on every fleet
group beyond 100). Such a response is left out, with the reason, when the
structure reaches it only through the trim constants (velocities and angles)
and its size through them is under :data:`TRIM_FRACTION` of its size with
each trim replaced by that signal's own RMS swing in the records. The
products left out scale as swing times swing, the trim path as trim times
swing: below a fraction of one the linear path is smaller than what the
linearisation leaves out, and the response is not the structure's to fit.
One is that boundary, not a tuned value. For body w from the pitch input
the ratio runs 0.01-0.88 on the 200-log fleet (position hold, no
anemometer: U0 is the mean ground speed, within 0.4 m/s), and 2.0-6.3 on the
chapter 3 campaign's lon sweeps with the anemometer (U0 the airspeed,
0.8-5 m/s): left out on the first, fitted on the second.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from sysid.freqresp import DroppedResponse, FrequencyResponse
from sysid.model.assemble import structure_model
from sysid.model.statespace import DelayedStateSpace
from sysid.model.structure import ModelStructure

__all__ = ["TRIM_FRACTION", "trim_only_responses"]

#: A path through the trims smaller than this fraction of the same path at the signals' RMS swings is smaller
#: than the products the linear structure leaves out (they scale with the swings).
TRIM_FRACTION = 1.0

#: Signals whose trim a structure's constants may carry (eq. 3.5: U0, V0, W0, phi0, theta0), and their units.
_TRIMMED = {"u": "m/s", "v": "m/s", "w": "m/s", "phi": "rad", "theta": "rad"}


def trim_only_responses(
    structure: ModelStructure,
    responses: Sequence[FrequencyResponse],
    values: Mapping[str, float],
    constants: Mapping[str, float],
    swings: Mapping[str, Mapping[str, float]],
) -> tuple[DroppedResponse, ...]:
    """The responses the structure reaches only through trim velocities too small to carry them.

    Parameters
    ----------
    structure : ModelStructure
        The structure to be fitted.
    responses : sequence of FrequencyResponse
        Responses that passed gating.
    values : Mapping[str, float]
        Parameter values (the starting values): only whether a path exists, and its size, are read.
    constants : Mapping[str, float]
        Trim constants in use (``U0``, ``W0`` ... from the records' trim), SI.
    swings : Mapping[str, Mapping[str, float]]
        By input, the RMS swing about its mean of each trimmed signal (``u``, ``v``, ``w`` in m/s, ``phi``,
        ``theta`` in rad) over that input's records.

    Returns
    -------
    tuple of DroppedResponse
        One per response left out, its reason naming the trims and the swings.
    """
    trims = {c.name: c.trim for c in structure.constants if c.trim in _TRIMMED}
    if not trims or not responses:
        return ()
    with_trims = _model(structure, values, constants)
    without = _model(structure, values, {**constants, **dict.fromkeys(trims, 0.0)})
    dropped = []
    for response in responses:
        if response.input not in with_trims.inputs or response.output not in with_trims.outputs:
            continue
        omega = _fitted(response)
        through_trims = _size(with_trims, response, omega)
        if _size(without, response, omega) > 1e-9 * through_trims:
            continue  # a path that needs no trim velocity
        swing = swings.get(response.input, {})
        at_swings = {**constants, **{name: swing.get(signal, 0.0) for name, signal in trims.items()}}
        if through_trims >= TRIM_FRACTION * _size(_model(structure, values, at_swings), response, omega):
            continue
        used = ", ".join(f"{name} {constants[name]:+.2g} {_TRIMMED[signal]}" for name, signal in trims.items())
        swung = ", ".join(f"{signal} {swing.get(signal, 0.0):.2g} {_TRIMMED[signal]}" for signal in trims.values())
        dropped.append(
            DroppedResponse(
                input=response.input,
                output=response.output,
                reason=(
                    f"{response.pair}: the structure reaches {response.output} from {response.input} only through "
                    f"the trim ({used}), a smaller path than the RMS swings in the records would make "
                    f"({swung}): what is measured there is the products the linear model leaves out (such as θ·u), "
                    "not fitted"
                ),
            )
        )
    return tuple(dropped)


def _model(structure: ModelStructure, values: Mapping[str, float], constants: Mapping[str, float]) -> DelayedStateSpace:
    return structure_model(structure, values, constants=constants, include_wind=False)[0]


def _fitted(response: FrequencyResponse) -> np.ndarray:
    """The response's frequencies inside its fit range, rad/s, shape (n_freq,)."""
    omega = np.asarray(response.omega, dtype=float)
    if response.fit_range is None:
        return omega
    low, high = response.fit_range
    inside = omega[(omega >= low) & (omega <= high)]
    return inside if inside.size else omega


def _size(model: DelayedStateSpace, response: FrequencyResponse, omega: np.ndarray) -> float:
    """The largest magnitude of the model's `response` pair over `omega`."""
    i, j = model.outputs.index(response.output), model.inputs.index(response.input)
    return float(np.max(np.abs(model.frequency_response(omega)[:, i, j])))
