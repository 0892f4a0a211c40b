"""SIGINT and SIGTERM in the middle of a command, outputs that are inputs, and --no-clobber (issue 17).

The signal is sent to a real ``sysid`` process while it computes (the MRAC comparison, several seconds);
it must end with one line and 130 or 143, leave no output and no temporary file, and leave an earlier
output as it was.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from sysid_cli.main import cli

_MRAC = ["mrac", "compare", "--height-ratio", "4,3,2,22", "--trials", "3", "-q"]


def _run_and_signal(args: list[str], signum: int, after_s: float = 1.5) -> subprocess.CompletedProcess[str]:
    """Start ``sysid ARGS``, send `signum` once it is computing, and wait for it."""
    process = subprocess.Popen(
        [sys.executable, "-c", "from sysid_cli.main import cli; cli()", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(
            signal.SIGINT, signal.SIG_DFL
        ),  # as from a shell (a test runner may ignore it)
    )
    time.sleep(after_s)
    assert process.poll() is None, "the command ended before the signal"
    process.send_signal(signum)
    out, err = process.communicate(timeout=60)
    return subprocess.CompletedProcess(process.args, process.returncode, out, err)


@pytest.mark.skipif(not hasattr(signal, "SIGTERM") or os.name != "posix", reason="POSIX signals")
@pytest.mark.parametrize(("signum", "code", "name"), [(signal.SIGINT, 130, "SIGINT"), (signal.SIGTERM, 143, "SIGTERM")])
def test_a_signal_mid_run_leaves_nothing_behind(tmp_path: Path, signum: int, code: int, name: str) -> None:
    report, summary = tmp_path / "mrac.html", tmp_path / "mrac.json"
    summary.write_text("earlier run")
    done = _run_and_signal([*_MRAC, "--report", str(report), "--json", str(summary)], signum)
    assert done.returncode == code, done.stderr
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert lines == [f"interrupted ({name}): no file was left half-written"], done.stderr
    assert "Traceback" not in done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mrac.json"]  # no report, no temporary file
    assert summary.read_text() == "earlier run"


def test_an_output_that_is_an_input_is_refused_before_any_work(tmp_path: Path, real_data: Path) -> None:
    log = tmp_path / "log1.ulg"
    log.write_bytes((real_data / "kd0aij-impulse-response" / "log1.ulg").read_bytes())
    before = log.read_bytes()
    for option in ("-o", "--json"):
        result = CliRunner().invoke(cli, ["ingest", str(log), "-q", option, str(log)])
        assert result.exit_code == 1
        assert f"{log}: is also an input ({log}); writing {'--out' if option == '-o' else option}" in result.output
        assert log.read_bytes() == before


def test_no_clobber_refuses_an_existing_output_and_writes_a_new_one(tmp_path: Path, real_data: Path) -> None:
    log = real_data / "kd0aij-impulse-response" / "log1.ulg"
    summary = tmp_path / "summary.json"
    summary.write_text("kept")
    refused = CliRunner().invoke(cli, ["ingest", str(log), "-q", "--json", str(summary), "--no-clobber"])
    assert refused.exit_code == 1
    assert f"{summary}: exists, and --no-clobber leaves it as it is; give another --json" in refused.output
    assert summary.read_text() == "kept"
    fresh = tmp_path / "fresh.json"
    written = CliRunner().invoke(cli, ["ingest", str(log), "-q", "--json", str(fresh), "--no-clobber"])
    assert written.exit_code == 0, written.output
    assert fresh.read_text().startswith("{")


@pytest.mark.skipif(os.name != "posix", reason="POSIX signals")
def test_an_interrupted_simulation_leaves_no_folder(tmp_path: Path) -> None:
    """`sysid simulate` writes its folder whole or not at all (a temporary folder beside it, renamed)."""
    out = tmp_path / "campaign"
    done = _run_and_signal(["simulate", "chapter3-campaign", "-o", str(out), "-q"], signal.SIGINT, after_s=3.0)
    assert done.returncode == 130, done.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(os.name != "posix", reason="POSIX signals")
def test_an_interrupted_demo_leaves_its_folder_as_it_was(tmp_path: Path) -> None:
    """`sysid demo` writes into its folder itself (the dataset and the report name their files): what the folder
    held is set aside and put back when the run is cut short."""
    out = tmp_path / "sysid-demo"
    out.mkdir()
    (out / "report.html").write_text("an earlier demo's report")
    (out / "notes.txt").write_text("mine")
    done = _run_and_signal(["demo", "-o", str(out)], signal.SIGTERM, after_s=4.0)
    assert done.returncode == 143, done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sysid-demo"]  # nothing set aside is left
    assert {p.name: p.read_text() for p in out.iterdir()} == {
        "report.html": "an earlier demo's report",
        "notes.txt": "mine",
    }
