"""Parameter drift across a vehicle's flights: a change beyond the Cramér–Rao bounds, confirmed by the next flight.

Only fits within Tischler's guideline are trended (J_ave at most 150,
"acceptable"): a fit that missed (a local minimum, a response that gating let
through but no parameter explains) gives values that jump by tens of percent
with bounds of a few, and would be flagged on every vehicle. Each vehicle's
remaining groups are taken in date order. The first `baseline_groups`
set its baseline, the inverse-variance mean of their values (variance: the
Cramér–Rao bound squared, widened by `bound_scale`). A later group whose value
differs from the baseline by more than `sigmas` times the combined bound
``sqrt(bound² + baseline_bound²)`` is beyond it; a drift is flagged at the first
group beyond it whose next group is beyond it too, on the same side (a
wearing part stays worn; one noisy flight does not). A vehicle's last group
beyond its baseline, with none after it to confirm it, is reported
unconfirmed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sysid.batch.results import Drift, GroupFit
from sysid.fit.guidelines import DEFAULT_GUIDELINES

__all__ = ["DriftOptions", "find_drifts", "parameter_series"]


@dataclass(frozen=True, slots=True, kw_only=True)
class DriftOptions:
    """How drift is judged.

    Parameters
    ----------
    baseline_groups : int
        A vehicle's first groups (by date) that set its baseline.
    sigmas : float
        Change, in combined bounds, beyond which a group is off its baseline.
    bound_scale : float
        Factor on the Cramér–Rao bounds before they are combined: the bound is
        the least scatter an unbiased estimate can have; measured over the
        simulated fleet's healthy vehicles, the flight-to-flight scatter is
        0.2-0.5x the bound for the control derivatives and delays and 1.5-3x for
        the speed derivatives (closed loop with position hold), up to 5x.
    max_cost_average : float
        Fits with a larger J_ave are not trended (Tischler's "acceptable", 150).
    """

    baseline_groups: int = 3
    sigmas: float = 3.0
    bound_scale: float = 2.0
    max_cost_average: float = DEFAULT_GUIDELINES.j_average_acceptable


def parameter_series(groups: Sequence[GroupFit], vehicle: str, parameter: str) -> list[tuple[GroupFit, float, float]]:
    """``(group, value, Cramér–Rao bound)`` of `parameter` over `vehicle`'s fitted groups, by date.

    Parameters
    ----------
    groups : sequence of GroupFit
        The batch's groups.
    vehicle : str
        The vehicle.
    parameter : str
        The parameter's name.

    Returns
    -------
    list of (GroupFit, float, float)
        The bound in the parameter's unit. Groups where the parameter was not estimated (fixed,
        dropped, unidentified) or has no bound are left out.
    """
    found = []
    for group in sorted((g for g in groups if g.vehicle == vehicle and g.error is None), key=_order):
        for p in group.parameters:
            if p.name == parameter and p.status == "estimated" and math.isfinite(p.cr_percent):
                found.append((group, p.value, p.cramer_rao))
    return found


def find_drifts(groups: Sequence[GroupFit], options: DriftOptions = DriftOptions()) -> tuple[Drift, ...]:
    """Every parameter of every vehicle that left its baseline (see the module notes).

    Parameters
    ----------
    groups : sequence of GroupFit
        The batch's groups; those of an unknown or mixed vehicle, or undated, are not trended.
    options : DriftOptions, optional
        Baseline and threshold.

    Returns
    -------
    tuple of Drift
        By vehicle and parameter; at most one per vehicle and parameter (the first).
    """
    dated = [
        g
        for g in groups
        if g.date is not None and g.vehicle not in ("mixed", "unknown") and g.cost_average <= options.max_cost_average
    ]
    found = []
    for vehicle in sorted({g.vehicle for g in dated}):
        names = dict.fromkeys(p.name for g in dated if g.vehicle == vehicle for p in g.parameters)
        for name in names:
            drift = _first_drift(parameter_series(dated, vehicle, name), vehicle, name, options)
            if drift is not None:
                found.append(drift)
    return tuple(found)


def _first_drift(
    series: list[tuple[GroupFit, float, float]], vehicle: str, name: str, options: DriftOptions
) -> Drift | None:
    n_base = options.baseline_groups
    if len(series) <= n_base:
        return None
    values = np.array([v for _, v, _ in series])
    bounds = options.bound_scale * np.array([b for _, _, b in series])
    if not (bounds[:n_base] > 0).all():
        return None
    weights = 1.0 / bounds[:n_base] ** 2
    baseline = float(np.sum(weights * values[:n_base]) / np.sum(weights))
    baseline_bound = float(1.0 / np.sqrt(np.sum(weights)))
    z = (values - baseline) / np.sqrt(bounds**2 + baseline_bound**2)
    beyond = np.abs(z) > options.sigmas
    for i in range(n_base, len(series)):
        last = i == len(series) - 1
        if beyond[i] and (last or (beyond[i + 1] and np.sign(z[i + 1]) == np.sign(z[i]))):
            return Drift(
                vehicle=vehicle,
                parameter=name,
                before=series[i - 1][0].key,
                after=series[i][0].key,
                baseline=baseline,
                baseline_bound=baseline_bound,
                value=float(values[i]),
                bound=float(bounds[i]),
                change_percent=100.0 * (abs(values[i]) - abs(baseline)) / abs(baseline) if baseline else math.inf,
                sigmas=float(z[i]),
                confirmed=not last,
            )
    return None


def _order(group: GroupFit) -> tuple[str, str]:
    return (group.date or "", group.key)
