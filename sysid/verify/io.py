"""A time-domain verification on disk: versioned JSON with every time history, so a report can be redrawn.

``sysid validate --json`` prints a summary (errors and TIC per output); this
file keeps the whole :class:`~sysid.verify.Verification`: per record the
measured, simulated and one-step-ahead time histories, biases and reference
shifts, with and without the wind term. Non-finite numbers are written as
``null``; floats keep every digit, so a file read back redraws the same
report. Files are written atomically.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from types import MappingProxyType
from typing import Any

from flightlogs.errors import DataError
from sysid._json import finite_or_none as _num
from sysid._json import float_or_nan as _float
from sysid._json import read_json_object, write_json
from sysid.verify.results import OutputSummary, RecordVerification, Verification, WindCorrection

__all__ = [
    "VERIFICATION_SCHEMA",
    "VERIFICATION_SCHEMA_VERSION",
    "SavedVerification",
    "verification_to_dict",
    "verification_from_dict",
    "write_verification",
    "read_verification",
    "require_verified_model",
]

VERIFICATION_SCHEMA = "flight-sysid/verification"
VERIFICATION_SCHEMA_VERSION = 2
_READABLE_VERSIONS = (1, 2)  # version 1 had no excited input, off-axis outputs or off-axis summary


@dataclass(frozen=True, slots=True, kw_only=True)
class SavedVerification:
    """A verification with what it was run on and with.

    Parameters
    ----------
    verification : Verification
        The result of :func:`sysid.verify.verify`.
    model : str, optional
        The model file verified (its name or path).
    model_sha256 : str, optional
        SHA-256 of that file's bytes when it was verified ("" in files written before it was kept).
    options : Mapping[str, Any], optional
        Options of the verification (JSON-compatible: initial state, seconds
        kept before and after each doublet ...).
    created_utc : str, optional
        ISO 8601 time the verification was run.
    """

    verification: Verification
    model: str = ""
    model_sha256: str = ""
    options: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    created_utc: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "options", MappingProxyType(dict(self.options)))


def verification_to_dict(
    verification: Verification,
    *,
    model: str = "",
    model_sha256: str = "",
    options: Mapping[str, Any] | None = None,
    created_utc: str = "",
) -> dict[str, Any]:
    """The JSON document of a verification (schema ``flight-sysid/verification`` version 2).

    Parameters
    ----------
    verification : Verification
        The result to save.
    model : str, optional
        The model file verified.
    model_sha256 : str, optional
        SHA-256 of the model file's bytes (:func:`flightlogs.store.hashing.file_sha256`).
    options : Mapping[str, Any], optional
        JSON-compatible options of the verification.
    created_utc : str, optional
        ISO 8601 time of the verification.

    Returns
    -------
    dict
        JSON-compatible (non-finite numbers as None).
    """
    v = verification

    return {
        "schema": VERIFICATION_SCHEMA,
        "schema_version": VERIFICATION_SCHEMA_VERSION,
        "model": model,
        "model_sha256": model_sha256,
        "options": dict(options or {}),
        "created_utc": created_utc,
        "rmse": _num(v.rmse),
        "tic": _num(v.tic),
        "summary": [s.to_dict() for s in v.summary],
        "off_axis": [s.to_dict() for s in v.off_axis],
        "records": [r.to_dict() for r in v.records],
        "without_wind": [r.to_dict() for r in v.without_wind],
        "wind_correction": [c.to_dict() for c in v.wind_correction],
        "unverified": list(v.unverified),
    }


def verification_from_dict(doc: Mapping[str, Any], *, source: str = "<dict>") -> SavedVerification:
    """Rebuild a saved verification from its JSON document.

    Parameters
    ----------
    doc : Mapping[str, Any]
        As written by :func:`verification_to_dict`.
    source : str, optional
        Where it came from, for error messages.

    Returns
    -------
    SavedVerification

    Raises
    ------
    DataError
        If the document is not a saved verification of a known version, or is damaged.
    """
    if doc.get("schema") != VERIFICATION_SCHEMA:
        if "summary" in doc and "overall" in doc:
            raise DataError(
                f"{source}: this is the summary printed by 'sysid validate --json', which holds no time "
                "histories; give a verification saved with its time histories (schema "
                f"{VERIFICATION_SCHEMA})"
            )
        raise DataError(f"{source}: not a flight-sysid verification file (schema {doc.get('schema')!r})")
    if doc.get("schema_version") not in _READABLE_VERSIONS:
        raise DataError(
            f"{source}: verification schema version {doc.get('schema_version')!r} is not supported "
            f"(this version reads {', '.join(map(str, _READABLE_VERSIONS))})"
        )
    try:
        verification = Verification(
            records=tuple(RecordVerification.from_dict(r) for r in doc["records"]),
            summary=tuple(OutputSummary.from_dict(s) for s in doc["summary"]),
            rmse=_float(doc["rmse"]),
            tic=_float(doc["tic"]),
            without_wind=tuple(RecordVerification.from_dict(r) for r in doc.get("without_wind", [])),
            wind_correction=tuple(WindCorrection.from_dict(c) for c in doc.get("wind_correction", [])),
            off_axis=tuple(OutputSummary.from_dict(s) for s in doc.get("off_axis", [])),
            unverified=tuple(str(text) for text in doc.get("unverified", [])),
        )
        return SavedVerification(
            verification=verification,
            model=str(doc.get("model", "")),
            model_sha256=str(doc.get("model_sha256", "")),
            options=dict(doc.get("options") or {}),
            created_utc=str(doc.get("created_utc", "")),
        )
    except (KeyError, TypeError, ValueError, AttributeError) as err:
        raise DataError(f"{source}: verification file is incomplete or damaged ({type(err).__name__}: {err})") from err


def write_verification(
    path: str | Path,
    verification: Verification,
    *,
    model: str | Path = "",
    options: Mapping[str, Any] | None = None,
    created_utc: str | None = None,
) -> Path:
    """Write a verification as versioned JSON, atomically.

    Parameters
    ----------
    path : str or Path
        Destination (``validation.json``); its folder must exist.
    verification : Verification
        The result to save.
    model : str or Path, optional
        The model file verified: a `Path` keeps its name and the SHA-256 of its bytes (by which a report
        checks it is given the model verified, :func:`require_verified_model`); a `str` its name only.
    options : Mapping[str, Any], optional
        JSON-compatible options of the verification.
    created_utc : str, optional
        ISO 8601 time of the verification (default: now).

    Returns
    -------
    Path
        The path written.

    Examples
    --------
    >>> import tempfile
    >>> import numpy as np
    >>> from sysid.verify.results import OutputVerification
    >>> t = np.arange(3) * 0.01
    >>> out = OutputVerification(name="q", unit="rad/s", measured=np.array([0.0, 1.0, 0.0]),
    ...                          simulated=np.array([0.0, 0.9, 0.1]), bias=0.0, rmse=0.08, tic=0.05)
    >>> record = RecordVerification(label="lon doublet", source=Path("f.bin"), time_s=t, inputs=("delta_lon",),
    ...                             outputs=(out,), reference_shifts={}, rmse=4.6, tic=0.05, growth=1.0,
    ...                             unstable=False)
    >>> verification = Verification(records=(record,), summary=(), rmse=4.6, tic=0.05)
    >>> path = write_verification(Path(tempfile.mkdtemp()) / "v.json", verification)
    >>> read_verification(path).verification.records[0].output("q").simulated.tolist()
    [0.0, 0.9, 0.1]
    """
    sha256 = ""
    if isinstance(model, Path):
        from flightlogs.store.hashing import file_sha256

        model, sha256 = model.name, file_sha256(model)
    if created_utc is None:
        created_utc = datetime.now(UTC).isoformat(timespec="seconds")
    document = verification_to_dict(
        verification, model=model, model_sha256=sha256, options=options, created_utc=created_utc
    )
    return write_json(path, document)


def require_verified_model(saved: SavedVerification, model_path: str | Path, *, source: str = "verification") -> None:
    """Refuse a verification of another model than `model_path`'s.

    Parameters
    ----------
    saved : SavedVerification
        The verification read.
    model_path : str or Path
        The model file it is to be reported with.
    source : str, optional
        The verification's file, for the message.

    Raises
    ------
    DataError
        When the file it verified had other contents (SHA-256) or, in a file that kept no hash, another name.
    """
    model_path = Path(model_path)
    if saved.model_sha256:
        from flightlogs.store.hashing import file_sha256

        same = file_sha256(model_path) == saved.model_sha256
    else:
        same = not saved.model or Path(saved.model).name == model_path.name
    if not same:
        verified = Path(saved.model).name or "another model"
        raise DataError(
            f"{source}: verifies {verified}, not {model_path} (the files differ); a report shows a model with "
            "its own verification: verify this model, or give the model that was verified"
        )


def read_verification(path: str | Path) -> SavedVerification:
    """Read a verification written by :func:`write_verification`.

    Parameters
    ----------
    path : str or Path
        A verification JSON file.

    Returns
    -------
    SavedVerification

    Raises
    ------
    DataError
        If the file cannot be read or is not a verification file of a supported version.
    """
    return verification_from_dict(read_json_object(path, DataError, "verification"), source=str(path))
