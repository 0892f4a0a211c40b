"""Model reference adaptive control in the altitude loop (chapter 2, section 2.5 and Appendix A).

Reusable controllers that run in :mod:`simulator.flights.altitude` (or any loop that
calls ``reset`` and ``step``): :class:`PidAltitude` (eq. 2.14, Table 2.5),
:class:`MracAltitude` with the linear or RBF regressor (eqs. 2.15-2.26), the
reference model :data:`REFERENCE_EQ_2_20`, and the experiment of Tables
2.6-2.8 (:func:`compare_controllers`) with the rise times the chapter flew
(:data:`FLOWN_RISE_TIMES`).
"""

from __future__ import annotations

from simulator.mrac.adaptive import Regressor, adaptive_law, lyapunov_function
from simulator.mrac.analysis import LoopAnalysis, loop_analysis
from simulator.mrac.compare import (
    CONTROLLERS,
    CompareConfig,
    ControllerResult,
    MracComparison,
    StepCase,
    compare_controllers,
    step_case,
)
from simulator.mrac.controllers import AdaptiveHistory, MracAltitude, PidAltitude, PidGains
from simulator.mrac.flown import FLOWN_RISE_TIMES, FlownRiseTime, flown_rise_time
from simulator.mrac.metrics import MetricStatistics, Statistic, StepMetrics, statistics, step_metrics
from simulator.mrac.reference import REFERENCE_EQ_2_20, ReferenceModel, lyapunov_matrix
from simulator.mrac.summary import comparison_json

__all__ = [
    "Regressor",
    "adaptive_law",
    "lyapunov_function",
    "LoopAnalysis",
    "loop_analysis",
    "CONTROLLERS",
    "CompareConfig",
    "ControllerResult",
    "MracComparison",
    "StepCase",
    "compare_controllers",
    "comparison_json",
    "step_case",
    "AdaptiveHistory",
    "MracAltitude",
    "PidAltitude",
    "PidGains",
    "MetricStatistics",
    "Statistic",
    "StepMetrics",
    "statistics",
    "step_metrics",
    "REFERENCE_EQ_2_20",
    "FLOWN_RISE_TIMES",
    "FlownRiseTime",
    "flown_rise_time",
    "ReferenceModel",
    "lyapunov_matrix",
]
