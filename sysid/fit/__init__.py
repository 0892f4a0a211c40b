"""Identification of model structures from frequency responses (eqs. 3.9, 3.14) and the identified model.

:func:`identify_logs` / :func:`identify_flights` run the whole chain;
:func:`fit_frequency_responses` is the engine on responses alone;
:func:`fit_wind` the wind step; :class:`IdentifiedModel` the result, saved
by :func:`write_model` and exported by :func:`to_statespace` and
:func:`write_mat`.
"""

from .accuracy import Accuracy, accuracy
from .control_adapter import from_control_layout, from_statespace, to_control_layout, to_statespace
from .cost import CostSummary, CostWeights, FitPoints, ResponseModel, fit_points
from .engine import FitOptions, FrequencyFit, fit_frequency_responses
from .identify import FIT_PAIRS, IdentifyOptions, identify_flights, identify_logs, model_from_fit
from .model_file import SCHEMA_VERSION, model_from_dict, model_to_dict, read_model, write_mat, write_model
from .reduce import ReductionStep, worst_parameter
from .result import IdentifiedModel, ParameterEstimate, Provenance, WindFit
from .summary import fit_summary, mode_summary
from .synthetic import synthetic_responses
from .wind import WindStepResult, fit_wind

__all__ = [
    "Accuracy", "accuracy", "to_statespace", "from_statespace", "to_control_layout", "from_control_layout",
    "CostSummary", "CostWeights", "FitPoints", "ResponseModel", "fit_points", "FitOptions", "FrequencyFit",
    "fit_frequency_responses", "FIT_PAIRS", "IdentifyOptions", "identify_flights", "identify_logs", "model_from_fit",
    "SCHEMA_VERSION", "model_from_dict", "model_to_dict", "read_model", "write_mat", "write_model", "ReductionStep",
    "worst_parameter", "IdentifiedModel", "ParameterEstimate", "Provenance", "WindFit", "synthetic_responses",
    "WindStepResult", "fit_wind", "fit_summary", "mode_summary",
]
