"""Fast bulk decoder of ArduPilot DataFlash binary logs (``.bin``).

A DataFlash log is a stream of messages, ``A3 95 <type>`` then a fixed-size
body; ``FMT`` messages (type 128) define the other types. Format characters,
struct codes and multipliers come from pymavlink (``FORMAT_TO_STRUCT``,
``DFFormat``); the decoding differs: message boundaries come from a
vectorised scan for header candidates and a walk that loops in Python only
where the stream is not contiguous, and each type is decoded at once through
a numpy structured dtype.

Notes
-----
Values equal those of pymavlink's ``DFReader_binary`` read with
``_parse_next``, and the framing follows it, quirks included:

* Bytes that do not start a known message are skipped until the next
  ``A3 95 <known type>``, which is trusted (no look-ahead, no checksum).
* A message is decoded with the latest FMT for its type before it; before
  any, with the type's last FMT in the file (DFReader preloads them all).
* A type whose FMT ``Length`` disagrees with its format cannot be unpacked;
  the scan resumes three bytes on. DFReader also stops for good when that
  happens within 528 bytes of the end; we read on. A truncated final
  message is dropped. Where a type is redefined with another layout
  (appended logs of other firmware), DFReader keeps its cached struct and
  misreads; we decode with the FMT in force and keep the layouts apart.
* ``c C e E`` (×0.01) and ``L`` (×1e-7) become float64 divided by
  ``1/multiplier``, as DFReader computes them; ``f`` stays float32 and
  ``g`` float16 (same values); integers keep their width; ``M`` (flight
  mode) stays a number, as in DFReader. Strings (``n N Z``): UTF-8, else
  ISO-8859-1, cut at the first NUL; ``FILE.Data`` stays raw bytes; ``a`` is
  ``int16[32]``, shape ``(n, 32)``. A repeated column name keeps its last
  field (DFReader's ``colhash``).
* DFReader's ``_timestamp`` (GPS-based, always 18 leap seconds) is not
  reproduced: :attr:`MessageTable.time_s` is the log clock.
"""

from __future__ import annotations

import bisect
import struct
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from types import MappingProxyType

import numpy as np
from pymavlink.DFReader import FORMAT_TO_STRUCT, MULT_TO_PREFIX, DFFormat

from .errors import LogFormatError

__all__ = [
    "MessageFormat", "MessageTable", "DataFlashMessages", "read_messages", "decode_messages", "message_dtype",
]

HEAD1, HEAD2, FMT_TYPE = 0xA3, 0x95, 0x80
_FMT = DFFormat(FMT_TYPE, "FMT", 89, "BBnNZ", "Type,Length,Name,Format,Columns")  # as DFReader
_ULOG_MAGIC = b"ULog\x01\x12\x35"
_NUMPY_CODE = {"b": "i1", "B": "u1", "h": "<i2", "H": "<u2", "i": "<i4", "I": "<u4", "f": "<f4",
               "d": "<f8", "e": "<f2", "q": "<i8", "Q": "<u8"}
_CHAR_SIZE = {c: struct.calcsize("<" + code) for c, (code, _, _) in FORMAT_TO_STRUCT.items()}
_VALID_CHARS = frozenset(FORMAT_TO_STRUCT)
_INSTANCE_COLUMNS = ("I", "Instance", "Inst", "C", "Core")
_LISTED = 8  # gaps or resets spelled out in warnings before summarising


@dataclass(frozen=True, slots=True)
class MessageFormat:
    """Layout of one message type, from its FMT (and FMTU) messages.

    Parameters
    ----------
    type_id : int
        Message type byte (0-255).
    name : str
        Message name, e.g. ``"IMU"``.
    length : int
        Message length in bytes, 3-byte header included.
    format : str
        DataFlash format characters, one per column.
    columns : tuple of str
        Column names.
    units : tuple of str
        Unit of each column as DFReader derives it from FMTU/UNIT/MULT
        (``""`` when unknown); empty when the log has no FMTU.
    instance_field : str or None
        Column holding the sensor instance (FMTU ``#``), if any.
    """

    type_id: int
    name: str
    length: int
    format: str
    columns: tuple[str, ...]
    units: tuple[str, ...] = ()
    instance_field: str | None = None


@dataclass(frozen=True, slots=True)
class MessageTable:
    """All messages of one type, as columns.

    Parameters
    ----------
    format : MessageFormat
        The layout they share.
    columns : Mapping[str, ndarray]
        Values by column name, shape ``(n,)`` (``(n, 32)`` for ``a``), with
        multipliers applied as DFReader applies them.
    offsets : ndarray of int64, shape (n,)
        Byte offset of each message in the file, increasing.
    """

    format: MessageFormat
    columns: Mapping[str, np.ndarray]
    offsets: np.ndarray

    def __post_init__(self) -> None:
        for array in (*self.columns.values(), self.offsets):
            array.flags.writeable = False
        object.__setattr__(self, "columns", MappingProxyType(dict(self.columns)))

    def __len__(self) -> int:
        return int(self.offsets.size)

    def __getitem__(self, column: str) -> np.ndarray:
        return self.columns[column]

    def __contains__(self, column: object) -> bool:
        return column in self.columns

    @property
    def time_s(self) -> np.ndarray | None:
        """Log-clock time of each message, s: ``TimeUS/1e6`` or ``TimeMS/1e3``.

        Old GPS messages whose ``TimeMS`` is GPS time of week use their boot
        time ``T`` instead (as DFReader's msec clock does). None without any.
        """
        cols = self.columns
        if "TimeUS" in cols:
            return cols["TimeUS"].astype(np.float64) / 1e6
        if "T" in cols and "Week" in cols and self.format.name.startswith("GPS"):
            return cols["T"].astype(np.float64) / 1e3
        if "TimeMS" in cols:
            return cols["TimeMS"].astype(np.float64) / 1e3
        return None

    def select(self, rows: np.ndarray) -> MessageTable:
        """Return the messages picked by a boolean mask or index array."""
        return MessageTable(self.format, {k: v[rows] for k, v in self.columns.items()}, self.offsets[rows])


@dataclass(frozen=True, slots=True)
class DataFlashMessages:
    """Every message of a DataFlash log, decoded per type.

    Parameters
    ----------
    path : Path
        File read (``Path("<bytes>")`` for in-memory data).
    file_size : int
        Bytes in the file.
    tables : Mapping[str, MessageTable]
        Decoded messages by name. When a name is redefined with a different
        layout, the later layouts are stored as ``"NAME@1"``, ``"NAME@2"``.
    counts : Mapping[str, int]
        Messages found per name, decoded or not.
    warnings : tuple of str
        Recovered problems: skipped bytes, truncation, time resets.
    bytes_skipped : int
        Bytes that were not part of any decoded message.
    """

    path: Path
    file_size: int
    tables: Mapping[str, MessageTable]
    counts: Mapping[str, int]
    warnings: tuple[str, ...] = ()
    bytes_skipped: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "tables", MappingProxyType(dict(self.tables)))
        object.__setattr__(self, "counts", MappingProxyType(dict(self.counts)))
        object.__setattr__(self, "warnings", tuple(self.warnings))

    def __getitem__(self, name: str) -> MessageTable:
        return self.tables[name]

    def __contains__(self, name: object) -> bool:
        return name in self.tables

    def get(self, name: str) -> MessageTable | None:
        """The table of `name`, or None when absent or empty."""
        table = self.tables.get(name)
        return table if table is not None and len(table) else None

    def instance_field(self, name: str) -> str | None:
        """Column that numbers the instances of `name` (FMTU ``#``, else ``I``, ``C``...)."""
        table = self.tables[name]
        if table.format.instance_field is not None:
            return table.format.instance_field
        chars = dict(zip(table.format.columns, table.format.format))
        return next((c for c in _INSTANCE_COLUMNS if c in table.columns and chars.get(c, "") in {"b", "B"}), None)

    def instances(self, name: str) -> dict[int, MessageTable]:
        """Split `name` by sensor instance, for new and old logs alike.

        Newer logs carry an instance column (``IMU.I``, ``XKF1.C``); older
        logs use numbered names (``IMU``, ``IMU2``, ``IMU3`` are instances
        0, 1, 2). Returns ``{instance: table}``, empty when `name` is absent.
        """
        if self.get(name) is None:
            return {}
        column = self.instance_field(name)
        if column is not None:
            values = self.tables[name][column]
            return {int(i): self.tables[name].select(values == i) for i in np.unique(values)}
        found = {0: self.tables[name]}
        for k in range(2, 10):
            table = self.get(f"{name}{k}")
            if table is not None:
                found[k - 1] = table
        return found


def read_messages(
    path: str | Path,
    *,
    types: Collection[str] | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> DataFlashMessages:
    """Read and decode a DataFlash ``.bin`` log.

    Parameters
    ----------
    path : str or Path
        The log file.
    types : collection of str, optional
        Names to decode (all when None); FMTU, UNIT and MULT are always read.
    progress : callable, optional
        ``progress(done, total)`` in bytes while decoding.

    Returns
    -------
    DataFlashMessages
        Columns per message type, warnings and the count of skipped bytes.

    Raises
    ------
    LogFormatError
        If the file cannot be read, is empty, is a ULog, or holds no FMT.
    """
    path = Path(path)
    try:
        data = np.fromfile(path, dtype=np.uint8)
    except OSError as err:
        raise LogFormatError(f"{path}: cannot be read ({err.strerror or err}) at byte offset 0.") from err
    return decode_messages(data, path=path, types=types, progress=progress)


def decode_messages(
    data: bytes | np.ndarray,
    *,
    path: str | Path = "<bytes>",
    types: Collection[str] | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> DataFlashMessages:
    """Decode DataFlash bytes already in memory.

    Parameters
    ----------
    data : bytes or ndarray of uint8
        The whole log.
    path : str or Path, optional
        Name used in messages and stored in the result.
    types : collection of str, optional
        Names to decode (all when None); FMTU, UNIT and MULT are always read.
    progress : callable, optional
        ``progress(done, total)`` in bytes while decoding.

    Returns
    -------
    DataFlashMessages
        As :func:`read_messages`.

    Raises
    ------
    LogFormatError
        If `data` is empty, a ULog, or holds no FMT message.

    Examples
    --------
    >>> from flightlogs.dataflash_writer import MessageBlock, MessageSpec, encode_dataflash
    >>> spec = MessageSpec("ATT", "Qcc", ("TimeUS", "Roll", "Pitch"))
    >>> block = MessageBlock(spec, {"TimeUS": [1000, 2000], "Roll": [1.5, -2.25], "Pitch": [0.0, 0.1]})
    >>> decode_messages(encode_dataflash([block]))["ATT"]["Roll"]
    array([ 1.5 , -2.25])
    """
    path = Path(path)
    buf = np.ascontiguousarray(np.frombuffer(data, dtype=np.uint8) if isinstance(data, (bytes, bytearray, memoryview))
                               else np.asarray(data, dtype=np.uint8).ravel())
    size = int(buf.size)
    if size == 0:
        raise LogFormatError(f"{path}: the file is empty (no DataFlash message at byte offset 0).")
    if buf[: len(_ULOG_MAGIC)].tobytes() == _ULOG_MAGIC:
        raise LogFormatError(f"{path}: is a PX4 ULog file, not an ArduPilot DataFlash log (ULog magic at byte offset 0).")
    warnings: list[str] = []
    groups, skipped = _frame(buf, path, warnings)
    done = 0
    if progress is not None:
        progress(0, size)
    meta = {k: _decode_table(buf, f, o, warnings) for k, f, o in groups if k in ("FMTU", "UNIT", "MULT")}
    units = _unit_context(meta)
    tables: dict[str, MessageTable] = {}
    counts: dict[str, int] = {}
    for key, fmt, offsets in groups:
        counts[fmt.name] = counts.get(fmt.name, 0) + offsets.size
        if types is None or fmt.name in types or key in meta:
            fmt = _with_units(fmt, *units) if units else fmt
            tables[key] = MessageTable(fmt, meta[key].columns, offsets) if key in meta else \
                _decode_table(buf, fmt, offsets, warnings)
            done += offsets.size * fmt.length
            if progress is not None:
                progress(min(done, size), size)
    warnings.extend(_time_resets(tables))
    if progress is not None:
        progress(size, size)
    return DataFlashMessages(path, size, tables, counts, tuple(warnings), skipped)


@dataclass(frozen=True, slots=True)
class _Definition:
    """One FMT message, parsed; `decodable` when its Length fits its format characters."""

    offset: int
    fmt: MessageFormat
    decodable: bool


_FMT_DEF = _Definition(-1, MessageFormat(FMT_TYPE, "FMT", _FMT.len, _FMT.format, tuple(_FMT.columns)), True)


def _frame(buf: np.ndarray, path: Path,
           warnings: list[str]) -> tuple[list[tuple[str, MessageFormat, np.ndarray]], int]:
    """``(table key, format, offsets)`` of the messages DFReader would decode, per layout; bytes skipped.

    The FMT messages on the chain of messages define the chain (types and
    lengths), so the walk is repeated until the two agree (once, in practice).
    """
    heads = np.flatnonzero(buf[:-2] == HEAD1) if buf.size > 2 else np.empty(0, np.int64)
    heads = heads[buf[heads + 1] == HEAD2].astype(np.int64)
    parsed = {d.offset: d for d in _parse_fmts(buf, heads[(buf[heads + 2] == FMT_TYPE) & (heads + _FMT.len <= buf.size)])}
    on_chain = {o for o, d in parsed.items() if d.decodable and d.fmt.name.isprintable() and d.fmt.name}
    for _ in range(6):
        by_type = _by_type([parsed[o] for o in sorted(on_chain) if o in parsed])
        starts, ends, decodes = _walk(buf, heads, by_type)
        found = set(starts[buf[starts + 2] == FMT_TYPE].tolist())
        if found == on_chain:
            break
        on_chain = found
    if len(by_type) == 1:
        kind = "a text DataFlash log" if buf[:4].tobytes() == b"FMT," else "no DataFlash FMT message"
        raise LogFormatError(f"{path}: holds {kind} (searched {buf.size} bytes from byte offset 0).")
    offsets, skipped = _account(buf, starts, ends, decodes, path, warnings)
    return _layouts(buf, offsets, by_type, path, warnings), skipped


def _by_type(defs: list[_Definition]) -> dict[int, list[_Definition]]:
    by_type: dict[int, list[_Definition]] = {FMT_TYPE: [_FMT_DEF]}
    for d in defs:
        if d.fmt.type_id != FMT_TYPE:
            by_type.setdefault(d.fmt.type_id, []).append(d)
    return by_type


def _walk(buf: np.ndarray, heads: np.ndarray,
          by_type: dict[int, list[_Definition]]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Start, end and decodability of each message, stepping as DFReader does.

    After a message, the next one is the first candidate ``A3 95 <known
    type>`` at or after its end. The Python loop turns once per
    discontinuity (garbage, a header inside a payload), not per message.
    """
    types = buf[heads + 2]
    lenmap, okmap = np.zeros(256, np.int64), np.zeros(256, bool)
    for type_id, defs in by_type.items():
        lenmap[type_id], okmap[type_id] = defs[-1].fmt.length if defs[-1].decodable else 3, defs[-1].decodable
    lengths, decodes = lenmap[types], okmap[types]
    for defs in by_type.values():
        if len({(d.fmt.length, d.decodable) for d in defs}) > 1:  # length redefined: the FMT in force
            sel = np.flatnonzero(types == defs[0].fmt.type_id)
            which = np.searchsorted([d.offset for d in defs], heads[sel]) - 1  # -1: the last (DFReader preload)
            lengths[sel] = np.array([d.fmt.length if d.decodable else 3 for d in defs])[which]
            decodes[sel] = np.array([d.decodable for d in defs])[which]
    known = lengths > 0
    cand, ends, decodes = heads[known], heads[known] + lengths[known], decodes[known]
    nxt = np.arange(1, cand.size + 1)
    jump = np.flatnonzero(ends[:-1] != cand[1:])  # usually a message ends where the next begins
    nxt[jump] = np.searchsorted(cand, ends[jump])
    breaks = jump.tolist()
    starts, stops, i = [], [], 0
    while i < cand.size:
        k = bisect.bisect_left(breaks, i)
        j = breaks[k] if k < len(breaks) else cand.size - 1
        starts.append(i)
        stops.append(j)
        i = int(nxt[j]) if k < len(breaks) else cand.size
    mark = np.zeros(cand.size + 1, np.int64)
    np.add.at(mark, np.array(starts, np.int64), 1)
    np.add.at(mark, np.array(stops, np.int64) + 1, -1)
    chain = np.flatnonzero(np.cumsum(mark[:-1]) > 0)
    return cand[chain], ends[chain], decodes[chain]


def _account(buf: np.ndarray, starts: np.ndarray, ends: np.ndarray, decodes: np.ndarray, path: Path,
             warnings: list[str]) -> tuple[np.ndarray, int]:
    """Offsets of the decodable, complete messages; the rest reported in `warnings`."""
    size, name = buf.size, path.name
    if not decodes.all():
        types = ", ".join(sorted({str(t) for t in buf[starts[~decodes] + 2].tolist()}))
        warnings.append(f"{name}: {int((~decodes).sum())} messages of type(s) {types} have a FMT length "
                        "that disagrees with their format; skipped.")
    truncated = ends > size
    if truncated.any():
        at = int(starts[truncated][0])
        warnings.append(f"{name}: truncated final message (type {buf[at + 2]}) at byte offset {at}: "
                        f"{size - at} bytes left of {int(ends[truncated][0]) - at}.")
    gap_at = np.concatenate([[0], np.minimum(ends, size)])
    gap_len = np.concatenate([starts, [size]]) - gap_at
    shown = np.flatnonzero(gap_len > 0)
    warnings.extend(f"{name}: skipped {int(gap_len[k])} bytes at offset {int(gap_at[k])}." for k in shown[:_LISTED])
    if shown.size > _LISTED:
        warnings.append(f"{name}: skipped bytes at {shown.size - _LISTED} more places.")
    skipped = int(gap_len.sum() + 3 * (~decodes).sum() + (size - starts[truncated]).sum())
    return starts[decodes & ~truncated], skipped


def _layouts(buf: np.ndarray, offsets: np.ndarray, by_type: dict[int, list[_Definition]], path: Path,
             warnings: list[str]) -> list[tuple[str, MessageFormat, np.ndarray]]:
    """Group message offsets by layout (name, format, columns) under their table key."""
    types = buf[offsets + 2]
    order = np.argsort(types, kind="stable")
    present, first = np.unique(types[order], return_index=True)
    layouts: dict[tuple[str, str, tuple[str, ...]], list[np.ndarray]] = {}
    formats: dict[tuple[str, str, tuple[str, ...]], MessageFormat] = {}
    for type_id, lo, hi in zip(present.tolist(), first.tolist(), [*first[1:].tolist(), order.size]):
        sel, defs = offsets[order[lo:hi]], by_type[type_id]
        pieces = [(defs[0], sel)]
        if len(defs) > 1:  # the FMT in force for each message (the last one before any FMT)
            which = np.searchsorted([d.offset for d in defs], sel) - 1
            pieces = [(defs[k], sel[which == k]) for k in np.unique(which).tolist()]
        for d, part in pieces:
            key = (d.fmt.name, d.fmt.format, d.fmt.columns)
            layouts.setdefault(key, []).append(part)
            formats.setdefault(key, d.fmt)
    result, seen = [], dict[str, int]()
    for key in sorted(layouts, key=lambda k: min(int(a[0]) for a in layouts[k])):
        seen[key[0]] = seen.get(key[0], -1) + 1
        label = key[0] if seen[key[0]] == 0 else f"{key[0]}@{seen[key[0]]}"
        if seen[key[0]]:
            warnings.append(f"{path.name}: {key[0]} is redefined with format {key[1]!r}; those messages are in {label!r}.")
        parts = layouts[key]
        result.append((label, formats[key], parts[0] if len(parts) == 1 else np.sort(np.concatenate(parts))))
    return result


def _parse_fmts(buf: np.ndarray, offsets: np.ndarray) -> list[_Definition]:
    """Parse FMT candidates at `offsets`; formats pymavlink cannot read are left out."""
    if offsets.size == 0:
        return []
    rows = _gather(buf, offsets, _FMT.len)
    rec = rows.view(_layout(_FMT.format, _FMT.len)[0]).ravel()
    defs = []
    texts = (_strings(rec[f"f{i}"], _null_term).tolist() for i in (2, 3, 4))
    for off, type_id, length, name, fmt, cols in zip(offsets.tolist(), rec["f0"].tolist(), rec["f1"].tolist(), *texts):
        if not _VALID_CHARS.issuperset(fmt):
            continue
        size = sum(_CHAR_SIZE[c] for c in fmt)
        columns = tuple(cols.split(",")) if cols else ()
        defs.append(_Definition(off, MessageFormat(type_id, name, length, fmt, columns), length == size + 3))
    return defs


def message_dtype(fmt: str) -> np.dtype:
    """Numpy structured dtype of a whole message with DataFlash format `fmt`.

    Parameters
    ----------
    fmt : str
        Format characters of pymavlink's ``FORMAT_TO_STRUCT``.

    Returns
    -------
    numpy.dtype
        Fields ``h1``, ``h2``, ``type`` (the 3-byte header) then ``f0``,
        ``f1``... one per character, packed little-endian as the struct
        codes; ``a`` is ``int16[32]``.

    Examples
    --------
    >>> message_dtype("Qcc").itemsize
    15
    """
    return _layout(fmt, None)[0]


@lru_cache(maxsize=512)
def _layout(fmt: str, length: int | None) -> tuple[np.dtype, tuple[str, ...]]:
    """Structured dtype over a whole message (header included) and the format char of each field."""
    names, offsets, at = ["h1", "h2", "type"], [0, 1, 2], 3
    formats: list[object] = ["u1", "u1", "u1"]
    for i, c in enumerate(fmt):
        code = FORMAT_TO_STRUCT[c][0]
        names.append(f"f{i}")
        formats.append(("<i2", (32,)) if c == "a" else "S" + code[:-1] if code.endswith("s") else _NUMPY_CODE[code])
        offsets.append(at)
        at += struct.calcsize(code)
    spec = {"names": names, "formats": formats, "offsets": offsets, "itemsize": length or at}
    return np.dtype(spec), tuple(fmt)  # type: ignore[call-overload]


def _gather(buf: np.ndarray, offsets: np.ndarray, length: int) -> np.ndarray:
    """Copy the `length` bytes at each offset into a contiguous ``(n, length)`` array."""
    if offsets.size == 0 or buf.size < length:
        return np.empty((0, length), np.uint8)
    windows = np.ndarray((buf.size - length + 1, length), np.uint8, buffer=buf, strides=(1, 1))
    return windows[offsets]


def _decode_table(buf: np.ndarray, fmt: MessageFormat, offsets: np.ndarray, warnings: list[str]) -> MessageTable:
    dtype, chars = _layout(fmt.format, fmt.length)
    rec = _gather(buf, offsets, fmt.length).view(dtype).ravel()
    names = fmt.columns[: len(chars)]
    if len(set(names)) != len(names) or len(fmt.columns) != len(chars):
        warnings.append(f"{fmt.name}: {len(fmt.columns)} column names for {len(chars)} fields "
                        f"{fmt.columns}; as in DFReader, a repeated name keeps its last field.")
    columns = {name: _column(rec[f"f{i}"], chars[i], fmt.name) for i, name in enumerate(names)}
    return MessageTable(fmt, columns, offsets)


def _column(raw: np.ndarray, char: str, message: str) -> np.ndarray:
    """Convert one raw field to the values DFReader returns."""
    mult = FORMAT_TO_STRUCT[char][1]
    if mult is not None:
        if 0.0 < mult < 1.0:  # DFReader divides by 1/mult for accuracy
            return raw.astype(np.float64) / (1 / mult)
        return raw.astype(np.float64) * mult
    if raw.dtype.kind == "S":
        if message == "FILE" and char == "Z":
            return np.array([bytes(v).ljust(raw.dtype.itemsize, b"\0") for v in raw.tolist()], dtype=object)
        return _strings(raw, _df_string)
    return np.ascontiguousarray(raw)


def _strings(raw: np.ndarray, decode: Callable[[bytes], str]) -> np.ndarray:
    """Decode a bytes column with `decode`, vectorised when it is plain ASCII with nothing after a NUL."""
    raw = np.ascontiguousarray(raw)
    mat = raw.view(np.uint8).reshape(raw.size, raw.dtype.itemsize)
    zero = mat == 0
    if (mat < 128).all() and not ((np.cumsum(zero, axis=1) > 0) & ~zero).any():
        return raw.astype(f"U{raw.dtype.itemsize}")  # what either decoding rule gives for such bytes
    unique, inverse = np.unique(raw, return_inverse=True)
    decoded = np.array([decode(v) for v in unique.tolist()] or [""], dtype=str)
    return decoded[inverse.ravel()] if raw.size else decoded[:0]


def _null_term(value: bytes) -> str:
    """pymavlink's ``null_term(bytes)``: decode with backslashreplace, cut at the first NUL."""
    return value.split(b"\0", 1)[0].decode("utf-8", errors="backslashreplace")


def _df_string(value: bytes) -> str:
    """DFReader's string rule: UTF-8, else ISO-8859-1, cut at the first NUL."""
    try:
        text = value.decode("utf-8")
    except UnicodeDecodeError:
        text = value.decode("ISO-8859-1")
    return text.split("\0", 1)[0]


_UnitContext = tuple[dict[int, tuple[str, str]], dict[str, str], dict[str, float]]


def _unit_context(meta: dict[str, MessageTable]) -> _UnitContext | None:
    """FMTU ids per type (the last FMTU wins), UNIT labels and MULT values, as DFReader indexes them."""
    fmtu, unit, mult = meta.get("FMTU"), meta.get("UNIT"), meta.get("MULT")
    if fmtu is None or "FmtType" not in fmtu or "UnitIds" not in fmtu:
        return None
    unit_of = {chr(int(i) & 0xFF): str(s) for i, s in zip(unit["Id"], unit["Label"])} if unit else {}
    mult_of = {chr(int(i) & 0xFF): float("%.7g" % m) for i, m in zip(mult["Id"], mult["Mult"])} if mult else {}
    mult_ids = fmtu["MultIds"] if "MultIds" in fmtu else np.full(len(fmtu), "")
    return {int(t): (str(u), str(m)) for t, u, m in zip(fmtu["FmtType"], fmtu["UnitIds"], mult_ids)}, unit_of, mult_of


def _with_units(fmt: MessageFormat, ids: dict[int, tuple[str, str]], unit_of: dict[str, str],
                mult_of: dict[str, float]) -> MessageFormat:
    """`fmt` with the units and instance column ``DFFormat.set_unit_ids/set_mult_ids`` derive."""
    if fmt.type_id not in ids:
        return fmt
    unit_ids, mults = ids[fmt.type_id]
    units = [unit_of.get(unit_ids[i], "") if i < len(unit_ids) else "" for i in range(len(fmt.columns))]
    for i, char in enumerate(fmt.format[: len(units)]):
        if FORMAT_TO_STRUCT[char][1] is None and units[i] and i < len(mults) and mults[i] in mult_of:
            m = mult_of[mults[i]]
            units[i] = MULT_TO_PREFIX[m] + units[i] if m in MULT_TO_PREFIX else "%.4g %s" % (m, units[i])
    instance = fmt.columns[unit_ids.index("#")] if "#" in unit_ids[: len(fmt.columns)] else None
    return MessageFormat(fmt.type_id, fmt.name, fmt.length, fmt.format, fmt.columns, tuple(units), instance)


def _time_resets(tables: dict[str, MessageTable]) -> list[str]:
    """Warn where the log clock jumps back by more than a second (logs appended)."""
    best: tuple[int, str, list[tuple[int, float, float]]] | None = None
    last_time: dict[str, float] = {}
    for key, table in tables.items():
        column = next((c for c in ("TimeUS", "TimeMS") if c in table.columns), None)
        if column is None or not len(table) or key.startswith("GPS"):
            continue
        name, stamp = key.split("@")[0], table[column].astype(np.int64)
        drops = np.flatnonzero(np.diff(stamp) < -(10**6 if column == "TimeUS" else 10**3))
        if not drops.size and name not in last_time:
            last_time[name] = stamp[-1] / (1e6 if column == "TimeUS" else 1e3)
            continue
        time_s = table.time_s
        assert time_s is not None
        resets = [(int(table.offsets[k + 1]), float(time_s[k]), float(time_s[k + 1])) for k in drops]
        if name in last_time and time_s[0] < last_time[name] - 1.0:  # a later layout of the same name
            resets.insert(0, (int(table.offsets[0]), last_time[name], float(time_s[0])))
        last_time[name] = float(time_s[-1])
        if resets and (best is None or len(table) > best[0]):
            best = (len(table), key, resets)
    if best is None:
        return []
    _, name, resets = best
    where = ", ".join(f"byte offset {o} ({a:.3f} s → {b:.3f} s)" for o, a, b in resets[:_LISTED])
    return [f"{name}: the log clock goes back {len(resets)} time(s), at {where}: several logs are "
            "appended in one file; all their messages are kept."]
