"""The aligned, uniformly sampled table the identification works on."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import cast

import numpy as np
import pandas as pd

from flightlogs.errors import MissingSignalError

__all__ = ["Record"]

_UNIFORM_TOLERANCE = 1e-6  # relative spread of sample intervals still called uniform


@dataclass(frozen=True, slots=True, kw_only=True)
class Record:
    """A stretch of flight on one uniform time base, trim removed and kept.

    Parameters
    ----------
    table : pandas.DataFrame, shape (n_samples, n_signals)
        Canonical signals as perturbations from trim; index ``time_s`` (s, log
        clock), uniformly spaced; float64 columns named canonically.
    units : Mapping[str, str]
        Unit of every column.
    trim : Mapping[str, float]
        Value removed from each column (the mean over the quiet stretch), in
        the column's unit.
    source : Path
        The log the record came from.
    label : str
        Human-readable name, e.g. ``"flight 1 of 2"``.
    """

    table: pd.DataFrame
    units: Mapping[str, str]
    trim: Mapping[str, float]
    source: Path
    label: str = ""

    def __post_init__(self) -> None:
        index = np.asarray(self.table.index, dtype=np.float64)
        if index.size < 2:
            raise ValueError(f"record {self.label!r} needs at least two samples")
        steps = np.diff(index)
        if np.any(steps <= 0) or np.ptp(steps) > _UNIFORM_TOLERANCE * np.mean(steps) + 1e-9:
            raise ValueError(f"record {self.label!r}: time index is not uniform")
        missing_units = [c for c in self.table.columns if c not in self.units]
        if missing_units:
            raise ValueError(f"record {self.label!r}: no unit for {missing_units}")
        object.__setattr__(self, "units", MappingProxyType({c: self.units[c] for c in self.table.columns}))
        object.__setattr__(
            self, "trim", MappingProxyType({c: float(self.trim.get(c, 0.0)) for c in self.table.columns})
        )
        self.table.index.name = "time_s"
        self.table.attrs["units"] = dict(self.units)

    @property
    def time_s(self) -> np.ndarray:
        """Sample times, s, shape (n_samples,)."""
        return cast(np.ndarray, self.table.index.to_numpy(dtype=np.float64))

    @property
    def rate_hz(self) -> float:
        """Sample rate, Hz."""
        t = self.time_s
        return float((t.size - 1) / (t[-1] - t[0]))

    @property
    def start_s(self) -> float:
        """First sample time, s."""
        return float(self.table.index[0])

    @property
    def end_s(self) -> float:
        """Last sample time, s."""
        return float(self.table.index[-1])

    @property
    def signals(self) -> tuple[str, ...]:
        """Column names."""
        return tuple(self.table.columns)

    def __getitem__(self, name: str) -> np.ndarray:
        """Perturbation values of one signal, shape (n_samples,)."""
        if name not in self.table.columns:
            raise MissingSignalError(f"{self.source.name}: record {self.label!r} has no signal {name!r}")
        return cast(np.ndarray, self.table[name].to_numpy(dtype=np.float64))

    def absolute(self, name: str) -> np.ndarray:
        """Values of one signal with its trim added back, shape (n_samples,).

        Parameters
        ----------
        name : str
            Canonical signal name.
        """
        return self[name] + self.trim[name]

    def between(self, start_s: float, end_s: float, *, label: str | None = None) -> Record:
        """The part of the record from `start_s` to `end_s` (inclusive), same trim.

        Parameters
        ----------
        start_s, end_s : float
            Bounds, s.
        label : str, optional
            Label of the piece; default the record's own with the bounds.
        """
        piece = self.table.loc[start_s:end_s].copy()
        return Record(
            table=piece,
            units=self.units,
            trim=self.trim,
            source=self.source,
            label=label if label is not None else f"{self.label} [{start_s:.2f}, {end_s:.2f}] s",
        )
