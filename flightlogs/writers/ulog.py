"""Write valid PX4 ULog files from numpy columns, through pyulog's own writer.

Used by the simulator (:mod:`simulator.output.px4`) and for round-trip
tests. A :class:`TopicData` is one uORB topic instance as columns; field
types come from the numpy dtypes (``float32`` → ``float``, ``uint64`` →
``uint64_t``, ``bool`` → ``bool``, ``S<n>`` → ``char[n]``...) and a 2-D
column of shape ``(n_samples, k)`` becomes an array field ``type[k]``, read
back by pyulog as ``name[0]`` ... ``name[k-1]``. :func:`write_ulog` builds a
:class:`pyulog.core.ULog` in memory (formats, info messages, initial
parameters, subscriptions, data) and lets :meth:`pyulog.core.ULog.write_ulog`
serialise it, so what pyulog reads back is exactly what was given.
"""

from __future__ import annotations

import re
import struct
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

import numpy as np
from pyulog import ULog

from flightlogs.writers.atomic import atomic_output

__all__ = ["TopicData", "encode_ulog", "write_ulog"]

#: ULog type name of each numpy scalar type a field may have.
_ULOG_TYPES: Mapping[np.dtype, str] = MappingProxyType(
    {
        np.dtype(np.int8): "int8_t",
        np.dtype(np.uint8): "uint8_t",
        np.dtype(np.int16): "int16_t",
        np.dtype(np.uint16): "uint16_t",
        np.dtype(np.int32): "int32_t",
        np.dtype(np.uint32): "uint32_t",
        np.dtype(np.int64): "int64_t",
        np.dtype(np.uint64): "uint64_t",
        np.dtype(np.float32): "float",
        np.dtype(np.float64): "double",
        np.dtype(np.bool_): "bool",
    }
)
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_MAX_PAYLOAD = 65535  # a ULog message's 16-bit size
_MAX_PARAM_NAME = 16  # PX4 parameter names
_MAX_KEY = 255  # "type name" of an info message, 8-bit length
_LOG_LEVEL_INFO = ord("6")
_INT32 = (-(2**31), 2**31 - 1)


@dataclass(frozen=True, slots=True)
class TopicData:
    """One instance of one uORB topic, as columns.

    Parameters
    ----------
    name : str
        Topic name as PX4 logs it, e.g. ``"vehicle_angular_velocity"``.
    fields : Mapping[str, ndarray]
        Column per field, shape ``(n_samples,)`` for a scalar field or
        ``(n_samples, k)`` for an array field ``type[k]`` (e.g. ``q`` with
        ``k = 4``). The dtype gives the ULog type: ``int8`` ... ``uint64``,
        ``float32`` (``float``), ``float64`` (``double``), ``bool``, or
        ``S<n>`` (ASCII ``char[n]``, shape ``(n_samples,)``). A
        ``timestamp`` column, µs since boot, is required: any integer dtype
        with values ≥ 0, stored as ``uint64_t`` and written first; other
        fields keep their order.
    multi_id : int, optional
        Instance number, 0 to 255 (e.g. the second IMU is 1).

    Raises
    ------
    ValueError
        If a name is not an identifier, ``timestamp`` is missing, negative or
        not integer, columns differ in length, a dtype is not supported, or a
        message would exceed 65535 bytes.

    Examples
    --------
    >>> import numpy as np
    >>> topic = TopicData("battery_status", {"timestamp": np.array([10, 20]),
    ...                                      "voltage_v": np.float32([16.8, 16.7])})
    >>> len(topic), topic.format_fields()
    (2, (('uint64_t', 0, 'timestamp'), ('float', 0, 'voltage_v')))
    """

    name: str
    fields: Mapping[str, np.ndarray]
    multi_id: int = 0

    def __post_init__(self) -> None:
        if not _NAME.fullmatch(self.name):
            raise ValueError(f"topic name {self.name!r} must be an identifier ([A-Za-z_][A-Za-z0-9_]*)")
        if not 0 <= self.multi_id <= 255:
            raise ValueError(f"{self.name}: {self.multi_id=} must be within 0..255")
        if "timestamp" not in self.fields:
            raise ValueError(f"{self.name}: a 'timestamp' field (µs, integer) is required")
        columns = {"timestamp": _timestamps(self.name, self.fields["timestamp"])}
        for key, values in self.fields.items():
            if key != "timestamp":
                columns[key] = _column(self.name, key, values)
        lengths = {key: column.shape[0] for key, column in columns.items()}
        if len(set(lengths.values())) > 1:
            raise ValueError(f"{self.name}: columns must have one length, got {lengths}")
        size = 2 + sum(column.dtype.itemsize * _width(column) for column in columns.values())
        if size > _MAX_PAYLOAD:
            raise ValueError(f"{self.name}: a message would be {size} bytes (at most {_MAX_PAYLOAD})")
        for column in columns.values():
            column.setflags(write=False)
        object.__setattr__(self, "fields", MappingProxyType(columns))

    def __len__(self) -> int:
        return int(self.fields["timestamp"].shape[0])

    def format_fields(self) -> tuple[tuple[str, int, str], ...]:
        """The ULog format of the topic as pyulog holds it.

        Returns
        -------
        tuple of (str, int, str)
            ``(type, array_size, field_name)`` per field, ``array_size`` 0 for
            a scalar (``("float", 3, "xyz")`` is ``float[3] xyz``).
        """
        out = []
        for key, column in self.fields.items():
            if column.dtype.kind == "S":
                out.append(("char", column.dtype.itemsize, key))
            else:
                out.append((_ULOG_TYPES[column.dtype], column.shape[1] if column.ndim == 2 else 0, key))
        return tuple(out)


def _timestamps(topic: str, values: np.ndarray) -> np.ndarray:
    """The timestamp column as uint64, checked integer and non-negative."""
    stamps = np.asarray(values)
    if stamps.ndim != 1 or stamps.dtype.kind not in "iu":
        raise ValueError(
            f"{topic}.timestamp must be a 1-D integer array (µs), got {stamps.dtype} of shape {stamps.shape}"
        )
    if stamps.size and stamps.min() < 0:
        raise ValueError(f"{topic}.timestamp must be ≥ 0, got {stamps.min()}")
    return np.array(stamps, dtype=np.uint64)


def _column(topic: str, key: str, values: np.ndarray) -> np.ndarray:
    """A field column, checked: identifier name, supported dtype, 1-D or 2-D."""
    if not _NAME.fullmatch(key) or key.startswith("_padding"):
        raise ValueError(f"{topic}: field name {key!r} must be an identifier not starting with _padding")
    column = np.array(values)
    where = f"{topic}.{key}"
    if column.dtype.kind == "S":
        if column.ndim != 1 or column.dtype.itemsize == 0:
            raise ValueError(f"{where}: a char field needs shape (n_samples,) of bytes, got {column.shape}")
        raw = column.view(np.uint8)
        if raw.size and raw.max() > 127:
            raise ValueError(f"{where}: char fields hold ASCII only")
        return column
    if column.dtype.kind in "biuf" and not column.dtype.isnative:
        column = column.astype(column.dtype.newbyteorder("="))
    if column.dtype not in _ULOG_TYPES:
        raise ValueError(
            f"{where}: dtype {column.dtype} has no ULog type; use one of "
            f"{', '.join(str(d) for d in _ULOG_TYPES)} or S<n>"
        )
    if column.ndim not in (1, 2) or (column.ndim == 2 and column.shape[1] == 0):
        raise ValueError(f"{where}: shape {column.shape} must be (n_samples,) or (n_samples, k ≥ 1)")
    return column


def _width(column: np.ndarray) -> int:
    """Scalars per sample of a column (1 for scalars and char strings)."""
    return column.shape[1] if column.ndim == 2 and column.dtype.kind != "S" else 1


def encode_ulog(
    topics: Sequence[TopicData],
    *,
    info: Mapping[str, str | int | float | np.generic] | None = None,
    parameters: Mapping[str, int | float | np.number] | None = None,
    messages: Sequence[tuple[int, str]] = (),
) -> ULog:
    """Build the in-memory pyulog :class:`~pyulog.core.ULog` of a log.

    Parameters
    ----------
    topics : sequence of TopicData
        Data, one per (name, multi_id); instances of one topic must share
        their format (field names, order and types).
    info : Mapping[str, str or int or float or numpy scalar], optional
        Info messages (``sys_name``, ``ver_hw``, ``ver_sw``, ``sys_uuid``...):
        ``str`` → ``char[n]`` (UTF-8), ``int`` → ``int32_t`` (``uint32_t`` or
        ``int64_t`` if it does not fit), ``float`` → ``double``; a numpy
        scalar keeps its own type.
    parameters : Mapping[str, int or float or numpy number], optional
        Initial parameters, names up to 16 characters: ``int`` →
        ``int32_t``, ``float`` → ``float`` (float32).
    messages : sequence of (int, str), optional
        Logged strings ``(timestamp_us, text)`` at level INFO.

    Returns
    -------
    pyulog.core.ULog
        Ready for :meth:`~pyulog.core.ULog.write_ulog`; its ``data_list``
        holds the topics sorted by name and instance, message ids from 0.

    Raises
    ------
    ValueError
        If a (name, multi_id) repeats, instances of a topic differ in format,
        or an info key, parameter name or value cannot be written.
    """
    ulog = ULog(None)
    ulog._file_version = 1
    ordered = sorted(topics, key=lambda t: (t.name, t.multi_id))
    seen = [(t.name, t.multi_id) for t in ordered]
    if len(set(seen)) != len(seen):
        raise ValueError(f"each (topic, multi_id) may appear once, got {seen}")
    stamps = [int(t.fields["timestamp"].min()) for t in ordered if len(t)]
    stamps += [int(stamp) for stamp, _ in messages]
    ulog._start_timestamp = min(stamps, default=0)
    for topic in ordered:
        _add_format(ulog, topic)
    for msg_id, topic in enumerate(ordered):
        ulog._data_list.append(_data(ulog, topic, msg_id))
    for key, value in (info or {}).items():
        ulog._msg_info_dict[key], ulog._msg_info_dict_types[key] = _info_value(key, value)
    for name, value in (parameters or {}).items():
        ulog._initial_parameters[name] = _parameter_value(name, value)
    for stamp, text in messages:
        if not 0 <= int(stamp) < 2**64:
            raise ValueError(f"logged message {text!r}: timestamp {stamp} must be within 0..2**64-1 µs")
        payload = struct.pack("<BQ", _LOG_LEVEL_INFO, int(stamp)) + text.encode("utf-8")
        ulog._logged_messages.append(ULog.MessageLogging(payload, None))
    return ulog


def write_ulog(
    path: str | Path,
    topics: Sequence[TopicData],
    *,
    info: Mapping[str, str | int | float | np.generic] | None = None,
    parameters: Mapping[str, int | float | np.number] | None = None,
    messages: Sequence[tuple[int, str]] = (),
) -> Path:
    """Write a PX4 ULog file, through a temporary file renamed at the end.

    Parameters
    ----------
    path : str or Path
        Destination ``.ulg``; its folder must exist.
    topics : sequence of TopicData
        Data, as for :func:`encode_ulog`.
    info : Mapping[str, str or int or float or numpy scalar], optional
        Info messages, as for :func:`encode_ulog`.
    parameters : Mapping[str, int or float or numpy number], optional
        Initial parameters, as for :func:`encode_ulog`.
    messages : sequence of (int, str), optional
        Logged strings ``(timestamp_us, text)``.

    Returns
    -------
    Path
        `path`.

    Raises
    ------
    ValueError
        As :func:`encode_ulog`.

    Notes
    -----
    The file is ULog version 1 with no compat or incompat flags: header,
    flag bits, formats, info, parameters, then one subscription per topic
    instance and the data and logged strings sorted by timestamp (pyulog's
    writer sorts them, stably). pyulog packs every field of every sample in
    Python, about a microsecond each.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> from pyulog import ULog
    >>> gyro = TopicData("vehicle_angular_velocity", {
    ...     "timestamp": np.array([1000, 2000]), "xyz": np.float32([[0.1, 0, 0], [0.2, 0, 0]])})
    >>> path = write_ulog(pathlib.Path(tempfile.mkdtemp()) / "x.ulg", [gyro], info={"sys_name": "PX4"})
    >>> ULog(str(path)).get_dataset("vehicle_angular_velocity").data["xyz[0]"]
    array([0.1, 0.2], dtype=float32)
    """
    path = Path(path)
    ulog = encode_ulog(topics, info=info, parameters=parameters, messages=messages)
    with atomic_output(path) as tmp, tmp.open("wb") as stream:
        ulog.write_ulog(stream)
    return path


def _add_format(ulog: ULog, topic: TopicData) -> None:
    """Register the topic's format, parsed by pyulog from its text form."""
    text = (
        topic.name
        + ":"
        + "".join(f"{kind}[{size}] {key};" if size else f"{kind} {key};" for kind, size, key in topic.format_fields())
    )
    if len(text) > _MAX_PAYLOAD:
        raise ValueError(f"{topic.name}: the format message would be {len(text)} bytes (at most {_MAX_PAYLOAD})")
    parsed = ULog.MessageFormat(text.encode("ascii"), None)
    known = ulog._message_formats.get(topic.name)
    if known is not None and known.fields != parsed.fields:
        raise ValueError(
            f"{topic.name}[{topic.multi_id}]: format {parsed.fields} differs from that of "
            f"another instance, {known.fields}"
        )
    ulog._message_formats[topic.name] = parsed


def _data(ulog: ULog, topic: TopicData, msg_id: int) -> ULog.Data:
    """pyulog's Data of one topic instance: its subscription with the samples packed in."""
    subscription = ULog._MessageAddLogged(
        struct.pack("<BH", topic.multi_id, msg_id) + topic.name.encode("ascii"), None, ulog._message_formats
    )
    packed = np.zeros(len(topic), dtype=subscription.dtype)
    for key, column in topic.fields.items():
        if column.dtype.kind == "S":
            column = column.view(np.int8).reshape(len(topic), column.dtype.itemsize)
        if column.ndim == 2:
            for k in range(column.shape[1]):
                packed[f"{key}[{k}]"] = column[:, k]
        else:
            packed[key] = column
    subscription.buffer = bytearray(packed.tobytes())
    return ULog.Data(subscription)


def _info_value(key: str, value: object) -> tuple[object, str]:
    """An info message's value as pyulog stores it, and its ULog type."""
    if not _NAME.fullmatch(key) or len(key) > _MAX_KEY - len("char[65535] "):
        raise ValueError(f"info key {key!r} must be an identifier of at most {_MAX_KEY - 12} characters")
    if isinstance(value, str):
        size = len(value.encode("utf-8"))
        if size > _MAX_PAYLOAD - _MAX_KEY - 1:
            raise ValueError(f"info {key}: {size} bytes of text is too long for one message")
        return value, f"char[{size}]"
    if isinstance(value, np.generic) and value.dtype in _ULOG_TYPES and value.dtype != np.bool_:
        return value.item(), _ULOG_TYPES[value.dtype]
    if isinstance(value, int) and not isinstance(value, bool):
        for kind, low, high in (("int32_t", *_INT32), ("uint32_t", 0, 2**32 - 1), ("int64_t", -(2**63), 2**63 - 1)):
            if low <= value <= high:
                return value, kind
        raise ValueError(f"info {key}={value} does not fit 64 bits")
    if isinstance(value, float):
        return value, "double"
    raise ValueError(f"info {key}: {type(value).__name__} values cannot be written (str, int or float)")


def _parameter_value(name: str, value: object) -> int | float:
    """A parameter's value as pyulog writes it: int32 or float32."""
    if not _NAME.fullmatch(name) or len(name) > _MAX_PARAM_NAME:
        raise ValueError(f"parameter name {name!r} must be an identifier of at most {_MAX_PARAM_NAME} characters")
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"parameter {name}: bool is not a parameter type (use 0 or 1)")
    if isinstance(value, (int, np.integer)):
        if not _INT32[0] <= int(value) <= _INT32[1]:
            raise ValueError(f"parameter {name}={value} does not fit int32")
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(np.float32(value))
    raise ValueError(f"parameter {name}: {type(value).__name__} values cannot be written (int or float)")
