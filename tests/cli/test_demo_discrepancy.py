"""``sysid demo --discrepancy`` end to end: a pair with a concealed 30 ms delay, found, written, reported."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from sysid_cli.main import cli

pytestmark = [
    pytest.mark.long,  # 66 s: run by .ci/run with -m long, out of the README's ten-minute suite
    pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning"),
]


def test_the_discrepancy_demo_finds_the_delay_and_ends_with_its_report(tmp_path: Path) -> None:
    result = CliRunner().invoke(cli, ["demo", "--discrepancy", "-o", str(tmp_path)])
    assert result.exit_code == 0, result.output
    saved = json.loads((tmp_path / "discrepancy.json").read_text())
    assert saved["verdict"] == "time_delay"
    assert saved["findings"][0]["parameters"]["delay_s"]["value"] == pytest.approx(0.030, abs=0.0025)
    assert {p.name for p in tmp_path.glob("*.ulg")} == {"sim-7.ulg", "real.ulg"}  # no name tells the effect
    page = tmp_path / "discrepancy.html"
    assert result.stdout.strip().splitlines()[-1] == f"report: {page.resolve()}"
    assert "Real against simulated frequency responses" in page.read_text()
