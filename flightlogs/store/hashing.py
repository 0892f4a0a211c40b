"""SHA-256 of input files: the provenance of what a dataset, a model or a verification was made from.

Its own module, without h5py: a fit that reads logs records their hashes and loads no HDF5.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

__all__ = ["file_sha256"]


def file_sha256(path: str | Path) -> str:
    """SHA-256 hex digest of a file's bytes (provenance of ingested inputs).

    Parameters
    ----------
    path : str or Path
        File to hash.

    Returns
    -------
    str
        64 lower-case hex digits.
    """
    digest = hashlib.sha256()
    with Path(path).open("rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()
