"""Tests of flightlogs.writers.dataflash: what it writes, DFReader and our decoder read back exactly."""

from __future__ import annotations

import array
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pymavlink.DFReader import FORMAT_TO_STRUCT, DFReader_binary

from flightlogs.readers.dataflash import DataFlashMessages, decode_messages, message_dtype, read_messages
from flightlogs.writers.dataflash import (
    STANDARD_FORMATS,
    MessageBlock,
    MessageSpec,
    encode_dataflash,
    parameter_block,
    standard_block,
    text_block,
    write_dataflash,
)


def assert_same_as_dfreader(ours: DataFlashMessages, path: Path) -> None:
    """Every field DFReader reads equals ours (floats bitwise, ints and strings exactly)."""
    reader = DFReader_binary(str(path))
    counts: dict[str, int] = {}
    while (msg := reader._parse_next()) is not None:
        name = msg.get_type()
        i = counts[name] = counts.get(name, -1) + 1
        for column in msg.fmt.columns:
            ref, got = getattr(msg, column), ours[name][column][i]
            if isinstance(ref, float):
                assert np.float64(got).tobytes() == np.float64(ref).tobytes(), f"{name}.{column}"
            elif isinstance(ref, array.array):
                assert got.tolist() == list(ref), f"{name}.{column}"
            else:
                assert got.tolist() == ref and type(got.tolist()) is type(ref), f"{name}.{column}"
    reader.close()
    assert counts == {k: len(t) - 1 for k, t in ours.tables.items() if len(t)}


_STRING_SIZE = {"n": 4, "N": 16, "Z": 64}
_INT_RANGE = {
    "b": (-128, 127),
    "B": (0, 255),
    "h": (-32768, 32767),
    "H": (0, 65535),
    "i": (-(2**31), 2**31 - 1),
    "I": (0, 2**32 - 1),
    "q": (-(2**63), 2**63 - 1),
    "Q": (0, 2**64 - 1),
    "M": (-128, 127),
    "c": (-32768, 32767),
    "C": (0, 65535),
    "e": (-(2**31), 2**31 - 1),
    "E": (0, 2**32 - 1),
    "L": (-(2**31), 2**31 - 1),
}


def _column(char: str, n: int) -> st.SearchStrategy:
    """Values of one column as DFReader returns them (multipliers applied the DFReader way)."""
    if char in _STRING_SIZE:
        text = st.text(st.characters(min_codepoint=32, max_codepoint=126), max_size=_STRING_SIZE[char])
        return st.lists(text, min_size=n, max_size=n).map(lambda v: np.array(v, dtype=object))
    if char == "a":
        return st.lists(st.lists(st.integers(-32768, 32767), min_size=32, max_size=32), min_size=n, max_size=n).map(
            lambda v: np.array(v, dtype=np.int16).reshape(n, 32)
        )
    if char in "fgd":
        width = {"f": 32, "g": 16, "d": 64}[char]
        return st.lists(st.floats(width=width, allow_nan=False), min_size=n, max_size=n).map(np.array)
    lo, hi = _INT_RANGE[char]
    mult = FORMAT_TO_STRUCT[char][1]
    raw = st.lists(st.integers(lo, hi), min_size=n, max_size=n)
    if mult is None:
        return raw.map(lambda v: np.array(v, dtype=object).astype(np.uint64 if lo == 0 else np.int64))
    return raw.map(lambda v: np.array(v, dtype=np.float64) / (1 / mult))


@st.composite
def _blocks(draw: st.DrawFn) -> list[MessageBlock]:
    chars = "".join(sorted(FORMAT_TO_STRUCT))
    blocks = []
    for k in range(draw(st.integers(1, 3))):
        # a message is at most 255 bytes (its FMT Length is one byte): draw formats that fit
        fmt = draw(
            st.text(st.sampled_from(chars), min_size=1, max_size=8).filter(
                lambda f: message_dtype("Q" + f).itemsize <= 255
            )
        )
        n = draw(st.integers(0, 6))
        spec = MessageSpec(name=f"T{k}", format="Q" + fmt, columns=("TimeUS", *(f"F{i}" for i in range(len(fmt)))))
        data = {"TimeUS": np.array(draw(st.lists(st.integers(0, 10**12), min_size=n, max_size=n)), dtype=np.uint64)}
        data.update({f"F{i}": draw(_column(c, n)) for i, c in enumerate(fmt)})
        blocks.append(MessageBlock(spec, data))
    return blocks


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(blocks=_blocks())
def test_any_format_round_trips_through_dfreader_and_our_decoder(blocks: list[MessageBlock]) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = write_dataflash(Path(tmp) / "any.bin", blocks)
        ours = read_messages(path)
        assert ours.warnings == ()
        for block in blocks:
            if not len(block):
                assert block.spec.name not in ours.counts
                continue
            table = ours[block.spec.name]
            order = np.argsort(block.time_us(), kind="stable")
            for column, values in block.data.items():
                expected = np.asarray(values)[order]
                got = table[column]
                if got.dtype.kind == "U":
                    assert got.tolist() == expected.tolist(), column
                else:
                    np.testing.assert_array_equal(got, expected.astype(got.dtype), err_msg=column)
        assert_same_as_dfreader(ours, path)


def _sysid_log() -> tuple[bytes, dict[str, np.ndarray]]:
    """A mixer-roll sweep as ArduCopter's System ID mode logs it."""
    t = 20_000_000 + 2500 * np.arange(2000)
    chirp = np.sin(2 * np.pi * np.linspace(0.5, 5.0, t.size) * (t - t[0]) / 1e6).astype(np.float32)
    sidd = standard_block(
        "SIDD",
        TimeUS=t,
        Time=((t - t[0]) / 1e6).astype(np.float32),
        Targ=chirp,
        F=np.linspace(0.5, 5.0, t.size).astype(np.float32),
        Gx=np.zeros(t.size),
    )
    sids = standard_block(
        "SIDS", TimeUS=t[:1] - 1, Ax=[10], Mag=[0.1], FSt=[0.5], FSp=[5.0], TFin=[1.0], TC=[4.0], TR=[5.0], TFout=[0.5]
    )
    payload = encode_dataflash(
        [sidd, sids], parameters={"SID_AXIS": 10.0, "FRAME_CLASS": 1.0}, firmware="ArduCopter V4.5.7 (synthetic)"
    )
    return payload, {"TimeUS": t, "Targ": chirp}


def test_sidd_sids_parm_msg_round_trip(tmp_path: Path) -> None:
    payload, truth = _sysid_log()
    path = tmp_path / "sysid.bin"
    path.write_bytes(payload)
    ours = read_messages(path)
    assert_same_as_dfreader(ours, path)
    np.testing.assert_array_equal(ours["SIDD"]["TimeUS"], truth["TimeUS"])
    np.testing.assert_array_equal(ours["SIDD"]["Targ"], truth["Targ"])
    assert ours["SIDS"]["Ax"].tolist() == [10] and ours["SIDS"]["FSp"].tolist() == [5.0]
    assert ours["SIDD"].format.columns == ("TimeUS", "Time", "Targ", "F", "Gx", "Gy", "Gz", "Ax", "Ay", "Az")
    assert ours["SIDD"].format.units == ("µs", "s", "", "Hz", "deg/s", "deg/s", "deg/s", "m/s/s", "m/s/s", "m/s/s")
    assert ours["SIDS"].format.format == "QBfffffff"
    assert dict(zip(ours["PARM"]["Name"], ours["PARM"]["Value"])) == {"SID_AXIS": 10.0, "FRAME_CLASS": 1.0}
    assert ours["MSG"]["Message"].tolist() == ["ArduCopter V4.5.7 (synthetic)"]
    reader = DFReader_binary(str(path))
    assert reader.params == {"SID_AXIS": 10.0, "FRAME_CLASS": 1.0}
    reader.close()


def test_firmware_and_parameters_join_user_msg_and_parm_blocks() -> None:
    frame = text_block([(5000, "Frame: QUAD/X")])
    parm = parameter_block({"FRAME_CLASS": 1.0}, time_us=5000)
    ours = decode_messages(encode_dataflash([frame, parm], firmware="ArduCopter V4.5.7", parameters={"A": 2.0}))
    assert ours["MSG"]["Message"].tolist() == ["ArduCopter V4.5.7", "Frame: QUAD/X"]
    assert ours["PARM"]["Name"].tolist() == ["A", "FRAME_CLASS"]


def test_messages_are_interleaved_by_time() -> None:
    att = standard_block("ATT", TimeUS=[100, 300, 500], Roll=[1.0, 2.0, 3.0])
    rate = standard_block("RATE", TimeUS=[200, 300, 400], ROut=[0.5, 0.25, 0.125])
    ours = decode_messages(encode_dataflash([att, rate]))
    offsets = np.concatenate([ours["ATT"].offsets, ours["RATE"].offsets])
    times = np.concatenate([ours["ATT"]["TimeUS"], ours["RATE"]["TimeUS"]])
    assert times[np.argsort(offsets)].tolist() == [100, 200, 300, 300, 400, 500]  # ties keep block order
    assert ours["ATT"].offsets[1] < ours["RATE"].offsets[1]


def test_write_dataflash_leaves_no_temporary_file(tmp_path: Path) -> None:
    path = write_dataflash(tmp_path / "one.bin", [standard_block("ATT", TimeUS=[1], Roll=[0.5])])
    assert [p.name for p in tmp_path.iterdir()] == ["one.bin"]
    assert read_messages(path)["ATT"]["Roll"].tolist() == [0.5]


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: MessageSpec(name="TOOLONG", format="Q", columns=("TimeUS",)), "1 to 4 ASCII"),
        (lambda: MessageSpec(name="X", format="Qx", columns=("TimeUS", "A")), "format 'Qx'"),
        (lambda: MessageSpec(name="X", format="QB", columns=("TimeUS",)), "1 columns for format"),
        (lambda: MessageSpec(name="X", format="QB", columns=("TimeUS", "A"), units="s?"), "units"),
        (
            lambda: MessageBlock(MessageSpec(name="X", format="QB", columns=("TimeUS", "A")), {"TimeUS": [1]}),
            "no data for columns",
        ),
        (lambda: encode_dataflash([standard_block("ATT", TimeUS=[1], Roll=[400.0])]), "outside the range"),
        (lambda: encode_dataflash([standard_block("RCOU", TimeUS=[1], C1=[1500.5])]), "fractions"),
        (lambda: encode_dataflash([standard_block("MSG", TimeUS=[1], Message=["x" * 65])]), "longer than 64"),
        (lambda: encode_dataflash([standard_block("ATT", TimeUS=[1])] * 2), "one block per message name"),
        (lambda: standard_block("ATT", Bogus=[1]), "has no columns"),
    ],
    ids=["name", "format", "columns", "units", "data", "range", "fraction", "string", "duplicate", "unknown-column"],
)
def test_invalid_definitions_and_values_are_refused(make, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        make()


def test_standard_formats_are_valid_and_sized_like_ardupilot() -> None:
    assert STANDARD_FORMATS["SIDS"].length == 3 + 8 + 1 + 7 * 4
    assert STANDARD_FORMATS["SIDD"].length == 3 + 8 + 9 * 4
    assert STANDARD_FORMATS["IMU"].units[1] == "#"


def test_a_message_longer_than_255_bytes_is_refused(tmp_path: Path) -> None:
    """DataFlash's FMT Length is one byte: Q + four 64-byte strings (3 + 8 + 256 bytes) cannot be written."""
    spec = MessageSpec(name="LONG", format="QZZZZ", columns=("TimeUS", "A", "B", "C", "D"))
    block = MessageBlock(
        spec, {"TimeUS": np.array([1], dtype=np.uint64), **{c: np.array(["x"], dtype=object) for c in "ABCD"}}
    )
    with pytest.raises(ValueError, match="FMT.Length"):
        write_dataflash(tmp_path / "long.bin", [block])
    assert not (tmp_path / "long.bin").exists()
