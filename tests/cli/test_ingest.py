"""``sysid ingest`` end to end: exit codes, JSON, the dataset it writes, bad input."""

from __future__ import annotations

import json
import shutil
import sys
import warnings
from pathlib import Path

import pytest
from click.testing import CliRunner

from flightlogs.store.dataset import read_dataset
from sysid_cli.main import cli

# (file under real/, autopilot, log format, signals that must be present)
REAL_LOGS = [
    ("kd0aij-impulse-response/log1.ulg", "px4", "ulog", {"p", "q", "r", "ax", "ay", "az"}),
    (
        "px4-ulog-rs/quadrotor_local.ulg",
        "px4",
        "ulog",
        {
            "p",
            "q",
            "r",
            "phi",
            "theta",
            "psi",
            "vd",
            "ax",
            "delta_lat",
            "delta_thr",
            "motor_1",
            "motor_4",
            "battery_v",
            "height_agl",
        },
    ),
    ("px4-ulog-rs/corrupt_unregistered_msg_id.ulg", "px4", "ulog", {"p", "q", "r", "phi", "motor_1", "battery_v"}),
    ("px4-ulog-rs/corrupt_actuator_armed_wrong_size.ulg", "px4", "ulog", {"p", "q", "r"}),
    ("pyulog/sample.ulg", "px4", "ulog", {"p", "q", "r", "phi", "ax", "delta_lat", "delta_thr", "motor_1"}),
    ("pyulog/sample_appended_multiple.ulg", "px4", "ulog", {"p", "q", "r", "phi", "ax"}),
    (
        "dronekit-la-testdata/log171.bin",
        "ardupilot",
        "dataflash",
        {"p", "q", "r", "phi", "theta", "psi", "ax", "motor_1", "motor_4", "battery_v", "vn", "ve", "vd"},
    ),
    ("ardupilot-log-diagnosis/sample.bin", "ardupilot", "dataflash", {"p", "q", "r", "phi", "ax", "motor_1", "vn"}),
    ("phoenix/2018-09-17 16-44-06.tlog", "ardupilot", "tlog", {"p", "q", "r", "phi", "theta", "psi", "motor_1"}),
]


@pytest.mark.parametrize(("relative", "autopilot", "log_format", "present"), REAL_LOGS, ids=[r[0] for r in REAL_LOGS])
def test_every_real_log_ingests(
    runner: CliRunner,
    real_data: Path,
    tmp_path: Path,
    relative: str,
    autopilot: str,
    log_format: str,
    present: set[str],
) -> None:
    out = tmp_path / "set.h5"
    result = runner.invoke(cli, ["ingest", str(real_data / relative), "-o", str(out), "--json", "-", "-q"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert (summary["autopilot"], summary["log_format"]) == (autopilot, log_format)
    assert present <= set(summary["signals"]), f"missing {present - set(summary['signals'])}"
    assert not present & set(summary["missing"])
    assert summary["duration_s"] > 0
    # the dataset holds exactly what the summary reports
    log = read_dataset(out).logs[0]
    assert set(log.signals) == set(summary["signals"])
    for name, info in summary["signals"].items():
        assert log[name].samples == info["samples"]
        assert log[name].unit == info["unit"] and log[name].source == info["source"]


def test_human_table_lists_signals_and_missing(runner: CliRunner, real_data: Path) -> None:
    result = runner.invoke(cli, ["ingest", str(real_data / "kd0aij-impulse-response/log1.ulg")])
    assert result.exit_code == 0, result.output
    assert "sensor_gyro" in result.stdout
    assert "missing:" in result.stdout and "motor_1..n" in result.stdout


def test_json_to_file(runner: CliRunner, real_data: Path, tmp_path: Path) -> None:
    target = tmp_path / "summary.json"
    result = runner.invoke(
        cli, ["ingest", str(real_data / "dronekit-la-testdata/log171.bin"), "--json", str(target), "-q"]
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(target.read_text())
    assert summary["signals"]["battery_v"]["unit"] == "V"


CORRUPT_LOG = "px4-ulog-rs/corrupt_unregistered_msg_id.ulg"
SKIPPED = "skipped 1 data message(s) with message id 32812, which no subscription declares (corrupt bytes)"


def test_each_warning_is_printed_once(runner: CliRunner, real_data: Path) -> None:
    """The table lists the log's warnings; the group prints none of them again, and no Python warning line."""
    result = runner.invoke(cli, ["ingest", str(real_data / CORRUPT_LOG)])
    assert result.exit_code == 0, result.output
    assert f"  warning: {SKIPPED}" in result.stdout.splitlines()
    assert result.output.count(SKIPPED) == 1 and "Warning:" not in result.output.replace("pyulog: Warning:", "")
    quiet = runner.invoke(cli, ["ingest", str(real_data / CORRUPT_LOG), "-q", "--json", "-"])
    assert quiet.exit_code == 0, quiet.output
    summary = json.loads(quiet.stdout)
    assert SKIPPED in summary["warnings"]  # the JSON keeps its warnings list; -q counts them (one line)
    (line,) = quiet.stderr.splitlines()
    assert line.startswith(f"warning: {len(summary['warnings'])} warnings of ") and SKIPPED not in quiet.stderr


def test_under_w_error_a_warning_fails_the_command(
    runner: CliRunner, real_data: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sys, "warnoptions", ["error"])  # as python -W error, or PYTHONWARNINGS=error
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = runner.invoke(cli, ["ingest", str(real_data / CORRUPT_LOG)])
    assert result.exit_code == 1 and result.stdout == ""
    assert result.stderr.splitlines() == [f"error: {SKIPPED} (LogCorruptionWarning, an error under -W error)"]


def _bad_files(real_data: Path, tmp_path: Path) -> dict[str, tuple[Path, str]]:
    empty = tmp_path / "empty.ulg"
    empty.write_bytes(b"")
    garbage = tmp_path / "garbage.bin"
    garbage.write_bytes(bytes(range(256)) * 40)
    truncated = tmp_path / "truncated.ulg"
    truncated.write_bytes((real_data / "pyulog/sample.ulg").read_bytes()[:200])
    csv_as_log = tmp_path / "wind.ulg"
    shutil.copyfile(real_data / "nmt-uas-wind/level0.csv", csv_as_log)
    return {
        "empty": (empty, "empty"),
        "garbage": (garbage, "garbage.bin"),
        "truncated": (truncated, "truncated.ulg"),
        "csv renamed .ulg": (csv_as_log, "wind.ulg"),
    }


@pytest.mark.parametrize("case", ["empty", "garbage", "truncated", "csv renamed .ulg"])
def test_bad_input_is_one_sentence_exit_1_and_no_output(
    runner: CliRunner, real_data: Path, tmp_path: Path, case: str
) -> None:
    path, fragment = _bad_files(real_data, tmp_path)[case]
    out = tmp_path / "out.h5"
    out.write_bytes(b"precious")
    result = runner.invoke(cli, ["ingest", str(path), "-o", str(out)])
    assert result.exit_code == 1
    assert "Traceback" not in result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and fragment in lines[0]
    assert out.read_bytes() == b"precious"
    assert not list(tmp_path.glob("*.part"))


def test_debug_shows_the_traceback(runner: CliRunner, tmp_path: Path) -> None:
    path = tmp_path / "empty.bin"
    path.write_bytes(b"")
    result = runner.invoke(cli, ["--debug", "ingest", str(path)])
    assert result.exit_code == 1
    assert result.exception is not None and "empty" in str(result.exception)


@pytest.mark.parametrize("args", [["ingest"], ["ingest", "/no/such/file.ulg"], ["ingest", "x", "--bogus"]])
def test_usage_errors_exit_2(runner: CliRunner, args: list[str]) -> None:
    assert runner.invoke(cli, args).exit_code == 2


def test_help_has_an_example(runner: CliRunner) -> None:
    result = runner.invoke(cli, ["ingest", "--help"])
    assert result.exit_code == 0 and "Examples:" in result.output and "sysid ingest" in result.output


def test_warnings_of_one_kind_are_one_line_and_q_counts_them(runner: CliRunner, real_data: Path) -> None:
    """Issue 33: log171.bin's 2 s pause splits 13 signals' records; the table shows that as one line naming
    them with the gap's range, and -q prints one line, the count of all the warnings the JSON lists."""
    log = str(real_data / "dronekit-la-testdata/log171.bin")
    result = runner.invoke(cli, ["ingest", log])
    assert result.exit_code == 0, result.output
    gaps = [line for line in result.stdout.splitlines() if "gap at" in line]
    assert len(gaps) == 1
    names, _, rest = gaps[0].removeprefix("  warning: ").partition(": ")
    assert len(names.split(", ")) == 13 and {"p", "q", "r", "phi", "delta_thr"} <= set(names.split(", "))
    assert rest == "2.02-2.10 s gap at 72.59-72.61 s; record split"
    quiet = runner.invoke(cli, ["ingest", log, "-q", "--json", "-"])
    listed = json.loads(quiet.stdout)["warnings"]
    kinds = sum(1 for line in result.stdout.splitlines() if line.startswith("  warning: "))
    assert quiet.stderr.splitlines() == [
        f"warning: {len(listed)} warnings of {kinds} kinds; without -q they are listed"
    ]
    assert len(listed) > kinds > 1
