"""Write valid ArduPilot DataFlash ``.bin`` logs from numpy columns.

Used for round-trip tests and synthetic fixtures now, and by the simulator
later. A log is FMT messages (then UNIT, MULT and FMTU when units are given)
followed by the data messages of every block, interleaved by time. Values
are given as pymavlink's ``DFReader`` reads them back (multipliers applied),
so ``decode(encode(values)) == values`` for both DFReader and
:mod:`flightlogs.readers.dataflash`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import numpy as np
from pymavlink.DFReader import FORMAT_TO_STRUCT

from flightlogs.readers.dataflash import message_dtype
from flightlogs.writers.atomic import atomic_output

__all__ = [
    "MessageSpec",
    "MessageBlock",
    "STANDARD_FORMATS",
    "standard_block",
    "parameter_block",
    "text_block",
    "encode_dataflash",
    "write_dataflash",
]

_UNIT_LABELS = {
    "-": "",
    "#": "instance",
    "A": "A",
    "d": "deg",
    "E": "rad/s",
    "h": "degheading",
    "k": "deg/s",
    "m": "m",
    "n": "m/s",
    "o": "m/s/s",
    "O": "degC",
    "s": "s",
    "S": "satellites",
    "v": "V",
    "Y": "us",
    "z": "Hz",
    "D": "deglatitude",
    "U": "deglongitude",
    "%": "%",
}
_MULT_VALUES = {
    "-": 0.0,
    "?": 1.0,
    "2": 1e2,
    "1": 1e1,
    "0": 1.0,
    "A": 1e-1,
    "B": 1e-2,
    "C": 1e-3,
    "D": 1e-4,
    "E": 1e-5,
    "F": 1e-6,
    "G": 1e-7,
    "I": 1e-9,
}


@dataclass(frozen=True, slots=True, kw_only=True)
class MessageSpec:
    """Definition of one DataFlash message type, as its FMT (and FMTU) state it.

    Parameters
    ----------
    name : str
        Up to 4 ASCII characters.
    format : str
        Format characters of pymavlink's ``FORMAT_TO_STRUCT``, one per column.
    columns : tuple of str
        Column names; comma-joined at most 64 characters.
    units : str, optional
        FMTU unit identifiers, one per column (e.g. ``"s#EEE"``); empty for none.
    multipliers : str, optional
        FMTU multiplier identifiers, one per column (e.g. ``"F-000"``).
    """

    name: str
    format: str
    columns: tuple[str, ...]
    units: str = ""
    multipliers: str = ""

    def __post_init__(self) -> None:
        columns = tuple(self.columns.split(",")) if isinstance(self.columns, str) else tuple(self.columns)
        object.__setattr__(self, "columns", columns)
        if not (0 < len(self.name) <= 4 and self.name.isascii()):
            raise ValueError(f"message name {self.name!r} must be 1 to 4 ASCII characters")
        bad = [c for c in self.format if c not in FORMAT_TO_STRUCT]
        if bad or len(self.format) > 16:
            raise ValueError(f"{self.name}: format {self.format!r} must be at most 16 of {''.join(FORMAT_TO_STRUCT)}")
        if len(columns) != len(self.format) or len(",".join(columns)) > 64:
            raise ValueError(
                f"{self.name}: {len(columns)} columns for format {self.format!r} "
                "(need one per character, at most 64 characters joined)"
            )
        for ids, what, table in ((self.units, "units", _UNIT_LABELS), (self.multipliers, "multipliers", _MULT_VALUES)):
            if ids and (len(ids) != len(columns) or any(i not in table for i in ids)):
                raise ValueError(f"{self.name}: {what} {ids!r} need one known identifier per column")

    @property
    def length(self) -> int:
        """Message length in bytes, header included."""
        return message_dtype(self.format).itemsize


@dataclass(frozen=True, slots=True)
class MessageBlock:
    """Messages of one type to write, as columns.

    Parameters
    ----------
    spec : MessageSpec
        The message type.
    data : Mapping[str, array_like]
        One array per column, shape ``(n,)`` (``(n, 32)`` for ``a``), in the
        values DFReader returns: floats for ``c C e E L`` (0.01 and 1e-7
        multipliers applied), ``str`` for ``n N Z``. A ``TimeUS`` (µs) or
        ``TimeMS`` (ms) column orders the messages in the file.
    """

    spec: MessageSpec
    data: Mapping[str, np.ndarray] = field(default_factory=dict)

    def __post_init__(self) -> None:
        missing = [c for c in self.spec.columns if c not in self.data]
        if missing:
            raise ValueError(f"{self.spec.name}: no data for columns {missing}")
        arrays = {c: np.asarray(self.data[c]) for c in self.spec.columns}
        sizes = {c: (a.shape[0] if a.ndim else -1) for c, a in arrays.items()}
        if len(set(sizes.values())) > 1 or -1 in sizes.values():
            raise ValueError(f"{self.spec.name}: columns must be arrays of one length, got {sizes}")
        object.__setattr__(self, "data", MappingProxyType(arrays))

    def __len__(self) -> int:
        return int(next(iter(self.data.values())).shape[0]) if self.data else 0

    def time_us(self) -> np.ndarray:
        """Sort key of each message, µs (-1 when the type has no time column)."""
        if "TimeUS" in self.data:
            return np.asarray(self.data["TimeUS"], dtype=np.int64)
        if "TimeMS" in self.data:
            return np.asarray(self.data["TimeMS"], dtype=np.int64) * 1000
        return np.full(len(self), -1, np.int64)


def _spec(name: str, fmt: str, columns: str, units: str = "", mults: str = "") -> MessageSpec:
    return MessageSpec(name=name, format=fmt, columns=tuple(columns.split(",")), units=units, multipliers=mults)


#: Message types as ArduCopter 4.x logs them (SIDD/SIDS as ``mode_systemid.cpp`` writes them).
STANDARD_FORMATS: Mapping[str, MessageSpec] = MappingProxyType(
    {
        s.name: s
        for s in (
            _spec("PARM", "QNf", "TimeUS,Name,Value", "s--", "F--"),
            _spec("MSG", "QZ", "TimeUS,Message", "s-", "F-"),
            _spec("MODE", "QMBB", "TimeUS,Mode,ModeNum,Rsn", "s---", "F---"),
            _spec(
                "IMU",
                "QBffffffIIfBBHH",
                "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz",
                "s#EEEooo--O--zz",
                "F-000000-----00",
            ),
            _spec(
                "ATT",
                "QccccCCCCB",
                "TimeUS,DesRoll,Roll,DesPitch,Pitch,DesYaw,Yaw,ErrRP,ErrYaw,AEKF",
                "sddddhhdh-",
                "F--------?",
            ),
            _spec(
                "RATE",
                "Qffffffffffff",
                "TimeUS,RDes,R,ROut,PDes,P,POut,YDes,Y,YOut,ADes,A,AOut",
                "skk-kk-kk-oo-",
                "F?????????BB-",
            ),
            _spec(
                "RCOU",
                "QHHHHHHHHHHHHHH",
                "TimeUS,C1,C2,C3,C4,C5,C6,C7,C8,C9,C10,C11,C12,C13,C14",
                "sYYYYYYYYYYYYYY",
                "F--------------",
            ),
            _spec(
                "BAT", "QBfffffcf", "TimeUS,Instance,Volt,VoltR,Curr,CurrTot,EnrgTot,Temp,Res", "s#vvA--O-", "F-000--0-"
            ),
            _spec(
                "CTUN",
                "Qffffffefcfhh",
                "TimeUS,ThI,ABst,ThO,ThH,DAlt,Alt,BAlt,DSAlt,SAlt,TAlt,DCRt,CRt",
                "s----mmmmmmnn",
                "F----00B000BB",
            ),
            _spec("RFND", "QBCBB", "TimeUS,Instance,Dist,Stat,Orient", "s#m--", "F-0--"),
            _spec(
                "GPS",
                "QBBIHBcLLeffffB",
                "TimeUS,I,Status,GMS,GWk,NSats,HDop,Lat,Lng,Alt,Spd,GCrs,VZ,Yaw,U",
                "s#---S-DUmnhnh-",
                "F----0BGGB000--",
            ),
            _spec(
                "XKF1",
                "QBccCfffffffccce",
                "TimeUS,C,Roll,Pitch,Yaw,VN,VE,VD,dPD,PN,PE,PD,GX,GY,GZ,OH",
                "s#ddhnnnnmmmkkkm",
                "F-BBB0000000BBBB",
            ),
            _spec("XKF2", "QBccccchhhhhhB", "TimeUS,C,AX,AY,AZ,VWN,VWE,MN,ME,MD,MX,MY,MZ,MI"),
            _spec("SIDS", "QBfffffff", "TimeUS,Ax,Mag,FSt,FSp,TFin,TC,TR,TFout", "s--ssssss", "F--------"),
            _spec("SIDD", "Qfffffffff", "TimeUS,Time,Targ,F,Gx,Gy,Gz,Ax,Ay,Az", "ss-zkkkooo", "F---------"),
        )
    }
)


def standard_block(name: str, **columns: np.ndarray | Sequence[float]) -> MessageBlock:
    """A block of a :data:`STANDARD_FORMATS` type; columns not given are zeros.

    Parameters
    ----------
    name : str
        Message name, a key of :data:`STANDARD_FORMATS`.
    **columns : array_like, shape (n,)
        Values by column name, as DFReader reads them back.

    Returns
    -------
    MessageBlock

    Examples
    --------
    >>> len(standard_block("SIDD", TimeUS=[1000, 2000], Targ=[0.0, 0.5]))
    2
    """
    spec = STANDARD_FORMATS[name]
    unknown = set(columns) - set(spec.columns)
    if unknown:
        raise ValueError(f"{name} has no columns {sorted(unknown)}; it has {spec.columns}")
    n = len(next(iter(columns.values()))) if columns else 0
    data = {}
    for col, char in zip(spec.columns, spec.format):
        if col in columns:
            data[col] = np.asarray(columns[col])
        elif char in "nNZ":
            data[col] = np.full(n, "", dtype=object)
        else:
            data[col] = np.zeros((n, 32) if char == "a" else n)
    return MessageBlock(spec, data)


def parameter_block(parameters: Mapping[str, float], *, time_us: int = 0) -> MessageBlock:
    """PARM messages, one per parameter.

    Parameters
    ----------
    parameters : Mapping[str, float]
        Name (up to 16 characters) → value (stored as float32).
    time_us : int, optional
        Log time of the messages, µs.

    Returns
    -------
    MessageBlock
    """
    names = list(parameters)
    return standard_block(
        "PARM",
        TimeUS=np.full(len(names), time_us, np.int64),
        Name=np.array(names, dtype=object),
        Value=np.array([parameters[k] for k in names]),
    )


def text_block(texts: Sequence[tuple[int, str]]) -> MessageBlock:
    """MSG messages, e.g. the firmware string or ``"Frame: QUAD"``.

    Parameters
    ----------
    texts : sequence of (int, str)
        ``(time_us, text)`` pairs; text up to 64 bytes in UTF-8.

    Returns
    -------
    MessageBlock
    """
    return standard_block(
        "MSG", TimeUS=np.array([t for t, _ in texts], np.int64), Message=np.array([m for _, m in texts], dtype=object)
    )


def encode_dataflash(
    blocks: Sequence[MessageBlock],
    *,
    parameters: Mapping[str, float] | None = None,
    firmware: str | None = None,
    type_ids: Mapping[str, int] | None = None,
) -> bytes:
    """Encode message blocks as the bytes of a DataFlash ``.bin`` log.

    Parameters
    ----------
    blocks : sequence of MessageBlock
        Data messages; at most one block per message name.
    parameters : Mapping[str, float], optional
        Written as PARM messages at the earliest time of the log.
    firmware : str, optional
        Written as the first MSG, e.g. ``"ArduCopter V4.5.7 (sim)"``; a MSG
        block in `blocks` (say ``"Frame: QUAD"``) is kept after it.
    type_ids : Mapping[str, int], optional
        Type byte per name; others get free numbers from 129 up.

    Returns
    -------
    bytes
        FMT messages, then UNIT/MULT/FMTU if any block has units, then all
        data messages sorted by time (stable: ties keep block order, blocks
        without a time column first).

    Raises
    ------
    ValueError
        If a value does not fit its format (range, string length) or a name repeats.
    """
    blocks = list(blocks)
    times = [b.time_us() for b in blocks if len(b)]
    start = int(min((t.min() for t in times), default=0))
    if firmware is not None:
        blocks = _prepend(blocks, text_block([(max(start, 0), firmware)]))
    if parameters:
        blocks = _prepend(blocks, parameter_block(parameters, time_us=max(start, 0)))
    names = [b.spec.name for b in blocks]
    if len(set(names)) != len(names):
        raise ValueError(f"one block per message name, got {names}")
    specs = [b.spec for b in blocks]
    ids = _assign_ids(specs, dict(type_ids or {}))
    meta = _unit_blocks(specs, ids, max(start, 0))
    ids = _assign_ids([m.spec for m in meta], ids)
    head = [_encode_rows(_fmt_block([*specs, *(m.spec for m in meta)], ids), 128)]
    head += [_encode_rows(m, ids[m.spec.name]) for m in meta]
    return b"".join(r.tobytes() for r in head) + _interleave(blocks, ids)


def write_dataflash(
    path: str | Path,
    blocks: Sequence[MessageBlock],
    *,
    parameters: Mapping[str, float] | None = None,
    firmware: str | None = None,
    type_ids: Mapping[str, int] | None = None,
) -> Path:
    """Write a DataFlash ``.bin`` log, through a temporary file renamed at the end.

    Parameters
    ----------
    path : str or Path
        File to write.
    blocks : sequence of MessageBlock
        Data messages, as for :func:`encode_dataflash`.
    parameters : Mapping[str, float], optional
        PARM messages.
    firmware : str, optional
        First MSG message.
    type_ids : Mapping[str, int], optional
        Type byte per name.

    Returns
    -------
    Path
        `path`.
    """
    path = Path(path)
    payload = encode_dataflash(blocks, parameters=parameters, firmware=firmware, type_ids=type_ids)
    with atomic_output(path) as tmp:
        tmp.write_bytes(payload)
    return path


def _prepend(blocks: list[MessageBlock], extra: MessageBlock) -> list[MessageBlock]:
    """`extra` before the block of the same name (same spec required), else first."""
    for k, block in enumerate(blocks):
        if block.spec.name == extra.spec.name:
            if block.spec != extra.spec:
                raise ValueError(f"{block.spec.name}: the block's format differs from {extra.spec.format!r}")
            merged = {c: np.concatenate([np.asarray(extra.data[c]), np.asarray(block.data[c])]) for c in block.data}
            return [*blocks[:k], MessageBlock(block.spec, merged), *blocks[k + 1 :]]
    return [extra, *blocks]


def _free_id(ids: Mapping[str, int]) -> int:
    used = set(ids.values()) | {128}
    for candidate in range(129, 256):
        if candidate not in used:
            return candidate
    for candidate in range(1, 128):
        if candidate not in used:
            return candidate
    raise ValueError("more than 254 message types")


def _assign_ids(specs: Sequence[MessageSpec], ids: dict[str, int]) -> dict[str, int]:
    for spec in specs:
        if spec.name not in ids:
            ids[spec.name] = _free_id(ids)
    return ids


def _fmt_block(specs: Sequence[MessageSpec], ids: Mapping[str, int]) -> MessageBlock:
    fmt = MessageSpec(name="FMT", format="BBnNZ", columns=("Type", "Length", "Name", "Format", "Columns"))
    return MessageBlock(
        fmt,
        {
            "Type": np.array([ids[s.name] for s in specs]),
            "Length": np.array([s.length for s in specs]),
            "Name": np.array([s.name for s in specs], dtype=object),
            "Format": np.array([s.format for s in specs], dtype=object),
            "Columns": np.array([",".join(s.columns) for s in specs], dtype=object),
        },
    )


def _unit_blocks(specs: Sequence[MessageSpec], ids: Mapping[str, int], time_us: int) -> list[MessageBlock]:
    """UNIT, MULT and FMTU blocks for the specs that carry units."""
    with_units = [s for s in specs if s.units]
    if not with_units:
        return []
    unit_ids = sorted({u for s in with_units for u in s.units})
    mult_ids = sorted({m for s in with_units for m in (s.multipliers or "?" * len(s.columns))})
    unit = MessageBlock(
        MessageSpec(name="UNIT", format="QbZ", columns=("TimeUS", "Id", "Label")),
        {
            "TimeUS": np.full(len(unit_ids), time_us),
            "Id": np.array([ord(u) for u in unit_ids]),
            "Label": np.array([_UNIT_LABELS[u] for u in unit_ids], dtype=object),
        },
    )
    mult = MessageBlock(
        MessageSpec(name="MULT", format="Qbd", columns=("TimeUS", "Id", "Mult")),
        {
            "TimeUS": np.full(len(mult_ids), time_us),
            "Id": np.array([ord(m) for m in mult_ids]),
            "Mult": np.array([_MULT_VALUES[m] for m in mult_ids]),
        },
    )
    fmtu = MessageBlock(
        MessageSpec(name="FMTU", format="QBNN", columns=("TimeUS", "FmtType", "UnitIds", "MultIds")),
        {
            "TimeUS": np.full(len(with_units), time_us),
            "FmtType": np.array([ids[s.name] for s in with_units]),
            "UnitIds": np.array([s.units for s in with_units], dtype=object),
            "MultIds": np.array([s.multipliers or "?" * len(s.columns) for s in with_units], dtype=object),
        },
    )
    return [unit, mult, fmtu]


def _encode_rows(block: MessageBlock, type_id: int) -> np.ndarray:
    """The block's messages as a structured array, one record per message."""
    spec = block.spec
    rec = np.zeros(len(block), dtype=message_dtype(spec.format))
    rec["h1"], rec["h2"], rec["type"] = 0xA3, 0x95, type_id
    for i, (column, char) in enumerate(zip(spec.columns, spec.format)):
        rec[f"f{i}"] = _raw(block.data[column], char, rec.dtype[f"f{i}"], f"{spec.name}.{column}")
    return rec


def _raw(values: np.ndarray, char: str, dtype: np.dtype, where: str) -> np.ndarray:
    """Values as DFReader returns them → the raw field (undoing the multiplier)."""
    if dtype.kind == "S":
        encoded = [str(v).encode("utf-8") for v in np.asarray(values, dtype=object).ravel()]
        too_long = [v for v in encoded if len(v) > dtype.itemsize]
        if too_long:
            raise ValueError(f"{where}: {too_long[0]!r} is longer than {dtype.itemsize} bytes")
        return np.array(encoded, dtype=dtype)
    base = dtype.base if dtype.subdtype else dtype
    mult = FORMAT_TO_STRUCT[char][1]
    values = np.asarray(values, dtype=np.float64 if mult is not None else None)
    if mult is not None:
        values = np.rint(values * (1 / mult))
    if base.kind in "iu":
        info = np.iinfo(base)
        if values.size and values.dtype.kind == "f" and np.any(values != np.round(values)):
            raise ValueError(f"{where}: format {char!r} holds integers, got fractions")
        if values.size and (not np.all(np.isfinite(values)) or values.min() < info.min or values.max() > info.max):
            raise ValueError(f"{where}: values outside the range of format {char!r} ({info.min}..{info.max} raw)")
    return values.astype(base)


def _interleave(blocks: Sequence[MessageBlock], ids: Mapping[str, int]) -> bytes:
    """All data messages, sorted by time, as one byte string."""
    blocks = [b for b in blocks if len(b)]
    if not blocks:
        return b""
    rows = [_encode_rows(b, ids[b.spec.name]) for b in blocks]
    times = np.concatenate([b.time_us() for b in blocks])
    lengths = np.concatenate([np.full(len(b), r.dtype.itemsize, np.int64) for b, r in zip(blocks, rows)])
    order = np.argsort(times, kind="stable")
    starts = np.empty_like(lengths)
    starts[order] = np.concatenate([[0], np.cumsum(lengths[order])[:-1]])
    out = np.zeros(int(lengths.sum()), np.uint8)
    at = 0
    for r in rows:
        n, width = r.size, r.dtype.itemsize
        windows = np.ndarray((out.size - width + 1, width), np.uint8, buffer=out, strides=(1, 1))
        windows[starts[at : at + n]] = r.view(np.uint8).reshape(n, width)
        at += n
    return out.tobytes()
