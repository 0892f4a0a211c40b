"""Conditioned flights from what a command was given: HDF5 datasets (``sysid ingest -o``) or logs."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import click

from ._common import progress_bar

__all__ = ["check_sources", "conditioned_flights", "reading_options", "reading_from"]

_MAP_HELP = (
    "Column map of CSV / Parquet tables among the inputs: time=0,delta_lat=1,p=2:deg/s (canonical name = "
    "column name or 0-based index, optional :unit converted to SI), or a .toml file of such entries."
)


def _parse_map(_ctx: click.Context, _param: click.Parameter, value: str | None) -> Any:
    """The ``--map`` text as a :class:`~flightlogs.readers.table.TableMap` (click callback; a bad map exits 1)."""
    if value is None:
        return None
    from flightlogs.readers.table import parse_table_map

    return parse_table_map(value)


def reading_options(map_help: str = _MAP_HELP) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """``--map TEXT|FILE`` (into ``table_map``: how a table's columns are read as signals) and
    ``--vehicle multirotor`` (into ``vehicle``: read a log of another vehicle type as a multirotor)."""

    def decorate(command: Callable[..., Any]) -> Callable[..., Any]:
        vehicle = click.option(
            "--vehicle",
            type=click.Choice(["multirotor"]),
            help="Read a log whose vehicle type says otherwise (fixed wing, rover...) as a multirotor.",
        )
        return click.option("--map", "table_map", metavar="MAP", callback=_parse_map, help=map_help)(vehicle(command))

    return decorate


def reading_from(table_map: Any, vehicle: str | None) -> Any:
    """The :class:`~flightlogs.readers.dispatch.ReadOptions` of ``--map`` and ``--vehicle``.

    Parameters
    ----------
    table_map : flightlogs.readers.table.TableMap or None
        The parsed ``--map``.
    vehicle : str or None
        ``--vehicle`` (``"multirotor"`` or None).
    """
    from flightlogs.readers.dispatch import ReadOptions

    return ReadOptions(table_map=table_map, force_multirotor=vehicle == "multirotor")


def check_sources(sources: Sequence[Path], log_only: Mapping[str, Any]) -> bool:
    """True when `sources` are datasets, False when they are logs; a usage error when they are mixed.

    Parameters
    ----------
    sources : sequence of Path
        The files given.
    log_only : Mapping[str, Any]
        Options that only make sense with logs (``{"--wind": paths}``), by
        option name; any that is set (not None, False or empty; 0.0 is set)
        with datasets is a usage error.

    Raises
    ------
    click.UsageError
        If datasets and logs are mixed, or a log-only option is given with datasets.
    """
    from flightlogs.errors import DataError
    from flightlogs.store.sources import are_datasets

    try:
        if not are_datasets(sources):
            return False
    except DataError as err:
        raise click.UsageError(str(err)) from None
    given = [name for name, value in log_only.items() if _is_set(value)]
    if given:
        raise click.UsageError(
            f"{', '.join(given)} go{'es' if len(given) == 1 else ''} with logs: a dataset already "
            "holds its aligned wind and its maneuvers (give them to `sysid ingest`)"
        )
    return True


def _is_set(value: Any) -> bool:
    return not (value is None or value is False or (isinstance(value, (tuple, list)) and not value))


def conditioned_flights(
    sources: Sequence[Path],
    wind_paths: Sequence[Path],
    conditioning: Any,
    *,
    log_only: Mapping[str, Any],
    quiet: bool,
    reading: Any = None,
) -> list[Any]:
    """The conditioned flights of `sources`: read from datasets, or logs ingested here with a progress bar.

    Parameters
    ----------
    sources : sequence of Path
        Datasets or logs (not both).
    wind_paths : sequence of Path
        Anemometer files or folders (logs only).
    conditioning : flightlogs.conditioning.condition.ConditioningOptions
        How to condition logs.
    log_only : Mapping[str, Any]
        Options the command was given that only go with logs (see :func:`check_sources`).
    quiet : bool
        No progress bar.
    reading : flightlogs.readers.dispatch.ReadOptions, optional
        How tables among the logs are read and another vehicle refused (``--map``, ``--vehicle``).

    Returns
    -------
    list of flightlogs.conditioning.condition.ConditionedFlight

    Raises
    ------
    click.UsageError
        See :func:`check_sources`.
    flightlogs.errors.DataError
        If no flight could be conditioned (or a dataset holds none).
    """
    from flightlogs.store.sources import conditioned_sources

    if check_sources(sources, log_only):
        return conditioned_sources(sources)
    with progress_bar("reading", unit="bytes", quiet=quiet) as bar:
        return conditioned_sources(
            sources,
            wind_paths,
            options=conditioning,
            progress=lambda _name, done, total: bar(done, total),
            **({} if reading is None else {"reading": reading}),
        )
