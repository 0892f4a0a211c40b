"""A found effect in physical parameters and in plain language."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from sysid.discrepancy.result import Finding, FittedParameter
from sysid.discrepancy.selection import TermFit
from sysid.discrepancy.terms import Candidate

__all__ = ["FAR_FROM_FLOOR", "parameters_of", "describe_finding", "summary_of"]

#: Residual over the noise floor, with the findings modelled, above which the summary warns that the
#: simulation is no close model of the real vehicle (synthetic pairs of one vehicle end at 1-3, against a log
#: of the simulation or a model fitted from one; a model fitted badly, at 4-7).
FAR_FROM_FLOOR = 4.0
_GROUND_EFFECT_END = 0.01  # the ground effect "ends" where the thrust gain falls below 1 %

#: Unit of each coefficient name.
_UNITS: Mapping[str, str] = {
    "c_m2": "m^2",
    "d_x_s_m": "s/m",
    "d_y_s_m": "s/m",
    "l_wind_rad_m": "rad/m",
    "m_wind_rad_m": "rad/m",
    "gain": "1",
    "exponent": "1",
    "mass_ratio": "1",
    "l_rad_m": "rad/m",
    "m_rad_m": "rad/m",
}
_NAMES: Mapping[str, str] = {
    "c_m2": "coefficient",
    "gain": "thrust_gain_change",
    "d_x_s_m": "drag_x",
    "d_y_s_m": "drag_y",
    "l_wind_rad_m": "roll_moment_per_wind",
    "m_wind_rad_m": "pitch_moment_per_wind",
    "l_rad_m": "roll_moment_per_thrust",
    "m_rad_m": "pitch_moment_per_thrust",
}


def parameters_of(
    fit: TermFit, thrust_scale: float = 1.0, rotor_radius_m: float | None = None
) -> tuple[FittedParameter, ...]:
    """The fitted parameters of a term, with standard deviations, in SI units.

    `thrust_scale` is the real over the simulated thrust per input apart from this term's own gain
    change (the trim taken out before any term, and the other terms' gains: the gains of the terms on
    az share one regressor, so only their sum is measured): the battery's exponent is the
    log-derivative of thrust against voltage, its coefficient over the whole thrust level.

    Parameters
    ----------
    fit : TermFit
        The term fitted on all of REAL.
    thrust_scale : float, optional
        Real over simulated thrust per input (the trim fitted before any term and the other terms' gains).
    rotor_radius_m : float, optional
        Propeller radius, m: the ground effect's end is also given as the rotor plane's Z/R (chapter 2).

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
    names = iter(candidate.coefficients)
    for o in candidate.outputs:
        if o not in fit.coefficients:
            continue
        sigma = np.sqrt(np.maximum(np.diag(fit.covariance[o]), 0.0))
        for value, spread in zip(fit.coefficients[o], sigma):
            coefficient = next(names)
            out.append(
                FittedParameter(
                    name=_NAMES.get(coefficient, coefficient),
                    value=float(value),
                    uncertainty=float(spread),
                    unit=_UNITS.get(coefficient, "1"),
                )
            )
    if candidate.effect == "battery_sag" and len(out) == 2:
        exponent, gain = out
        level = thrust_scale + gain.value
        out[0] = FittedParameter(
            name="exponent", value=exponent.value / level, uncertainty=exponent.uncertainty / level, unit="1"
        )
    if candidate.effect == "mass_change" and len(out) > 1:
        ratio = out[1]  # the specific force per thrust drops by dm / (m + dm): the mass grew by ratio / (1 - ratio)
        out.insert(
            2,
            FittedParameter(
                name="mass_change_fraction",
                value=ratio.value / (1.0 - ratio.value),
                uncertainty=ratio.uncertainty / (1.0 - ratio.value) ** 2,
                unit="1",
            ),
        )
    if candidate.effect == "ground_effect" and len(out) > 1:
        rotors_above, c = out[0], out[1]
        plane = np.sqrt(max(c.value, 0.0) / _GROUND_EFFECT_END)  # rotor-plane height where the gain falls to 1 %
        spread = 0.5 * plane * c.uncertainty / c.value if c.value > 0 else float("nan")
        ends = plane - rotors_above.value
        out.append(FittedParameter(name="ends_at_height", value=float(ends), uncertainty=float(spread), unit="m"))
        if rotor_radius_m is not None:
            out.append(
                FittedParameter(
                    name="ends_at_height_over_radius",
                    value=float(plane / rotor_radius_m),
                    uncertainty=float(spread / rotor_radius_m),
                    unit="1",
                )
            )
    return tuple(out)


def _pm(value: float, sigma: float, scale: float = 1.0, sign: bool = False) -> str:
    """``value ± sigma`` (times `scale`), the value to the sigma's second significant digit."""
    v, s = value * scale, abs(sigma * scale)
    digits = max(0, min(6, 1 - int(np.floor(np.log10(s)))) if s > 0 and np.isfinite(s) else 1)
    return f"{v:{'+' if sign else ''}.{digits}f} ± {s:.{digits}f}"


def _value(finding: Finding, name: str) -> FittedParameter | None:
    return next((p for p in finding.parameters if p.name == name), None)


def describe_finding(finding: Finding, candidate: Candidate) -> str:
    """One sentence: what the real vehicle does, with the numbers, and the held-out gain.

    Parameters
    ----------
    finding : Finding
        The finding (its evidence not yet set).
    candidate : Candidate
        Its term.
    """
    outputs = ", ".join(finding.outputs)
    gain = f"modelling it cuts the {outputs} residual by {finding.improvement_percent:.0f} % on held-out data"
    effect = candidate.effect
    if effect == "time_delay" and (p := _value(finding, "delay_s")) is not None:
        what = f"The real vehicle responds {_pm(p.value, p.uncertainty, 1e3)} ms later than the simulation"
    elif effect == "actuator_lag" and (p := _value(finding, "time_constant_s")) is not None:
        what = (
            f"The real actuators lag: an extra first-order lag of τ = {_pm(p.value, p.uncertainty, 1e3)} ms "
            "that the simulation lacks (the magnitude rolls off, not only the phase)"
        )
    elif effect == "ground_effect" and (p := _value(finding, "ends_at_height")) is not None:
        ratio = _value(finding, "ends_at_height_over_radius")
        where = f" (rotor plane at Z/R = {ratio.value:.1f})" if ratio is not None else ""
        what = (
            f"The real vehicle gains thrust near the ground, up to about {p.value:.2f} m{where}; "
            "the simulation has no ground effect"
        )
    elif effect == "mass_change" and (p := _value(finding, "mass_change_fraction")) is not None:
        t = _value(finding, "time_s")
        when = f" at t = {_pm(t.value, t.uncertainty)} s of flight" if t is not None else ""
        what = (
            f"The mass changes by {_pm(p.value, p.uncertainty, 100.0, sign=True)} %{when}, "
            "and the thrust needed to hover with it"
        )
    elif effect == "battery_sag" and (p := _value(finding, "exponent")) is not None:
        what = f"Thrust follows the battery voltage (thrust ∝ V^n, n = {_pm(p.value, p.uncertainty)}); the simulation keeps it constant"
    elif effect == "cg_offset":
        what = "A constant moment follows the thrust: the centre of gravity is off the thrust axis"
    elif effect == "rotor_drag" and (p := _value(finding, "drag_x")) is not None:
        what = (
            "The real rotors drag more: a force in the rotor plane of specific thrust × ground speed × "
            f"{_pm(p.value, p.uncertainty)} s/m along the nose that the simulation lacks"
        )
    elif effect == "wind" and (p := _value(finding, "drag_x")) is not None:
        what = (
            "Forces and moments follow the wind the real vehicle flew in (a drag of specific thrust × wind × "
            f"{_pm(p.value, p.uncertainty)} s/m along the nose); the simulation flew in a calm"
        )
    else:
        what = f"{effect} acts on {outputs}"
    return f"{what}; {gain}."


def summary_of(
    findings: Sequence[Finding], noise_floor: Mapping[str, float], unexplained: Mapping[str, float] | None = None
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
    if not findings:
        floor = ", ".join(f"{o} {v:.3g}" for o, v in noise_floor.items())
        what = "No candidate term" if far else "Nothing is missing: no candidate term"
        return (
            f"{what} explains more of the real flight's residual than it explains of "
            f"held-out simulated flight (residual RMS floor: {floor})." + caveat
        )
    return " ".join(f.evidence for f in findings) + caveat
