"""The flight controller's unique id, which tells one vehicle of a fleet from another, read from real logs."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from flightlogs.readers.dispatch import read_log
from flightlogs.writers.dataflash import standard_block, text_block, write_dataflash


@pytest.mark.parametrize(
    ("relative", "expected"),
    [
        # ArduPilot logs its board and 96-bit id at boot; PX4 its sys_uuid
        ("ardupilot-log-diagnosis/sample.bin", "fmuv5 00290019 32375118 32363435"),
        ("dronekit-la-testdata/log171.bin", "PX4v2 004A002F 33345119 32383433"),
        ("kd0aij-impulse-response/log1.ulg", "001d00313235510c32393433"),
        ("px4-ulog-rs/quadrotor_local.ulg", "0006000000003535323734325116003d0021"),
    ],
)
def test_real_logs_give_their_board_id(real_data: Path, relative: str, expected: str) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the readers' warnings on these logs are tested elsewhere
        log = read_log(real_data / relative)
    assert log.board_id == expected


def test_a_log_without_the_board_message_has_no_id(tmp_path: Path) -> None:
    imu = standard_block("IMU", TimeUS=[1_000_000, 1_010_000], GyrX=[0.0, 0.0])
    texts = text_block([(1_000_000, "Frame: OCTA/X"), (1_000_000, "fmuv5 0029 bad id")])
    log = write_dataflash(tmp_path / "a.bin", [imu, texts], firmware="ArduCopter V4.5.7")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert read_log(log).board_id == ""
