"""The versioned-schema HDF5 files flight-sysid writes: the root attributes, and opening one checked.

Every such file carries the root attributes ``schema`` (what it holds),
``schema_version``, ``software`` and ``created_utc``. A reader refuses a file
of another schema or of a newer version than it knows.

Files are written in HDF5's 1.10 format (:func:`create_schema_file`), whose metadata (superblock,
object headers, link and attribute heaps, B-trees) carries checksums, and text goes in fixed-length
UTF-8 strings (:func:`put_text`), never variable-length ones: those live in HDF5's global heap, which
has no checksum, and a damaged global heap can hang libhdf5 (2.0.0 loops forever on a heap whose
free-space object has size zero, found by fuzzing). Damage to a file's structure is then a checksum
error, which :func:`open_schema` turns into one sentence. Files written before (version 1, with
variable-length text) are still read; their global heaps are walked first (:func:`_check_global_heaps`)
so that such a heap is refused instead of hanging the reader.
"""

from __future__ import annotations

import mmap
import struct
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from flightlogs.errors import LogFormatError, SysidError

__all__ = ["software_version", "stamp_schema", "open_schema", "create_schema_file", "put_text", "text", "text_dtype"]

#: The oldest HDF5 file format written: 1.10's, the first with checksums on every kind of metadata it writes.
_LIBVER = ("v110", "v110")


def create_schema_file(path: Path) -> h5py.File:
    """A new HDF5 file at `path`, open for writing, in the checksummed 1.10 format.

    Parameters
    ----------
    path : Path
        The file to create (replaced if it exists).

    Returns
    -------
    h5py.File
    """
    return h5py.File(path, "w", libver=_LIBVER)


def put_text(attrs: h5py.AttributeManager, name: str, value: str) -> None:
    """Store `value` as the attribute `name`, a fixed-length UTF-8 string (out of HDF5's global heap).

    Parameters
    ----------
    attrs : h5py.AttributeManager
        A group's or dataset's ``attrs``.
    name : str
        Attribute name.
    value : str
        The text.
    """
    attrs[name] = np.bytes_(value.encode("utf-8"))


def text(value: Any) -> str:
    """An attribute's or string field's value as ``str``: fixed-length bytes decoded as UTF-8, text as it is.

    Parameters
    ----------
    value : bytes, numpy.bytes_ or str
        What h5py returned (a file of an earlier version holds variable-length strings, read as ``str``).

    Returns
    -------
    str
    """
    return value.decode("utf-8") if isinstance(value, bytes) else str(value)


def text_dtype(values: list[str]) -> np.dtype:
    """The fixed-length byte-string dtype that holds every one of `values` once UTF-8 encoded (at least 1 byte).

    Parameters
    ----------
    values : list of str
        The texts of one field.

    Returns
    -------
    numpy.dtype
        ``S<n>``, n the longest encoded length.
    """
    return np.dtype(f"S{max([1, *(len(v.encode('utf-8')) for v in values)])}")


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
    put_text(h5.attrs, "schema", schema)
    h5.attrs["schema_version"] = version
    put_text(h5.attrs, "software", f"flight-sysid {software_version()}")
    put_text(h5.attrs, "created_utc", datetime.now(UTC).isoformat(timespec="seconds"))


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
    if not _checksummed(path):
        _check_global_heaps(path)
    try:
        h5 = h5py.File(path, "r")
    except (OSError, ValueError) as err:
        raise LogFormatError(f"{path}: not {not_hdf5} ({err}).") from err
    with h5:
        try:
            if text(h5.attrs.get("schema", "")) != schema:
                raise LogFormatError(f"{path}: {wrong_schema}")
            version = int(h5.attrs["schema_version"])
            if version > newest:
                raise LogFormatError(
                    f"{path}: {what} schema version {version} is newer than this software reads "
                    f"({newest}); upgrade flight-sysid."
                )
            yield h5, version
        except SysidError as err:
            if str(path) in str(err):
                raise
            # a value the schema holds but the domain refuses (a segment of kind ""): the file's data are damaged
            raise LogFormatError(f"{path}: the {what} is damaged ({err}).") from err
        except _DAMAGED as err:  # what h5py raises on a damaged file, and a missing or mistyped member
            raise LogFormatError(f"{path}: the {what} is damaged or incomplete ({type(err).__name__}: {err}).") from err


_SIGNATURE = b"\x89HDF\r\n\x1a\n"  # an HDF5 file's first 8 bytes (without a user block), then the superblock version


def _checksummed(path: Path) -> bool:
    """Whether `path` starts with a superblock of version 2 or later: the format this package writes (1.10's).

    Such a file's structure is checksummed, and what this package wrote in it holds no global heap; only
    older files (version-1 datasets: superblock 0) have their heaps walked, a scan of the whole file.
    """
    try:
        with path.open("rb") as stream:
            head = stream.read(len(_SIGNATURE) + 1)
    except OSError:  # h5py's open says so
        return True
    return len(head) > len(_SIGNATURE) and head.startswith(_SIGNATURE) and head[-1] >= 2


#: A global heap collection's header: signature, version 1, three reserved bytes (HDF5 spec, III.E).
_HEAP_HEADER = b"GCOL\x01\x00\x00\x00"
_HEAP_OBJECT_HEADER = 16  # bytes: index (2), reference count (2), reserved (4), size (8)


def _check_global_heaps(path: Path) -> None:
    """Walk every global heap collection of `path`; raise if one's objects do not tile it exactly.

    libhdf5 (2.0.0) loops forever on a collection whose free-space object (index 0) has a size below
    its own header; other inconsistencies it reports as errors. Only files with variable-length data
    hold such heaps (this package's version-1 files); others are scanned for the header and pass.

    Raises
    ------
    LogFormatError
        Naming the file and the collection's byte offset.
    """
    try:
        with path.open("rb") as stream:
            data = mmap.mmap(stream.fileno(), 0, access=mmap.ACCESS_READ)  # stays open after the file
    except (OSError, ValueError):  # unreadable or empty: h5py's open says so
        return
    with data:
        start = data.find(_HEAP_HEADER)
        while start >= 0:
            _walk_heap(path, data, start)
            start = data.find(_HEAP_HEADER, start + 1)


def _walk_heap(path: Path, data: mmap.mmap, start: int) -> None:
    if start + 16 > len(data):
        return
    (size,) = struct.unpack_from("<Q", data, start + 8)
    end = min(start + size, len(data))
    at = start + 16
    while at + _HEAP_OBJECT_HEADER <= end:
        index, _, _, length = struct.unpack_from("<HHIQ", data, at)
        if index == 0:  # free space to the end: its size counts its own header
            if length < _HEAP_OBJECT_HEADER or at + length != start + size:
                raise LogFormatError(
                    f"{path}: damaged HDF5 global heap at byte {start} (its free space is inconsistent)."
                )
            return
        at += _HEAP_OBJECT_HEADER + -(-length // 8) * 8
