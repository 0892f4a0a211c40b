"""Format detection reads content, not names."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from flightlogs.errors import LogFormatError
from flightlogs.readers.detect import detect_format

REAL = {
    "kd0aij-impulse-response/log1.ulg": "ulog",
    "px4-ulog-rs/quadrotor_local.ulg": "ulog",
    "px4-ulog-rs/corrupt_unregistered_msg_id.ulg": "ulog",
    "px4-ulog-rs/corrupt_actuator_armed_wrong_size.ulg": "ulog",
    "pyulog/sample.ulg": "ulog",
    "pyulog/sample_appended_multiple.ulg": "ulog",
    "dronekit-la-testdata/log171.bin": "dataflash",
    "ardupilot-log-diagnosis/sample.bin": "dataflash",
    "phoenix/2018-09-17 16-44-06.tlog": "tlog",
}


@pytest.mark.parametrize(("relative", "expected"), REAL.items())
def test_real_logs_are_recognised(real_data: Path, relative: str, expected: str) -> None:
    assert detect_format(real_data / relative) == expected


def test_a_renamed_file_is_read_as_what_it_is(real_data: Path, tmp_path: Path) -> None:
    renamed = tmp_path / "flight.ulg"
    shutil.copyfile(real_data / "dronekit-la-testdata/log171.bin", renamed)
    assert detect_format(renamed) == "dataflash"


@pytest.mark.parametrize(
    ("content", "fragment"),
    [
        (b"", "empty"),
        (b"\x00" * 64, "not a PX4 ULog"),
        (b"time,speed,dir\n1,2,3\n", "first bytes 74 69 6d 65"),
        (b"ULog\x01", "not a PX4 ULog"),
    ],
)
def test_unknown_content_names_the_file(tmp_path: Path, content: bytes, fragment: str) -> None:
    path = tmp_path / "mystery.ulg"
    path.write_bytes(content)
    with pytest.raises(LogFormatError, match=fragment) as info:
        detect_format(path)
    assert str(path) in str(info.value)


def test_a_missing_file_is_a_log_format_error(tmp_path: Path) -> None:
    with pytest.raises(LogFormatError, match="cannot be read"):
        detect_format(tmp_path / "absent.bin")


def test_dataflash_with_a_damaged_start_is_still_dataflash(real_data: Path, tmp_path: Path) -> None:
    damaged = tmp_path / "damaged.bin"
    damaged.write_bytes(b"\x00\xff" * 37 + (real_data / "dronekit-la-testdata/log171.bin").read_bytes())
    assert detect_format(damaged) == "dataflash"
