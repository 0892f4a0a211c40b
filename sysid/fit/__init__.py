"""Identification of model structures from frequency responses (eqs. 3.9, 3.14) and the identified model.

:func:`identify_logs` / :func:`identify_flights` run the whole chain;
:func:`fit_frequency_responses` is the engine on responses alone;
:func:`fit_wind` the wind step; :class:`IdentifiedModel` the result, saved
by :func:`write_model` and exported by :func:`to_statespace` and
:func:`write_mat`; :class:`Guidelines` holds Tischler's limits and
:func:`model_verdict` judges a model by them.
"""

from sysid.fit.accuracy import Accuracy, accuracy
from sysid.fit.axes import AxisStatus, unidentified_message
from sysid.fit.control_adapter import from_control_layout, from_statespace, to_control_layout, to_statespace
from sysid.fit.cost import CostSummary, CostWeights, FitPoints, ResponseModel, fit_points
from sysid.fit.engine import FitOptions, FrequencyFit, fit_frequency_responses
from sysid.fit.guidelines import DEFAULT_GUIDELINES, Check, Grade, Guidelines, Verdict, model_verdict
from sysid.fit.identify import FIT_PAIRS, IdentifyOptions, identify_flights, identify_logs, model_from_fit
from sysid.fit.model_file import SCHEMA_VERSION, model_from_dict, model_to_dict, read_model, write_mat, write_model
from sysid.fit.reduce import ReductionStep, worst_parameter
from sysid.fit.result import PARAMETER_STATUSES, IdentifiedModel, ParameterEstimate, Provenance, WindFit
from sysid.fit.summary import fit_summary, mode_summary
from sysid.fit.synthetic import synthetic_responses
from sysid.fit.wind import WindStepResult, fit_wind

__all__ = [
    "Accuracy",
    "accuracy",
    "AxisStatus",
    "unidentified_message",
    "to_statespace",
    "from_statespace",
    "to_control_layout",
    "from_control_layout",
    "CostSummary",
    "CostWeights",
    "FitPoints",
    "ResponseModel",
    "fit_points",
    "FitOptions",
    "FrequencyFit",
    "fit_frequency_responses",
    "DEFAULT_GUIDELINES",
    "Check",
    "Grade",
    "Guidelines",
    "Verdict",
    "model_verdict",
    "FIT_PAIRS",
    "IdentifyOptions",
    "identify_flights",
    "identify_logs",
    "model_from_fit",
    "SCHEMA_VERSION",
    "model_from_dict",
    "model_to_dict",
    "read_model",
    "write_mat",
    "write_model",
    "ReductionStep",
    "worst_parameter",
    "IdentifiedModel",
    "PARAMETER_STATUSES",
    "ParameterEstimate",
    "Provenance",
    "WindFit",
    "synthetic_responses",
    "WindStepResult",
    "fit_wind",
    "fit_summary",
    "mode_summary",
]
