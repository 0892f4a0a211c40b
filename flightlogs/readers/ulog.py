"""Read PX4 ULog files (through pyulog) into canonical signals.

pyulog parses; this module wraps it so that a bad file raises
:class:`~flightlogs.errors.LogFormatError` with one sentence naming the file,
recoverable damage becomes a :class:`~flightlogs.errors.LogCorruptionWarning`
whose sentence is kept in ``FlightLog.warnings`` (pyulog only sets a flag and
prints), and topics become canonical signals through the table in
:mod:`flightlogs.readers.px4_topics`.
"""

from __future__ import annotations

import contextlib
import io
import os
import struct
import warnings as _warnings
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from pyulog import ULog
from pyulog.exceptions import ULogException, ULogIncompatibleFlagException

from flightlogs.errors import DataQualityWarning, LogCorruptionWarning, LogFormatError, collected_warnings
from flightlogs.flightlog import FlightLog, Signal
from flightlogs.frames import quaternion_to_euler
from flightlogs.readers._series import make_signal
from flightlogs.readers._ulog_fast import FastPathDeclined, FastULog, WholeFile, scan_clean
from flightlogs.readers.px4_topics import (
    GPS_TOPICS,
    MAPPED_TOPICS,
    PX4_GROUPS,
    PX4_MOTOR_SOURCES,
    MotorSource,
    SignalGroup,
    TopicSource,
    describe_vehicle,
    px4_vehicle_type,
    rotor_count,
)

__all__ = ["read_ulog"]

_ULOG_MAGIC = b"ULog\x01\x12\x35"
_HEADER_BYTES = 16
_MAX_PAYLOAD = 65535  # a ULog message payload is at most this long (16-bit size)
_WHOLE_FILE_LIMIT = 1 << 28  # files up to 256 MB are read into memory when their messages chain cleanly
#: Files up to this size have every topic read (pyulog then also checks the messages of the topics no signal
#: comes from, and their damage is reported); larger ones only the topics of
#: :data:`~flightlogs.readers.px4_topics.MAPPED_TOPICS`: a 1 GB log's other topics are not held in memory.
_EVERY_TOPIC_UP_TO = _WHOLE_FILE_LIMIT
_STALL_READS = 400_000  # reads with nothing new: pyulog loops (walking garbage re-reads < 2 * 65535)
_MIN_UTC_US = 946_684_800_000_000  # 2000-01-01: GPS time before this is a receiver default
_DOWNWARD = 25  # distance_sensor.orientation ROTATION_DOWNWARD_FACING
_ARMED = 2  # vehicle_status.arming_state ARMING_STATE_ARMED
_PYULOG_ERRORS = (
    ULogException,
    struct.error,
    IndexError,
    KeyError,
    ValueError,
    UnicodeDecodeError,
    OverflowError,
    TypeError,
    AttributeError,
)

_Datasets = dict[str, dict[int, Mapping[str, np.ndarray]]]
#: A pyulog reader class: ``kind(source, topics)`` parses `source`, keeping `topics` (None: every one).
_Reader = Callable[[Any, frozenset[str] | None], "_PlainULog | FastULog"]


def read_ulog(path: str | os.PathLike[str], *, progress: Callable[[int, int], None] | None = None) -> FlightLog:
    """Read a PX4 ULog file into canonical signals.

    Parameters
    ----------
    path : str or PathLike
        The ``.ulg`` file.
    progress : callable, optional
        ``progress(done, total)`` in bytes of the file, called at the start,
        while pyulog parses, and at the end (``done == total``).

    Returns
    -------
    FlightLog
        Signals on the log clock (``time_s`` = ULog ``timestamp`` µs / 1e6),
        each with its ``"topic[instance].field"`` source; vehicle description
        from the info messages and airframe parameters; initial parameters;
        ``utc_offset_s`` from GPS time; warnings for anything recovered from.

    Raises
    ------
    LogFormatError
        If the file cannot be opened, is empty, is not a ULog, is cut inside
        its header, or holds no data message pyulog could read.

    Warns
    -----
    LogCorruptionWarning
        For each kind of damage read past (truncation, unknown message ids,
        unreadable bytes or parameters, pyulog's own complaints).
    DataQualityWarning
        For logging dropouts, samples dropped as invalid, and signals or
        motors that could not be read; every message is also in ``warnings``.

    Notes
    -----
    Topics map to signals through :data:`flightlogs.readers.px4_topics.PX4_GROUPS`
    (first usable source and instance wins). Samples with timestamp 0, or
    flagged invalid by the topic (``v_xy_valid``, ``z_valid``...), are
    dropped and counted in a warning; a signal with fewer than two samples
    left is reported missing. ``utc_offset_s`` is the median of
    ``time_utc_usec - timestamp`` over GPS samples with a time set
    (after 2000-01-01). A file over 256 MB has only the topics signals come
    from read (:data:`~flightlogs.readers.px4_topics.MAPPED_TOPICS`): damage
    in its other topics goes unreported, as they are not read.

    Examples
    --------
    >>> from pathlib import Path
    >>> read_ulog(Path("no-such-file.ulg"))
    Traceback (most recent call last):
    ...
    flightlogs.errors.LogFormatError: no-such-file.ulg: cannot be read (No such file or directory).
    """
    path = Path(path)
    size = _check_header(path)
    if progress is not None:
        progress(0, size)
    with collected_warnings() as caught:
        large = size > _EVERY_TOPIC_UP_TO
        ulog = _parse(path, size, progress, MAPPED_TOPICS if large else None)
        datasets = _datasets(ulog)
        if large and not datasets:  # none of the mapped topics: every topic, to tell a log of others from an empty one
            caught.discard()
            ulog = _parse(path, size, None, None)
            datasets = _datasets(ulog)
        if not datasets:
            detail = f" ({caught.messages[0]})" if caught.messages else ""
            caught.discard()  # the error names the damage
            raise LogFormatError(
                f"{path}: holds no readable data message ({size} bytes): it is truncated or damaged "
                f"before the first one{detail}."
            )
        parameters = _parameters(ulog.initial_parameters)
        signals: dict[str, Signal] = {}
        with np.errstate(invalid="ignore"):  # damaged floats (signalling NaN) become NaN, then dropped
            for group in PX4_GROUPS:
                signals.update(_map_group(group, datasets))
            signals.update(_map_motors(datasets, parameters))
            utc_offset_s = _utc_offset(datasets)
        log = FlightLog(
            path=path,
            log_format="ulog",
            autopilot="px4",
            signals=signals,
            vehicle=describe_vehicle(ulog.msg_info_dict, parameters),
            vehicle_type=px4_vehicle_type(parameters),
            board_id=str(ulog.msg_info_dict.get("sys_uuid", "")),
            parameters=parameters,
            utc_offset_s=utc_offset_s,
            warnings=caught.messages,
        )
    if progress is not None:
        progress(size, size)
    return log


def _datasets(ulog: ULog) -> _Datasets:
    """The data pyulog read, by topic and instance (a topic whose damaged format lost its timestamp left out)."""
    datasets: _Datasets = {}
    for dataset in ulog.data_list:
        if "timestamp" in dataset.data:
            datasets.setdefault(dataset.name, {})[dataset.multi_id] = dataset.data
    return datasets


def _check_header(path: Path) -> int:
    """Check the 16-byte ULog header ourselves, for messages pyulog cannot give; return the size."""
    try:
        with path.open("rb") as stream:
            head = stream.read(_HEADER_BYTES)
            size = os.fstat(stream.fileno()).st_size
    except OSError as err:
        raise LogFormatError(f"{path}: cannot be read ({err.strerror or err}).") from err
    if not head:
        raise LogFormatError(f"{path}: the file is empty.")
    if not head.startswith(_ULOG_MAGIC[: len(head)]):
        if head.startswith(b"\xa3\x95"):
            raise LogFormatError(
                f"{path}: not a PX4 ULog but, by its first bytes ({head[:8].hex(' ')}), an ArduPilot DataFlash log."
            )
        raise LogFormatError(
            f"{path}: not a PX4 ULog (first bytes {head[:8].hex(' ')}, "
            f"where a ULog starts with {_ULOG_MAGIC.hex(' ')})."
        )
    if len(head) < _HEADER_BYTES:
        raise LogFormatError(f"{path}: truncated inside the ULog header at byte {len(head)} ({_HEADER_BYTES} needed).")
    return size


class _TrackedFile:
    """A read-only file for pyulog: reports progress, notices a cut-off last message, and
    ends before a long zero-filled tail (which pyulog would walk one byte at a time)."""

    def __init__(self, path: Path, size: int, progress: Callable[[int, int], None] | None) -> None:
        self._stream = path.open("rb")
        self.size = size
        self.zero_tail = _zero_tail(self._stream, size)
        self.zero_start = size - self.zero_tail
        # a last message may end in up to _MAX_PAYLOAD zero bytes; past that, zeros are padding
        self.end = min(size, self.zero_start + _MAX_PAYLOAD)
        self._pos = 0
        self._progress = progress
        self._step = max(size // 50, 1 << 16)
        self._next_report = self._step
        self.searching = False  # pyulog is scanning for a sync marker: short reads are expected
        self.cut_at: int | None = None  # offset where a message came back short: file truncated
        self.stalled_at: int | None = None  # pyulog stopped making progress here; reading ended
        self.furthest = 0
        self.last_read_at = 0
        self._idle_reads = 0

    def read(self, count: int = -1) -> bytes:
        self.last_read_at = start = self._pos
        wanted = self.end - start if count < 0 else count
        data = self._stream.read(max(0, min(wanted, self.end - start)))
        self._pos = end = start + len(data)
        if 0 < count and len(data) < count and not self.searching and self.stalled_at is None:
            # an empty 3-byte read is the clean end of the file, zeros are padding
            if data.strip(b"\0") or (not data and count != 3 and start < self.zero_start):
                self.cut_at = start
        if end > self.furthest:
            self.furthest = end
            self._idle_reads = 0
            if self._progress is not None and end >= self._next_report:
                self._progress(end, self.size)
                self._next_report = end + self._step
        else:
            self._idle_reads += 1
            if self._idle_reads > _STALL_READS:
                self.stalled_at, self.end = self.furthest, 0  # from now on every read is end of file
        return data

    def seek(self, offset: int, whence: int = 0) -> int:
        base = {0: 0, 1: self._pos, 2: self.size}[whence]
        if base + offset < 0:  # pyulog stepping back past the start over a damaged header
            self.stalled_at, self.end = self.furthest, 0
            return self._pos
        self._pos = self._stream.seek(offset, whence)
        return self._pos

    def tell(self) -> int:
        return self._pos

    def close(self) -> None:
        self._stream.close()


def _zero_tail(stream: Any, size: int) -> int:
    """Number of zero bytes at the end of the file."""
    run = 0
    while run < size:
        count = min(1 << 16, size - run)
        stream.seek(size - run - count)
        kept = stream.read(count).rstrip(b"\0")
        run += count - len(kept)
        if kept:
            break
    stream.seek(0)
    return run


class _PlainULog(ULog):  # type: ignore[misc]
    """pyulog's reader as it is, with the damage counters of :class:`_CountingULog` at zero (a clean file)."""

    def __init__(self, log_file: _TrackedFile | WholeFile, topics: frozenset[str] | None) -> None:
        self.skipped: dict[str | int, int] = {}  # topic name (wrong size) or unknown msg id
        self.skipped_bytes = 0
        self.resyncs = 0
        kept = None if topics is None else sorted(topics)
        super().__init__(log_file, message_name_filter_list=kept, disable_str_exceptions=True)


class _CountingULog(_PlainULog):
    """pyulog's reader, counting the messages and bytes it skips (pyulog only sets a flag)."""

    class _MessageData(ULog._MessageData):  # type: ignore[misc]
        def initialize(self, data: bytes, header: Any, subscriptions: dict[int, Any], ulog_object: Any) -> bool:
            corrupt = bool(super().initialize(data, header, subscriptions, ulog_object))
            if corrupt:
                msg_id = int.from_bytes(data[:2], "little")
                subscription = subscriptions.get(msg_id)
                key = subscription.message_name if subscription is not None else msg_id
                ulog_object.skipped[key] = ulog_object.skipped.get(key, 0) + 1
            return corrupt

    def __init__(self, log_file: _TrackedFile | WholeFile, topics: frozenset[str] | None) -> None:
        self._last_skip = -1
        super().__init__(log_file, topics)

    def _find_sync(self, last_n_bytes: int = -1) -> bool:
        start = self._file_handle.tell()
        self._file_handle.searching = True
        try:
            found = bool(super()._find_sync(last_n_bytes))
        finally:
            self._file_handle.searching = False
        if found:
            self.resyncs += 1
            landed = min(self._file_handle.tell(), self._file_handle.zero_start)
            self.skipped_bytes += max(0, landed - start)
        return found

    def _check_packet_corruption(self, header: Any) -> bool:
        corrupt = bool(super()._check_packet_corruption(header))
        header_at = self._file_handle.last_read_at - 3  # the payload read follows the header
        if corrupt and self._last_skip < header_at < self._file_handle.zero_start:
            self.skipped_bytes += 1  # pyulog steps one byte past a corrupt header
            self._last_skip = header_at
        return corrupt


def _parse(path: Path, size: int, progress: Callable[[int, int], None] | None, topics: frozenset[str] | None) -> ULog:
    """Run pyulog with its prints and warnings captured as our warnings; turn its errors into LogFormatError.

    pyulog keeps the data of `topics` only (every topic with None): on a log of many topics the
    others' bytes are walked past instead of being copied, parsed and held.

    A file whose messages chain cleanly (up to 256 MB) is parsed in memory: by
    :class:`~flightlogs.readers._ulog_fast.FastULog` (pyulog for every message
    but the data ones, numpy for those), else, where that path is declined, by
    pyulog as it is. One that pyulog then finds corrupt, or whose chain is not
    clean, is parsed again through :class:`_TrackedFile` with the damage counted.
    """
    clean = scan_clean(path, size, progress) if size <= _WHOLE_FILE_LIMIT else None
    if clean is not None:
        readers: tuple[tuple[_Reader, Callable[[], WholeFile]], ...] = (
            (FastULog, clean.reduced_file),
            (_PlainULog, clean.whole),
        )
        for kind, source in readers:
            try:
                ulog, tracked, said = _run_pyulog(path, kind, source(), topics)
            except (FastPathDeclined, LogFormatError):
                continue  # the whole file, then the tracked reader, which says where the damage lies
            if not ulog.file_corruption:
                return _reported(ulog, tracked, said, size, path)
    tracked = _TrackedFile(path, size, progress)
    return _reported(*_run_pyulog(path, _CountingULog, tracked, topics), size, path)


def _run_pyulog(
    path: Path, kind: _Reader, source: _TrackedFile | WholeFile, topics: frozenset[str] | None
) -> tuple[_PlainULog | FastULog, _TrackedFile | WholeFile, list[str]]:
    """pyulog's parse of `source`, and what it printed or warned."""
    printed = io.StringIO()
    try:
        with contextlib.redirect_stdout(printed), _warnings.catch_warnings(record=True) as caught:
            _warnings.simplefilter("always")
            ulog = kind(source, topics)
    except ULogIncompatibleFlagException as err:
        raise LogFormatError(f"{path}: uses a ULog extension pyulog cannot read ({err}).") from err
    except _PYULOG_ERRORS as err:
        raise LogFormatError(
            f"{path}: damaged beyond reading near byte {source.furthest} ({type(err).__name__}: {err})."
        ) from err
    finally:
        source.close()
    said = [line.strip() for line in printed.getvalue().splitlines() if line.strip()]
    said += [str(w.message) for w in caught if not issubclass(w.category, DeprecationWarning)]
    return ulog, source, said


def _reported(
    ulog: _PlainULog | FastULog, tracked: _TrackedFile | WholeFile, said: list[str], size: int, path: Path
) -> ULog:
    """`ulog`, after warning of the damage read past, the dropouts and pyulog's own complaints."""
    for note in _damage_notes(ulog, tracked, size, path.name):
        _warnings.warn(LogCorruptionWarning(note), stacklevel=2)
    if ulog.dropouts:
        lost_ms = sum(int(dropout.duration) for dropout in ulog.dropouts)
        message = f"{len(ulog.dropouts)} logging dropout(s): the logger lost {lost_ms} ms of data"
        _warnings.warn(DataQualityWarning(message), stacklevel=2)
    for text in said:
        _warnings.warn(LogCorruptionWarning(f"pyulog: {text}"), stacklevel=2)
    return ulog


def _damage_notes(ulog: _PlainULog | FastULog, tracked: _TrackedFile | WholeFile, size: int, name: str) -> list[str]:
    """Sentences saying what pyulog skipped, from our counters and its flag."""
    notes = []
    if tracked.stalled_at is not None:
        notes.append(
            f"{name}: pyulog lost its place in damaged data near byte {tracked.stalled_at} "
            f"of {size}; the rest of the file was not read"
        )
    if tracked.cut_at is not None:
        notes.append(
            f"{name}: the file is truncated: it ends inside a message at byte {tracked.cut_at} "
            f"of {size}; that last message was skipped"
        )
    if tracked.zero_tail > _MAX_PAYLOAD:
        notes.append(
            f"the last {tracked.zero_tail} bytes of the file are zeros (space the logger "
            "reserved but never wrote); ignored"
        )
    for key, count in sorted(ulog.skipped.items(), key=lambda item: str(item[0])):
        if isinstance(key, int):
            notes.append(
                f"skipped {count} data message(s) with message id {key}, which no subscription declares (corrupt bytes)"
            )
        else:
            notes.append(f"skipped {count} '{key}' message(s) whose size does not match its format")
    if ulog.skipped_bytes:
        notes.append(
            f"skipped about {ulog.skipped_bytes} unreadable bytes "
            f"({ulog.resyncs} resynchronisation(s) on the sync marker)"
        )
    if ulog.file_corruption and not notes:
        notes.append("pyulog flagged the file as corrupt; messages it could not parse were skipped")
    return notes


def _map_group(group: SignalGroup, datasets: _Datasets) -> dict[str, Signal]:
    """Signals of one group from its first usable source and instance."""
    for source in group.sources:
        for instance, data in sorted(datasets.get(source.topic, {}).items()):
            found = _read_source(group, source, instance, data)
            if found:
                if instance:
                    message = f"{source.topic}[0] is empty or invalid; {', '.join(found)} read from instance {instance}"
                    _warnings.warn(DataQualityWarning(message), stacklevel=2)
                return found
    return {}


def _read_source(
    group: SignalGroup, source: TopicSource, instance: int, data: Mapping[str, np.ndarray]
) -> dict[str, Signal]:
    """Signals from one topic instance, or {} if none has enough usable samples.

    What was dropped is warned about only when the instance is used.
    """
    if not all(field in data for field in source.fields):
        return {}
    stamps = np.asarray(data["timestamp"])
    every = stamps / 1e6  # the topic's times, shared by its signals where none drops a sample
    columns, in_range = _convert(source, data)
    label = f"{source.topic}[{instance}]"
    signals: dict[str, Signal] = {}
    unused: list[str] = []
    with collected_warnings() as caught:
        for k, name in enumerate(group.names):
            text = _source_text(source, label, k)
            keep, valid_fraction, reasons = _usable(source, k, data, in_range, stamps)
            why = "; ".join(reasons) or "fewer than 2 samples"
            if keep.sum() < 2 or valid_fraction < source.min_valid_fraction:
                unused.append(f"{text}: no usable samples ({why}); {name} missing")
                continue
            if reasons:
                dropped = stamps.size - int(keep.sum())
                message = f"{text}: dropped {dropped} of {stamps.size} samples ({why})"
                _warnings.warn(DataQualityWarning(message), stacklevel=2)
            whole = bool(keep.all())
            time_s, values = (every, columns[k]) if whole else (every[keep], columns[k][keep])
            signal = make_signal(name, time_s, values, group.unit, text)
            if signal is not None and signal.samples >= 2:
                signals[name] = signal
        if not signals:
            caught.discard()  # this instance is not used: what it dropped does not matter
    for message in unused if signals else ():
        _warnings.warn(DataQualityWarning(message), stacklevel=2)
    return signals


_OUT_OF_RANGE = {"rangefinder": "out of range or not facing down", "quaternion_to_euler": "with a zero quaternion"}


def _usable(
    source: TopicSource, k: int, data: Mapping[str, np.ndarray], in_range: np.ndarray, stamps: np.ndarray
) -> tuple[np.ndarray, float, list[str]]:
    """Samples of output `k` to keep, the fraction the topic counts valid, and why others go."""
    valid = in_range.copy()
    reasons = []
    if count := int((~in_range).sum()):
        reasons.append(f"{count} {_OUT_OF_RANGE.get(source.conversion, 'invalid')}")
    flag = source.valid[k] if source.valid else None
    if flag is not None and flag in data:
        unset = np.asarray(data[flag]) == 0
        if count := int((unset & valid).sum()):
            reasons.append(f"{count} with {flag} not set")
        valid &= ~unset
    for field, least in source.at_least:
        if field in data:
            below = np.asarray(data[field]) < least
            if count := int((below & valid).sum()):
                reasons.append(f"{count} with {field} < {least:g}")
            valid &= ~below
    unstamped = stamps == 0
    if count := int((unstamped & valid).sum()):
        reasons.append(f"{count} with timestamp 0")
    return valid & ~unstamped, float(valid.mean()) if valid.size else 0.0, reasons


def _convert(source: TopicSource, data: Mapping[str, np.ndarray]) -> tuple[list[np.ndarray], np.ndarray]:
    """Apply the source's conversion; return one column per signal and a mask of usable samples."""
    columns = [np.asarray(data[field]) for field in source.fields]  # as logged: a float32 field stays so (Signal)
    usable = np.ones(columns[0].shape, dtype=bool)
    if source.conversion == "negate":
        columns = [-column.astype(np.float64) if column.dtype.kind in "iub" else -column for column in columns]
    elif source.conversion in ("degrees", "degrees_e7"):
        scale = 1e-7 if source.conversion == "degrees_e7" else 1.0
        columns = [np.deg2rad(column.astype(np.float64) * scale) for column in columns]
    elif source.conversion == "quaternion_to_euler":
        quaternion = np.column_stack(columns).astype(np.float64)
        norm = np.linalg.norm(quaternion, axis=1)
        usable = np.isfinite(norm) & (norm > 0.5)  # an all-zero quaternion is "not set"
        quaternion[~usable] = np.nan
        columns = list(quaternion_to_euler(quaternion).T)
    elif source.conversion == "arming_state":
        columns = [(columns[0] == _ARMED).astype(np.float64)]
    elif source.conversion == "rangefinder":
        distance, low, high = columns
        usable = (distance >= low) & (distance <= high)
        if "signal_quality" in data:
            usable &= np.asarray(data["signal_quality"]) != 0
        if "orientation" in data:
            usable &= np.asarray(data["orientation"]) == _DOWNWARD
        columns = [distance]
    return columns, usable


def _source_text(source: TopicSource, label: str, k: int) -> str:
    """``topic[i].field`` with the conversion, e.g. ``-vehicle_local_position[0].z``."""
    if source.conversion == "quaternion_to_euler":
        first, last = source.fields[0], source.fields[-1]
        return f"{label}.{first.split('[')[0]}[{first[-2]}..{last[-2]}] (quaternion→Euler)"
    field = source.fields[0] if source.conversion == "rangefinder" else source.fields[k]
    sign = "-" if source.conversion == "negate" else ""
    unit = {"degrees": " (deg→rad)", "degrees_e7": " (1e-7 deg→rad)", "arming_state": " (2: armed)"}.get(
        source.conversion, ""
    )
    return f"{sign}{label}.{field}{unit}"


def _map_motors(datasets: _Datasets, parameters: Mapping[str, float]) -> dict[str, Signal]:
    """``motor_1..n`` from the first motor topic and instance whose motor count is known."""
    for source in PX4_MOTOR_SOURCES:
        for instance, data in sorted(datasets.get(source.topic, {}).items()):
            label = f"{source.topic}[{instance}]"
            channels = _motor_channels(source, data, parameters)
            if channels is None:
                message = (
                    f"{label}: cannot tell which outputs drive motors (no CA_ROTOR_COUNT, "
                    "and MAV_TYPE/SYS_AUTOSTART name no multirotor); motor signals not read"
                )
                _warnings.warn(DataQualityWarning(message), stacklevel=2)
                continue
            stamps = np.asarray(data["timestamp"])
            keep = stamps > 0
            if keep.sum() < 2:
                continue
            signals = {}
            with collected_warnings() as caught:
                for i in channels:
                    field = source.field_pattern.format(i=i)
                    name = f"motor_{i + 1}"
                    signal = make_signal(
                        name, stamps[keep] / 1e6, np.asarray(data[field])[keep], source.unit, f"{label}.{field}"
                    )
                    if signal is not None and signal.samples >= 2:
                        signals[name] = signal
                if not signals:
                    caught.discard()  # this instance is not used: what it dropped does not matter
            if signals:
                return signals
    return {}


def _motor_channels(
    source: MotorSource, data: Mapping[str, np.ndarray], parameters: Mapping[str, float]
) -> list[int] | None:
    """Channel indices holding motors, or None when the count cannot be known."""
    present = []
    i = 0
    while source.field_pattern.format(i=i) in data:
        present.append(i)
        i += 1
    if source.count_from == "channels":
        fields = [source.field_pattern.format(i=i) for i in present]
        used = [i for i, field in zip(present, fields) if not np.isnan(np.asarray(data[field], float)).all()]
        allocated = rotor_count(parameters, allocator_only=True)
        return used[:allocated] if allocated else used
    rotors = rotor_count(parameters)
    if not rotors:
        return None
    if "noutputs" in data and np.size(data["noutputs"]):
        rotors = min(rotors, int(np.max(data["noutputs"])))
    return present[:rotors]


def _utc_offset(datasets: _Datasets) -> float | None:
    """UNIX seconds minus log seconds, from GPS samples that carry a time."""
    for topic in GPS_TOPICS:
        for _, data in sorted(datasets.get(topic, {}).items()):
            if "time_utc_usec" not in data:
                continue
            utc_us = np.asarray(data["time_utc_usec"]).astype(np.int64)
            stamps = np.asarray(data["timestamp"]).astype(np.int64)
            ok = (utc_us > _MIN_UTC_US) & (stamps > 0)
            if ok.any():
                return float(np.median(utc_us[ok] - stamps[ok])) / 1e6
    return None


def _parameters(initial: Mapping[str, Any]) -> dict[str, float]:
    """Initial parameters as floats; values a damaged file left unreadable are skipped."""
    parameters = {}
    unreadable = []
    for key, value in initial.items():
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            parameters[str(key)] = float(value)
        else:
            unreadable.append(str(key))
    if unreadable:
        message = f"ignored {len(unreadable)} parameter(s) with unreadable values (first: {unreadable[0]!r})"
        _warnings.warn(LogCorruptionWarning(message), stacklevel=2)
    return parameters
