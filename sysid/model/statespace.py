"""A linear model with per-input transport delays: what fitting produces and verification simulates."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import cast

import numpy as np

__all__ = ["DelayedStateSpace"]


@dataclass(frozen=True, slots=True, kw_only=True)
class DelayedStateSpace:
    """``x' = A x + B u(t - tau)``, ``y = C x + D u(t - tau)`` with named signals.

    Outputs are perturbations from trim; `trim` keeps the values removed.

    Parameters
    ----------
    a : ndarray, shape (n_states, n_states)
    b : ndarray, shape (n_states, n_inputs)
    c : ndarray, shape (n_outputs, n_states)
    d : ndarray, shape (n_outputs, n_inputs)
    states, inputs, outputs : tuple of str
        Names (canonical signal names where one exists).
    input_delays_s : ndarray, shape (n_inputs,)
        Transport delay of each input, s (>= 0).
    trim : Mapping[str, float], optional
        Trim values of inputs and outputs removed before fitting (SI / as logged).
    """

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    input_delays_s: np.ndarray
    trim: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({}))

    def __post_init__(self) -> None:
        n_x, n_u, n_y = len(self.states), len(self.inputs), len(self.outputs)
        expected = {"a": (n_x, n_x), "b": (n_x, n_u), "c": (n_y, n_x), "d": (n_y, n_u), "input_delays_s": (n_u,)}
        for name, shape in expected.items():
            actual = np.shape(getattr(self, name))
            if actual != shape:
                raise ValueError(f"{name} has shape {actual}, expected {shape} from the state/input/output names")
        if np.any(np.asarray(self.input_delays_s) < 0):
            raise ValueError("input_delays_s must be >= 0")

    def frequency_response(self, omega: np.ndarray) -> np.ndarray:
        """Complex response including the delays, shape (n_freq, n_outputs, n_inputs).

        Parameters
        ----------
        omega : ndarray, shape (n_freq,)
            Angular frequency, rad/s.

        Examples
        --------
        >>> model = DelayedStateSpace(a=np.array([[-1.0]]), b=np.array([[1.0]]), c=np.array([[1.0]]),
        ...                           d=np.zeros((1, 1)), states=("x",), inputs=("u",), outputs=("y",),
        ...                           input_delays_s=np.array([0.1]))
        >>> h = model.frequency_response(np.array([1.0]))[0, 0, 0]
        >>> round(float(abs(h)), 4), round(float(np.angle(h)), 4)
        (0.7071, -0.8854)
        """
        omega = np.asarray(omega, dtype=float)
        s = 1j * omega
        identity = np.eye(len(self.states))
        out = np.empty((omega.size, len(self.outputs), len(self.inputs)), dtype=complex)
        for k, s_k in enumerate(s):
            out[k] = self.c @ np.linalg.solve(s_k * identity - self.a, self.b) + self.d
        return cast(np.ndarray, out * np.exp(-s[:, None, None] * np.asarray(self.input_delays_s)[None, None, :]))
