"""The catalogue of physics a simulation may leave out: one module per effect, one line each below.

Each module holds one :class:`Term` (its shape on a flight, parameters with units, the outputs it
acts on, the regime variable that locates it and its sentence). To add an effect, write its module
and add its ``TERM`` to :data:`CATALOGUE`; the search, the report and the JSON know it from there.
"""

from __future__ import annotations

from collections.abc import Sequence

from sysid.discrepancy.catalogue import (
    actuator_lag,
    battery_sag,
    cg_offset,
    control_effectiveness,
    ground_effect,
    inflow,
    mass_change,
    parasitic_drag,
    rotor_drag,
    sensor_scale,
    thrust_saturation,
    time_delay,
    translational_lift,
    wind,
)
from sysid.discrepancy.catalogue._term import Calibration, Candidate, Coefficient, Derivation, FlightContext, Term

__all__ = [
    "CATALOGUE",
    "EFFECTS",
    "Calibration",
    "Candidate",
    "Coefficient",
    "Derivation",
    "FlightContext",
    "Term",
    "candidate_terms",
    "term_of",
]

#: Every term, in the order they are tried.
CATALOGUE: tuple[Term, ...] = (
    ground_effect.TERM,
    rotor_drag.TERM,
    wind.TERM,
    time_delay.TERM,
    actuator_lag.TERM,
    battery_sag.TERM,
    mass_change.TERM,
    cg_offset.TERM,
    control_effectiveness.TERM,
    parasitic_drag.TERM,
    inflow.TERM,
    translational_lift.TERM,
    thrust_saturation.TERM,
    sensor_scale.TERM,
)

#: The effects the catalogue can name.
EFFECTS: tuple[str, ...] = tuple(t.effect for t in CATALOGUE)
_BY_NAME = {t.effect: t for t in CATALOGUE}


def term_of(effect: str) -> Term:
    """The catalogue's term named `effect`.

    Parameters
    ----------
    effect : str
        A name from :data:`EFFECTS`.

    Raises
    ------
    KeyError
        If the catalogue has no such term (the message lists those it has).
    """
    try:
        return _BY_NAME[effect]
    except KeyError:
        raise KeyError(f"no term {effect!r} in the catalogue; it has {', '.join(EFFECTS)}") from None


def candidate_terms(context: FlightContext, *, exclude: Sequence[str] = ()) -> list[Candidate]:
    """The candidates of every term that applies to the flight (whose signals it logs), but the `exclude`d.

    Parameters
    ----------
    context : FlightContext
        The flight, the simulation's model and the specific thrust of the current prediction.
    exclude : sequence of str
        Effects not to try (found already, or a found effect's rivals).
    """
    found = []
    for term in CATALOGUE:
        if term.effect in exclude:
            continue
        made = term.make(context)
        if made is not None:
            found.append(made)
    return found
