"""JSON pieces shared by the model file (:mod:`sysid.fit.model_file`) and the CLI summary (:mod:`sysid.fit.summary`)."""

from __future__ import annotations

from typing import Any

from sysid._json import finite_or_none
from sysid.fit.axes import AxisStatus
from sysid.fit.result import ParameterEstimate

__all__ = ["parameter_entry", "axis_entry"]


def parameter_entry(p: ParameterEstimate) -> dict[str, Any]:
    """One parameter as JSON: ``value``, ``cr_percent``, ``insensitivity_percent``, ``status``, ``unit``, ``stage``.

    ``value`` is None for an unidentified parameter (it has none); the two
    bounds are None unless finite.

    Parameters
    ----------
    p : ParameterEstimate
        The estimate (value in its `unit`, bounds in % of ``|value|``).

    Returns
    -------
    dict
    """
    return {
        "value": finite_or_none(p.value),
        "cr_percent": finite_or_none(p.cr_percent),
        "insensitivity_percent": finite_or_none(p.insensitivity_percent),
        "status": p.status,
        "unit": p.unit,
        "stage": p.stage,
    }


def axis_entry(a: AxisStatus) -> dict[str, Any]:
    """One axis as JSON: ``axis``, ``input``, ``status`` ("identified" or "unidentified"), ``reason``, ``remedy``.

    Parameters
    ----------
    a : AxisStatus
        The axis.

    Returns
    -------
    dict

    Examples
    --------
    >>> axis_entry(AxisStatus(axis="lon", input="delta_lon", status="unidentified", reason="no sweep found in 3 logs"))
    {'axis': 'lon', 'input': 'delta_lon', 'status': 'unidentified', 'reason': 'no sweep found in 3 logs', 'remedy': ''}
    """
    return {"axis": a.axis, "input": a.input, "status": a.status, "reason": a.reason, "remedy": a.remedy}
