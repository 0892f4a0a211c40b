"""Ingest a flight-test campaign: logs, anemometer files, pairing and conditioning."""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from flightlogs._memory import give_back_freed_memory
from flightlogs.conditioning.align import pair_winds
from flightlogs.conditioning.condition import ConditionedFlight, ConditioningOptions, condition_flight
from flightlogs.errors import DataError, DataQualityWarning, LogFormatError
from flightlogs.flightlog import FlightLog
from flightlogs.parallel import map_forked
from flightlogs.readers.anemometer import WindMeasurement, read_anemometer_csv
from flightlogs.readers.dispatch import ReadOptions, read_log

__all__ = ["Campaign", "ingest_campaign", "expand_wind_paths"]

#: Logs conditioned in worker processes up to this much in all: each worker sends its result back.
_MAX_FORKED_BYTES = 256 * 2**20


@dataclass(frozen=True, slots=True, kw_only=True)
class Campaign:
    """Everything read and conditioned in one ingest.

    Parameters
    ----------
    logs : tuple of FlightLog
        The flights, in the order given.
    winds : tuple of WindMeasurement
        Every anemometer file read.
    conditioned : tuple of ConditionedFlight or None
        For each log, its conditioned records, or None when it could not be
        conditioned (the reason is in `notes`).
    notes : tuple of tuple of str
        For each log, why conditioning was skipped (empty when it was not).
    """

    logs: tuple[FlightLog, ...]
    winds: tuple[WindMeasurement, ...]
    conditioned: tuple[ConditionedFlight | None, ...]
    notes: tuple[tuple[str, ...], ...]

    @property
    def flights(self) -> tuple[ConditionedFlight, ...]:
        """The flights that could be conditioned, in the order given."""
        return tuple(flight for flight in self.conditioned if flight is not None)

    def require_flights(self) -> tuple[ConditionedFlight, ...]:
        """`flights`, or DataError saying why no log could be conditioned.

        Raises
        ------
        DataError
            If no log could be conditioned (the message gives each log's reason).
        """
        if not self.flights:
            reasons = "; ".join(note for notes in self.notes for note in notes)
            raise DataError(f"no log could be conditioned ({reasons})")
        return self.flights


def _size(path: str | Path) -> int:
    """Bytes of a file, 0 if it cannot be read (the reader then says why)."""
    try:
        return Path(path).stat().st_size
    except OSError:
        return 0


def expand_wind_paths(paths: Sequence[Path]) -> list[Path]:
    """Files given as they are, folders as the ``*.csv`` files inside them (sorted).

    Parameters
    ----------
    paths : sequence of Path
        Files or folders.

    Raises
    ------
    LogFormatError
        If a folder holds no CSV file.
    """
    found: list[Path] = []
    for path in paths:
        if Path(path).is_dir():
            inside = sorted(p for p in Path(path).iterdir() if p.suffix.lower() == ".csv")
            if not inside:
                raise LogFormatError(f"{path}: the folder holds no .csv anemometer file")
            found.extend(inside)
        else:
            found.append(Path(path))
    return found


def ingest_campaign(
    log_paths: Sequence[Path],
    wind_paths: Sequence[Path] = (),
    *,
    columns: Mapping[str, str] | None = None,
    options: ConditioningOptions = ConditioningOptions(),
    progress: Callable[[str, int, int], None] | None = None,
    reading: ReadOptions = ReadOptions(),
) -> Campaign:
    """Read logs and anemometer files, pair them by UTC and condition each flight.

    Parameters
    ----------
    log_paths : sequence of Path
        Flight logs (any supported format), or CSV / Parquet tables read through ``reading.table_map``.
    wind_paths : sequence of Path, optional
        Anemometer CSV files or folders of them.
    columns : Mapping[str, str], optional
        Anemometer column override (see :func:`read_anemometer_csv`).
    options : ConditioningOptions, optional
        Conditioning choices.
    progress : callable, optional
        ``progress(file_name, done, total)`` while reading: bytes read of all
        the logs so far and in all, so one bar runs once from 0 to the end.
    reading : ReadOptions, optional
        How tables are read, and whether a log of another vehicle is refused (:func:`read_log`).

    Returns
    -------
    Campaign

    Raises
    ------
    LogFormatError, DataError
        On a file that cannot be read, or wind that cannot be aligned.

    Warns
    -----
    DataQualityWarning
        For a log (without wind) that cannot be conditioned; the reason is
        also in ``notes``. The readers' and the conditioning's own warnings go on.
    """
    sizes = [_size(path) for path in log_paths]
    logs = []
    for k, path in enumerate(log_paths):

        def report(
            done: int, _total: int, name: str = Path(path).name, before: int = sum(sizes[:k]), size: int = sizes[k]
        ) -> None:
            if progress is not None:
                progress(name, before + min(done, size), sum(sizes))

        logs.append(read_log(path, progress=report, reading=reading))
    winds = [read_anemometer_csv(path, columns=columns) for path in expand_wind_paths(wind_paths)]
    paired = pair_winds(logs, winds, clock_offset_s=options.wind_offset_s)

    def condition(k: int) -> ConditionedFlight | DataError:
        try:
            return condition_flight(logs[k], paired[k], options)
        except DataError as err:
            return err
        finally:
            give_back_freed_memory()  # segmentation's working arrays, before the next log or the writing

    forked = sum(sizes) <= _MAX_FORKED_BYTES  # larger logs one at a time, each spread over the cores by trace
    conditioned: list[ConditionedFlight | None] = []
    notes: list[tuple[str, ...]] = []
    for wind, flight in zip(paired, map_forked(condition, len(logs)) if forked else map(condition, range(len(logs)))):
        if isinstance(flight, ConditionedFlight):
            conditioned.append(flight)
            notes.append(())
            continue
        if wind is not None:
            raise flight  # the user asked for wind alignment: its failure is the answer
        conditioned.append(None)
        message = f"not conditioned: {flight}"
        warnings.warn(DataQualityWarning(message), stacklevel=2)
        notes.append((message,))
    return Campaign(logs=tuple(logs), winds=tuple(winds), conditioned=tuple(conditioned), notes=tuple(notes))
