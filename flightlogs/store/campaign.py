"""Ingest a flight-test campaign: logs, anemometer files, pairing and conditioning."""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from itertools import accumulate
from pathlib import Path

from flightlogs._memory import give_back_freed_memory
from flightlogs.conditioning.align import pair_winds
from flightlogs.conditioning.condition import ConditionedFlight, ConditioningOptions, condition_flight
from flightlogs.errors import DataError, DataQualityWarning, LogFormatError
from flightlogs.flightlog import FlightLog
from flightlogs.parallel import map_forked
from flightlogs.readers.anemometer import WindMeasurement, read_anemometer_csv
from flightlogs.readers.dispatch import ReadOptions, read_log

__all__ = ["Campaign", "ingest_campaign", "conditioned_campaign", "expand_wind_paths"]

#: Logs conditioned in worker processes up to this much in all: each worker sends its result back.
_MAX_FORKED_BYTES = 256 * 2**20

#: A log's conditioning: whether it was paired with wind, and its flight or why it has none.
_Conditioned = tuple[bool, ConditionedFlight | DataError]


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
        return _required(self.conditioned, self.notes)


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
    winds = _read_winds(wind_paths, columns)
    paired = pair_winds(logs, winds, clock_offset_s=options.wind_offset_s)

    def condition(k: int) -> _Conditioned:
        return paired[k] is not None, _conditioned(logs[k], paired[k], options)

    conditioned, notes = _collected(_each(condition, sizes))
    return Campaign(logs=tuple(logs), winds=tuple(winds), conditioned=conditioned, notes=notes)


def conditioned_campaign(
    log_paths: Sequence[Path],
    wind_paths: Sequence[Path] = (),
    *,
    columns: Mapping[str, str] | None = None,
    options: ConditioningOptions = ConditioningOptions(),
    progress: Callable[[str, int, int], None] | None = None,
    reading: ReadOptions = ReadOptions(),
) -> tuple[ConditionedFlight, ...]:
    """The flights of a campaign, conditioned as :func:`ingest_campaign` conditions them, each log read by the
    worker process that conditions it: for a command that needs the flights alone (a fit, a validation).

    The logs are read on the cores beside their conditioning, not one after the other before it, and none
    comes back: only the flights do. The anemometer files are read first, here.

    Parameters
    ----------
    log_paths, wind_paths, columns, options, reading
        As :func:`ingest_campaign`'s.
    progress : callable, optional
        ``progress(file_name, done, total)``: the bytes of the logs read and conditioned so far, of all of
        them, after each log in turn (from 0).

    Returns
    -------
    tuple of ConditionedFlight
        The flights that could be conditioned, in the order given.

    Raises
    ------
    LogFormatError, DataError
        As :func:`ingest_campaign`'s, and when no log could be conditioned (:meth:`Campaign.require_flights`).

    Warns
    -----
    DataQualityWarning
        As :func:`ingest_campaign`.
    """
    sizes = [_size(path) for path in log_paths]
    done, total = list(accumulate(sizes)), sum(sizes)  # bytes after each log, of all
    winds = _read_winds(wind_paths, columns)

    def condition(k: int) -> _Conditioned:
        log = read_log(log_paths[k], reading=reading)
        wind = pair_winds([log], winds, clock_offset_s=options.wind_offset_s)[0]
        return wind is not None, _conditioned(log, wind, options)

    def reported(k: int, result: _Conditioned) -> _Conditioned:
        if progress is not None:
            progress(Path(log_paths[k]).name, done[k], total)
        return result

    if progress is not None and log_paths:
        progress(Path(log_paths[0]).name, 0, total)
    return _required(*_collected(reported(k, result) for k, result in enumerate(_each(condition, sizes))))


def _read_winds(wind_paths: Sequence[Path], columns: Mapping[str, str] | None) -> list[WindMeasurement]:
    """The anemometer files of `wind_paths` (files or folders), all of them: every log is paired with the one
    that overlaps it most, so all are read before any log is conditioned. Here, not on the cores: the chapter 3
    campaign's 120 files (2.1 MB) take 0.25 s in one process and 0.23 s over two, what the pool's start and the
    sending back cost."""
    return [read_anemometer_csv(path, columns=columns) for path in expand_wind_paths(wind_paths)]


def _each(condition: Callable[[int], _Conditioned], sizes: Sequence[int]) -> Iterator[_Conditioned]:
    """``condition(k)`` for each log, in order: on the cores while the logs (of `sizes` bytes) are small enough
    to send their flights back; larger ones one at a time here, each spread over the cores by trace."""
    if sum(sizes) <= _MAX_FORKED_BYTES:
        return map_forked(condition, len(sizes))
    return map(condition, range(len(sizes)))


def _required(
    conditioned: Sequence[ConditionedFlight | None], notes: Sequence[tuple[str, ...]]
) -> tuple[ConditionedFlight, ...]:
    """The flights conditioned, or DataError giving each log's reason when there is none."""
    flights = tuple(flight for flight in conditioned if flight is not None)
    if not flights:
        reasons = "; ".join(note for log_notes in notes for note in log_notes)
        raise DataError(f"no log could be conditioned ({reasons})")
    return flights


def _conditioned(
    log: FlightLog, wind: WindMeasurement | None, options: ConditioningOptions
) -> ConditionedFlight | DataError:
    """`log` conditioned, or the DataError that says why it cannot be; freed memory given back after either."""
    try:
        return condition_flight(log, wind, options)
    except DataError as err:
        return err
    finally:
        give_back_freed_memory()  # segmentation's working arrays, before the next log or the writing


def _collected(
    results: Iterable[_Conditioned],
) -> tuple[tuple[ConditionedFlight | None, ...], tuple[tuple[str, ...], ...]]:
    """Each log's flight (None where it could not be conditioned) and notes, from ``(paired with wind, result)``.

    A log paired with wind that cannot be conditioned raises its error: the user asked for wind alignment,
    and its failure is the answer. One without wind is left out with a warning, its reason in its notes.
    """
    conditioned: list[ConditionedFlight | None] = []
    notes: list[tuple[str, ...]] = []
    for with_wind, flight in results:
        if isinstance(flight, ConditionedFlight):
            conditioned.append(flight)
            notes.append(())
            continue
        if with_wind:
            raise flight
        conditioned.append(None)
        message = f"not conditioned: {flight}"
        warnings.warn(DataQualityWarning(message), stacklevel=3)
        notes.append((message,))
    return tuple(conditioned), tuple(notes)
