"""Parameter values to matrices: ``A = M^-1 F``, ``B = M^-1 G``, ``C = H0 + H1 A``, ``D = H1 B``.

The accelerometer outputs of eq. 3.7 read state derivatives (``y = H0 x + H1
x'``); substituting ``x' = A x + B u`` gives an ordinary state-space output.
Derivatives of the matrices with respect to the free parameters come from a
complex step on each entry that reads the parameter (exact to rounding, as
every allowed operation is analytic).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from flightlogs.errors import ModelError
from sysid.model.statespace import DelayedStateSpace
from sysid.model.structure import Entry, ModelStructure

__all__ = ["SystemMatrices", "Assembler", "structure_model"]

_STEP = 1e-30  # complex step


@dataclass(frozen=True, slots=True, kw_only=True)
class SystemMatrices:
    """``A, B, C, D`` and input delays, or their derivatives stacked on a leading parameter axis.

    Parameters
    ----------
    a : ndarray, shape ([n_par,] n_states, n_states)
    b : ndarray, shape ([n_par,] n_states, n_inputs)
    c : ndarray, shape ([n_par,] n_outputs, n_states)
    d : ndarray, shape ([n_par,] n_outputs, n_inputs)
    delays : ndarray, shape ([n_par,] n_inputs)
        Input delays, s (or their derivatives).
    """

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray
    delays: np.ndarray


class Assembler:
    """Builds the matrices of a structure for a vector of free-parameter values.

    Parameters
    ----------
    structure : ModelStructure
        The structure.
    free : sequence of str
        Names of the parameters in the vector ``theta``, in order.
    fixed : Mapping[str, float]
        Values of every other parameter the structure reads.
    constants : Mapping[str, float]
        Trim constants (``g``, ``U0`` ...), SI.
    include_wind : bool, optional
        Keep the wind channels (columns of ``G_w``) as inputs.

    Raises
    ------
    ModelError
        If a parameter the entries read has no value, or a value that is not
        finite (an unidentified parameter).

    Examples
    --------
    >>> from sysid.model import load_structure
    >>> hover = load_structure("hover")
    >>> values = hover.values()
    >>> asm = Assembler(hover, free=["X_u"], fixed=values, constants=hover.default_constants(), include_wind=False)
    >>> m = asm.matrices(np.array([-0.5]))
    >>> float(m.a[hover.states.index("u"), hover.states.index("u")])
    -0.5
    """

    def __init__(
        self,
        structure: ModelStructure,
        *,
        free: Sequence[str],
        fixed: Mapping[str, float],
        constants: Mapping[str, float],
        include_wind: bool = True,
    ) -> None:
        self.structure = structure
        self.free = tuple(free)
        for name in self.free:
            structure.parameter(name)
        channels = [k for k, c in enumerate(structure.inputs) if include_wind or not c.wind]
        self.channels = tuple(structure.inputs[k] for k in channels)
        self._column = {k: j for j, k in enumerate(channels)}
        self._entries = tuple(
            e for e in structure.entries if e.matrix not in ("G_u", "G_w") or e.column in self._column
        )
        base = dict(constants) | {k: float(v) for k, v in fixed.items() if k not in self.free}
        needed = set().union(
            *(e.expression.names for e in self._entries), *(c.delay.names for c in self.channels)
        ) - set(self.free)
        missing = sorted(needed - set(base))
        if missing:
            raise ModelError(f"structure {structure.name}: no value for {', '.join(missing)}")
        unknown = [p.name for p in structure.parameters if p.name in needed and not np.isfinite(base[p.name])]
        if unknown:
            raise ModelError(
                f"structure {structure.name}: {', '.join(unknown)} {'has' if len(unknown) == 1 else 'have'} no value "
                "(unidentified), so the matrices that read it cannot be built"
            )
        self._base = MappingProxyType(base)
        self._reads = tuple(tuple(e for e in self._entries if name in e.expression.names) for name in self.free)
        self._delay_reads = tuple(
            tuple(j for j, c in enumerate(self.channels) if name in c.delay.names) for name in self.free
        )
        n_x, n_y = len(structure.states), len(structure.outputs)
        self._identity_outputs = [
            (k, structure.states.index(o))
            for k, o in enumerate(structure.outputs)
            if o in structure.states and not any(e.matrix in ("H0", "H1") and e.row == k for e in structure.entries)
        ]
        self._shapes = {
            "M": (n_x, n_x),
            "F": (n_x, n_x),
            "G_u": (n_x, len(channels)),
            "G_w": (n_x, len(channels)),
            "H0": (n_y, n_x),
            "H1": (n_y, n_x),
        }

    def environment(self, theta: np.ndarray) -> dict[str, float | complex]:
        """Values of every name the expressions read.

        Parameters
        ----------
        theta : ndarray, shape (n_free,)
            Free-parameter values.
        """
        theta = np.asarray(theta)
        if theta.shape != (len(self.free),):
            raise ValueError(f"theta has shape {theta.shape}, expected ({len(self.free)},)")
        return dict(self._base) | {name: theta[k].item() for k, name in enumerate(self.free)}

    def raw(self, theta: np.ndarray) -> dict[str, np.ndarray]:
        """The matrices of eq. 3.4 as written (M, F, G with both G_u and G_w columns, H0, H1).

        Parameters
        ----------
        theta : ndarray, shape (n_free,)
            Free-parameter values.
        """
        env = self.environment(theta)
        mats = {k: np.zeros(shape) for k, shape in self._shapes.items() if k != "G_w"}
        mats["M"] = np.eye(len(self.structure.states))
        mats["G"] = mats.pop("G_u")
        for k, s in self._identity_outputs:
            mats["H0"][k, s] = 1.0
        for entry in self._entries:
            self._place(mats, entry, float(np.real(entry.expression(env))))
        return mats

    def matrices(self, theta: np.ndarray) -> SystemMatrices:
        """``A, B, C, D`` and delays at `theta`.

        Parameters
        ----------
        theta : ndarray, shape (n_free,)
            Free-parameter values.

        Raises
        ------
        ModelError
            If M is singular or an entry cannot be evaluated.
        """
        raw = self.raw(theta)
        a, b = self._solve_m(raw["M"], raw["F"]), self._solve_m(raw["M"], raw["G"])
        return SystemMatrices(a=a, b=b, c=raw["H0"] + raw["H1"] @ a, d=raw["H1"] @ b, delays=self.delays(theta))

    def delays(self, theta: np.ndarray) -> np.ndarray:
        """Each input channel's delay at `theta`, s, shape (n_channels,): those of :meth:`matrices`, without the
        matrices (a delay scan's points).

        Parameters
        ----------
        theta : ndarray, shape (n_free,)
            Free-parameter values.
        """
        env = self.environment(theta)
        return np.array([float(np.real(c.delay(env))) for c in self.channels])

    def derivatives(self, theta: np.ndarray, base: SystemMatrices | None = None) -> SystemMatrices:
        """Derivatives of ``A, B, C, D`` and delays with respect to each free parameter.

        Parameters
        ----------
        theta : ndarray, shape (n_free,)
            Free-parameter values.
        base : SystemMatrices, optional
            ``matrices(theta)`` if already computed.

        Returns
        -------
        SystemMatrices
            Arrays with a leading axis of length n_free.
        """
        base = base if base is not None else self.matrices(theta)
        raw = self.raw(theta)
        n_p = len(self.free)
        d_a, d_b = np.zeros((n_p, *base.a.shape)), np.zeros((n_p, *base.b.shape))
        d_c, d_d = np.zeros((n_p, *base.c.shape)), np.zeros((n_p, *base.d.shape))
        d_tau = np.zeros((n_p, base.delays.size))
        real_env = self.environment(theta)
        for k, name in enumerate(self.free):
            env = dict(real_env)
            env[name] = complex(env[name]) + 1j * _STEP
            dm = {key: np.zeros_like(raw[key]) for key in ("M", "F", "G", "H0", "H1")}
            for entry in self._reads[k]:
                self._place(dm, entry, float(np.imag(entry.expression(env))) / _STEP)
            for j in self._delay_reads[k]:
                d_tau[k, j] = float(np.imag(self.channels[j].delay(env))) / _STEP
            d_a[k] = self._solve_m(raw["M"], dm["F"] - dm["M"] @ base.a)
            d_b[k] = self._solve_m(raw["M"], dm["G"] - dm["M"] @ base.b)
            d_c[k] = dm["H0"] + dm["H1"] @ base.a + raw["H1"] @ d_a[k]
            d_d[k] = dm["H1"] @ base.b + raw["H1"] @ d_b[k]
        return SystemMatrices(a=d_a, b=d_b, c=d_c, d=d_d, delays=d_tau)

    def state_space(self, theta: np.ndarray, *, trim: Mapping[str, float] | None = None) -> DelayedStateSpace:
        """The model at `theta` as a :class:`DelayedStateSpace` (inputs named by their signals).

        Parameters
        ----------
        theta : ndarray, shape (n_free,)
            Free-parameter values.
        trim : Mapping[str, float], optional
            Trim values to record in the model.

        Raises
        ------
        ModelError
            If a delay comes out negative.
        """
        m = self.matrices(theta)
        if np.any(m.delays < 0):
            bad = self.channels[int(np.argmin(m.delays))]
            raise ModelError(f"structure {self.structure.name}: delay of input {bad.name} is negative")
        return DelayedStateSpace(
            a=m.a,
            b=m.b,
            c=m.c,
            d=m.d,
            states=self.structure.states,
            inputs=tuple(c.signal for c in self.channels),
            outputs=self.structure.outputs,
            input_delays_s=m.delays,
            trim=MappingProxyType(dict(trim or {})),
        )

    def _place(self, mats: dict[str, np.ndarray], entry: Entry, value: float) -> None:
        key = "G" if entry.matrix in ("G_u", "G_w") else entry.matrix
        column = self._column[entry.column] if key == "G" else entry.column
        mats[key][entry.row, column] = value

    def _solve_m(self, m: np.ndarray, rhs: np.ndarray) -> np.ndarray:
        if m.shape[0] and np.array_equal(m, np.eye(m.shape[0])):
            return rhs.copy()
        try:
            return np.linalg.solve(m, rhs)
        except np.linalg.LinAlgError as err:
            raise ModelError(f"structure {self.structure.name}: the mass matrix M is singular") from err


def structure_model(
    structure: ModelStructure,
    values: Mapping[str, float],
    *,
    constants: Mapping[str, float] | None = None,
    include_wind: bool = True,
) -> tuple[DelayedStateSpace, tuple[str, ...]]:
    """A structure with given parameter values (published derivatives) as a :class:`DelayedStateSpace`.

    Parameters not given take their drop value (0: a term the publication
    does not list is taken as dropped), or, for parameters reduction would
    fix rather than drop (``T_a``), their declared value.

    Parameters
    ----------
    structure : ModelStructure
        The structure.
    values : Mapping[str, float]
        Parameter values by name.
    constants : Mapping[str, float], optional
        Trim constants; default the structure's (trim zero).
    include_wind : bool, optional
        Keep the wind inputs.

    Returns
    -------
    model : DelayedStateSpace
    unset : tuple of str
        Parameters that were not given, in declaration order.

    Raises
    ------
    ModelError
        If a value names no parameter of the structure or is not finite (an
        unidentified parameter has no value), or a constant names no trim constant of it.

    Examples
    --------
    >>> from sysid.model import load_structure
    >>> model, unset = structure_model(load_structure("hover"), {"X_u": -0.3172, "M_u": 0.769})
    >>> "N_r" in unset, model.a.shape
    (True, (11, 11))
    """
    for name in values:
        structure.parameter(name)
    structure.check_constants(constants or {})
    unset = tuple(p.name for p in structure.parameters if p.name not in values)
    full = {p.name: (p.drop_value if p.reduce == "drop" else p.value) for p in structure.parameters}
    full |= {k: float(v) for k, v in values.items()}
    consts = structure.default_constants() | dict(constants or {})
    assembler = Assembler(structure, free=(), fixed=full, constants=consts, include_wind=include_wind)
    return assembler.state_space(np.zeros(0)), unset
