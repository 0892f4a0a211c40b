"""The comparison as JSON: the machine-readable summary of ``sysid mrac compare``."""

from __future__ import annotations

from typing import Any

import numpy as np

from simulator.mrac.compare import MracComparison
from simulator.mrac.flown import flown_rise_time
from simulator.mrac.metrics import StepMetrics

__all__ = ["comparison_json"]


def _ratio(numerator: float, denominator: float) -> float:
    if np.isfinite(numerator) and np.isfinite(denominator) and denominator:
        return numerator / denominator
    return float("nan")


def comparison_json(comparison: MracComparison, *, per_trial: bool = False) -> dict[str, Any]:
    """A JSON-ready summary: ``controllers.NAME.INDEX.{mean,std,n}`` over all cases and phases, then per case.

    Parameters
    ----------
    comparison : MracComparison
        The result.
    per_trial : bool, optional
        Add every trial's indices.

    Returns
    -------
    dict
        Plain numbers, strings, lists and dicts (NaN stays NaN; the CLI writes null).
    """
    config, names = comparison.config, comparison.config.controllers
    cases = []
    for case, analysis in zip(comparison.cases, comparison.analyses):
        phases: dict[str, Any] = {}
        for phase in ("takeoff", "landing"):
            stats = {n: comparison.statistics(n, height_ratio=case.height_ratio, phase=phase) for n in names}
            entry: dict[str, Any] = {"controllers": {n: s.as_dict() for n, s in stats.items()}}
            if "pid" in stats:
                entry["rise_time_over_pid"] = {
                    n: _ratio(stats[n].rise_time_s.mean, stats["pid"].rise_time_s.mean) for n in names if n != "pid"
                }
            flown = flown_rise_time(case.height_ratio, phase)
            if flown is not None:  # Tables 2.6-2.8; null where the table has no figure
                entry["flown_rise_time_over_pid"] = {n: flown.cut(n) for n in ("mrac_linear", "mrac_rbf")}
            if "mrac_linear" in stats and "mrac_rbf" in stats:
                entry["mse_rbf_over_linear"] = _ratio(stats["mrac_rbf"].mse_m2.mean, stats["mrac_linear"].mse_m2.mean)
            if per_trial:
                entry["trials"] = {
                    n: [_as_dict(m) for m in comparison.result(case.height_ratio, n).metrics(phase)] for n in names
                }
            phases[phase] = entry
        cases.append(
            {
                "height_ratio": case.height_ratio,
                "low_m": case.low_m,
                "high_m": case.high_m,
                "in_ground_effect": case.in_ground_effect,
                "phases": phases,
                "pid_loop": {
                    "ground_stiffness_n_m": analysis.ground_stiffness_n_m,
                    "proportional_stiffness_n_m": analysis.proportional_stiffness_n_m,
                    "integrator_time_constant_s": analysis.integrator_time_constant_s,
                },
            }
        )
    return {
        "height_ratios": list(config.height_ratios),
        "trials": config.trials,
        "seed": config.seed,
        "seeds": list(config.seeds()),
        "ground_effect": comparison.ground_effect,
        "phase_s": {"pid": config.pid_phase_s, "mrac": config.mrac_phase_s},
        "rate_hz": config.rate_hz,
        "controllers": {n: comparison.statistics(n).as_dict() for n in names},
        "cases": cases,
    }


def _as_dict(metrics: StepMetrics) -> dict[str, float]:
    return {name: getattr(metrics, name) for name in StepMetrics.__dataclass_fields__}
