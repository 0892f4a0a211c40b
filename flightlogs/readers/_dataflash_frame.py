"""Framing of DataFlash bytes: where each message is, and the layout it has.

The implementation behind :func:`flightlogs.readers.dataflash.decode_messages`; the
rules (DFReader's, quirks included) are in :mod:`flightlogs.readers.dataflash`. FMT
messages are parsed from header candidates found by a vectorised scan, the
chain of messages is walked as DFReader steps, the bytes left over are
reported, and the offsets are grouped per layout. :class:`MessageFormat` is
re-exported by :mod:`flightlogs.readers.dataflash`.
"""

from __future__ import annotations

import bisect
import mmap
import struct
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any, cast

import numpy as np
from pymavlink.DFReader import FORMAT_TO_STRUCT, DFFormat

from flightlogs.errors import DataQualityWarning, LogCorruptionWarning, LogFormatError

__all__ = ["MessageFormat"]

HEAD1, HEAD2, FMT_TYPE = 0xA3, 0x95, 0x80
LISTED = 8  # gaps or resets spelled out in warnings before summarising
_SCAN_BLOCK = 1 << 22  # bytes compared at a time in the header scan
_GATHER_BLOCK = 1 << 16  # messages copied at a time when the pages read are given back
GATHER_SPAN = 8 << 20  # bytes of the file read at most before they are given back
_FMT = DFFormat(FMT_TYPE, "FMT", 89, "BBnNZ", "Type,Length,Name,Format,Columns")  # as DFReader
_NUMPY_CODE = {
    "b": "i1",
    "B": "u1",
    "h": "<i2",
    "H": "<u2",
    "i": "<i4",
    "I": "<u4",
    "f": "<f4",
    "d": "<f8",
    "e": "<f2",
    "q": "<i8",
    "Q": "<u8",
}
_CHAR_SIZE = {c: struct.calcsize("<" + code) for c, (code, _, _) in FORMAT_TO_STRUCT.items()}
_VALID_CHARS = frozenset(FORMAT_TO_STRUCT)


@dataclass(frozen=True, slots=True, kw_only=True)
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
class _Definition:
    """One FMT message, parsed; `decodable` when its Length fits its format characters."""

    offset: int
    fmt: MessageFormat
    decodable: bool


_FMT_DEF = _Definition(
    -1,
    MessageFormat(type_id=FMT_TYPE, name="FMT", length=_FMT.len, format=_FMT.format, columns=tuple(_FMT.columns)),
    True,
)


Release = Callable[[int, int], None]
"""Gives the pages of bytes ``[lo, hi)`` of a memory-mapped log back to the page cache, once read."""


def mapped_log(path: Path) -> tuple[np.ndarray, Release]:
    """The bytes of the file at `path`, memory-mapped read-only, and their :data:`Release`.

    A page read is in the process's memory until it is released; the page
    cache keeps it, so reading it again costs a minor fault, not a disk read.
    """
    with path.open("rb") as stream:
        mapping = mmap.mmap(stream.fileno(), 0, access=mmap.ACCESS_READ)
    advice = getattr(mmap, "MADV_DONTNEED", None)

    def release(lo: int, hi: int) -> None:
        first = -(-max(lo, 0) // mmap.PAGESIZE) * mmap.PAGESIZE  # whole pages inside [lo, hi) only
        last = min(hi, len(mapping)) // mmap.PAGESIZE * mmap.PAGESIZE
        if advice is not None and last > first and not mapping.closed:
            mapping.madvise(advice, first, last - first)

    return np.frombuffer(mapping, dtype=np.uint8), release


def frame_messages(
    buf: np.ndarray, path: Path, release: Release | None = None
) -> tuple[list[tuple[str, MessageFormat, np.ndarray]], int]:
    """``(table key, format, offsets)`` of the messages DFReader would decode, per layout; bytes skipped.

    The FMT messages on the chain of messages define the chain (types and
    lengths), so the walk is repeated until the two agree (once, in practice).
    """
    heads, types = _header_candidates(buf, release)
    parsed = {d.offset: d for d in _parse_fmts(buf, heads[(types == FMT_TYPE) & (heads <= buf.size - _FMT.len)])}
    on_chain = {o for o, d in parsed.items() if d.decodable and d.fmt.name.isprintable() and d.fmt.name}
    for _ in range(6):
        by_type = _by_type([parsed[o] for o in sorted(on_chain) if o in parsed])
        starts, ends, decodes, kinds = _walk(heads, types, by_type)
        found = set(starts[kinds == FMT_TYPE].tolist())
        if found == on_chain:
            break
        on_chain = found
    if len(by_type) == 1:
        kind = "a text DataFlash log" if buf[:4].tobytes() == b"FMT," else "no DataFlash FMT message"
        raise LogFormatError(f"{path}: holds {kind} (searched {buf.size} bytes from byte offset 0).")
    kept, skipped = _account(buf, starts, ends, decodes, path)
    if release is not None:
        release(0, buf.size)  # the FMT messages and the damage read: the pages go back
    return _layouts(starts[kept], kinds[kept], by_type, path), skipped


def _header_candidates(buf: np.ndarray, release: Release | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Offset and type byte of every ``A3 95 <byte>``, shapes (n_candidates,), scanned a block at a time.

    One comparison over the whole file would take a temporary the size of the
    file, and most of its time in faulting that memory in. Each block's pages
    are released once scanned.
    """
    found, kinds = [np.empty(0, np.int64)], [np.empty(0, np.uint8)]
    for lo in range(0, max(buf.size - 2, 0), _SCAN_BLOCK):
        end = min(lo + _SCAN_BLOCK, buf.size - 2)
        block = buf[lo : end + 2]  # two bytes more: a last candidate's second byte and type
        first = np.flatnonzero(block[: end - lo] == HEAD1)
        first = first[block[first + 1] == HEAD2]
        found.append(first + lo)
        kinds.append(block[first + 2])
        if release is not None:
            release(lo, end)
    return np.concatenate(found).astype(_offset_dtype(buf.size), copy=False), np.concatenate(kinds)


def _offset_dtype(size: int) -> type[np.signedinteger[Any]]:
    """Byte offsets into `size` bytes: int32 (half the memory) when they fit, with room for a message's length."""
    return np.int32 if size < 2**31 - 2**16 else np.int64


def _by_type(defs: list[_Definition]) -> dict[int, list[_Definition]]:
    by_type: dict[int, list[_Definition]] = {FMT_TYPE: [_FMT_DEF]}
    for d in defs:
        if d.fmt.type_id != FMT_TYPE:
            by_type.setdefault(d.fmt.type_id, []).append(d)
    return by_type


def _walk(
    heads: np.ndarray, types: np.ndarray, by_type: dict[int, list[_Definition]]
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Start, end, decodability and type of each message, stepping as DFReader does.

    After a message, the next one is the first candidate ``A3 95 <known
    type>`` at or after its end. The Python loop turns once per
    discontinuity (garbage, a header inside a payload), not per message.
    """
    lenmap, okmap = np.zeros(256, heads.dtype), np.zeros(256, bool)
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
    cand, ends, decodes, kinds = heads[known], heads[known], decodes[known], types[known]
    ends += lengths[known]
    del lengths, known
    jump = np.flatnonzero(ends[:-1] != cand[1:])  # usually a message ends where the next begins
    resume = np.searchsorted(cand, ends[jump])  # where the walk goes on after each jump
    breaks = jump.tolist()
    on_chain = np.zeros(cand.size, bool)
    i = 0
    while i < cand.size:  # a run of contiguous messages from i to the next break, then a jump
        k = bisect.bisect_left(breaks, i)
        j = breaks[k] if k < len(breaks) else cand.size - 1
        on_chain[i : j + 1] = True
        i = int(resume[k]) if k < len(breaks) else cand.size
    return cand[on_chain], ends[on_chain], decodes[on_chain], kinds[on_chain]


def _account(
    buf: np.ndarray, starts: np.ndarray, ends: np.ndarray, decodes: np.ndarray, path: Path
) -> tuple[np.ndarray, int]:
    """Which messages are decodable and complete (a mask over `starts`); the rest warned about (:class:`LogCorruptionWarning`)."""
    size, name = buf.size, path.name
    found = []
    if not decodes.all():
        types = ", ".join(sorted({str(t) for t in buf[starts[~decodes] + 2].tolist()}))
        found.append(
            f"{name}: {int((~decodes).sum())} messages of type(s) {types} have a FMT length "
            "that disagrees with their format; skipped."
        )
    truncated = ends > size
    if truncated.any():
        at = int(starts[truncated][0])
        found.append(
            f"{name}: truncated final message (type {buf[at + 2]}) at byte offset {at}: "
            f"{size - at} bytes left of {int(ends[truncated][0]) - at}."
        )
    gap_at = np.concatenate([[0], np.minimum(ends, size)])
    gap_len = np.concatenate([starts, [size]]) - gap_at
    shown = np.flatnonzero(gap_len > 0)
    found.extend(f"{name}: skipped {int(gap_len[k])} bytes at offset {int(gap_at[k])}." for k in shown[:LISTED])
    if shown.size > LISTED:
        found.append(f"{name}: skipped bytes at {shown.size - LISTED} more places.")
    for message in found:
        warnings.warn(LogCorruptionWarning(message), stacklevel=2)
    skipped = int(gap_len.sum() + 3 * (~decodes).sum() + (size - starts[truncated]).sum())
    return decodes & ~truncated, skipped


def _layouts(
    offsets: np.ndarray, types: np.ndarray, by_type: dict[int, list[_Definition]], path: Path
) -> list[tuple[str, MessageFormat, np.ndarray]]:
    """Group message offsets (with their type bytes) by layout (name, format, columns) under their table key."""
    layouts: dict[tuple[str, str, tuple[str, ...]], list[np.ndarray]] = {}
    formats: dict[tuple[str, str, tuple[str, ...]], MessageFormat] = {}
    for type_id in np.flatnonzero(np.bincount(types, minlength=256)).tolist():
        sel, defs = offsets[types == type_id], by_type[type_id]
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
            message = f"{path.name}: {key[0]} is redefined with format {key[1]!r}; those messages are in {label!r}."
            warnings.warn(DataQualityWarning(message), stacklevel=2)
        parts = layouts[key]
        result.append((label, formats[key], parts[0] if len(parts) == 1 else np.sort(np.concatenate(parts))))
    return result


def _parse_fmts(buf: np.ndarray, offsets: np.ndarray) -> list[_Definition]:
    """Parse FMT candidates at `offsets`; formats pymavlink cannot read are left out."""
    if offsets.size == 0:
        return []
    rows = gather(buf, offsets, _FMT.len)
    rec = rows.view(layout(_FMT.format, _FMT.len)[0]).ravel()
    defs = []
    texts = (strings(rec[f"f{i}"], _null_term).tolist() for i in (2, 3, 4))
    for off, type_id, length, name, fmt, cols in zip(offsets.tolist(), rec["f0"].tolist(), rec["f1"].tolist(), *texts):
        if not _VALID_CHARS.issuperset(fmt):
            continue
        size = sum(_CHAR_SIZE[c] for c in fmt)
        columns = tuple(cols.split(",")) if cols else ()
        defs.append(
            _Definition(
                off,
                MessageFormat(type_id=type_id, name=name, length=length, format=fmt, columns=columns),
                length == size + 3,
            )
        )
    return defs


@lru_cache(maxsize=512)
def layout(fmt: str, length: int | None) -> tuple[np.dtype, tuple[str, ...]]:
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


def gather(buf: np.ndarray, offsets: np.ndarray, length: int, release: Release | None = None) -> np.ndarray:
    """Copy the `length` bytes at each offset (increasing) into a contiguous ``(n, length)`` array.

    With `release`, a block of offsets at a time, giving back the pages the
    next block starts past.
    """
    if offsets.size == 0 or buf.size < length:
        return np.empty((0, length), np.uint8)
    windows = np.ndarray((buf.size - length + 1, length), np.uint8, buffer=buf, strides=(1, 1))
    if release is None:
        return cast(np.ndarray, windows[offsets])
    out = np.empty((offsets.size, length), np.uint8)
    spans = np.searchsorted(offsets, np.arange(GATHER_SPAN, int(offsets[-1]) + 1, GATHER_SPAN))
    # a table sparse in the file touches every page in one block of messages (the kernel maps
    # the pages around each one read): blocks end every span of bytes as well
    ends = np.union1d(spans, np.arange(_GATHER_BLOCK, offsets.size, _GATHER_BLOCK)).tolist() + [offsets.size]
    lo = done = 0
    for hi in ends:
        if hi > lo:
            out[lo:hi] = windows[offsets[lo:hi]]
            reached = int(offsets[hi]) if hi < offsets.size else buf.size
            release(done, reached)
            done, lo = reached, hi
    return out


def strings(raw: np.ndarray, decode: Callable[[bytes], str]) -> np.ndarray:
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
