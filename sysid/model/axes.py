"""The axes of a structure: what each control input drives, which parameters its response reads, and cuts to them.

An axis is one control input (``delta_lon``: the pitch axis of the mixer).
Its part of the model is the states the input reaches through B and A, and
the outputs that read them, judged with every trim-linked constant (``U0
V0 W0 phi0 theta0``, eq. 3.5) at its declared value: zero for the built-in
structures, where the hover model is then decoupled into lateral,
longitudinal, yaw and heave dynamics (the trim terms of a real flight
couple them only weakly). A parameter belongs to every axis whose part
reads it (``T_a`` to lat, lon and thr); a model whose parameter is
unidentified cannot be simulated on that parameter's axes.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass

import numpy as np

from sysid.model.assemble import Assembler
from sysid.model.statespace import DelayedStateSpace
from sysid.model.structure import ModelStructure

__all__ = ["AxisPart", "reachable", "axis_parts", "restrict_model"]


def reachable(a: np.ndarray, start: np.ndarray) -> np.ndarray:
    """States `start` reaches through A (``a[i, j] != 0``: state j drives state i), `start` included.

    Pass ``a.T`` for the states that reach `start` instead.

    Parameters
    ----------
    a : ndarray, shape (n_states, n_states)
        State matrix (or its pattern of non-zeros).
    start : ndarray of bool, shape (n_states,)
        The states to start from.

    Returns
    -------
    ndarray of bool, shape (n_states,)

    Examples
    --------
    >>> a = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
    >>> reachable(a, np.array([True, False, False])).tolist()
    [True, True, False]
    """
    reached = np.asarray(start, dtype=bool)
    while True:
        grown = reached | np.any(a[:, reached] != 0, axis=1)
        if np.array_equal(grown, reached):
            return reached
        reached = grown


@dataclass(frozen=True, slots=True, kw_only=True)
class AxisPart:
    """What one control input drives in a structure at its declared trim.

    Parameters
    ----------
    signal : str
        The control input's signal (``delta_lon``).
    states : tuple of str
        States it reaches.
    outputs : tuple of str
        Outputs that read them (or the input directly).
    parameters : tuple of str
        Parameters its response to those outputs depends on (delays included), in declaration order.
    """

    signal: str
    states: tuple[str, ...]
    outputs: tuple[str, ...]
    parameters: tuple[str, ...]


def axis_parts(structure: ModelStructure, values: Mapping[str, float] | None = None) -> dict[str, AxisPart]:
    """Each control input's part of `structure`, by signal, with the trim constants at their declared values.

    Parameters
    ----------
    structure : ModelStructure
        The structure.
    values : Mapping[str, float], optional
        Parameter values to judge the pattern of non-zeros at; default the
        structure's (a non-finite value is replaced by the declared one). An
        entry that a parameter reads counts even where its value is 0.

    Returns
    -------
    dict of str to AxisPart
        In the order of the structure's control inputs.

    Examples
    --------
    >>> from sysid.model import load_structure
    >>> parts = axis_parts(load_structure("hover"))
    >>> parts["delta_yaw"].parameters, parts["delta_thr"].outputs
    (('N_r', 'N_yaw', 'tau_yaw'), ('w', 'az'))
    >>> "T_a" in parts["delta_lat"].parameters and "X_u" not in parts["delta_lat"].parameters
    True
    """
    wind = set(structure.wind_parameters)
    names = [p.name for p in structure.parameters if p.name not in wind]
    given = structure.values() | {k: float(v) for k, v in (values or {}).items() if np.isfinite(v) and k not in wind}
    assembler = Assembler(
        structure, free=names, fixed=given, constants=structure.default_constants(), include_wind=False
    )
    theta = np.array([given[n] for n in names])
    m = assembler.matrices(theta)
    dm = assembler.derivatives(theta, m)
    pattern = {key: (getattr(m, key) != 0) | np.any(getattr(dm, key) != 0, axis=0) for key in ("a", "b", "c", "d")}
    parts: dict[str, AxisPart] = {}
    for j, channel in enumerate(assembler.channels):
        reached = reachable(pattern["a"], pattern["b"][:, j])
        rows = np.any(pattern["c"][:, reached], axis=1) | pattern["d"][:, j]
        inside = np.ix_(reached, reached)
        read = [
            name
            for k, name in enumerate(names)
            if np.any(dm.a[k][inside])
            or np.any(dm.b[k][reached, j])
            or np.any(dm.c[k][np.ix_(rows, reached)])
            or np.any(dm.d[k][rows, j])
            or dm.delays[k, j] != 0
        ]
        previous = parts.get(channel.signal)
        states = [s for k, s in enumerate(structure.states) if reached[k]]
        outputs = [o for k, o in enumerate(structure.outputs) if rows[k]]
        if previous is not None:  # one signal through several channels: their union
            states = [s for s in structure.states if s in states or s in previous.states]
            outputs = [o for o in structure.outputs if o in outputs or o in previous.outputs]
            read = [n for n in names if n in read or n in previous.parameters]
        parts[channel.signal] = AxisPart(
            signal=channel.signal, states=tuple(states), outputs=tuple(outputs), parameters=tuple(read)
        )
    return parts


def restrict_model(
    model: DelayedStateSpace,
    *,
    states: Collection[str],
    outputs: Collection[str],
    inputs: Collection[int],
) -> DelayedStateSpace:
    """`model` cut to some of its states, outputs and inputs (by input position: a signal may enter twice).

    Parameters
    ----------
    model : DelayedStateSpace
        The whole model.
    states, outputs : collection of str
        Names to keep; model order is kept.
    inputs : collection of int
        Positions of the inputs to keep.

    Returns
    -------
    DelayedStateSpace

    Examples
    --------
    >>> m = DelayedStateSpace(a=-np.eye(2), b=np.eye(2), c=np.eye(2), d=np.zeros((2, 2)), states=("x", "y"),
    ...                       inputs=("u", "v"), outputs=("x", "y"), input_delays_s=np.array([0.0, 0.1]))
    >>> cut = restrict_model(m, states={"y"}, outputs={"y"}, inputs=[1])
    >>> cut.states, cut.inputs, cut.input_delays_s.tolist()
    (('y',), ('v',), [0.1])
    """
    x = [k for k, name in enumerate(model.states) if name in states]
    y = [k for k, name in enumerate(model.outputs) if name in outputs]
    u = sorted(set(inputs))
    a, b, c, d = (np.asarray(part, dtype=float) for part in (model.a, model.b, model.c, model.d))
    return DelayedStateSpace(
        a=a[np.ix_(x, x)],
        b=b[np.ix_(x, u)],
        c=c[np.ix_(y, x)],
        d=d[np.ix_(y, u)],
        states=tuple(model.states[k] for k in x),
        inputs=tuple(model.inputs[k] for k in u),
        outputs=tuple(model.outputs[k] for k in y),
        input_delays_s=np.asarray(model.input_delays_s, dtype=float)[u],
        trim=model.trim,
    )
