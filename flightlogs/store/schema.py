"""The versioned-schema HDF5 files flight-sysid writes: the root attributes, and opening one checked.

Every such file carries the root attributes ``schema`` (what it holds),
``schema_version``, ``software`` and ``created_utc``. A reader refuses a file
of another schema or of a newer version than it knows.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path

import h5py

from flightlogs.errors import LogFormatError, SysidError

__all__ = ["software_version", "stamp_schema", "open_schema"]


def software_version() -> str:
    """The installed flight-sysid version, or ``"unknown"`` when running from a source tree.

    Returns
    -------
    str
    """
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("flight-sysid")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        return "unknown"


def stamp_schema(h5: h5py.File, schema: str, version: int) -> None:
    """Write the root attributes: ``schema``, ``schema_version``, ``software`` and ``created_utc`` (now).

    Parameters
    ----------
    h5 : h5py.File
        A file open for writing.
    schema : str
        What the file holds (``"flight-sysid dataset"``).
    version : int
        Layout version written.
    """
    h5.attrs["schema"] = schema
    h5.attrs["schema_version"] = version
    h5.attrs["software"] = f"flight-sysid {software_version()}"
    h5.attrs["created_utc"] = datetime.now(UTC).isoformat(timespec="seconds")


#: Exceptions of reading a damaged HDF5 file: h5py's (OSError, RuntimeError), and a member missing or of another
#: type than the schema's (KeyError, ValueError, TypeError, IndexError, AttributeError).
_DAMAGED = (OSError, RuntimeError, KeyError, ValueError, TypeError, IndexError, AttributeError)


@contextmanager
def open_schema(
    path: Path, schema: str, newest: int, *, what: str, not_hdf5: str, wrong_schema: str
) -> Iterator[tuple[h5py.File, int]]:
    """Open an HDF5 file for reading and check its schema and version; closed on exit.

    Parameters
    ----------
    path : Path
        The ``.h5`` file.
    schema : str
        The ``schema`` root attribute required.
    newest : int
        The newest layout version this software reads.
    what : str
        The kind of file in the version message (``"dataset"``: "dataset schema version 2 is newer ...").
    not_hdf5 : str
        What the file is not when h5py cannot open it (``"an HDF5 dataset"``: "not an HDF5 dataset (...)").
    wrong_schema : str
        The sentence after ``"<path>: "`` when the schema differs.

    Yields
    ------
    (h5py.File, int)
        The open file and its layout version.

    Raises
    ------
    LogFormatError
        If the file is not HDF5, holds another schema, or is of a newer version.
    """
    try:
        h5 = h5py.File(path, "r")
    except (OSError, ValueError) as err:
        raise LogFormatError(f"{path}: not {not_hdf5} ({err}).") from err
    with h5:
        try:
            if h5.attrs.get("schema") != schema:
                raise LogFormatError(f"{path}: {wrong_schema}")
            version = int(h5.attrs["schema_version"])
            if version > newest:
                raise LogFormatError(
                    f"{path}: {what} schema version {version} is newer than this software reads "
                    f"({newest}); upgrade flight-sysid."
                )
            yield h5, version
        except SysidError:
            raise
        except _DAMAGED as err:  # what h5py raises on a damaged file, and a missing or mistyped member
            raise LogFormatError(f"{path}: the {what} is damaged or incomplete ({type(err).__name__}: {err}).") from err
