"""A found effect in physical parameters and in plain language."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from sysid.discrepancy.catalogue import EFFECTS, Derivation, Term, term_of
from sysid.discrepancy.result import Finding, FittedParameter
from sysid.discrepancy.selection import TermFit

__all__ = ["FAR_FROM_FLOOR", "parameters_of", "describe_finding", "summary_of"]

#: Residual over the noise floor, with the findings modelled, above which the summary warns that the
#: simulation is no close model of the real vehicle (synthetic pairs of one vehicle end at 1-3, against a log
#: of the simulation or a model fitted from one; a model fitted badly, at 4-7).
FAR_FROM_FLOOR = 4.0


def parameters_of(fit: TermFit, term: Term, derivation: Derivation = Derivation()) -> tuple[FittedParameter, ...]:
    """The fitted parameters of a term, with standard deviations, in SI units, and those derived from them.

    The derivation's `thrust_scale` is the real over the simulated thrust per input apart from this
    term's own gain change (the trim taken out before any term, and the other terms' gains: the gains of
    the terms on az share one regressor, so only their sum is measured).

    Parameters
    ----------
    fit : TermFit
        The term fitted on all of REAL.
    term : Term
        Its catalogue entry (names, units, derived parameters).
    derivation : Derivation, optional
        The thrust level and the rotor radius the derived parameters may use.

    Returns
    -------
    tuple of FittedParameter
    """
    candidate = fit.candidate
    out: list[FittedParameter] = []
    if candidate.grid_parameter:
        unit = candidate.grid_parameter.rsplit("_", 1)[1]  # names end in their unit: delay_s, time_s
        out.append(
            FittedParameter(
                name=candidate.grid_parameter, value=fit.value, uncertainty=fit.value_uncertainty, unit=unit
            )
        )
    for key, value, spread in fit.coefficient_values():
        coefficient = term.coefficient(key)
        out.append(FittedParameter(name=coefficient.name, value=value, uncertainty=spread, unit=coefficient.unit))
    return tuple(term.derive(out, derivation))


def describe_finding(finding: Finding, term: Term) -> str:
    """One sentence: what the real vehicle does, with the numbers, and the held-out gain.

    Parameters
    ----------
    finding : Finding
        The finding (its evidence not yet set).
    term : Term
        Its catalogue entry.
    """
    outputs = ", ".join(finding.outputs)
    gain = (
        f"modelling it cuts the {outputs} residual by {finding.improvement_percent:.0f} % on held-out data"
        if finding.modelled
        else "it is located, not modelled: no held-out improvement is claimed"
    )
    return f"{term.what(finding)}; {gain}." + _ambiguity(finding, term)


def _ambiguity(finding: Finding, term: Term) -> str:
    """The sentence that says an ambiguous finding is, and which flight would tell its explanations apart."""
    if not finding.alternatives:
        return ""
    if finding.effect == "unexplained":
        closest = ", ".join(f"{a.effect} {100 * a.explained_variance:.0f} %" for a in finding.alternatives)
        return f" The closest catalogue terms explain less of it on held-out data ({closest})."
    others = ", ".join(f"{a.effect} ({100 * a.explained_variance:.0f} %)" for a in finding.alternatives)
    flights = [term.separated_by] + [
        term_of(a.effect).separated_by for a in finding.alternatives if a.effect in EFFECTS
    ]
    what = "; ".join(dict.fromkeys(f for f in flights if f))
    separate = f" A flight with {what} would tell them apart." if what else ""
    return (
        f" Ambiguous: {others} explains the same held-out residual about as well as {finding.effect} "
        f"({100 * finding.explained_variance:.0f} %).{separate}"
    )


def summary_of(
    findings: Sequence[Finding],
    noise_floor: Mapping[str, float],
    unexplained: Mapping[str, float] | None = None,
    *,
    misfit: str | None = None,
) -> str:
    """Plain-language summary, the most important finding first (or that nothing is missing).

    Parameters
    ----------
    findings : sequence of Finding
        By importance.
    noise_floor : Mapping[str, float]
        Held-out residual RMS of each output on simulated flight, in its unit.
    unexplained : Mapping[str, float], optional
        Per output, the real residual left with the findings modelled, over the noise floor; where it stays
        above :data:`FAR_FROM_FLOOR` the summary says the simulation is no close model of the real vehicle.
    misfit : str, optional
        Why the simulation (a fitted model) is no close model of its own flights: the summary then says the
        search could not judge, not that nothing is missing.
    """
    left = dict(unexplained or {})
    far = sorted((o for o, r in left.items() if r > FAR_FROM_FLOOR), key=lambda o: -left[o])
    caveat = ""
    if far:
        ratios = ", ".join(f"{o} {left[o]:.0f}×" for o in far)
        caveat = (
            f" Caution: the real flight's residual stays far above the simulation's noise floor ({ratios}) even with "
            f"{'these findings' if findings else 'every candidate tried'}: the simulation is not a close model of this "
            "vehicle (another airframe, controller or mission, or far noisier sensors), or what differs is outside the "
            "library; read the findings as leads, not as the answer."
        )
    if misfit:
        judged = "Not judged" if not findings else "Read the findings as leads only"
        caveat += (
            f" {judged}: {misfit}, so it is not close enough to its own flights to tell what it leaves out "
            "from its own misfit."
        )
        if not findings:
            return caveat.strip()
    if not findings:
        floor = ", ".join(f"{o} {v:.3g}" for o, v in noise_floor.items())
        what = "No candidate term" if far else "Nothing is missing: no candidate term"
        return (
            f"{what} explains more of the real flight's residual than it explains of "
            f"held-out simulated flight (residual RMS floor: {floor})." + caveat
        )
    return " ".join(f.evidence for f in findings) + caveat
