"""Conditioned flights from what a caller was given: HDF5 datasets written by an ingest, or flight logs."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from flightlogs.conditioning.condition import ConditionedFlight, ConditioningOptions
from flightlogs.errors import DataError
from flightlogs.readers.dispatch import ReadOptions

__all__ = ["is_dataset", "are_datasets", "dataset_flights", "conditioned_sources"]

#: Suffixes of an HDF5 dataset (:func:`~flightlogs.store.dataset.write_dataset`).
_DATASET_SUFFIXES = (".h5", ".hdf5")


def is_dataset(path: str | Path) -> bool:
    """Whether `path` names an HDF5 dataset (by its suffix) rather than a flight log.

    Parameters
    ----------
    path : str or Path
        A file given as a source.

    Returns
    -------
    bool

    Examples
    --------
    >>> is_dataset("campaign.h5"), is_dataset("flight.ulg")
    (True, False)
    """
    return Path(path).suffix.lower() in _DATASET_SUFFIXES


def are_datasets(sources: Sequence[str | Path]) -> bool:
    """True when `sources` are HDF5 datasets, False when they are logs.

    Parameters
    ----------
    sources : sequence of str or Path
        The files given.

    Returns
    -------
    bool

    Raises
    ------
    DataError
        If datasets and logs are mixed.
    """
    datasets = [p for p in sources if is_dataset(p)]
    if datasets and len(datasets) != len(sources):
        raise DataError("give either datasets (.h5 written by an ingest) or logs, not both")
    return bool(datasets)


def dataset_flights(datasets: Sequence[str | Path]) -> list[ConditionedFlight]:
    """The conditioned flights held in HDF5 datasets, in order.

    Parameters
    ----------
    datasets : sequence of str or Path
        Dataset files.

    Returns
    -------
    list of ConditionedFlight

    Raises
    ------
    DataError
        If the datasets hold no conditioned flight.
    """
    from flightlogs.store.dataset import read_dataset  # h5py: only for a dataset

    flights = [flight for path in datasets for flight in read_dataset(path).conditioned]
    if not flights:
        raise DataError(f"{', '.join(Path(p).name for p in datasets)}: no conditioned flight in the dataset")
    return flights


def conditioned_sources(
    sources: Sequence[str | Path],
    wind_paths: Sequence[str | Path] = (),
    *,
    options: ConditioningOptions = ConditioningOptions(),
    progress: Callable[[str, int, int], None] | None = None,
    reading: ReadOptions = ReadOptions(),
) -> list[ConditionedFlight]:
    """The conditioned flights of `sources`: read from datasets when they are datasets, else ingested.

    Parameters
    ----------
    sources : sequence of str or Path
        HDF5 datasets (all of them), or flight logs / tables.
    wind_paths : sequence of str or Path, optional
        Anemometer files or folders (logs only: a dataset holds its aligned wind).
    options : ConditioningOptions, optional
        How logs are conditioned (unused for datasets).
    progress : callable, optional
        ``progress(file_name, done, total)``, bytes of the logs read and conditioned so far
        (:func:`~flightlogs.store.campaign.conditioned_campaign`).
    reading : ReadOptions, optional
        How tables among the logs are read, and whether another vehicle is refused.

    Returns
    -------
    list of ConditionedFlight

    Raises
    ------
    DataError
        If datasets and logs are mixed (:func:`are_datasets`), wind files come with datasets, or no flight
        could be conditioned.
    """
    if are_datasets(sources):
        if wind_paths:
            raise DataError("`wind_paths` go with logs: a dataset already holds its aligned wind")
        return dataset_flights(sources)
    from flightlogs.store.campaign import conditioned_campaign

    flights = conditioned_campaign(
        [Path(p) for p in sources], [Path(p) for p in wind_paths], options=options, progress=progress, reading=reading
    )
    return list(flights)
