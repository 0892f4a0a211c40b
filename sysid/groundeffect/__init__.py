"""Ground-effect models of chapter 2: F/F0 against Z/R from a test rig or hover steps in flight.

Read the data (:func:`load_thrust_ratio`: a rig CSV or a flight log), fit
eqs. 2.1-2.3 and the piecewise-linear law of eq. 2.5 with confidence
intervals and choose by AICc or BIC (:func:`fit_ground_effect`), save the
chosen model for a controller study (:func:`write_ground_effect_model`,
:func:`read_ground_effect_model`), or compare rotor spacings
(:func:`spacing_study`). The laws themselves are in
:mod:`sysid.groundeffect.formulas`, which the simulator shares.
"""

from __future__ import annotations

from sysid.groundeffect.data import load_thrust_ratio, rig_thrust_ratio
from sysid.groundeffect.fitting import FitConfig, fit_ground_effect, fit_model
from sysid.groundeffect.flight import flight_thrust_ratio, plateaus
from sysid.groundeffect.modelfile import (
    FittedGroundEffect,
    fit_summary,
    read_ground_effect_model,
    write_ground_effect_model,
)
from sysid.groundeffect.models import (
    MODEL_NAMES,
    PARAMETER_NAMES,
    Criterion,
    GroundEffectFit,
    ModelFit,
    ModelName,
    evaluate_model,
)
from sysid.groundeffect.records import GroundEffectDataConfig, HoverStep, HoverSteps, ThrustRatioData
from sysid.groundeffect.spacing import SpacingStudy, default_families, spacing_study, spacing_summary

__all__ = [
    "GroundEffectDataConfig",
    "HoverStep",
    "HoverSteps",
    "ThrustRatioData",
    "load_thrust_ratio",
    "rig_thrust_ratio",
    "flight_thrust_ratio",
    "plateaus",
    "MODEL_NAMES",
    "PARAMETER_NAMES",
    "Criterion",
    "FitConfig",
    "GroundEffectFit",
    "ModelFit",
    "ModelName",
    "evaluate_model",
    "fit_ground_effect",
    "fit_model",
    "FittedGroundEffect",
    "fit_summary",
    "read_ground_effect_model",
    "write_ground_effect_model",
    "SpacingStudy",
    "default_families",
    "spacing_study",
    "spacing_summary",
]
