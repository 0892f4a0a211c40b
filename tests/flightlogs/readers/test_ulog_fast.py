"""The fast path of ``read_ulog`` (``flightlogs.readers._ulog_fast``) against pyulog's own parse of the same file.

Reference values are cross-implementation and exact: pyulog's ``ULog`` reading
the whole file (every array bitwise, with its dtype; info, parameters,
dropouts with their stamps, parameter changes, logged strings), and
``read_ulog`` with the fast path switched off (every signal bitwise, every
warning). Files: the real ULogs of ``/work/shared/data/real`` (read in place),
logs the project's writers make (the simulator's PX4 writer; the independent
generator's, with logging gaps; one with dropout and parameter-change messages
in its data section), and damaged variants of a small log, one per fall-back
rule.
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import struct
import warnings
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest
from independent_sim import simulate
from independent_sim.pairs import open_pair_case
from independent_sim.px4_log import write_px4
from independent_sim.scenario import FlightPlan
from pyulog import ULog

import flightlogs.readers.ulog as ulog_module
from flightlogs.flightlog import FlightLog
from flightlogs.readers._ulog_fast import FastULog, scan_clean
from flightlogs.readers.px4_topics import MAPPED_TOPICS
from flightlogs.readers.ulog import read_ulog
from flightlogs.writers.ulog import TopicData, write_ulog
from simulator.autopilot.excitation import Maneuver
from simulator.flights.linear import simulate_hover
from simulator.output.px4 import write_px4_log

CLEAN_REAL = ["pyulog/sample.ulg", "px4-ulog-rs/quadrotor_local.ulg", "kd0aij-impulse-response/log1.ulg"]
OTHER_REAL = [
    "pyulog/sample_appended_multiple.ulg",
    "px4-ulog-rs/corrupt_actuator_armed_wrong_size.ulg",
    "px4-ulog-rs/corrupt_unregistered_msg_id.ulg",
]

pytestmark = pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning")


@pytest.fixture(name="real")
def real_fixture(real_data: Path) -> Callable[[str], Path]:
    """A real log of ``../shared/data/real`` by its name there (the suite fails where that folder is missing)."""

    def path(name: str) -> Path:
        assert (real_data / name).is_file(), f"{real_data / name} is missing"
        return real_data / name

    return path


def _parse(path: Path, topics: frozenset[str] | None = None) -> ULog:
    """The reader's pyulog parse of `path` (fast path where it is taken), warnings dropped."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ulog_module._parse(path, path.stat().st_size, None, topics)


def _pyulog(path: Path, topics: frozenset[str] | None = None) -> ULog:
    """pyulog's own parse of the whole file."""
    with contextlib.redirect_stdout(io.StringIO()), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ULog(str(path), None if topics is None else sorted(topics), True)


def assert_same_parse(got: ULog, expected: ULog) -> None:
    """Every dataset (name, instance, fields, dtypes, values bitwise) and every other record equal."""
    assert [(d.name, d.multi_id, d.msg_id) for d in got.data_list] == [
        (d.name, d.multi_id, d.msg_id) for d in expected.data_list
    ]
    for mine, theirs in zip(got.data_list, expected.data_list):
        assert list(mine.data) == list(theirs.data), mine.name
        assert mine.field_data == theirs.field_data and mine.timestamp_idx == theirs.timestamp_idx
        for field, values in mine.data.items():
            reference = theirs.data[field]
            assert values.dtype == reference.dtype, f"{mine.name}.{field}"
            assert values.tobytes() == reference.tobytes(), f"{mine.name}.{field}"  # bitwise, NaNs included
    assert got.msg_info_dict == expected.msg_info_dict
    assert got.msg_info_multiple_dict == expected.msg_info_multiple_dict
    assert got.initial_parameters == expected.initial_parameters
    assert got.changed_parameters == expected.changed_parameters  # (stamp, name, value)
    assert [(d.duration, d.timestamp) for d in got.dropouts] == [(d.duration, d.timestamp) for d in expected.dropouts]
    assert got.logged_messages == expected.logged_messages
    assert got.logged_messages_tagged == expected.logged_messages_tagged
    assert got.last_timestamp == expected.last_timestamp and got.start_timestamp == expected.start_timestamp
    assert got.file_corruption == expected.file_corruption


def _without_fast_path(monkeypatch: pytest.MonkeyPatch) -> None:
    """Make the reader decline the fast path on every file (today's path: pyulog over the whole file)."""
    original = scan_clean

    def declined(*args: object, **kwargs: object) -> object:
        clean = original(*args, **kwargs)  # type: ignore[arg-type]
        return None if clean is None else dataclasses.replace(clean, layout=None, reduced=b"", declined="test")

    monkeypatch.setattr(ulog_module, "scan_clean", declined)


def assert_same_read(path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``read_ulog`` with and without the fast path: signals bitwise, warnings, vehicle and parameters equal."""
    fast = read_ulog(path)
    with monkeypatch.context() as patch:
        _without_fast_path(patch)
        slow = read_ulog(path)
        assert not isinstance(_parse(path), FastULog)
    _assert_same_log(fast, slow)


def _assert_same_log(fast: FlightLog, slow: FlightLog) -> None:
    assert fast.warnings == slow.warnings
    assert list(fast.signals) == list(slow.signals)
    for name, signal in fast.signals.items():
        other = slow.signals[name]
        assert (signal.source, signal.unit) == (other.source, other.unit), name
        for mine, theirs in ((signal.time_s, other.time_s), (signal.values, other.values)):
            assert mine.dtype == theirs.dtype and mine.tobytes() == theirs.tobytes(), name
    assert (fast.vehicle, fast.board_id, fast.utc_offset_s) == (slow.vehicle, slow.board_id, slow.utc_offset_s)
    assert fast.parameters == slow.parameters


# ------------------------------------------------------------------ real logs


@pytest.mark.parametrize("name", CLEAN_REAL)
def test_a_clean_real_log_takes_the_fast_path_and_parses_as_pyulog(
    name: str, real: Callable[[str], Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = real(name)
    got = _parse(path)
    assert isinstance(got, FastULog)
    assert_same_parse(got, _pyulog(path))
    assert_same_read(path, monkeypatch)


@pytest.mark.parametrize("name", CLEAN_REAL[:2])
def test_the_fast_path_keeps_only_the_topics_asked_for_as_pyulog(name: str, real: Callable[[str], Path]) -> None:
    path = real(name)
    got = _parse(path, MAPPED_TOPICS)
    assert isinstance(got, FastULog)
    assert_same_parse(got, _pyulog(path, MAPPED_TOPICS))


def test_the_real_logs_with_dropouts_and_parameter_changes_are_stamped_as_pyulog(real: Callable[[str], Path]) -> None:
    sample = _pyulog(real("pyulog/sample.ulg"))
    assert len(sample.dropouts) == 4 and len(sample.changed_parameters) == 6  # what the comparison above covered
    assert len(_pyulog(real("kd0aij-impulse-response/log1.ulg")).dropouts) == 3


@pytest.mark.parametrize("name", OTHER_REAL)
def test_an_appended_or_damaged_real_log_is_read_as_before(
    name: str, real: Callable[[str], Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = real(name)
    got = _parse(path)
    assert not isinstance(got, FastULog)
    clean = scan_clean(path, path.stat().st_size, None)
    assert clean is None or clean.declined  # appended data: clean chain, fast path declined
    assert_same_read(path, monkeypatch)


# ------------------------------------------------------------------ the project's writers


@pytest.fixture(scope="module")
def simulator_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """6 s of hover with a pitch doublet, written by the simulator's PX4 writer."""
    maneuvers = (Maneuver(axis="lon", kind="doublet", start_s=2.0, amplitude=10.0, duration_s=1.0),)
    flight = simulate_hover(6.0, maneuvers, seed=4)
    path = tmp_path_factory.mktemp("fast") / "simulator.ulg"
    return write_px4_log(flight, path, utc_start=datetime(2024, 5, 1, 10, tzinfo=UTC))


@pytest.fixture(scope="module")
def independent_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 40 s flight of the independent generator with vibration, gyro drift and two logging gaps."""
    case = open_pair_case("short", 17)
    two_gaps = dataclasses.replace(case.nuisances, dropouts=(2, 2))  # gaps fall 10 s inside the airborne span
    case = dataclasses.replace(case, plan=FlightPlan(duration_s=40.0), maneuvers=(), nuisances=two_gaps)
    flight = simulate(case)
    assert len(flight.dropouts_s) == 2  # gaps in every topic
    path = tmp_path_factory.mktemp("fast") / "independent.ulg"
    write_px4(flight, path)
    return path


@pytest.fixture(scope="module")
def dropouts_log(independent_log: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The independent log with a dropout message at each gap and two parameter changes, written by pyulog."""
    ulog = _pyulog(independent_log)
    stamps = np.sort(np.concatenate([d.data["timestamp"] for d in ulog.data_list]))
    gaps = np.flatnonzero(np.diff(stamps) > 50_000)
    assert gaps.size
    for k in gaps:
        duration = int(stamps[k + 1] - stamps[k]) // 1000
        ulog._dropouts.append(ULog.MessageDropout(struct.pack("<H", duration), None, int(stamps[k]) + 1))
    ulog._changed_parameters += [
        (int(stamps[100]) + 1, "MPC_THR_HOVER", 0.45),
        (int(stamps[-50]), "SYS_AUTOSTART", 4001),
    ]
    path = tmp_path_factory.mktemp("fast") / "dropouts.ulg"
    with path.open("wb") as stream:
        ulog.write_ulog(stream)
    return path


@pytest.mark.parametrize("log", ["simulator_log", "independent_log", "dropouts_log"])
def test_a_log_of_the_project_s_writers_takes_the_fast_path_and_reads_as_pyulog(
    log: str, request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch
) -> None:
    path: Path = request.getfixturevalue(log)
    got = _parse(path)
    assert isinstance(got, FastULog)
    expected = _pyulog(path)
    assert_same_parse(got, expected)
    if log == "dropouts_log":
        assert len(expected.dropouts) >= 1 and len(expected.changed_parameters) == 2
        assert any("logging dropout" in text for text in read_ulog(path).warnings)
    assert_same_read(path, monkeypatch)


# ------------------------------------------------------------------ fall-back rules, on a small log


def _messages(data: bytes) -> list[tuple[int, bytes]]:
    """The (type, payload) of every message after the 16-byte header."""
    out, position = [], 16
    while position < len(data):
        size, kind = struct.unpack_from("<HB", data, position)
        out.append((kind, data[position + 3 : position + 3 + size]))
        position += 3 + size
    return out


def _assemble(header: bytes, messages: list[tuple[int, bytes]]) -> bytes:
    return header + b"".join(struct.pack("<HB", len(payload), kind) + payload for kind, payload in messages)


def _dup_subscription(messages: list[tuple[int, bytes]]) -> list[tuple[int, bytes]]:
    first_a = next(m for m in messages if m[0] == ord("A"))
    return messages[:-5] + [first_a] + messages[-5:]  # pyulog drops what it read before the second 'A'


def _remove_subscription(messages: list[tuple[int, bytes]]) -> list[tuple[int, bytes]]:
    return messages[:-5] + [(ord("R"), struct.pack("<H", 0))] + messages[-5:]


def _data_before_subscription(messages: list[tuple[int, bytes]]) -> list[tuple[int, bytes]]:
    first_a = next(i for i, m in enumerate(messages) if m[0] == ord("A"))
    first_d = next(m for m in messages if m[0] == ord("D"))
    return messages[:first_a] + [first_d] + messages[first_a:]


def _long_data(messages: list[tuple[int, bytes]]) -> list[tuple[int, bytes]]:
    k = next(i for i, m in enumerate(messages) if m[0] == ord("D"))
    return messages[:k] + [(ord("D"), messages[k][1] + b"\0")] + messages[k + 1 :]


def _short_dropout(messages: list[tuple[int, bytes]]) -> list[tuple[int, bytes]]:
    return messages[:-5] + [(ord("O"), b"\x01")] + messages[-5:]  # pyulog stops reading here, silently


def _unsubscribed_id(messages: list[tuple[int, bytes]]) -> list[tuple[int, bytes]]:
    k = next(i for i, m in enumerate(messages) if m[0] == ord("D"))
    return messages[: k + 1] + [(ord("D"), struct.pack("<H", 99) + messages[k][1][2:])] + messages[k + 1 :]


@pytest.fixture(scope="module")
def small_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two topics of 40 samples each, interleaved in time."""
    stamps = np.arange(40, dtype=np.uint64) * 4000 + 1_000_000
    gyro = TopicData(
        "vehicle_angular_velocity", {"timestamp": stamps, "xyz": np.arange(120, dtype=np.float32).reshape(40, 3)}
    )
    battery = TopicData(
        "battery_status", {"timestamp": stamps + 2000, "voltage_v": np.linspace(16, 15, 40, dtype=np.float32)}
    )
    path = tmp_path_factory.mktemp("fast") / "small.ulg"
    return write_ulog(path, [gyro, battery], info={"sys_name": "PX4"}, parameters={"MAV_TYPE": 2})


@pytest.mark.parametrize(
    "damage",
    [
        _dup_subscription,
        _remove_subscription,
        _data_before_subscription,
        _long_data,
        _short_dropout,
        _unsubscribed_id,
    ],
)
def test_the_fast_path_is_declined_where_it_could_differ_from_pyulog(
    damage: object, small_log: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    data = small_log.read_bytes()
    path = tmp_path / "damaged.ulg"
    path.write_bytes(_assemble(data[:16], damage(_messages(data))))  # type: ignore[operator]
    assert scan_clean(path, path.stat().st_size, None) is not None  # the chain is clean: only the rules decline
    got = _parse(path)
    assert not isinstance(got, FastULog)
    expected = _pyulog(path)
    assert [(d.name, d.multi_id) for d in got.data_list] == [(d.name, d.multi_id) for d in expected.data_list]
    for mine, theirs in zip(got.data_list, expected.data_list):
        assert all(np.array_equal(mine.data[k], theirs.data[k]) for k in theirs.data)
    assert_same_read(path, monkeypatch)


def test_the_small_log_itself_takes_the_fast_path(small_log: Path) -> None:
    got = _parse(small_log)
    assert isinstance(got, FastULog)
    assert_same_parse(got, _pyulog(small_log))
