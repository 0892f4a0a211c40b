"""The HDF5 dataset store: ingested logs and wind measurements, with provenance.

Layout (schema version 2; version 1 held variable-length strings, still read)::

    /                               attrs: schema, schema_version, software, created_utc
    /logs/<key>/                    attrs: path, sha256, log_format, autopilot, vehicle,
                                           board_id, vehicle_type (absent in files written before them: ""),
                                           utc_offset_s (NaN when unknown), warnings (JSON)
    /logs/<key>/parameters          compound dataset (name, value)
    /logs/<key>/system_id_runs      compound dataset, one row per ArduPilot SIDS run (fields of SystemIdRun)
    /logs/<key>/signals/<name>/     attrs: unit, source
    /logs/<key>/signals/<name>/time_s   float64 (n_samples,), s, log clock: a hard link into
                                           /logs/<key>/times/<i>, where each distinct time array is stored once
    /logs/<key>/signals/<name>/values   float64 (n_samples,), in `unit`
    /wind/<key>/                    attrs: path, sha256, and the measurement's scalar
                                           fields; JSON for mappings and tuples
    /wind/<key>/<array field>       float64 (n_samples,) (``utc_s`` in UNIX s, winds m/s)
    /conditioned/<key>/             attrs: source, rate_hz, warnings (JSON), derived (JSON: the signals
                                           computed, not measured), wind_alignment (JSON or "null")
    /conditioned/<key>/segments     compound (axis, kind, start_s, end_s, source, f_min_hz, f_max_hz, detail)
    /conditioned/<key>/records/<i>/ attrs: label, units (JSON), trim (JSON)
    /conditioned/<key>/records/<i>/time_s, /<signal>   float64 (n_samples,), trim removed

Text (attributes and the compound tables' string fields) is fixed-length UTF-8, and the file is
in HDF5's checksummed 1.10 format (:mod:`flightlogs.store.schema`). Arrays are LZF-compressed after byte shuffling (h5py reads them as any other). ``<key>`` is the file's
stem, made unique with a numeric suffix. Later steps
add groups of their own beside these (aligned records, segments); a reader
ignores groups it does not know.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import h5py
import numpy as np

from flightlogs._arrays import ByContents
from flightlogs.flightlog import FlightLog, Signal, SystemIdRun, WindMeasurement
from flightlogs.store.hashing import file_sha256
from flightlogs.store.schema import create_schema_file, open_schema, put_text, stamp_schema, text, text_dtype
from flightlogs.writers.atomic import atomic_output
from flightlogs.writers.jsonio import jsonable

if TYPE_CHECKING:  # conditioning loads when a dataset holds conditioned flights
    from flightlogs.conditioning.condition import ConditionedFlight

#: Time arrays' filter: LZF (in every h5py build) after byte shuffling; steady steps shrink well. Signal
#: values are stored plain: measured on a 113 MB log's signals and records, LZF took 1.2 s of a 1.5 s
#: write to save 38 % of the file, and most of that saving is had by storing in float32 the values the
#: log held as float32 (:func:`_narrowed`), at no cost in time.
_COMPRESSION: dict[str, Any] = {"compression": "lzf", "shuffle": True}

__all__ = ["Dataset", "write_dataset", "read_dataset", "SCHEMA_VERSION"]

SCHEMA = "flight-sysid dataset"
SCHEMA_VERSION = 2


@dataclass(frozen=True, slots=True, kw_only=True)
class Dataset:
    """What a dataset file holds.

    Parameters
    ----------
    logs : tuple of FlightLog
        Ingested flight logs, in the order they were written.
    winds : tuple of WindMeasurement
        Wind measurements.
    conditioned : tuple of ConditionedFlight
        Conditioned flights.
    sha256 : dict
        Hash of each source file as it was at ingest, by path string.
    schema_version : int
        Layout version of the file read.
    """

    logs: tuple[FlightLog, ...]
    winds: tuple[WindMeasurement, ...] = ()
    conditioned: tuple[ConditionedFlight, ...] = ()
    sha256: dict[str, str] = dataclasses.field(default_factory=dict)
    schema_version: int = SCHEMA_VERSION


def write_dataset(
    path: str | Path,
    logs: Sequence[FlightLog],
    winds: Sequence[WindMeasurement] = (),
    conditioned: Sequence[ConditionedFlight] = (),
) -> Path:
    """Write logs, wind measurements and conditioned flights to an HDF5 dataset, atomically.

    Parameters
    ----------
    path : str or Path
        Destination ``.h5``; replaced only once the whole file is written.
    logs : sequence of FlightLog
        Logs to store.
    winds : sequence of WindMeasurement, optional
        Anemometer measurements to store.
    conditioned : sequence of ConditionedFlight, optional
        Aligned records, segments and alignment of each flight.

    Returns
    -------
    Path
        The file written.
    """
    with atomic_output(path) as tmp, create_schema_file(tmp) as h5:
        stamp_schema(h5, SCHEMA, SCHEMA_VERSION)
        log_group = h5.create_group("logs")
        for log in logs:
            _write_log(log_group.create_group(_unique_key(log_group, log.path)), log)
        wind_group = h5.create_group("wind")
        for wind in winds:
            _write_dataclass(wind_group.create_group(_unique_key(wind_group, wind.path)), wind)
        flights = h5.create_group("conditioned")
        for flight in conditioned:
            _write_conditioned(flights.create_group(_unique_key(flights, flight.source)), flight)
    return Path(path)


def read_dataset(path: str | Path) -> Dataset:
    """Read a dataset written by :func:`write_dataset`.

    Parameters
    ----------
    path : str or Path
        The ``.h5`` file.

    Raises
    ------
    LogFormatError
        If the file is not an HDF5 dataset of this schema, or of a newer version.
    """
    path = Path(path)
    with open_schema(
        path,
        SCHEMA,
        SCHEMA_VERSION,
        what="dataset",
        not_hdf5="an HDF5 dataset",
        wrong_schema="HDF5 file is not a flight-sysid dataset.",
    ) as (h5, version):
        logs = tuple(_read_log(group) for group in h5["logs"].values())
        sha = {text(g.attrs["path"]): text(g.attrs["sha256"]) for g in h5["logs"].values()}
        winds = tuple(_read_wind(group) for group in _members(h5, "wind"))
        sha.update({text(g.attrs["path"]): text(g.attrs["sha256"]) for g in _members(h5, "wind")})
        conditioned = tuple(_read_conditioned(g) for g in _members(h5, "conditioned"))
    return Dataset(logs=logs, winds=winds, conditioned=conditioned, sha256=sha, schema_version=version)


def _members(h5: h5py.File, name: str) -> list[Any]:
    """The members of the optional group `name`: none when there is no such link; a group that is linked but
    cannot be opened (damaged) raises, where ``h5.get`` would answer with its default."""
    return list(h5[name].values()) if name in h5 else []


def _unique_key(group: h5py.Group, path: Path) -> str:
    stem = Path(path).stem.replace("/", "_") or "log"
    key, n = stem, 1
    while key in group:
        n += 1
        key = f"{stem}_{n}"
    return key


class _SharedTimes:
    """A log's time arrays, each stored once: signals of one message share theirs (HDF5 hard links)."""

    def __init__(self, group: h5py.Group) -> None:
        self._group = group.create_group("times")
        self._stored: ByContents[h5py.Dataset] = ByContents()

    def dataset(self, time_s: np.ndarray) -> h5py.Dataset:
        """The dataset holding `time_s` (s, shape (n,)): one written before with equal values, or a new one."""
        stored = self._stored.get(time_s)
        if stored is None:
            stored = self._group.create_dataset(str(len(self._group)), data=time_s, **_COMPRESSION)
            self._stored.put(time_s, stored)
        return stored


def _source_hash(path: Path) -> str:
    return file_sha256(path) if Path(path).is_file() else ""


def _write_log(group: h5py.Group, log: FlightLog) -> None:
    for name, value in (
        ("path", str(log.path)),
        ("sha256", _source_hash(log.path)),
        ("log_format", log.log_format),
        ("autopilot", log.autopilot),
        ("vehicle", log.vehicle),
        ("board_id", log.board_id),
        ("vehicle_type", log.vehicle_type),
        ("warnings", json.dumps(list(log.warnings))),
    ):
        put_text(group.attrs, name, value)
    group.attrs["utc_offset_s"] = np.nan if log.utc_offset_s is None else log.utc_offset_s
    parameters = [(name, float(log.parameters[name])) for name in sorted(log.parameters)]
    group.create_dataset("parameters", data=_table((("name", "S"), ("value", "f8")), parameters))
    runs = [dataclasses.astuple(run) for run in log.system_id_runs]
    group.create_dataset("system_id_runs", data=_table(_RUN_FIELDS, runs))
    signals = group.create_group("signals")
    times = _SharedTimes(group)
    for name, signal in log.signals.items():
        sub = signals.create_group(name)
        put_text(sub.attrs, "unit", signal.unit)
        put_text(sub.attrs, "source", signal.source)
        if signal.derived:
            sub.attrs["derived"] = True
        sub["time_s"] = times.dataset(signal.time_s)
        sub.create_dataset("values", data=_narrowed(signal.stored_values))


def _table(fields: Sequence[tuple[str, str]], rows: Sequence[tuple[Any, ...]]) -> np.ndarray:
    """A compound array of `rows` (n,), its ``"S"`` fields fixed-length UTF-8 as long as their longest value."""
    columns = list(zip(*rows, strict=True)) if rows else [() for _ in fields]
    dtype = [
        (name, text_dtype(list(column)) if kind == "S" else kind)
        for (name, kind), column in zip(fields, columns, strict=True)
    ]
    encoded = [
        tuple(v.encode("utf-8") if kind == "S" else v for (_, kind), v in zip(fields, row, strict=True)) for row in rows
    ]
    return np.array(encoded, dtype=dtype)


def _narrowed(values: np.ndarray) -> np.ndarray:
    """`values` in float32 when that holds every one of them exactly (a log's float32 fields), else as they are."""
    if values.dtype != np.float64:
        return values
    single = values.astype(np.float32)
    return single if np.array_equal(single, values, equal_nan=True) else values


def _read_log(group: h5py.Group) -> FlightLog:
    signals = {
        name: Signal(
            name=name,
            time_s=sub["time_s"][()],
            values=sub["values"][()],  # float32 where the log logged float32: held so (Signal)
            unit=text(sub.attrs["unit"]),
            source=text(sub.attrs["source"]),
            derived=bool(sub.attrs.get("derived", False)),
        )
        for name, sub in group["signals"].items()
    }
    table = group["parameters"][()]
    parameters = {text(row["name"]): float(row["value"]) for row in table}
    offset = float(group.attrs["utc_offset_s"])
    runs = tuple(_run_from_row(row) for row in group["system_id_runs"][()]) if "system_id_runs" in group else ()
    return FlightLog(
        path=Path(text(group.attrs["path"])),
        log_format=text(group.attrs["log_format"]),  # type: ignore[arg-type]
        autopilot=text(group.attrs["autopilot"]),  # type: ignore[arg-type]
        signals=signals,
        vehicle=text(group.attrs["vehicle"]),
        board_id=text(group.attrs["board_id"]) if "board_id" in group.attrs else "",
        parameters=parameters,
        utc_offset_s=None if np.isnan(offset) else offset,
        warnings=tuple(json.loads(group.attrs["warnings"])),
        system_id_runs=runs,
        vehicle_type=text(group.attrs["vehicle_type"]) if "vehicle_type" in group.attrs else "",
    )


#: The SIDS runs' table fields and their types (``axis_name``'s string length is set per file).
_RUN_FIELDS = tuple(
    (f.name, "S" if f.name == "axis_name" else ("i8" if f.name == "axis" else "f8"))
    for f in dataclasses.fields(SystemIdRun)
)


def _run_from_row(row: np.void) -> SystemIdRun:
    numbers = {
        name: float(row[name])
        for name in ("magnitude", "f_start_hz", "f_stop_hz", "fade_in_s", "const_s", "record_s", "fade_out_s")
    }
    return SystemIdRun(
        start_s=float(row["start_s"]),
        end_s=float(row["end_s"]),
        axis=int(row["axis"]),
        axis_name=text(row["axis_name"]),
        **numbers,
    )


def _write_dataclass(group: h5py.Group, item: Any) -> None:
    """Store a frozen dataclass: arrays as datasets, the rest as attributes."""
    put_text(group.attrs, "sha256", _source_hash(item.path))
    for field in dataclasses.fields(item):
        value = getattr(item, field.name)
        if isinstance(value, np.ndarray):
            group.create_dataset(field.name, data=value, **_COMPRESSION)
        elif isinstance(value, (str, Path)):
            put_text(group.attrs, field.name, str(value))
        elif value is None:
            put_text(group.attrs, field.name, "null")
            group.attrs[f"{field.name}.json"] = True
        elif isinstance(value, (int, float, bool, np.floating, np.integer)):
            group.attrs[field.name] = value
        else:
            put_text(group.attrs, field.name, json.dumps(jsonable(value, nonfinite="keep")))
            group.attrs[f"{field.name}.json"] = True


def _read_wind(group: h5py.Group) -> WindMeasurement:
    kwargs: dict[str, Any] = {}
    for field in dataclasses.fields(WindMeasurement):
        if field.name in group:
            kwargs[field.name] = group[field.name][()]
        elif field.name in group.attrs:
            raw = group.attrs[field.name]
            raw = text(raw) if isinstance(raw, (bytes, str)) else raw
            if group.attrs.get(f"{field.name}.json", False):
                raw = json.loads(raw)
                raw = tuple(raw) if isinstance(raw, list) else raw
            kwargs[field.name] = raw
    kwargs["path"] = Path(kwargs["path"])
    return WindMeasurement(**kwargs)


#: The segments table's fields: "S" a text field, its length set per file by the longest value.
_SEGMENT_FIELDS = (
    ("axis", "S"),
    ("kind", "S"),
    ("start_s", "f8"),
    ("end_s", "f8"),
    ("source", "S"),
    ("f_min_hz", "f8"),
    ("f_max_hz", "f8"),
    ("detail", "S"),
)


def _write_conditioned(group: h5py.Group, flight: Any) -> None:
    put_text(group.attrs, "source", str(flight.source))
    group.attrs["rate_hz"] = flight.rate_hz
    put_text(group.attrs, "warnings", json.dumps(list(flight.warnings)))
    put_text(group.attrs, "derived", json.dumps(list(flight.derived)))
    put_text(group.attrs, "wind_alignment", json.dumps(jsonable(flight.wind, nonfinite="keep")))
    rows = [
        (
            s.axis or "",
            s.kind,
            s.start_s,
            s.end_s,
            s.source,
            np.nan if s.f_min_hz is None else s.f_min_hz,
            np.nan if s.f_max_hz is None else s.f_max_hz,
            s.detail,
        )
        for s in flight.segments
    ]
    group.create_dataset("segments", data=_table(_SEGMENT_FIELDS, rows))
    records = group.create_group("records")
    for k, record in enumerate(flight.records):
        sub = records.create_group(str(k))
        put_text(sub.attrs, "label", record.label)
        put_text(sub.attrs, "units", json.dumps(dict(record.units)))
        put_text(sub.attrs, "trim", json.dumps(dict(record.trim)))
        sub.create_dataset("time_s", data=record.time_s)
        for name in record.signals:
            sub.create_dataset(name, data=record[name])


def _read_conditioned(group: h5py.Group) -> Any:
    from flightlogs.conditioning.align import WindAlignment
    from flightlogs.conditioning.condition import ConditionedFlight
    from flightlogs.conditioning.lag import LagEstimate, TransportDelay
    from flightlogs.maneuvers.segments import Segment
    from flightlogs.record import Record

    segments = tuple(
        Segment(
            axis=cast(Any, text(row["axis"]) or None),
            kind=cast(Any, text(row["kind"])),
            start_s=float(row["start_s"]),
            end_s=float(row["end_s"]),
            source=cast(Any, text(row["source"])),
            f_min_hz=None if np.isnan(row["f_min_hz"]) else float(row["f_min_hz"]),
            f_max_hz=None if np.isnan(row["f_max_hz"]) else float(row["f_max_hz"]),
            detail=text(row["detail"]),
        )
        for row in group["segments"][()]
    )
    source = Path(text(group.attrs["source"]))
    records = []
    for key in sorted(group["records"], key=int):
        sub = group["records"][key]
        units = json.loads(sub.attrs["units"])
        records.append(
            Record(
                time_s=sub["time_s"][()],
                columns={name: sub[name][()] for name in units},
                units=units,
                trim=json.loads(sub.attrs["trim"]),
                source=source,
                label=text(sub.attrs["label"]),
            )
        )
    raw = json.loads(group.attrs["wind_alignment"])
    wind = None
    if raw is not None:
        raw["wind_path"] = Path(raw["wind_path"])
        raw["transport"] = TransportDelay(**raw["transport"])
        raw["residual"] = None if raw["residual"] is None else LagEstimate(**raw["residual"])
        wind = WindAlignment(**raw)
    return ConditionedFlight(
        source=source,
        records=tuple(records),
        segments=segments,
        rate_hz=float(group.attrs["rate_hz"]),
        wind=wind,
        warnings=tuple(json.loads(group.attrs["warnings"])),
        derived=tuple(json.loads(group.attrs.get("derived", "[]"))),
    )
