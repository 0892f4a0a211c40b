"""Model structures: named states, inputs, outputs and parameters, and matrices of expressions.

A structure is eq. 3.4 of the dissertation written down with names::

    M x' = F x + G_u u(t - tau_u) + G_w u_w(t - tau_w),    y = H0 x + H1 x'

Every matrix entry is an :class:`~sysid.model.expression.Expression` of
parameters (identified or fixed) and constants (trim: ``g U0 V0 W0 phi0
theta0``). Structures are read from TOML (:mod:`sysid.model.toml_format`);
:mod:`sysid.model.assemble` turns parameter values into matrices.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Literal

from flightlogs.errors import ModelError
from sysid.model.expression import Expression

__all__ = ["Parameter", "Constant", "InputChannel", "Entry", "ModelStructure", "MATRICES"]

#: The matrices of eq. 3.4, in the order they appear.
MATRICES = ("M", "F", "G_u", "G_w", "H0", "H1")


@dataclass(frozen=True, slots=True, kw_only=True)
class Parameter:
    """A named parameter of a structure.

    Parameters
    ----------
    name : str
        Name as in the dissertation (``X_u``, ``M_lon``, ``T_a``, ``tau_lat``).
    value : float
        Initial value (free) or the value used (fixed), SI / per unit of input.
    lower, upper : float
        Bounds of the search (``-inf``/``inf`` for none).
    free : bool
        Identified (True) or held at `value` (False).
    unit : str
        Unit text; ``{delta_lon}`` and the like are replaced by the unit of
        that logged input.
    reduce : {"drop", "fix"}
        What structure reduction does to it: set it to `drop_value`, or keep
        it at its current estimate.
    drop_value : float
        Value of a dropped parameter (0: the term leaves the model).
    input : str or None
        For a control derivative, the input it is per unit of: its start is
        rescaled to match the measured gain of that input's responses.
    """

    name: str
    value: float
    lower: float = -math.inf
    upper: float = math.inf
    free: bool = True
    unit: str = ""
    reduce: Literal["drop", "fix"] = "drop"
    drop_value: float = 0.0
    input: str | None = None

    def __post_init__(self) -> None:
        if not self.lower < self.upper:
            raise ModelError(f"parameter {self.name}: bounds [{self.lower}, {self.upper}] must be increasing")
        if not math.isfinite(self.value):
            raise ModelError(f"parameter {self.name}: value {self.value} must be finite")
        if self.free and not self.lower <= self.value <= self.upper:
            raise ModelError(
                f"parameter {self.name}: initial value {self.value} lies outside its bounds "
                f"[{self.lower}, {self.upper}]"
            )
        if self.reduce not in ("drop", "fix"):
            raise ModelError(f"parameter {self.name}: reduce={self.reduce!r} must be 'drop' or 'fix'")


@dataclass(frozen=True, slots=True)
class Constant:
    """A trim constant (``g``, ``U0``, ``theta0`` ...).

    Parameters
    ----------
    name : str
        Name used in expressions.
    value : float
        Default value, SI.
    trim : str or None
        Canonical signal whose trim (the mean removed from the records) sets
        it when a structure is fitted (``U0`` from ``u``, ``theta0`` from
        ``theta``); None for a true constant such as ``g``.
    """

    name: str
    value: float
    trim: str | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class InputChannel:
    """One column of ``[G_u G_w]``: a signal entering with its own delay.

    Parameters
    ----------
    name : str
        Name unique within the structure (the column's key in ``G_u``/``G_w``).
    signal : str
        Canonical signal it reads (``delta_lon``, ``wind_lon``); several wind
        channels may read one signal with different delays.
    delay : Expression
        Transport delay, s (a parameter name, a number or arithmetic).
    wind : bool
        A wind input (column of ``G_w``, eq. 3.6) rather than a control.
    """

    name: str
    signal: str
    delay: Expression
    wind: bool = False


@dataclass(frozen=True, slots=True, kw_only=True)
class Entry:
    """One non-zero matrix entry.

    Parameters
    ----------
    matrix : {"M", "F", "G_u", "G_w", "H0", "H1"}
        Which matrix of eq. 3.4.
    row : int
        Row index (state, or output for H0/H1).
    column : int
        Column index (state, or input channel for G_u/G_w).
    expression : Expression
        The entry.
    """

    matrix: str
    row: int
    column: int
    expression: Expression


@dataclass(frozen=True, slots=True, kw_only=True)
class ModelStructure:
    """A linear model structure of eq. 3.4 with named, bounded parameters.

    Parameters
    ----------
    name : str
        Short name (``hover``).
    description : str
        One line on what it models.
    states : tuple of str
        State names.
    inputs : tuple of InputChannel
        Control channels first, then wind channels.
    outputs : tuple of str
        Output names (canonical signals).
    parameters : tuple of Parameter
        Every parameter the entries and delays read.
    constants : tuple of Constant
        Trim constants the entries read.
    entries : tuple of Entry
        Non-zero entries of M, F, G_u, G_w, H0, H1 (M defaults to identity,
        an output named like a state with no H0/H1 row reads that state).
    text : str
        The TOML source, kept so that a fitted model can rebuild its structure.
    """

    name: str
    description: str
    states: tuple[str, ...]
    inputs: tuple[InputChannel, ...]
    outputs: tuple[str, ...]
    parameters: tuple[Parameter, ...]
    constants: tuple[Constant, ...]
    entries: tuple[Entry, ...]
    text: str = ""
    _index: Mapping[str, Parameter] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_index", MappingProxyType({p.name: p for p in self.parameters}))
        for label, names in (
            ("state", self.states),
            ("output", self.outputs),
            ("input", [c.name for c in self.inputs]),
            ("parameter", list(self._index)),
            ("constant", [c.name for c in self.constants]),
        ):
            duplicates = sorted({n for n in names if list(names).count(n) > 1})
            if duplicates:
                raise ModelError(f"structure {self.name}: {label} names repeated: {', '.join(duplicates)}")
        clash = set(self._index) & {c.name for c in self.constants}
        if clash:
            raise ModelError(f"structure {self.name}: {', '.join(sorted(clash))} is both a parameter and a constant")
        known = set(self._index) | {c.name for c in self.constants}
        for item in [e.expression for e in self.entries] + [c.delay for c in self.inputs]:
            unknown = sorted(item.names - known)
            if unknown:
                raise ModelError(
                    f"structure {self.name}: expression {item.text!r} reads unknown name "
                    f"{unknown[0]!r} (not a parameter or constant)"
                )

    def parameter(self, name: str) -> Parameter:
        """The parameter called `name`.

        Parameters
        ----------
        name : str
            Parameter name.

        Raises
        ------
        ModelError
            If the structure has no such parameter.
        """
        try:
            return self._index[name]
        except KeyError:
            raise ModelError(
                f"structure {self.name} has no parameter {name!r} (it has {', '.join(self._index)})"
            ) from None

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """All parameter names, in declaration order."""
        return tuple(self._index)

    @property
    def control_inputs(self) -> tuple[InputChannel, ...]:
        """Channels of ``G_u``."""
        return tuple(c for c in self.inputs if not c.wind)

    @property
    def wind_inputs(self) -> tuple[InputChannel, ...]:
        """Channels of ``G_w``."""
        return tuple(c for c in self.inputs if c.wind)

    @property
    def wind_parameters(self) -> tuple[str, ...]:
        """Parameters read only by the wind columns and wind delays (fitted in the wind step)."""
        wind_columns = {k for k, c in enumerate(self.inputs) if c.wind}
        in_wind: set[str] = set().union(*(c.delay.names for c in self.wind_inputs)) if self.wind_inputs else set()
        elsewhere: set[str] = (
            set().union(*(c.delay.names for c in self.control_inputs)) if self.control_inputs else set()
        )
        for entry in self.entries:
            is_wind = entry.matrix == "G_w" and entry.column in wind_columns
            (in_wind if is_wind else elsewhere).update(entry.expression.names)
        return tuple(n for n in self._index if n in in_wind and n not in elsewhere)

    def default_constants(self) -> dict[str, float]:
        """Constant values as declared (trim zero), by name."""
        return {c.name: c.value for c in self.constants}

    def check_constants(self, names: Iterable[str]) -> None:
        """Raise unless every name is a trim constant of the structure (``--trim NAME=VALUE``).

        Parameters
        ----------
        names : iterable of str
            Constant names given by the user.

        Raises
        ------
        ModelError
            Naming the first unknown name and the structure's trim constants.

        Examples
        --------
        >>> from sysid.model import load_structure
        >>> load_structure("hover").check_constants(["U0", "theta0"])
        >>> load_structure("hover").check_constants(["Q0"])  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        flightlogs.errors.ModelError: structure hover has no trim constant 'Q0' (its trim constants: g, U0, ...)
        """
        known = [c.name for c in self.constants]
        unknown = [n for n in names if n not in known]
        if unknown:
            raise ModelError(
                f"structure {self.name} has no trim constant {unknown[0]!r} "
                f"(its trim constants: {', '.join(known) or 'none'})"
            )

    def constants_from_trim(self, trim: Mapping[str, float]) -> dict[str, float]:
        """Constant values with each trim-linked constant set from `trim`.

        Parameters
        ----------
        trim : Mapping[str, float]
            Trim value of canonical signals (a record's ``trim``), SI.
        """
        return {
            c.name: float(trim[c.trim]) if c.trim is not None and c.trim in trim else c.value for c in self.constants
        }

    def values(self, overrides: Mapping[str, float] | None = None) -> dict[str, float]:
        """Parameter values: declared values with `overrides` applied.

        Parameters
        ----------
        overrides : Mapping[str, float], optional
            Values by parameter name.

        Raises
        ------
        ModelError
            If an override names no parameter of the structure.
        """
        values = {p.name: p.value for p in self.parameters}
        for name, value in (overrides or {}).items():
            self.parameter(name)
            values[name] = float(value)
        return values
