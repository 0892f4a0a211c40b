"""The data section of a clean PX4 ULog, read by pyulog for everything but the data messages, by numpy for those.

A clean file is one whose messages chain from the 16-byte header to its last
byte, each of a ULog type (:func:`scan_clean` walks the 3-byte headers: uint16
payload size, uint8 type). pyulog reads a file one message at a time in Python;
in a flight log nearly every message is a data message ('D'), so on a clean
file:

1. the walk records the offset of every 'D' message (a numpy array);
2. pyulog parses a reduced stream: the header and every message that is not a
   'D', in file order (formats, info, parameters, subscriptions, logged
   strings, dropouts, sync...) -- a few thousand messages instead of hundreds
   of thousands;
3. when pyulog meets a subscription ('A') it builds its own
   ``ULog._MessageAddLogged`` (:class:`FastULog` shadows that nested class with a
   method), whose ``buffer`` is then filled at once: the ``dtype.itemsize``
   bytes after the msg_id of each of that msg_id's 'D' payloads, gathered by
   one fancy index. pyulog's own dtype and ``ULog.Data`` turn the buffer into
   arrays, so they are pyulog's by construction. Topics pyulog filters out
   (``message_name_filter_list``) are not gathered;
4. the stamps pyulog gives dropouts ('O') and parameter changes ('P') of the
   data section -- the largest data timestamp read before them, from the
   header's start time on -- and its ``last_timestamp`` are set afterwards from
   the gathered timestamps (a running maximum over the data messages in file
   order).

Fall-back rules: the fast path is declined (:class:`FastPathDeclined`, and the
reader parses the whole file with pyulog as before) whenever its result could
differ from pyulog's:

* a 'D' message shorter than its 2-byte msg_id, or whose msg_id has no 'A'
  earlier in the file (pyulog would warn, flag corruption and skip it);
* a msg_id subscribed twice (pyulog replaces the subscription and loses the
  data read so far);
* an 'R' message (remove subscription; pyulog skips it as unknown);
* a flag-bits message ('B') shorter than 40 bytes, or with an incompatible
  flag or an appended-data offset set (pyulog reads appended data in parts
  or refuses the file);
* for a kept topic with data: a payload size outside
  ``[dtype.itemsize + 2, max_data_size + 2]`` (pyulog skips it as corrupt),
  or a ``timestamp`` not ending within the kept bytes (pyulog stops reading
  the file at its first such message);
* pyulog's loop ending before the end of the reduced stream (a message whose
  parse raised ``struct.error``: pyulog silently stops there, and would have
  dropped the data messages after it);
* the counts of dropouts or parameter changes pyulog read differing from the
  'O' and 'P' messages of the data section.

A parse that pyulog flags corrupt is also not kept by the caller
(:func:`flightlogs.readers.ulog._parse`).
"""

from __future__ import annotations

import io
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from pyulog import ULog

__all__ = ["CleanFile", "DataLayout", "FastPathDeclined", "FastULog", "ReducedFile", "WholeFile", "scan_clean"]

_HEADER_BYTES = 16
_DATA = ord("D")
_ADD = ord("A")
_REMOVE = ord("R")
_FLAG_BITS = ord("B")
_DROPOUT = ord("O")
_PARAMETER = ord("P")
_DEFINITIONS_END = frozenset(b"ALC")  # pyulog's definitions section ends before the first of these
_FLAG_BITS_BYTES = 40  # 8 compat + 8 incompat flag bytes, 3 uint64 appended offsets
_MESSAGE_TYPES = frozenset(
    getattr(ULog, name) for name in dir(ULog) if name.startswith("MSG_TYPE_") and isinstance(getattr(ULog, name), int)
)


class FastPathDeclined(Exception):
    """The fast path could differ from pyulog's parse of the whole file: the caller reads it the usual way."""


class WholeFile(io.BytesIO):
    """A file read into memory whose messages chain cleanly to its end: pyulog reads it at C speed.

    It answers what :class:`flightlogs.readers.ulog._TrackedFile` answers with
    nothing to report: no zero tail, no cut, no stall.
    """

    def __init__(self, data: bytes) -> None:
        super().__init__(data)
        self.size = self.zero_start = self.end = self.furthest = len(data)
        self.zero_tail = self.last_read_at = 0
        self.searching = False
        self.cut_at: int | None = None
        self.stalled_at: int | None = None


@dataclass(frozen=True, slots=True, eq=False)
class DataLayout:
    """Where the data ('D') messages of a clean file lie, and the stamps pyulog gives to what follows them.

    Parameters
    ----------
    file : ndarray of uint8, shape (n_bytes,)
        The whole file.
    at : ndarray of int64, shape (n_data,)
        Byte offset of each data message's 3-byte header, in file order.
    sizes : ndarray of int64, shape (n_data,)
        Payload size of each data message, bytes (msg_id included).
    by_id : ndarray of int64, shape (n_data,)
        Indices into `at` sorted by msg_id, file order within one msg_id.
    ids_sorted : ndarray of uint16, shape (n_data,)
        The msg_id of each entry of `by_id`.
    dropouts_after : ndarray of int64, shape (n_dropouts,)
        Number of data messages before each dropout ('O') of the data section.
    changes_after : ndarray of int64, shape (n_changes,)
        Number of data messages before each parameter change ('P') of the data section.
    """

    file: np.ndarray
    at: np.ndarray
    sizes: np.ndarray
    by_id: np.ndarray
    ids_sorted: np.ndarray
    dropouts_after: np.ndarray
    changes_after: np.ndarray

    def of(self, msg_id: int) -> np.ndarray:
        """Indices into `at` of the data messages of `msg_id`, in file order, shape (n,)."""
        lo, hi = np.searchsorted(self.ids_sorted, [msg_id, msg_id + 1])
        return self.by_id[lo:hi]


class ReducedFile(WholeFile):
    """The header and every non-data message of a clean file, knowing whether pyulog read it to its end."""

    def __init__(self, data: bytes, layout: DataLayout) -> None:
        super().__init__(data)
        self.layout = layout
        self.read_to_end = False

    def read(self, size: int | None = -1) -> bytes:
        chunk = super().read(size)
        # pyulog's loop ends on an empty 3-byte header read; any other last read is a message it stopped at
        self.read_to_end = size == 3 and not chunk
        return chunk


@dataclass(frozen=True, slots=True, eq=False)
class CleanFile:
    """A file whose messages chain cleanly, and what the fast path needs of it.

    Parameters
    ----------
    data : bytes
        The whole file.
    reduced : bytes
        The header and every non-data message, in file order (empty when declined).
    layout : DataLayout or None
        Where the data messages lie; None when the fast path is declined.
    declined : str
        Why the fast path is declined; empty when it is not.
    """

    data: bytes
    reduced: bytes
    layout: DataLayout | None
    declined: str

    def whole(self) -> WholeFile:
        """The whole file for pyulog."""
        return WholeFile(self.data)

    def reduced_file(self) -> ReducedFile:
        """The reduced stream for :class:`FastULog`; raises :class:`FastPathDeclined` when declined."""
        if self.layout is None:
            raise FastPathDeclined(self.declined)
        return ReducedFile(self.reduced, self.layout)


def scan_clean(path: Path, size: int, progress: Callable[[int, int], None] | None) -> CleanFile | None:
    """The file in memory if every message, from the header on, is of a ULog type and the last ends at the end.

    Parameters
    ----------
    path : Path
        The ``.ulg`` file (its 16-byte header already checked).
    size : int
        Its size, bytes.
    progress : callable, optional
        ``progress(done, total)`` in bytes, about every 2 % of the walk.

    Returns
    -------
    CleanFile or None
        None if a message is of an unknown type or the chain does not end at
        the file's end (a cut or damaged file: the caller reads it through its
        tracked file).
    """
    data = path.read_bytes()
    walked = _walk(data, size, progress)
    if walked is None:
        return None
    at, others = walked
    try:
        reduced, layout = _layout(data, at, others)
    except FastPathDeclined as declined:
        return CleanFile(data, b"", None, str(declined))
    return CleanFile(data, reduced, layout, "")


def _walk(data: bytes, size: int, progress: Callable[[int, int], None] | None) -> tuple[list[int], list[int]] | None:
    """Offsets of the data messages and of the others, or None if the chain is not clean."""
    at: list[int] = []
    others: list[int] = []
    add_data, add_other = at.append, others.append
    types, end = _MESSAGE_TYPES, len(data) - 3
    position, step = _HEADER_BYTES, max(size // 50, 1 << 16)
    while position <= end:
        stop = min(position + step, end + 1)
        while position < stop:  # the hot loop: one message
            kind = data[position + 2]
            if kind == _DATA:
                add_data(position)
            elif kind in types:
                add_other(position)
            else:
                return None
            position += 3 + (data[position] | data[position + 1] << 8)
        if progress is not None:
            progress(min(position, size), size)
    return (at, others) if position == len(data) else None


def _layout(data: bytes, at_list: list[int], others: list[int]) -> tuple[bytes, DataLayout]:
    """The reduced stream and the data messages' layout; raises FastPathDeclined where pyulog could differ."""
    pieces = [data[:_HEADER_BYTES]]
    subscribed_at = np.full(1 << 16, np.iinfo(np.int64).max, np.int64)
    dropouts, changes = [], []
    definitions = True
    for position in others:
        length, kind = data[position] | data[position + 1] << 8, data[position + 2]
        payload = data[position + 3 : position + 3 + length]
        pieces.append(data[position : position + 3 + length])
        definitions = definitions and kind not in _DEFINITIONS_END
        if kind == _ADD:
            if length < 3:
                raise FastPathDeclined(f"a subscription message of {length} bytes at byte {position}")
            msg_id = payload[1] | payload[2] << 8
            if subscribed_at[msg_id] != np.iinfo(np.int64).max:
                raise FastPathDeclined(f"msg_id {msg_id} subscribed twice")
            subscribed_at[msg_id] = position
        elif kind == _REMOVE:
            raise FastPathDeclined(f"a remove-subscription message at byte {position}")
        elif kind == _FLAG_BITS and (length < _FLAG_BITS_BYTES or any(payload[8:_FLAG_BITS_BYTES])):
            raise FastPathDeclined("incompatible flags or appended data in the flag bits")
        elif kind == _DROPOUT and not definitions:
            dropouts.append(position)
        elif kind == _PARAMETER and not definitions:
            changes.append(position)
    file = np.frombuffer(data, np.uint8)
    at = np.array(at_list, np.int64)
    sizes = file[at].astype(np.int64) | file[at + 1].astype(np.int64) << 8
    if np.any(sizes < 2):
        raise FastPathDeclined("a data message shorter than its msg_id")
    ids = (file[at + 3].astype(np.int64) | file[at + 4].astype(np.int64) << 8).astype(np.uint16)
    if np.any(at < subscribed_at[ids]):
        raise FastPathDeclined("a data message before (or without) its subscription")
    by_id = np.argsort(ids, kind="stable")
    layout = DataLayout(
        file=file,
        at=at,
        sizes=sizes,
        by_id=by_id,
        ids_sorted=ids[by_id],
        dropouts_after=np.searchsorted(at, np.array(dropouts, np.int64)),
        changes_after=np.searchsorted(at, np.array(changes, np.int64)),
    )
    return b"".join(pieces), layout


class FastULog(ULog):  # type: ignore[misc]
    """pyulog's reader on a :class:`ReducedFile`, each subscription's buffer gathered from the whole file.

    Parameters
    ----------
    log_file : ReducedFile
        The reduced stream of a clean file.
    topics : frozenset of str, optional
        Topics to keep (pyulog's ``message_name_filter_list``); None: every topic.

    Raises
    ------
    FastPathDeclined
        Where the result could differ from pyulog's parse of the whole file
        (see the module's fall-back rules).
    """

    _changed_parameters: list[tuple[int, str, Any]]  # pyulog's (timestamp, name, value) of each change

    def __init__(self, log_file: ReducedFile, topics: frozenset[str] | None) -> None:
        self.skipped: dict[str | int, int] = {}  # the damage counters of a clean file, as _PlainULog's
        self.skipped_bytes = 0
        self.resyncs = 0
        self._layout = log_file.layout
        self._kept = None if topics is None else sorted(topics)
        self._stamps: list[tuple[np.ndarray, np.ndarray]] = []  # (data message indices, timestamps) per kept topic
        super().__init__(log_file, message_name_filter_list=self._kept, disable_str_exceptions=True)
        if not log_file.read_to_end:
            raise FastPathDeclined("pyulog stopped before the end of the file")
        self._restamp()

    def _MessageAddLogged(self, data: bytes, header: Any, message_formats: dict[str, Any]) -> Any:
        """pyulog's subscription, its buffer filled with every data message of its msg_id at once."""
        subscription = ULog._MessageAddLogged(data, header, message_formats)
        if self._kept is None or subscription.message_name in self._kept:
            rows = self._layout.of(subscription.msg_id)
            if rows.size:
                payloads, stamps = _gather(self._layout, rows, subscription)
                subscription.buffer = bytearray(payloads)
                self._stamps.append((rows, stamps))
        return subscription

    def _restamp(self) -> None:
        """Stamp dropouts, parameter changes and ``last_timestamp`` as pyulog's walk through the data would."""
        layout = self._layout
        latest = np.zeros(layout.at.size + 1, np.uint64)
        latest[0] = self._start_timestamp
        for rows, stamps in self._stamps:
            latest[rows + 1] = stamps
        np.maximum.accumulate(latest, out=latest)
        if len(self._dropouts) != layout.dropouts_after.size:
            raise FastPathDeclined("pyulog read another number of dropouts than the file holds")
        if len(self._changed_parameters) != layout.changes_after.size:
            raise FastPathDeclined("pyulog read another number of parameter changes than the file holds")
        for dropout, before in zip(self._dropouts, layout.dropouts_after):
            dropout.timestamp = int(latest[before])
        self._changed_parameters = [
            (int(latest[before]), key, value)
            for (_, key, value), before in zip(self._changed_parameters, layout.changes_after)
        ]
        self._last_timestamp = int(latest[-1])


def _gather(layout: DataLayout, rows: np.ndarray, subscription: Any) -> tuple[np.ndarray, np.ndarray]:
    """The kept bytes of the data messages `rows`, shape (n, itemsize), and their timestamps, shape (n,)."""
    itemsize = subscription.dtype.itemsize
    sizes = layout.sizes[rows] - 2
    name = subscription.message_name
    if sizes.min() < itemsize or sizes.max() > subscription.max_data_size:
        raise FastPathDeclined(f"'{name}' data of a size pyulog skips as corrupt")
    offset = subscription.timestamp_offset
    if offset + 8 > itemsize:
        raise FastPathDeclined(f"'{name}' has no uint64 timestamp within its data (pyulog stops there)")
    payloads = sliding_window_view(layout.file, itemsize)[layout.at[rows] + 5]  # after header and msg_id
    stamps = np.ascontiguousarray(payloads[:, offset : offset + 8]).view("<u8").ravel()
    return payloads, stamps
