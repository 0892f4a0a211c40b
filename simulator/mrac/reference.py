"""The reference model of the altitude loop (eq. 2.20) and the Lyapunov matrix of the adaptive law (eq. A.8)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import cast

import numpy as np
import scipy.linalg

__all__ = ["ReferenceModel", "REFERENCE_EQ_2_20", "lyapunov_matrix"]


def _eq_2_20_a() -> np.ndarray:
    return np.array([[0.0, 1.0], [-5.416, -7.027]])


def _eq_2_20_b() -> np.ndarray:
    return np.array([-0.1145, 6.273])


def lyapunov_matrix(a: np.ndarray, q: np.ndarray) -> np.ndarray:
    """P solving ``A^T P + P A = -Q`` (eq. A.8), symmetric positive definite for a Hurwitz A.

    Parameters
    ----------
    a : ndarray, shape (n, n)
        Hurwitz state matrix (``A_ref``).
    q : ndarray, shape (n, n)
        Symmetric positive definite weight.

    Returns
    -------
    ndarray, shape (n, n)

    Examples
    --------
    >>> p = lyapunov_matrix(REFERENCE_EQ_2_20.a, np.diag([100.0, 1.0]))
    >>> np.round(p, 3)
    array([[72.373,  9.232],
           [ 9.232,  1.385]])
    """
    a = np.asarray(a, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    if a.ndim != 2 or a.shape[0] != a.shape[1] or q.shape != a.shape:
        raise ValueError(f"a {a.shape} and q {q.shape} must be square and alike")
    if np.any(np.linalg.eigvals(a).real >= 0):
        raise ValueError("a must be Hurwitz (all eigenvalues in the left half-plane)")
    if not np.allclose(q, q.T) or np.any(np.linalg.eigvalsh(q) <= 0):
        raise ValueError("q must be symmetric positive definite")
    p = scipy.linalg.solve_continuous_lyapunov(a.T, -q)
    return cast(np.ndarray, 0.5 * (p + p.T))


@dataclass(frozen=True, slots=True)
class ReferenceModel:
    """A second-order reference model ``x' = A x + b z_c`` with states ``[z, v_z]`` (eq. 2.20).

    Parameters
    ----------
    a : ndarray, shape (2, 2)
        Hurwitz state matrix, 1/s and 1/s^2.
    b : ndarray, shape (2,)
        Input vector per metre of commanded height, 1/s and 1/s^2.

    Notes
    -----
    Eq. 2.20 was identified from hover steps flown with the PID loop out of
    ground effect. Its first row, ``z' = v_z - 0.1145 z_c``, makes ``v_z`` differ
    from the height rate while a command is held; :meth:`height_rate` gives
    the rate itself. The MRAC compares the vehicle with the states themselves
    (``e = x - x_ref``, eq. A.4). The DC gain is ``(6.273 - 7.027 * 0.1145) / 5.416 = 1.0097``
    and the poles are -0.881 and -6.146 rad/s.
    """

    a: np.ndarray = field(default_factory=_eq_2_20_a)
    b: np.ndarray = field(default_factory=_eq_2_20_b)

    def __post_init__(self) -> None:
        a = np.array(self.a, dtype=np.float64)
        b = np.array(self.b, dtype=np.float64)
        if a.shape != (2, 2) or b.shape != (2,) or not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
            raise ValueError(f"a must be a finite (2, 2) and b a finite (2,) array, got {a.shape} and {b.shape}")
        if np.any(np.linalg.eigvals(a).real >= 0):
            raise ValueError(f"reference model a={a.tolist()} is not Hurwitz")
        a.setflags(write=False)
        b.setflags(write=False)
        object.__setattr__(self, "a", a)
        object.__setattr__(self, "b", b)

    def poles(self) -> np.ndarray:
        """Eigenvalues of A, rad/s, sorted by real part (slowest first).

        Returns
        -------
        ndarray, shape (2,), complex

        Examples
        --------
        >>> np.round(REFERENCE_EQ_2_20.poles().real, 3)
        array([-0.881, -6.146])
        """
        poles = np.linalg.eigvals(self.a)
        return poles[np.argsort(-poles.real)]

    def dc_gain(self) -> np.ndarray:
        """Steady states ``[z, v_z]`` per metre of held command, ``-A^-1 b``.

        Returns
        -------
        ndarray, shape (2,)

        Examples
        --------
        >>> np.round(REFERENCE_EQ_2_20.dc_gain(), 4)
        array([1.0097, 0.1145])
        """
        return -np.linalg.solve(self.a, self.b)

    def height_rate(self, state: np.ndarray, command_m: np.ndarray | float) -> np.ndarray:
        """The reference height's rate ``z'`` (first row of eq. 2.20), m/s.

        Parameters
        ----------
        state : ndarray, shape (..., 2)
            ``[z, v_z]``, m and m/s.
        command_m : ndarray or float
            Commanded height, m (broadcast against ``state[..., 0]``).

        Returns
        -------
        ndarray, shape (...)
        """
        state = np.asarray(state)
        return cast(
            np.ndarray, self.a[0, 0] * state[..., 0] + self.a[0, 1] * state[..., 1] + self.b[0] * np.asarray(command_m)
        )

    def discretize(self, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Exact zero-order-hold discretisation over `dt_s`.

        Parameters
        ----------
        dt_s : float
            Step, s.

        Returns
        -------
        ad : ndarray, shape (2, 2)
        bd : ndarray, shape (2,)
        """
        if dt_s <= 0:
            raise ValueError(f"{dt_s=} must be > 0")
        block = np.zeros((3, 3))
        block[:2, :2], block[:2, 2] = self.a, self.b
        phi = scipy.linalg.expm(block * dt_s)
        return phi[:2, :2], phi[:2, 2]

    def response(self, time_s: np.ndarray, command_m: np.ndarray, *, initial: np.ndarray | None = None) -> np.ndarray:
        """States on a uniform time grid for a command held between samples (zero-order hold).

        Parameters
        ----------
        time_s : ndarray, shape (n_samples,)
            Uniformly spaced times, s.
        command_m : ndarray, shape (n_samples,)
            Commanded height at each time, held until the next, m.
        initial : ndarray, shape (2,), optional
            State at ``time_s[0]``; default zero.

        Returns
        -------
        ndarray, shape (n_samples, 2)
            ``[z, v_z]`` at each time.

        Examples
        --------
        >>> t = np.arange(0.0, 30.0, 0.01)
        >>> round(float(REFERENCE_EQ_2_20.response(t, np.ones_like(t))[-1, 0]), 4)
        1.0097
        """
        time_s = np.asarray(time_s, dtype=np.float64)
        command = np.asarray(command_m, dtype=np.float64)
        if time_s.ndim != 1 or command.shape != time_s.shape:
            raise ValueError(f"time_s {time_s.shape} and command_m {command.shape} must be equal 1-D shapes")
        out = np.empty((time_s.size, 2))
        if time_s.size == 0:
            return out
        out[0] = np.zeros(2) if initial is None else np.asarray(initial, dtype=np.float64)
        if time_s.size > 1:
            steps = np.diff(time_s)
            if not np.allclose(steps, steps[0], rtol=1e-9, atol=0.0) or steps[0] <= 0:
                raise ValueError("time_s must be increasing and uniformly spaced")
            ad, bd = self.discretize(float(steps[0]))
            for k in range(time_s.size - 1):
                out[k + 1] = ad @ out[k] + bd * command[k]
        return out

    def lyapunov(self, q: np.ndarray) -> np.ndarray:
        """P with ``A^T P + P A = -Q`` for this model (eq. A.8).

        Parameters
        ----------
        q : ndarray, shape (2, 2)
            Weight (chapter 2: ``diag(100, 1)``).

        Returns
        -------
        ndarray, shape (2, 2)
        """
        return lyapunov_matrix(self.a, q)


#: Eq. 2.20: the PID loop out of ground effect, identified by the dissertation.
REFERENCE_EQ_2_20 = ReferenceModel()
