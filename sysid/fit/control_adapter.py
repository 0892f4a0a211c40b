"""The one adapter to python-control: state-space models and response-array layout.

python-control orders frequency responses ``(n_outputs, n_inputs, n_freq)``;
this project orders them ``(n_freq, n_outputs, n_inputs)``. Its
``StateSpace`` has no input delays: :func:`to_statespace` drops them (the
default; they are kept in the signal names' metadata only) or replaces each
by a Padé approximant of chosen order, appended as extra states.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from scipy import linalg

from sysid.model.statespace import DelayedStateSpace

if TYPE_CHECKING:
    import control

__all__ = ["to_statespace", "from_statespace", "to_control_layout", "from_control_layout"]


def to_control_layout(response: np.ndarray) -> np.ndarray:
    """``(n_freq, n_out, n_in)`` to python-control's ``(n_out, n_in, n_freq)``.

    Parameters
    ----------
    response : ndarray, shape (n_freq, n_outputs, n_inputs)
        Responses in this project's layout.

    Examples
    --------
    >>> to_control_layout(np.zeros((5, 2, 3))).shape
    (2, 3, 5)
    """
    return np.moveaxis(np.asarray(response), 0, -1)


def from_control_layout(response: np.ndarray) -> np.ndarray:
    """python-control's ``(n_out, n_in, n_freq)`` to ``(n_freq, n_out, n_in)``.

    Parameters
    ----------
    response : ndarray, shape (n_outputs, n_inputs, n_freq)
        Responses in python-control's layout.
    """
    return np.moveaxis(np.asarray(response), -1, 0)


def _unique(names: tuple[str, ...]) -> list[str]:
    seen: dict[str, int] = {}
    out = []
    for name in names:
        seen[name] = seen.get(name, 0) + 1
        out.append(name if seen[name] == 1 else f"{name}_{seen[name]}")
    return out


def _pade_block(delays_s: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, list[str]]:
    """Block-diagonal state space of one Padé approximant per input (identity where no delay)."""
    import control
    from scipy import signal as sps  # here, as python-control: loaded only to export (0.75 s and 0.35 s)

    parts = []
    for tau in delays_s:
        if tau > 0 and order > 0:
            num, den = control.pade(float(tau), order)
            parts.append(sps.tf2ss(num, den))
        else:
            parts.append((np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.ones((1, 1))))
    names = [f"pade{j}_{k}" for j, p in enumerate(parts) for k in range(p[0].shape[0])]
    n, m = len(names), len(parts)
    a, b, c, d = (linalg.block_diag(*[p[i] for p in parts]) for i in range(4))
    return a.reshape(n, n), b.reshape(n, m), c.reshape(m, n), d.reshape(m, m), names


def to_statespace(model: Any, *, delays: Literal["drop", "pade"] = "drop", pade_order: int = 3) -> control.StateSpace:
    """A python-control ``StateSpace`` of an identified model or a :class:`DelayedStateSpace`.

    Parameters
    ----------
    model : IdentifiedModel or DelayedStateSpace
        The model (an IdentifiedModel is taken with its wind inputs).
    delays : {"drop", "pade"}, optional
        Leave the input delays out (the frequency response then lacks the
        phase ``-omega tau``), or approximate each by a Padé approximant.
    pade_order : int, optional
        Order of each Padé approximant.

    Returns
    -------
    control.StateSpace
        Signal names from the model; a signal entering twice (a wind input
        with two delays) gets ``_2`` appended the second time.

    Examples
    --------
    >>> m = DelayedStateSpace(a=np.array([[-1.0]]), b=np.array([[1.0]]), c=np.array([[1.0]]), d=np.zeros((1, 1)),
    ...                       states=("x",), inputs=("u",), outputs=("y",), input_delays_s=np.array([0.1]))
    >>> sys = to_statespace(m, delays="pade", pade_order=2)
    >>> sys.nstates, sys.input_labels
    (3, ['u'])
    """
    import control

    linear = model.linear_model() if hasattr(model, "linear_model") else model
    if not isinstance(linear, DelayedStateSpace):
        raise TypeError(f"cannot convert a {type(model).__name__}: give an IdentifiedModel or a DelayedStateSpace")
    if delays not in ("drop", "pade"):
        raise ValueError(f"delays={delays!r} must be 'drop' or 'pade'")
    a, b, c, d = (np.asarray(m, dtype=float) for m in (linear.a, linear.b, linear.c, linear.d))
    states = list(linear.states)
    if delays == "pade":
        ad, bd, cd, dd, extra = _pade_block(np.asarray(linear.input_delays_s, dtype=float), pade_order)
        n, k = a.shape[0], ad.shape[0]
        a = np.block([[a, b @ cd], [np.zeros((k, n)), ad]])
        b, c, d = np.vstack([b @ dd, bd]), np.hstack([c, d @ cd]), d @ dd
        states += extra
    return control.ss(a, b, c, d, inputs=_unique(linear.inputs), outputs=_unique(linear.outputs), states=states)


def from_statespace(system: control.StateSpace, input_delays_s: np.ndarray | None = None) -> DelayedStateSpace:
    """A :class:`DelayedStateSpace` from a python-control ``StateSpace`` (the inverse of a "drop" conversion).

    Parameters
    ----------
    system : control.StateSpace
        The system.
    input_delays_s : ndarray, shape (n_inputs,), optional
        Delays to attach, s; default none.
    """
    n_u = system.ninputs
    delays = np.zeros(n_u) if input_delays_s is None else np.asarray(input_delays_s, dtype=float)
    return DelayedStateSpace(
        a=np.asarray(system.A),
        b=np.asarray(system.B),
        c=np.asarray(system.C),
        d=np.asarray(system.D),
        states=tuple(system.state_labels),
        inputs=tuple(system.input_labels),
        outputs=tuple(system.output_labels),
        input_delays_s=delays,
    )
