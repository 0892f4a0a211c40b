"""Storage: the versioned HDF5 dataset, campaigns of logs and anemometer files, and their summaries.

The public names of :mod:`~flightlogs.store.campaign`, :mod:`~flightlogs.store.dataset`,
:mod:`~flightlogs.store.hashing`, :mod:`~flightlogs.store.schema`, :mod:`~flightlogs.store.sources` and
:mod:`~flightlogs.store.summary` are
re-exported here: write
``from flightlogs.store import name``. Modules with a leading underscore are private. Each name loads
its module on first use (the dataset loads h5py).
"""

from typing import TYPE_CHECKING

from flightlogs._lazy import lazy_names

if TYPE_CHECKING:
    from flightlogs.store.campaign import Campaign, conditioned_campaign, expand_wind_paths, ingest_campaign
    from flightlogs.store.dataset import SCHEMA_VERSION, Dataset, read_dataset, write_dataset
    from flightlogs.store.hashing import file_sha256
    from flightlogs.store.schema import open_schema, software_version, stamp_schema
    from flightlogs.store.sources import conditioned_sources, dataset_flights, is_dataset
    from flightlogs.store.summary import campaign_summary, conditioned_summary, log_summary, wind_summary

__all__ = [
    "Campaign",
    "ingest_campaign",
    "conditioned_campaign",
    "expand_wind_paths",
    "Dataset",
    "write_dataset",
    "read_dataset",
    "file_sha256",
    "SCHEMA_VERSION",
    "software_version",
    "stamp_schema",
    "open_schema",
    "log_summary",
    "wind_summary",
    "conditioned_summary",
    "campaign_summary",
    "is_dataset",
    "dataset_flights",
    "conditioned_sources",
]

_HOMES = {
    **dict.fromkeys(("Campaign", "conditioned_campaign", "expand_wind_paths", "ingest_campaign"), "campaign"),
    **dict.fromkeys(("SCHEMA_VERSION", "Dataset", "read_dataset", "write_dataset"), "dataset"),
    "file_sha256": "hashing",
    **dict.fromkeys(("open_schema", "software_version", "stamp_schema"), "schema"),
    **dict.fromkeys(("campaign_summary", "conditioned_summary", "log_summary", "wind_summary"), "summary"),
    **dict.fromkeys(("conditioned_sources", "dataset_flights", "is_dataset"), "sources"),
}
__getattr__, __dir__ = lazy_names(__name__, _HOMES)
