"""Recognise a log's format from its first bytes, never from its name."""

from __future__ import annotations

from pathlib import Path

from flightlogs.errors import LogFormatError
from flightlogs.flightlog import LogFormat

__all__ = ["detect_format"]

_ULOG_MAGIC = b"ULog\x01\x12\x35"
_DATAFLASH_HEADER = b"\xa3\x95"
_MAVLINK_STX = (0xFE, 0xFD)  # MAVLink v1, v2 start bytes
_HEAD_BYTES = 4096


def detect_format(path: Path) -> LogFormat:
    """Return the format of a flight log from its content.

    Parameters
    ----------
    path : Path
        File to inspect; only its first 4 KiB are read.

    Returns
    -------
    {"ulog", "dataflash", "tlog"}
        PX4 ULog (magic ``ULog\\x01\\x12\\x35``), ArduPilot DataFlash (first
        message a FMT, header ``A3 95 80``) or a MAVLink telemetry log (64-bit
        big-endian µs timestamp followed by a MAVLink start byte, at least
        twice in a row).

    Raises
    ------
    LogFormatError
        If the file is missing, empty or none of the three.
    """
    path = Path(path)
    try:
        with path.open("rb") as stream:
            head = stream.read(_HEAD_BYTES)
    except OSError as err:
        raise LogFormatError(f"{path}: cannot be read ({err.strerror or err}).") from err
    if not head:
        raise LogFormatError(f"{path}: the file is empty.")
    if head.startswith(_ULOG_MAGIC):
        return "ulog"
    if head.startswith(_DATAFLASH_HEADER + b"\x80") or _dataflash_after_garbage(head):
        return "dataflash"
    if _looks_like_tlog(head):
        return "tlog"
    raise LogFormatError(
        f"{path}: not a PX4 ULog, ArduPilot DataFlash or MAVLink telemetry log (first bytes {head[:8].hex(' ')})."
    )


def _dataflash_after_garbage(head: bytes) -> bool:
    """A FMT-of-FMT message (A3 95 80 80 59) somewhere in the head: damaged start, readable rest."""
    return b"\xa3\x95\x80\x80\x59" in head


def _looks_like_tlog(head: bytes) -> bool:
    """Two consecutive MAVLink frames, each behind an 8-byte timestamp."""
    offset = 0
    for _ in range(2):
        if len(head) < offset + 10 or head[offset + 8] not in _MAVLINK_STX:
            return False
        stx, payload_len = head[offset + 8], head[offset + 9]
        if stx == 0xFE:
            frame = 6 + payload_len + 2
        else:
            incompat_flags = head[offset + 10] if len(head) > offset + 10 else 0
            frame = 10 + payload_len + 2 + (13 if incompat_flags & 0x01 else 0)
        offset += 8 + frame
    return True
