"""Tests of flightlogs.writers.ulog: every field, info message and parameter reads back exactly through pyulog."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from pyulog import ULog

from flightlogs.readers.dispatch import read_log
from flightlogs.writers.ulog import TopicData, encode_ulog, write_ulog

N = 50
STAMPS = 20_000_000 + 10_000 * np.arange(N)


def every_type(rng: np.random.Generator, stamps: np.ndarray = STAMPS) -> dict[str, np.ndarray]:
    """One column of every supported dtype, scalar and array."""
    n = stamps.size
    columns: dict[str, np.ndarray] = {"timestamp": stamps}
    for dtype in (np.int8, np.uint8, np.int16, np.uint16, np.int32, np.uint32, np.int64, np.uint64):
        info = np.iinfo(dtype)
        columns[f"v_{np.dtype(dtype).name}"] = rng.integers(info.min, info.max, size=n, dtype=dtype, endpoint=True)
    columns["f32"] = rng.normal(size=n).astype(np.float32)
    columns["f64"] = rng.normal(size=n)
    columns["flag"] = rng.integers(0, 2, size=n).astype(bool)
    columns["q"] = rng.normal(size=(n, 4)).astype(np.float32)
    columns["counts"] = rng.integers(0, 1000, size=(n, 3)).astype(np.uint16)
    columns["label"] = np.array([f"m{i:03d}".encode() for i in range(n)], dtype="S6")
    return columns


def flattened(columns: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The columns as pyulog names them: ``q[0]``..., char strings as int8 bytes."""
    out = {}
    for key, column in columns.items():
        if column.dtype.kind == "S":
            column = column.view(np.int8).reshape(column.size, column.dtype.itemsize)
        if column.ndim == 2:
            out.update({f"{key}[{k}]": column[:, k] for k in range(column.shape[1])})
        else:
            out[key] = column
    return out


def assert_round_trip(data: dict[str, np.ndarray], written: dict[str, np.ndarray]) -> None:
    """Every written field reads back equal: integers exactly, floats bitwise (NaN included)."""
    expected = flattened(written)
    assert list(data) == list(expected)
    for key, values in expected.items():
        got = data[key]
        if values.dtype.kind == "f":
            assert got.dtype == values.dtype, key
            assert got.tobytes() == values.tobytes(), key
        else:
            np.testing.assert_array_equal(
                got.astype(np.int64 if values.dtype != np.uint64 else np.uint64),
                values.astype(np.int64 if values.dtype != np.uint64 else np.uint64),
                err_msg=key,
            )


@pytest.fixture
def path(tmp_path: Path) -> Path:
    return tmp_path / "log.ulg"


def test_every_field_type_reads_back_exactly(path: Path) -> None:
    columns = every_type(np.random.default_rng(1))
    write_ulog(path, [TopicData("probe", columns)])
    ulog = ULog(str(path))
    assert not ulog.file_corruption
    assert_round_trip(ulog.get_dataset("probe").data, columns)
    fields = ulog.message_formats["probe"].fields
    assert fields[0] == ("uint64_t", 0, "timestamp")
    assert ("float", 4, "q") in fields and ("char", 6, "label") in fields and ("bool", 0, "flag") in fields
    assert ulog.start_timestamp == STAMPS[0]


def test_multi_instance_topics_keep_their_data(path: Path) -> None:
    rng = np.random.default_rng(2)
    gyro = rng.normal(size=(N, 3)).astype(np.float32)
    first: dict[str, np.ndarray] = {"timestamp": STAMPS, "xyz": gyro}
    second: dict[str, np.ndarray] = {"timestamp": STAMPS[::2] + 3, "xyz": 2 * gyro[::2]}
    other: dict[str, np.ndarray] = {
        "timestamp": STAMPS[:5],
        "voltage_v": np.array([16.8, 16.7, 16.7, 16.6, 16.6], np.float32),
    }
    write_ulog(
        path,
        [
            TopicData("sensor_gyro", second, multi_id=1),
            TopicData("battery_status", other),
            TopicData("sensor_gyro", first, multi_id=0),
        ],
    )
    ulog = ULog(str(path))
    assert sorted((d.name, d.multi_id) for d in ulog.data_list) == [
        ("battery_status", 0),
        ("sensor_gyro", 0),
        ("sensor_gyro", 1),
    ]
    assert_round_trip(ulog.get_dataset("sensor_gyro", 0).data, first)
    assert_round_trip(ulog.get_dataset("sensor_gyro", 1).data, second)
    assert_round_trip(ulog.get_dataset("battery_status").data, other)


def test_info_parameters_and_messages_read_back(path: Path) -> None:
    info: dict[str, str | int | float | np.generic] = {
        "sys_name": "PX4",
        "ver_hw": "PX4_FMU_V6X",
        "ver_sw": "94cb2012792b2ae89f0b147cfee53ee31ae550be",
        "sys_uuid": "0006000000003535323734325116003d0021",
        "ver_sw_release": np.uint32(0x011000FF),
        "time_ref_utc": -3600,
        "big": 2**40,
        "ratio": 0.125,
    }
    parameters: dict[str, int | float | np.number] = {
        "SYS_AUTOSTART": 4001,
        "MAV_TYPE": 2,
        "CA_ROTOR_COUNT": 4,
        "MPC_THR_HOVER": 0.42,
        "CA_ROTOR0_KM": np.float32(0.05),
    }
    messages = [(STAMPS[3], "Takeoff detected"), (STAMPS[10], "[logger] ünïcode ok")]
    write_ulog(
        path,
        [TopicData("probe", {"timestamp": STAMPS, "x": np.zeros(N, np.float32)})],
        info=info,
        parameters=parameters,
        messages=messages,
    )
    ulog = ULog(str(path))
    assert ulog.msg_info_dict == {k: (v.item() if isinstance(v, np.generic) else v) for k, v in info.items()}
    assert ulog._msg_info_dict_types["ver_sw_release"] == "uint32_t"
    assert ulog._msg_info_dict_types["time_ref_utc"] == "int32_t"
    assert ulog._msg_info_dict_types["big"] == "int64_t"
    assert ulog._msg_info_dict_types["sys_name"] == "char[3]"
    assert ulog.initial_parameters["SYS_AUTOSTART"] == 4001 and isinstance(ulog.initial_parameters["MAV_TYPE"], int)
    assert ulog.initial_parameters["MPC_THR_HOVER"] == float(np.float32(0.42))
    assert ulog.initial_parameters["CA_ROTOR0_KM"] == float(np.float32(0.05))
    assert [(m.timestamp, m.message, m.log_level_str()) for m in ulog.logged_messages] == [
        (int(t), text, "INFO") for t, text in messages
    ]


def test_the_file_is_a_ulog_the_reader_maps(path: Path) -> None:
    rates = np.column_stack([np.sin(0.01 * np.arange(N)), np.cos(0.01 * np.arange(N)), np.zeros(N)]).astype(np.float32)
    topics = [
        TopicData("vehicle_angular_velocity", {"timestamp": STAMPS, "timestamp_sample": STAMPS, "xyz": rates}),
        TopicData("battery_status", {"timestamp": STAMPS[::10], "voltage_v": np.full(5, 16.5, np.float32)}),
    ]
    write_ulog(
        path,
        topics,
        info={"sys_name": "PX4", "ver_hw": "PX4_FMU_V6X"},
        parameters={"MAV_TYPE": 2, "SYS_AUTOSTART": 4001},
    )
    log = read_log(path)
    assert log.log_format == "ulog" and log.autopilot == "px4"
    assert log.warnings == ()
    assert "PX4 on PX4_FMU_V6X" in log.vehicle and "quadrotor" in log.vehicle
    assert log.parameters == {"MAV_TYPE": 2.0, "SYS_AUTOSTART": 4001.0}
    assert log["p"].source == "vehicle_angular_velocity[0].xyz[0]"
    np.testing.assert_array_equal(log["p"].values, rates[:, 0].astype(np.float64))
    np.testing.assert_array_equal(log["q"].time_s, STAMPS / 1e6)
    np.testing.assert_array_equal(log["battery_v"].values, 16.5)


def test_encode_sorts_topics_and_numbers_subscriptions() -> None:
    topics = [
        TopicData("b", {"timestamp": STAMPS[:2]}),
        TopicData("a", {"timestamp": STAMPS[:2]}, multi_id=1),
        TopicData("a", {"timestamp": STAMPS[:2] + 1}),
    ]
    ulog = encode_ulog(topics)
    assert [(d.name, d.multi_id, d.msg_id) for d in ulog.data_list] == [("a", 0, 0), ("a", 1, 1), ("b", 0, 2)]
    assert ulog.start_timestamp == STAMPS[0]


def test_a_failed_write_keeps_the_old_file(path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    topic = TopicData("probe", {"timestamp": STAMPS})
    write_ulog(path, [topic])
    before = path.read_bytes()

    def broken(self: ULog, stream: object) -> None:
        raise OSError("disk full")

    monkeypatch.setattr(ULog, "write_ulog", broken)
    with pytest.raises(OSError, match="disk full"):
        write_ulog(path, [topic])
    assert path.read_bytes() == before
    assert list(path.parent.iterdir()) == [path]


@pytest.mark.parametrize(
    ("fields", "options", "match"),
    [
        ({"x": np.zeros(3, np.float32)}, {}, "'timestamp' field"),
        ({"timestamp": np.array([0.5, 1.0])}, {}, "integer array"),
        ({"timestamp": np.array([-1, 2])}, {}, "must be ≥ 0"),
        ({"timestamp": np.arange(3), "x": np.zeros(2, np.float32)}, {}, "one length"),
        ({"timestamp": np.arange(3), "x": np.zeros(3, complex)}, {}, "no ULog type"),
        ({"timestamp": np.arange(3), "x": np.zeros((3, 2, 2), np.float32)}, {}, "shape"),
        ({"timestamp": np.arange(3), "x[0]": np.zeros(3, np.float32)}, {}, "identifier"),
        ({"timestamp": np.arange(3), "_padding0": np.zeros(3, np.uint8)}, {}, "_padding"),
        ({"timestamp": np.arange(3), "s": np.array([b"\xff", b"a", b"b"])}, {}, "ASCII"),
        ({"timestamp": np.arange(3), "x": np.zeros((3, 20000), np.float32)}, {}, "65535"),
        ({"timestamp": np.arange(3)}, {"multi_id": 256}, "multi_id"),
    ],
)
def test_bad_topics_are_refused(fields: dict, options: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        TopicData("probe", fields, **options)


def test_bad_names_and_values_are_refused() -> None:
    stamp = {"timestamp": np.arange(2)}
    with pytest.raises(ValueError, match="identifier"):
        TopicData("vehicle-attitude", stamp)
    with pytest.raises(ValueError, match="once"):
        encode_ulog([TopicData("a", stamp), TopicData("a", stamp)])
    with pytest.raises(ValueError, match="differs"):
        encode_ulog([TopicData("a", stamp), TopicData("a", stamp | {"x": np.zeros(2)}, multi_id=1)])
    with pytest.raises(ValueError, match="16 characters"):
        encode_ulog([], parameters={"A_VERY_LONG_PARAMETER": 1})
    with pytest.raises(ValueError, match="bool"):
        encode_ulog([], parameters={"SYS_HAS_GPS": True})
    with pytest.raises(ValueError, match="int32"):
        encode_ulog([], parameters={"BIG": 2**31})
    with pytest.raises(ValueError, match="cannot be written"):
        encode_ulog([], info={"sys_name": b"PX4"})  # type: ignore[dict-item]


@settings(max_examples=25, deadline=None)
@given(
    values=hnp.arrays(np.float32, st.integers(1, 40), elements=st.floats(width=32, allow_nan=True)), wide=st.booleans()
)
def test_float32_columns_round_trip_bitwise(values: np.ndarray, wide: bool) -> None:
    stamps = np.arange(values.size, dtype=np.uint64) * 4000
    columns = {"timestamp": stamps, "v": np.column_stack([values, values[::-1]]) if wide else values}
    with tempfile.TemporaryDirectory() as folder:
        target = write_ulog(Path(folder) / "h.ulg", [TopicData("probe", columns)])
        assert_round_trip(ULog(str(target)).get_dataset("probe").data, columns)
