"""JSON pieces shared by the model file (:mod:`sysid.fit.model_file`) and the CLI summary (:mod:`sysid.fit.summary`)."""

from __future__ import annotations

from typing import Any

from sysid._json import finite_or_none
from sysid.fit.result import ParameterEstimate

__all__ = ["parameter_entry"]


def parameter_entry(p: ParameterEstimate) -> dict[str, Any]:
    """One parameter as JSON: ``value``, ``cr_percent``, ``insensitivity_percent``, ``status``, ``unit``, ``stage``.

    ``value`` is as held (NaN stays NaN); the two bounds are None unless finite.

    Parameters
    ----------
    p : ParameterEstimate
        The estimate (value in its `unit`, bounds in % of ``|value|``).

    Returns
    -------
    dict
    """
    return {
        "value": p.value,
        "cr_percent": finite_or_none(p.cr_percent),
        "insensitivity_percent": finite_or_none(p.insensitivity_percent),
        "status": p.status,
        "unit": p.unit,
        "stage": p.stage,
    }
