"""The batch's content-addressed cache: a result is kept under the hash of everything it was made from.

A log's survey is keyed by the log's bytes; a group's fit by its logs'
bytes, the wind files', the options and the software version. A re-run finds
unchanged work under the same key and skips it; anything changed gets a new
key (old entries are left, never wrongly reused). Entries are written whole
(temporary file, then rename), so an interrupted run leaves none half-written.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from flightlogs.store.schema import software_version
from flightlogs.writers.jsonio import write_json
from sysid.batch.results import GroupFit, LogSurvey

__all__ = ["CACHE_VERSION", "cache_key", "load_survey", "save_survey", "load_fit", "save_fit"]

#: Bumped when what an entry holds changes.
CACHE_VERSION = 2


def cache_key(*parts: str | Iterable[str]) -> str:
    """SHA-256 of the parts, the cache's version and the software's: the key of a result made from them.

    Parameters
    ----------
    *parts : str or iterable of str
        Texts (file hashes, options), each alone or a sequence of them.

    Returns
    -------
    str
        Hex digest.
    """
    digest = hashlib.sha256(f"flight-sysid batch cache {CACHE_VERSION} {software_version()}".encode())
    for part in parts:
        for text in [part] if isinstance(part, str) else part:
            digest.update(b"\0" + text.encode())
    return digest.hexdigest()


def load_survey(cache: Path, sha256: str, path: str) -> LogSurvey | None:
    """The cached survey of the log with these bytes (under its present path), or None.

    Parameters
    ----------
    cache : Path
        The cache folder.
    sha256 : str
        Hex digest of the log's bytes.
    path : str
        The log's present path.
    """
    doc = _read(cache / "survey" / f"{sha256}.json")
    if doc is None:
        return None
    return LogSurvey.from_dict(doc | {"path": path, "cached": True})


def save_survey(cache: Path, survey: LogSurvey) -> None:
    """Keep `survey` under its log's hash.

    Parameters
    ----------
    cache : Path
        The cache folder.
    survey : LogSurvey
        What to keep (its reason too, when the log cannot be read).
    """
    _write(cache / "survey" / f"{survey.sha256}.json", survey.to_dict() | {"cached": False})


def load_fit(cache: Path, key: str) -> GroupFit | None:
    """The cached fit under `key`, or None (also when a file it names has gone).

    Parameters
    ----------
    cache : Path
        The cache folder.
    key : str
        From :func:`cache_key`.
    """
    doc = _read(cache / "fit" / f"{key}.json")
    if doc is None:
        return None
    files = [doc[name] for name in ("model_file", "verification_file", "report_file") if doc[name]]
    if not all(Path(f).is_file() for f in files):
        return None
    return GroupFit.from_dict(doc | {"cached": True})


def save_fit(cache: Path, key: str, fit: GroupFit) -> None:
    """Keep `fit` under `key`.

    Parameters
    ----------
    cache : Path
        The cache folder.
    key : str
        From :func:`cache_key`.
    fit : GroupFit
        What to keep.
    """
    _write(cache / "fit" / f"{key}.json", fit.to_dict() | {"cached": False})


def _read(path: Path) -> dict[str, Any] | None:
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None  # absent, or not ours: recomputed and written again
    return doc if isinstance(doc, dict) else None


def _write(path: Path, doc: dict[str, Any]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    write_json(path, doc)


def _float(value: Any) -> float:
    return math.nan if value is None else float(value)
