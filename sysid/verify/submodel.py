"""Which part of a model one excited input drives, and so which outputs a record excites is judged on."""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np

from flightlogs.errors import ModelError
from sysid.model.axes import reachable, restrict_model
from sysid.model.statespace import DelayedStateSpace

if TYPE_CHECKING:
    from sysid.fit import IdentifiedModel

__all__ = ["driven_part", "axis_outputs"]


def driven_part(model: DelayedStateSpace, excited: str) -> DelayedStateSpace:
    """The part of a decoupled model that input `excited` drives.

    States reachable from `excited` through B and A, the outputs that read
    them (or `excited` directly), and every input that drives those states
    (the wind as well as the mixer input). For a model of one axis this is
    the model itself.

    Parameters
    ----------
    model : DelayedStateSpace
        Model, possibly of several decoupled axes.
    excited : str
        The input excited in a record (for example ``"delta_lon"``).

    Returns
    -------
    DelayedStateSpace

    Raises
    ------
    ModelError
        If `excited` is not a model input.
    """
    if excited not in model.inputs:
        raise ModelError(f"{excited!r} is not an input of the model ({', '.join(model.inputs)})")
    a, b, c, d = (np.asarray(m, dtype=float) for m in (model.a, model.b, model.c, model.d))
    columns = [j for j, name in enumerate(model.inputs) if name == excited]
    reached = reachable(a, np.any(b[:, columns] != 0, axis=1))
    rows = np.any(c[:, reached] != 0, axis=1) | np.any(d[:, columns] != 0, axis=1)
    keep_inputs = np.any(b[reached] != 0, axis=0) | np.any(d[rows] != 0, axis=0)
    return restrict_model(
        model,
        states={model.states[i] for i in np.flatnonzero(reached)},
        outputs={model.outputs[i] for i in np.flatnonzero(rows)},
        inputs=np.flatnonzero(keep_inputs).tolist(),
    )


def axis_outputs(model: IdentifiedModel) -> dict[str, tuple[str, ...]]:
    """The on-axis outputs of each control input of an identified model, read from its structure.

    The outputs each input drives (:func:`driven_part`) in the model rebuilt
    with every trim-linked constant (``U0 V0 W0 phi0 theta0``, eq. 3.5) at
    its declared value, zero for the built-in structures: the trim terms
    couple the axes of a hovering vehicle weakly, which must not make a yaw
    doublet judged on the lateral outputs. For the hover structures this
    gives lon ``u q theta ax``, lat ``v p phi ay``, yaw ``r``, heave ``w az``.

    Parameters
    ----------
    model : IdentifiedModel
        The identified model (its structure and values; the wind inputs are left out).

    Returns
    -------
    dict of str to tuple of str
        Control input name (``"delta_lon"``) to its outputs, in model order.

    Examples
    --------
    >>> from importlib import resources
    >>> from sysid.fit import CostSummary, IdentifiedModel, ParameterEstimate
    >>> from sysid.model import parse_structure
    >>> text = (resources.files("sysid.model") / "builtin" / "hover.toml").read_text()
    >>> parameters = tuple(ParameterEstimate(name=p.name, value=p.value) for p in parse_structure(text).parameters)
    >>> hover = IdentifiedModel(structure_name="hover", structure_text=text, parameters=parameters,
    ...                         correlation_names=(), correlation=np.zeros((0, 0)), cost=CostSummary(average=1.0),
    ...                         constants={"g": 9.81, "U0": 1.4, "V0": -2.3, "W0": 0.1, "phi0": 0.0, "theta0": 0.0})
    >>> axis_outputs(hover)["delta_yaw"], axis_outputs(hover)["delta_thr"]
    (('r',), ('w', 'az'))
    """
    structure = model.structure
    constants = {
        c.name: c.value if c.trim is not None else float(model.constants.get(c.name, c.value))
        for c in structure.constants
    }
    nominal = dataclasses.replace(model, constants=constants).linear_model(include_wind=False)
    return {name: driven_part(nominal, name).outputs for name in dict.fromkeys(nominal.inputs)}
