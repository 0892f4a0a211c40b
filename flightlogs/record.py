"""The aligned, uniformly sampled table the identification works on."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from flightlogs.errors import MissingSignalError

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["Record"]

_UNIFORM_TOLERANCE = 1e-6  # relative spread of sample intervals still called uniform


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Record:
    """A stretch of flight on one uniform time base, trim removed and kept.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Sample times, s (log clock), uniformly spaced.
    columns : Mapping[str, ndarray]
        Canonical signals as perturbations from trim, each float64 of shape
        (n_samples,), by canonical name. The arrays are taken, not copied,
        and made read-only.
    units : Mapping[str, str]
        Unit of every column.
    trim : Mapping[str, float]
        Value removed from each column (the mean over the quiet stretch), in
        the column's unit.
    source : Path
        The log the record came from.
    label : str
        Human-readable name, e.g. ``"flight 1 of 2"``.

    Notes
    -----
    Plain arrays, not a table: reading a log does not import pandas (0.2 s).
    :attr:`table` gives the same data as a ``pandas.DataFrame`` and
    :meth:`from_table` makes a record of one.
    """

    time_s: np.ndarray
    columns: Mapping[str, np.ndarray]
    units: Mapping[str, str]
    trim: Mapping[str, float]
    source: Path
    label: str = ""

    def __post_init__(self) -> None:
        time_s = np.array(self.time_s, dtype=np.float64)  # the record's own, read-only
        if time_s.ndim != 1 or time_s.size < 2:
            raise ValueError(f"record {self.label!r} needs at least two samples")
        steps = np.diff(time_s)
        if np.any(steps <= 0) or np.ptp(steps) > _UNIFORM_TOLERANCE * np.mean(steps) + 1e-9:
            raise ValueError(f"record {self.label!r}: time index is not uniform")
        columns = {}
        for name, values in self.columns.items():
            column = np.asarray(values, dtype=np.float64)
            if column.shape != time_s.shape:
                raise ValueError(f"record {self.label!r}: {name} has shape {column.shape}, the times {time_s.shape}")
            column.flags.writeable = False
            columns[str(name)] = column
        missing_units = [c for c in columns if c not in self.units]
        if missing_units:
            raise ValueError(f"record {self.label!r}: no unit for {missing_units}")
        time_s.flags.writeable = False
        object.__setattr__(self, "time_s", time_s)
        object.__setattr__(self, "columns", MappingProxyType(columns))
        object.__setattr__(self, "units", MappingProxyType({c: self.units[c] for c in columns}))
        object.__setattr__(self, "trim", MappingProxyType({c: float(self.trim.get(c, 0.0)) for c in columns}))

    @classmethod
    def from_table(
        cls, table: pd.DataFrame, *, units: Mapping[str, str], trim: Mapping[str, float], source: Path, label: str = ""
    ) -> Record:
        """A record of a table: index the sample times (s), one float column per signal.

        Parameters
        ----------
        table : pandas.DataFrame, shape (n_samples, n_signals)
            Signals as perturbations from trim, index uniform times, s.
        units, trim, source, label
            As the record's.
        """
        return cls(
            time_s=table.index.to_numpy(dtype=np.float64),
            columns={str(c): table[c].to_numpy(dtype=np.float64, copy=True) for c in table.columns},
            units=units,
            trim=trim,
            source=source,
            label=label,
        )

    @property
    def table(self) -> pd.DataFrame:
        """The signals as a ``pandas.DataFrame`` (index ``time_s``, units in ``attrs``), built on each call."""
        import pandas as pd

        frame = pd.DataFrame(dict(self.columns), index=pd.Index(self.time_s, name="time_s"))
        frame.attrs["units"] = dict(self.units)
        return frame

    @property
    def rate_hz(self) -> float:
        """Sample rate, Hz."""
        t = self.time_s
        return float((t.size - 1) / (t[-1] - t[0]))

    @property
    def start_s(self) -> float:
        """First sample time, s."""
        return float(self.time_s[0])

    @property
    def end_s(self) -> float:
        """Last sample time, s."""
        return float(self.time_s[-1])

    @property
    def signals(self) -> tuple[str, ...]:
        """Column names."""
        return tuple(self.columns)

    def __getitem__(self, name: str) -> np.ndarray:
        """Perturbation values of one signal, shape (n_samples,), read-only."""
        if name not in self.columns:
            raise MissingSignalError(f"{self.source.name}: record {self.label!r} has no signal {name!r}")
        return self.columns[name]

    def absolute(self, name: str) -> np.ndarray:
        """Values of one signal with its trim added back, shape (n_samples,).

        Parameters
        ----------
        name : str
            Canonical signal name.
        """
        return self[name] + self.trim[name]

    def samples_between(self, start_s: float, end_s: float) -> int:
        """How many samples lie from `start_s` to `end_s`, both included.

        Parameters
        ----------
        start_s, end_s : float
            Bounds, s.
        """
        first, stop = self._rows(start_s, end_s)
        return max(stop - first, 0)

    def between(self, start_s: float, end_s: float, *, label: str | None = None) -> Record:
        """The part of the record from `start_s` to `end_s` (inclusive), same trim; its columns are views of these.

        Parameters
        ----------
        start_s, end_s : float
            Bounds, s.
        label : str, optional
            Label of the piece; default the record's own with the bounds.
        """
        first, stop = self._rows(start_s, end_s)
        return Record(
            time_s=self.time_s[first:stop],
            columns={name: values[first:stop] for name, values in self.columns.items()},  # read-only views
            units=self.units,
            trim=self.trim,
            source=self.source,
            label=label if label is not None else f"{self.label} [{start_s:.2f}, {end_s:.2f}] s",
        )

    def _rows(self, start_s: float, end_s: float) -> tuple[int, int]:
        """Index range [first, stop) of the samples from `start_s` to `end_s`, both included."""
        return (
            int(np.searchsorted(self.time_s, start_s, side="left")),
            int(np.searchsorted(self.time_s, end_s, side="right")),
        )

    def __reduce__(self) -> tuple[Any, ...]:  # frozen with slots: pickled through its constructor's arguments
        return (_rebuild, (self.time_s, dict(self.columns), dict(self.units), dict(self.trim), self.source, self.label))


def _rebuild(
    time_s: np.ndarray,
    columns: dict[str, np.ndarray],
    units: dict[str, str],
    trim: dict[str, float],
    source: Path,
    label: str,
) -> Record:
    """A record from its pickled arguments."""
    return Record(time_s=time_s, columns=columns, units=units, trim=trim, source=source, label=label)
