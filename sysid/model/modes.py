"""Modes of a linear model: eigenvalues, damping, natural frequency, time to double or half, and a label.

The state matrix is first split into its strongly connected blocks (states
that feed each other back); the eigenvalues of a block-triangular matrix
are those of its diagonal blocks, so each mode belongs to one block even
when eigenvalues repeat across blocks (a dropped damping term leaves a zero
eigenvalue in heave and another in yaw, which a whole-matrix eigenvector
basis would mix). Within a block each mode is labelled by the states that
take part in it, measured by participation factors ``|l_i r_i|`` (left
times right eigenvector components, normalised), which do not depend on
the states' units. States
are grouped by name: ``roll`` (v, p, phi), ``pitch`` (u, q, theta), ``yaw``
(r, psi), ``heave`` (w, z, height_agl) and ``actuator`` (``d_*`` lag
states); any other state forms a group of its own name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from scipy import linalg
from scipy.sparse.csgraph import connected_components

from sysid.model.statespace import DelayedStateSpace

__all__ = ["Mode", "modes", "state_modes", "STATE_GROUPS"]

#: Mode label of each state name.
STATE_GROUPS: dict[str, str] = {
    "v": "roll",
    "p": "roll",
    "phi": "roll",
    "u": "pitch",
    "q": "pitch",
    "theta": "pitch",
    "r": "yaw",
    "psi": "yaw",
    "w": "heave",
    "z": "heave",
    "height_agl": "heave",
}
_NEUTRAL = 1e-9  # |real part| below this (1/s) is neutral


@dataclass(frozen=True, slots=True, kw_only=True)
class Mode:
    """One eigenvalue (a complex pair is reported once, with ``imag > 0``).

    Parameters
    ----------
    real : float
        Real part sigma, 1/s.
    imag : float
        Imaginary part (>= 0; the conjugate is implied), rad/s.
    damping : float
        zeta = -sigma / omega_n (negative when unstable; 1 or -1 for a real pole).
    natural_frequency_rad_s : float
        omega_n = |lambda|, rad/s.
    time_to_double_s : float
        ln 2 / sigma for an unstable mode, else ``inf``, s.
    time_to_half_s : float
        ln 2 / |sigma| for a stable mode, else ``inf``, s.
    mode : str
        Label: ``roll``, ``pitch``, ``yaw``, ``heave``, ``actuator``, or a
        state name.
    stability : {"stable", "unstable", "neutral"}
        Sign of the real part.
    """

    real: float
    imag: float
    damping: float
    natural_frequency_rad_s: float
    time_to_double_s: float
    time_to_half_s: float
    mode: str
    stability: Literal["stable", "unstable", "neutral"]

    @property
    def eigenvalue(self) -> complex:
        """sigma + i omega."""
        return complex(self.real, self.imag)

    @property
    def oscillatory(self) -> bool:
        """A complex pair."""
        return self.imag > 0

    @property
    def stable(self) -> bool:
        """Real part negative (a neutral mode is neither stable nor unstable)."""
        return self.stability == "stable"

    @property
    def unstable(self) -> bool:
        """Real part positive: the mode grows, doubling every `time_to_double_s`."""
        return self.stability == "unstable"


def _state_space(model: Any) -> tuple[np.ndarray, tuple[str, ...]]:
    if isinstance(model, DelayedStateSpace):
        return np.asarray(model.a, dtype=float), model.states
    if hasattr(model, "linear_model"):
        linear = model.linear_model()
        return np.asarray(linear.a, dtype=float), linear.states
    if hasattr(model, "A"):  # python-control StateSpace
        names = tuple(getattr(model, "state_labels", ())) or tuple(f"x{k}" for k in range(model.A.shape[0]))
        return np.asarray(model.A, dtype=float), names
    raise TypeError(
        f"cannot take modes of a {type(model).__name__}: give a DelayedStateSpace, an "
        "IdentifiedModel or a control.StateSpace"
    )


def _group(name: str) -> str:
    if name.startswith("d_"):
        return "actuator"
    return STATE_GROUPS.get(name, name)


def modes(model: Any) -> tuple[Mode, ...]:
    """Eigenvalues of the model's A matrix with damping, frequency, time to double/half and labels.

    Parameters
    ----------
    model : DelayedStateSpace or IdentifiedModel or control.StateSpace
        The model (delays do not change its modes).

    Returns
    -------
    tuple of Mode
        Ordered by label, then by real part (largest first).

    Examples
    --------
    >>> a = np.array([[-0.3172, 0.0, -9.81], [0.769, 0.0, 0.0], [0.0, 1.0, 0.0]])
    >>> m = DelayedStateSpace(a=a, b=np.zeros((3, 1)), c=np.eye(3), d=np.zeros((3, 1)), states=("u", "q", "theta"),
    ...                       inputs=("delta_lon",), outputs=("u", "q", "theta"), input_delays_s=np.zeros(1))
    >>> [(round(x.real, 3), round(x.imag, 3), x.mode, x.stability) for x in modes(m)]
    [(0.878, 1.694, 'pitch', 'unstable'), (-2.073, 0.0, 'pitch', 'stable')]
    """
    return state_modes(*_state_space(model))


def state_modes(a: np.ndarray, states: tuple[str, ...]) -> tuple[Mode, ...]:
    """Modes of a state matrix whose states have the given names (see :func:`modes`).

    Parameters
    ----------
    a : ndarray, shape (n_states, n_states)
        State matrix, 1/s.
    states : tuple of str
        State names, ``(n_states,)``; they decide the labels.

    Returns
    -------
    tuple of Mode
        Ordered by label, then by real part (largest first).
    """
    a = np.asarray(a, dtype=float)
    if a.size == 0:
        return ()
    found: list[Mode] = []
    for block in _coupled_blocks(a):
        found += _block_modes(a[np.ix_(block, block)], [states[i] for i in block])
    return tuple(sorted(found, key=lambda m: (m.mode, -m.real, -m.imag)))


def _coupled_blocks(a: np.ndarray) -> list[np.ndarray]:
    """State indices of each strongly connected block of `a` (edge j -> i where a[i, j] != 0)."""
    n_blocks, label = connected_components(a != 0, directed=True, connection="strong")
    return [np.flatnonzero(label == k) for k in range(n_blocks)]


def _block_modes(a: np.ndarray, states: list[str]) -> list[Mode]:
    """Modes of one strongly connected block, labelled by participation."""
    values, left, right = linalg.eig(a, left=True, right=True)
    found = []
    for k, value in enumerate(values):
        if value.imag < -1e-12 * max(1.0, abs(value)):
            continue  # the conjugate of a pair already listed
        participation = np.abs(left[:, k].conj() * right[:, k])
        groups: dict[str, float] = {}
        for name, share in zip(states, participation):
            groups[_group(name)] = groups.get(_group(name), 0.0) + float(share)
        found.append(_mode(complex(value.real, max(value.imag, 0.0)), max(groups, key=lambda g: groups[g])))
    return found


def _mode(value: complex, label: str) -> Mode:
    sigma, omega_n = value.real, abs(value)
    stability: Literal["stable", "unstable", "neutral"] = (
        "neutral" if abs(sigma) <= _NEUTRAL else "unstable" if sigma > 0 else "stable"
    )
    damping = -sigma / omega_n if omega_n > 0 else math.nan
    double = math.log(2.0) / sigma if stability == "unstable" else math.inf
    half = math.log(2.0) / -sigma if stability == "stable" else math.inf
    return Mode(
        real=float(sigma),
        imag=float(value.imag),
        damping=float(damping),
        natural_frequency_rad_s=float(omega_n),
        time_to_double_s=double,
        time_to_half_s=half,
        mode=label,
        stability=stability,
    )
