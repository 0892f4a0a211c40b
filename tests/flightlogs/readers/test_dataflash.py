"""Tests of flightlogs.readers.dataflash: values identical to pymavlink's DFReader, corruption handled.

Reference values are cross-implementation: pymavlink's ``DFReader_binary``
read message by message (``_parse_next``) on the same bytes. Equality is
exact: ints and strings equal, floats bitwise equal.
"""

from __future__ import annotations

import array
import functools
import warnings
from pathlib import Path

import numpy as np
import pytest
from pymavlink.DFReader import DFReader_binary

from flightlogs.errors import DataQualityWarning, LogCorruptionWarning, LogFormatError
from flightlogs.readers.dataflash import DataFlashMessages, decode_messages, message_dtype, read_messages
from flightlogs.writers.dataflash import MessageBlock, encode_dataflash, standard_block, text_block

SAMPLE = ("ardupilot-log-diagnosis", "sample.bin")  # ArduCopter 3.6.4, TimeUS, FMTU units
LOG171 = ("dronekit-la-testdata", "log171.bin")  # ArduCopter 3.3-dev, TimeMS, no FMTU


@functools.cache
def dfreader_rows(path: str) -> dict[str, tuple[tuple[str, ...], list[list[object]]]]:
    """Every message DFReader yields: name → (columns, one value list per message)."""
    reader = DFReader_binary(path)
    rows: dict[str, tuple[tuple[str, ...], list[list[object]]]] = {}
    while (msg := reader._parse_next()) is not None:
        entry = rows.setdefault(msg.get_type(), (tuple(msg.fmt.columns), []))
        entry[1].append([getattr(msg, c) for c in msg.fmt.columns])
    reader.close()
    return rows


def assert_column_equal(ours: np.ndarray, ref: list[object], where: str) -> None:
    """Exact equality with DFReader's Python values, type kind included."""
    first = ref[0]
    if isinstance(first, float):
        assert ours.dtype.kind == "f", where
        a, b = np.asarray(ours, np.float64), np.asarray(ref, np.float64)
        same = (a.view(np.uint64) == b.view(np.uint64)) | (np.isnan(a) & np.isnan(b))
        assert same.all(), f"{where}: first difference at {np.flatnonzero(~same)[0]}"
    elif isinstance(first, array.array):
        np.testing.assert_array_equal(ours, np.array([list(r) for r in ref], dtype=np.int16), err_msg=where)
    elif isinstance(first, str):
        assert ours.dtype.kind == "U", where
        assert ours.tolist() == ref, where
    elif isinstance(first, bytes):
        assert list(ours) == ref, where
    else:
        assert isinstance(first, int) and ours.dtype.kind in "iu", where
        assert ours.tolist() == ref, where


def assert_same_as_dfreader(ours: DataFlashMessages, path: Path) -> None:
    rows = dfreader_rows(str(path))
    assert {k: len(v[1]) for k, v in rows.items()} == {k: len(t) for k, t in ours.tables.items() if len(t)}
    for name, (columns, values) in rows.items():
        table = ours[name]
        assert table.format.columns == columns
        for i, column in enumerate(columns):
            assert_column_equal(table[column], [v[i] for v in values], f"{name}.{column}")


def assert_tables_equal(a: DataFlashMessages, b: DataFlashMessages, names: list[str] | None = None) -> None:
    for name in names if names is not None else list(b.tables):
        assert a[name].format == b[name].format, name
        for column, values in b[name].columns.items():
            np.testing.assert_array_equal(a[name][column], values, err_msg=f"{name}.{column}")


@pytest.mark.parametrize("where", [SAMPLE, LOG171], ids=lambda w: w[1])
def test_every_field_of_every_message_equals_dfreader(real_data: Path, where: tuple[str, str]) -> None:
    path = real_data.joinpath(*where)
    ours = read_messages(path)
    assert ours.warnings == () and ours.bytes_skipped == 0
    assert_same_as_dfreader(ours, path)


@pytest.mark.parametrize("where", [SAMPLE, LOG171], ids=lambda w: w[1])
def test_a_mapped_file_giving_its_pages_back_decodes_as_the_bytes_in_memory(real_data: Path, where) -> None:
    path = real_data.joinpath(*where)
    mapped, in_memory = read_messages(path), decode_messages(path.read_bytes())
    assert list(mapped.tables) == list(in_memory.tables) and mapped.counts == in_memory.counts
    for name in mapped.tables:  # instances split first, then every column: the pages go and come back
        assert mapped.instances(name).keys() == in_memory.instances(name).keys()
    assert_tables_equal(mapped, in_memory)


def test_gathering_a_block_at_a_time_with_release_copies_the_same_bytes() -> None:
    from flightlogs.readers._dataflash_frame import gather

    buf = np.random.default_rng(0).integers(0, 256, 1_000_003, dtype=np.uint8)
    offsets = np.sort(np.random.default_rng(1).choice(buf.size - 40, 200_000, replace=False)).astype(np.int32)
    released: list[tuple[int, int]] = []
    blocks = gather(buf, offsets, 40, lambda lo, hi: released.append((lo, hi)))
    np.testing.assert_array_equal(blocks, gather(buf, offsets, 40))
    assert released[0][0] == 0 and released[-1][1] == buf.size  # every byte given back, in order, once
    assert all(a[1] == b[0] for a, b in zip(released, released[1:])) and len(released) > 1


def test_a_table_sparse_in_the_file_gives_its_pages_back_every_few_megabytes() -> None:
    """A message every 64 kB: the kernel maps the pages around each one read, so a block of messages
    counted (65 536 of them) would hold the whole file; the span of bytes read ends a block too."""
    from flightlogs.readers._dataflash_frame import GATHER_SPAN, gather

    buf = np.zeros(96 << 20, np.uint8)
    offsets = np.arange(0, buf.size - 40, 1 << 16, dtype=np.int64)  # 1536 messages, far fewer than a block
    buf[offsets] = np.arange(offsets.size) % 251
    released: list[tuple[int, int]] = []
    blocks = gather(buf, offsets, 40, lambda lo, hi: released.append((lo, hi)))
    np.testing.assert_array_equal(blocks[:, 0], np.arange(offsets.size) % 251)
    assert max(hi - lo for lo, hi in released) <= GATHER_SPAN + (1 << 16)  # one message past the span at most
    assert released[0][0] == 0 and released[-1][1] == buf.size and len(released) >= buf.size // GATHER_SPAN


def test_units_and_instance_fields_equal_dfreader(real_data: Path) -> None:
    path = real_data.joinpath(*SAMPLE)
    reader = DFReader_binary(str(path))
    ours = read_messages(path)
    for table in ours.tables.values():
        ref = reader.formats[table.format.type_id]
        assert list(table.format.units) == (ref.units or []), table.format.name
        assert table.format.instance_field == ref.instance_field
    reader.close()
    assert ours["IMU"].format.units[1:4] == ("rad/s",) * 3
    assert ours["GPS"].format.units[0] == "µs"


@pytest.mark.parametrize(
    ("where", "expected"),
    [(SAMPLE, {0: 1820, 1: 1820}), (LOG171, {0: 11916, 1: 11916, 2: 11916})],
    ids=["3.6-IMU,IMU2", "3.3-IMU,IMU2,IMU3"],
)
def test_old_logs_number_their_instances_in_the_name(real_data: Path, where, expected) -> None:
    ours = read_messages(real_data.joinpath(*where))
    instances = ours.instances("IMU")
    assert {k: len(t) for k, t in instances.items()} == expected
    assert instances[1] is ours["IMU2"]


def test_instance_column_splits_newer_logs() -> None:
    n = 50
    time_us = np.repeat(1000 + 2500 * np.arange(n), 2)
    imu = standard_block("IMU", TimeUS=time_us, I=np.tile([0, 1], n), GyrX=np.tile([0.5, -0.5], n))
    ours = decode_messages(encode_dataflash([imu]))
    assert ours["IMU"].format.instance_field == "I"  # from the FMTU '#' unit
    split = ours.instances("IMU")
    assert sorted(split) == [0, 1]
    np.testing.assert_array_equal(split[0]["GyrX"], np.full(n, 0.5, np.float32))
    np.testing.assert_array_equal(split[1]["TimeUS"], time_us[1::2])


def _garbage(size: int, seed: int = 7) -> bytes:
    """Random bytes without 0xA3, so no header can hide in them."""
    values = np.random.default_rng(seed).integers(0, 256, size, dtype=np.uint8)
    values[values == 0xA3] = 0x00
    return values.tobytes()


def test_garbage_between_messages_is_skipped_and_reported(real_data: Path) -> None:
    path = real_data.joinpath(*SAMPLE)
    raw, clean = path.read_bytes(), read_messages(path)
    cut = int(clean["IMU"].offsets[900])
    with pytest.warns(LogCorruptionWarning, match="damaged.bin: skipped 777 bytes"):
        damaged = decode_messages(raw[:cut] + _garbage(777) + raw[cut:], path="damaged.bin")
    assert damaged.bytes_skipped == 777
    assert damaged.warnings == (f"damaged.bin: skipped 777 bytes at offset {cut}.",)
    assert_tables_equal(damaged, clean)  # everything before and after intact


def test_garbage_inside_a_message_loses_only_that_message_like_dfreader(real_data: Path, tmp_path: Path) -> None:
    path = real_data.joinpath(*SAMPLE)
    raw, clean = path.read_bytes(), read_messages(path)
    cut = int(clean["ATT"].offsets[300]) + 10  # 10 bytes into an ATT message
    damaged_path = tmp_path / "damaged.bin"
    damaged_path.write_bytes(raw[:cut] + _garbage(500) + raw[cut:])
    with (
        pytest.warns(DataQualityWarning, match="ATT: the log clock goes back"),  # the garbled ATT's time
        pytest.warns(LogCorruptionWarning, match="skipped 500 bytes"),
    ):
        damaged = read_messages(damaged_path)
    assert damaged.bytes_skipped == 500 and "skipped 500 bytes" in damaged.warnings[0]
    # the cut ATT is read from its own first bytes plus garbage (no check sum), as DFReader does
    assert len(damaged["ATT"]) == len(clean["ATT"])
    keep = np.arange(len(clean["ATT"])) != 300
    for column in clean["ATT"].columns:
        np.testing.assert_array_equal(damaged["ATT"][column][keep], clean["ATT"][column][keep])
    assert_tables_equal(damaged, clean, [n for n in clean.tables if n != "ATT"])
    assert_same_as_dfreader(damaged, damaged_path)


def test_truncated_final_message_is_dropped_with_a_warning(real_data: Path) -> None:
    path = real_data.joinpath(*SAMPLE)
    raw, clean = path.read_bytes(), read_messages(path)
    last = int(max(t.offsets[-1] for t in clean.tables.values()))
    with pytest.warns(LogCorruptionWarning, match="cut.bin: truncated final message"):
        damaged = decode_messages(raw[:-5], path="cut.bin")
    assert damaged.bytes_skipped == len(raw) - 5 - last
    assert damaged.warnings[0].startswith(
        f"cut.bin: truncated final message (type {raw[last + 2]}) at byte offset {last}"
    )
    assert sum(damaged.counts.values()) == sum(clean.counts.values()) - 1


def test_appended_logs_are_all_kept_and_the_clock_reset_reported(real_data: Path) -> None:
    raw = real_data.joinpath(*SAMPLE).read_bytes()
    clean = read_messages(real_data.joinpath(*SAMPLE))
    with pytest.warns(DataQualityWarning, match="IMU: the log clock goes back 1 time"):
        twice = decode_messages(raw + raw, path="twice.bin")  # FMT block repeated, same layouts
    assert dict(twice.counts) == {k: 2 * v for k, v in clean.counts.items()}
    np.testing.assert_array_equal(twice["ATT"]["Roll"], np.tile(clean["ATT"]["Roll"], 2))
    assert len(twice.warnings) == 1 and "clock goes back 1 time(s)" in twice.warnings[0]
    assert f"byte offset {len(raw) + int(clean['IMU'].offsets[0])}" in twice.warnings[0]


def test_appended_logs_with_other_layouts_are_kept_apart(real_data: Path) -> None:
    first, second = read_messages(real_data.joinpath(*SAMPLE)), read_messages(real_data.joinpath(*LOG171))
    with pytest.warns(DataQualityWarning, match="is redefined with format|the log clock goes back"):
        both = decode_messages(real_data.joinpath(*SAMPLE).read_bytes() + real_data.joinpath(*LOG171).read_bytes())
    for name, table in second.tables.items():
        key = name if name not in first.tables or first[name].format.format == table.format.format else f"{name}@1"
        tail = both[key].select(slice(len(both[key]) - len(table), None))
        for column, values in table.columns.items():
            np.testing.assert_array_equal(tail[column], values, err_msg=key)
    assert_tables_equal(both, first, [n for n in first.tables if n not in ("FMT", "STRT")])
    assert any("IMU is redefined" in w for w in both.warnings)
    assert any("clock goes back" in w for w in both.warnings)


def test_repeated_fmt_block_with_same_layout_changes_nothing() -> None:
    att = standard_block("ATT", TimeUS=1000 + np.arange(100) * 100, Roll=np.arange(100) / 100)
    once = encode_dataflash([att])
    header_end = int(decode_messages(once)["ATT"].offsets[0])
    middle = header_end + 50 * att.spec.length
    again = once[:middle] + once[:header_end] + once[middle:]
    assert_tables_equal(decode_messages(again), decode_messages(once), ["ATT"])
    assert decode_messages(again).warnings == ()


def test_fmt_length_disagreeing_with_format_skips_that_type() -> None:
    att = standard_block("ATT", TimeUS=1000 + np.arange(40) * 100, Roll=np.arange(40) / 100)
    rate = standard_block("RATE", TimeUS=1050 + np.arange(40) * 100, ROut=np.arange(40) / 8)
    data = bytearray(encode_dataflash([att, rate]))
    fmt = decode_messages(bytes(data))["FMT"]
    data[int(fmt.offsets[list(fmt["Name"]).index("RATE")]) + 4] += 2  # the Length byte
    with pytest.warns(LogCorruptionWarning, match="odd.bin: (40 messages of type.s. 130 have a FMT length|skipped)"):
        ours = decode_messages(bytes(data), path="odd.bin")
    assert "RATE" not in ours.counts
    assert (
        ours.warnings[0]
        == "odd.bin: 40 messages of type(s) 130 have a FMT length that disagrees with their format; skipped."
    )
    np.testing.assert_array_equal(ours["ATT"]["Roll"], np.arange(40) / 100)


def test_strings_decode_like_dfreader(tmp_path: Path) -> None:
    data = bytearray(encode_dataflash([text_block([(1000, "abcdef"), (2000, "abcdef"), (3000, "x")])]))
    offsets = decode_messages(bytes(data))["MSG"].offsets
    data[offsets[0] + 11 : offsets[0] + 17] = b"caf\xe9\x00z"  # not UTF-8: ISO-8859-1
    data[offsets[1] + 11 : offsets[1] + 17] = b"ok\x00\xff\xfez"  # garbage after the NUL
    path = tmp_path / "strings.bin"
    path.write_bytes(bytes(data))
    ours = read_messages(path)
    assert ours["MSG"]["Message"].tolist() == ["café", "ok", "x"]
    assert_same_as_dfreader(ours, path)


@pytest.mark.parametrize(
    ("content", "phrase"),
    [
        (b"", "is empty"),
        (_garbage(200_000), "holds no DataFlash FMT message"),
        (b"FMT, 128, 89, FMT, BBnNZ, Type,Length,Name,Format,Columns\n", "text DataFlash log"),
    ],
    ids=["empty", "random", "text-log"],
)
def test_bad_input_raises_one_sentence_naming_file_and_offset(tmp_path: Path, content: bytes, phrase: str) -> None:
    path = tmp_path / "bad.bin"
    path.write_bytes(content)
    with pytest.raises(LogFormatError, match=phrase) as err:
        read_messages(path)
    assert str(path) in str(err.value) and "byte offset" in str(err.value)


def test_ulog_and_missing_files_raise(real_data: Path, tmp_path: Path) -> None:
    with pytest.raises(LogFormatError, match=r"PX4 ULog file.*byte offset 0"):
        read_messages(real_data / "pyulog" / "sample.ulg")
    with pytest.raises(LogFormatError, match="cannot be read"):
        read_messages(tmp_path / "absent.bin")


def test_progress_reports_bytes_and_types_filter(real_data: Path) -> None:
    path = real_data.joinpath(*LOG171)
    calls: list[tuple[int, int]] = []
    ours = read_messages(path, types=["ATT", "IMU"], progress=lambda done, total: calls.append((done, total)))
    size = path.stat().st_size
    assert calls[0] == (0, size) and calls[-1] == (size, size)
    assert [d for d, _ in calls] == sorted(d for d, _ in calls)
    assert set(ours.tables) == {"ATT", "IMU"}  # log171 has no FMTU, UNIT, MULT
    assert ours.counts["RCOU"] == 11916 and ours.get("RCOU") is None


def test_message_dtype_follows_pymavlink_struct_sizes() -> None:
    assert message_dtype("QBffffffIIfBBHH").itemsize == 3 + 8 + 1 + 6 * 4 + 2 * 4 + 4 + 2 + 4
    assert message_dtype("a").itemsize == 3 + 64 and message_dtype("a")["f0"].shape == (32,)
    block = MessageBlock(standard_block("RCOU", TimeUS=[1]).spec, standard_block("RCOU", TimeUS=[1]).data)
    assert len(decode_messages(encode_dataflash([block]))["RCOU"]) == 1


def _every_column(messages: DataFlashMessages) -> dict[str, tuple[str, ...]]:
    return {table.format.name: table.format.columns for table in messages.tables.values()}


@pytest.mark.parametrize("where", [SAMPLE, LOG171], ids=lambda w: w[1])
def test_columns_decoded_in_one_pass_equal_those_decoded_table_by_table(real_data: Path, where) -> None:
    path = real_data.joinpath(*where)
    one_by_one = read_messages(path)
    for columns in (_every_column(one_by_one), {"IMU": ("GyrX",)}, {}):  # every column; one; only the clocks
        in_one_pass = read_messages(path, columns=columns)
        assert list(in_one_pass.tables) == list(one_by_one.tables)
        for name in one_by_one.tables:
            split, whole = in_one_pass.instances(name), one_by_one.instances(name)
            assert split.keys() == whole.keys()
            for instance, table in split.items():
                for column, values in whole[instance].columns.items():
                    np.testing.assert_array_equal(table[column], values, err_msg=f"{name}[{instance}].{column}")
        assert_tables_equal(in_one_pass, one_by_one)
        assert in_one_pass.warnings == one_by_one.warnings


@pytest.mark.parametrize("which", ["synthetic System ID", "sample"])
def test_the_ardupilot_mapping_reads_every_page_of_the_file_once(
    real_data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, which: str
) -> None:
    """The columns it maps are decoded in the one pass: no table's messages are copied out again after it."""
    import sys

    import flightlogs.readers.dataflash as dataflash
    from flightlogs.readers.ardupilot import _COLUMNS, _TYPES, flightlog_from_messages

    sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "benchmarks"))
    from bench_dataflash import synthetic_log

    path = synthetic_log(tmp_path / "sysid.bin", 20.0) if which != "sample" else real_data.joinpath(*SAMPLE)
    messages = read_messages(path, types=_TYPES, columns=_COLUMNS)
    first = {int(t.offsets[0]): t.format.name for t in messages.tables.values() if len(t)}
    copied: list[str] = []
    original = dataflash.gather

    def counting(buf: np.ndarray, offsets: np.ndarray, *args: object, **kwargs: object) -> np.ndarray:
        copied.append(first.get(int(offsets[0]), "?") if offsets.size else "")
        return original(buf, offsets, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(dataflash, "gather", counting)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataQualityWarning)  # the sample's EKF wind is zero throughout
        log = flightlog_from_messages(messages)
    assert {"p", "phi", "delta_lat", "motor_1"} <= set(log.signals)
    assert [name for name in copied if name in _COLUMNS] == []  # PARM, MSG (text) are read as they come
