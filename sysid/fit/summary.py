"""Machine-readable summaries of identified models and modes (what ``sysid fit/modes --json`` print)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from flightlogs.signals import describe
from sysid._json import finite_or_none as _num
from sysid.fit._json import axis_entry, parameter_entry
from sysid.fit.guidelines import model_verdict
from sysid.fit.result import IdentifiedModel
from sysid.model.modes import Mode, modes

__all__ = ["mode_summary", "fit_summary"]


def mode_summary(found: Sequence[Mode]) -> list[dict[str, Any]]:
    """One JSON object per mode.

    Parameters
    ----------
    found : sequence of Mode
        Modes, e.g. from :func:`sysid.model.modes.modes`.

    Returns
    -------
    list of dict
        ``real``, ``imag`` (1/s, rad/s), ``damping``, ``natural_frequency_rad_s``,
        ``time_to_double_s``, ``time_to_half_s`` (None when infinite),
        ``mode``, ``stability``.
    """
    return [
        {
            "real": m.real,
            "imag": m.imag,
            "damping": _num(m.damping),
            "natural_frequency_rad_s": m.natural_frequency_rad_s,
            "time_to_double_s": _num(m.time_to_double_s),
            "time_to_half_s": _num(m.time_to_half_s),
            "mode": m.mode,
            "stability": m.stability,
        }
        for m in found
    ]


def fit_summary(model: IdentifiedModel) -> dict[str, Any]:
    """The JSON summary of an identification.

    Parameters
    ----------
    model : IdentifiedModel
        The model.

    Returns
    -------
    dict
        ``model`` (structure name); ``parameters.NAME`` with ``value``,
        ``cr_percent``, ``insensitivity_percent`` (None unless estimated),
        ``status``, ``unit``, ``stage``; ``cost`` with ``average`` and
        ``responses``; ``eigenvalues`` (see :func:`mode_summary`);
        ``dropped`` (names of dropped parameters); ``unidentified`` (names of
        the parameters no response informed: value None); ``axes`` (each
        control input's ``axis``, ``input``, ``status`` "identified" or
        "unidentified", ``reason``, ``remedy``); ``reduction`` (the log, a
        ``kept`` step with the costs that rose); ``wind`` (residual RMS
        before/after, or None); ``notes``; ``maneuvers`` (how the fitted
        maneuvers were found, ``"kind axis source"``); ``verdict`` (``grade``
        and ``sentence`` by the guidelines of the fit, not yet verified on
        doublets: :func:`~sysid.fit.guidelines.model_verdict`). Eigenvalues
        are those of the identified axes.
    """
    verdict = model_verdict(model)
    return {
        "model": model.structure_name,
        "parameters": {p.name: parameter_entry(p) for p in model.parameters},
        "cost": {"average": model.cost.average, "responses": dict(model.cost.responses)},
        "eigenvalues": mode_summary(modes(model.linear_model())),
        "dropped": [p.name for p in model.parameters if p.dropped],
        "unidentified": [p.name for p in model.parameters if p.unidentified],
        "axes": [axis_entry(a) for a in model.axis_status],
        "reduction": [
            {
                "step": s.step,
                "parameter": s.parameter,
                "action": s.action,
                "value": s.value,
                "reason": s.reason,
                "cost_average": _num(s.cost_average),
                "cost_average_after": _num(s.cost_average_after),
            }
            for s in model.reduction
        ],
        "wind": None
        if model.wind is None
        else {
            "outputs": list(model.wind.outputs),
            "units": [_unit(o) for o in model.wind.outputs],
            "rms_before": list(model.wind.rms_before),
            "rms_after": list(model.wind.rms_after),
            "samples": model.wind.samples,
        },
        "trim": dict(model.trim),
        "input_units": dict(model.input_units),
        "notes": list(model.notes),
        "maneuvers": list(model.provenance.maneuvers),
        "verdict": {"grade": verdict.grade, "sentence": verdict.sentence},
    }


def _unit(signal: str) -> str:
    """The SI unit of a canonical signal ("" for a name that is not one)."""
    try:
        return describe(signal).unit
    except KeyError:
        return ""
