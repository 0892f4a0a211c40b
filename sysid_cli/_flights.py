"""Conditioned flights from what a command was given: HDF5 datasets (``sysid ingest -o``) or logs."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import click

from ._common import progress_bar

__all__ = ["is_dataset", "check_sources", "dataset_flights", "conditioned_flights", "reading_options", "reading_from"]

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


def is_dataset(path: Path) -> bool:
    """Whether `path` names an HDF5 dataset (by its suffix) rather than a flight log.

    Parameters
    ----------
    path : Path
        A file given on the command line.
    """
    return Path(path).suffix.lower() in (".h5", ".hdf5")


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
    datasets = [p for p in sources if is_dataset(p)]
    if datasets and len(datasets) != len(sources):
        raise click.UsageError("give either datasets (.h5 from `sysid ingest -o`) or logs, not both")
    if not datasets:
        return False
    given = [name for name, value in log_only.items() if _is_set(value)]
    if given:
        raise click.UsageError(
            f"{', '.join(given)} go{'es' if len(given) == 1 else ''} with logs: a dataset already "
            "holds its aligned wind and its maneuvers (give them to `sysid ingest`)"
        )
    return True


def _is_set(value: Any) -> bool:
    return not (value is None or value is False or (isinstance(value, (tuple, list)) and not value))


def dataset_flights(datasets: Sequence[Path]) -> list[Any]:
    """The conditioned flights held in HDF5 datasets (``sysid ingest -o``), in order.

    Parameters
    ----------
    datasets : sequence of Path
        Dataset files.

    Raises
    ------
    flightlogs.errors.DataError
        If the datasets hold no conditioned flight.
    """
    from flightlogs.errors import DataError
    from flightlogs.store.dataset import read_dataset

    flights = [flight for path in datasets for flight in read_dataset(path).conditioned]
    if not flights:
        raise DataError(f"{', '.join(p.name for p in datasets)}: no conditioned flight in the dataset")
    return flights


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
    if check_sources(sources, log_only):
        return dataset_flights(sources)
    from flightlogs.store.campaign import ingest_campaign

    with progress_bar("reading", unit="bytes", quiet=quiet) as bar:
        campaign = ingest_campaign(
            list(sources),
            list(wind_paths),
            options=conditioning,
            progress=lambda _name, done, total: bar(done, total),
            **({} if reading is None else {"reading": reading}),
        )
    return list(campaign.require_flights())
