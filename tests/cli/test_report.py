"""``sysid report`` rebuilds the model report from the saved files, also after ``sysid fit`` and ``sysid validate``.

(The verification file itself, :mod:`sysid.verify.io`, is tested in ``tests/sysid/verify/test_io.py``.)
"""

from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from flightlogs.errors import DataError
from reports.ingest_card import ingest_card
from reports.model_report import model_report_html
from simulator.campaign.fly import run_scenario
from simulator.campaign.scenario import read_scenario
from sysid.fit import IdentifiedModel, read_model, write_model
from sysid.verify import Verification
from sysid.verify.io import read_verification, write_verification
from sysid_cli.main import cli

import builders

_FOOTER = re.compile(r"<footer>.*?</footer>", re.S)
INGEST = {
    "path": "/data/flight.bin",
    "log_format": "dataflash",
    "autopilot": "ardupilot",
    "vehicle": "ArduCopter V4.5.7 <octo>",
    "duration_s": 204.0,
    "utc_start": "2024-05-01T10:00:00+00:00",
    "wind_alignment": {
        "clock_offset_s": 1.5003,
        "clock_offset_source": "estimated",
        "transport_delay_s": 1.7374,
        "transport_delay_source": "geometry",
        "turbulence_ratio": 0.2046,
    },
}


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, IdentifiedModel, Verification]:
    folder = tmp_path_factory.mktemp("saved")
    model = builders.small_model(files=("flight.bin", "anemometer.csv"))
    verification = builders.sample_verification()
    write_model(folder / "model.json", model)
    write_verification(
        folder / "validation.json",
        verification,
        model="model.json",
        options={"initial_state": "estimated", "after_s": 1.0},
    )
    return folder / "model.json", folder / "validation.json", model, verification


def test_report_rebuilds_the_same_page_from_the_saved_files(
    saved: tuple[Path, Path, IdentifiedModel, Verification], tmp_path: Path
) -> None:
    model_path, validation_path, model, verification = saved
    out = tmp_path / "report.html"
    result = CliRunner().invoke(cli, ["report", str(model_path), str(validation_path), "-o", str(out), "--json", "-"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert summary["report"] == str(out) and summary["verdict"] == "good"
    direct = model_report_html(
        model, verification=verification, verification_options={"initial_state": "estimated", "after_s": 1.0}
    )
    assert _FOOTER.sub("", out.read_text()) == _FOOTER.sub("", direct)


def test_without_a_verification_the_default_output_sits_beside_the_model(
    saved: tuple[Path, Path, IdentifiedModel, Verification], tmp_path: Path
) -> None:
    model_path, _, _, _ = saved
    copy = tmp_path / "m.json"
    copy.write_text(model_path.read_text())
    result = CliRunner().invoke(cli, ["report", str(copy), "--ingest-summary", _ingest(tmp_path)])
    assert result.exit_code == 0, result.output
    page = (tmp_path / "m.html").read_text()
    assert 'id="verification"' not in page
    assert "ArduCopter V4.5.7 &lt;octo&gt;" in page and "transport delay 1.74 s (geometry)" in page
    assert result.output.strip().endswith(f"wrote {tmp_path / 'm.html'}")


def test_a_verification_of_another_model_is_refused(
    saved: tuple[Path, Path, IdentifiedModel, Verification], tmp_path: Path
) -> None:
    """Issue 33: the verification keeps the SHA-256 of the model it verified; a report of another model with
    it is one sentence naming both, exit 1, nothing written. A file from before the hash was kept is judged
    by the model's name."""
    model_path, _, model, verification = saved
    verified = tmp_path / "model.json"
    write_model(verified, model)
    validation = write_verification(tmp_path / "validation.json", verification, model=verified)  # name and SHA
    other = tmp_path / "other.json"
    document = json.loads(verified.read_text())
    name = next(iter(document["parameters"]))
    document["parameters"][name]["value"] *= 1.5
    for candidate, code in ((verified, 0), (other, 1)):
        if candidate is other:
            other.write_text(json.dumps(document))
        out = tmp_path / f"{candidate.stem}.html"
        result = CliRunner().invoke(cli, ["report", str(candidate), str(validation), "-o", str(out), "-q"])
        assert result.exit_code == code, result.output
        assert out.exists() == (code == 0)
    assert result.stderr.strip() == (
        f"error: {validation}: verifies model.json, not {other} (the files differ); a report shows a model with its "
        "own verification: verify this model, or give the model that was verified"
    )
    renamed = tmp_path / "renamed.json"  # the verified model's bytes under another name: the same model
    renamed.write_bytes(verified.read_bytes())
    assert CliRunner().invoke(cli, ["report", str(renamed), str(validation), "-q"]).exit_code == 0
    legacy = json.loads(validation.read_text())
    legacy.pop("model_sha256")
    old = tmp_path / "old-validation.json"
    old.write_text(json.dumps(legacy))
    assert CliRunner().invoke(cli, ["report", str(verified), str(old), "-q"]).exit_code == 0
    assert CliRunner().invoke(cli, ["report", str(other), str(old), "-q"]).exit_code == 1


def _ingest(folder: Path) -> str:
    path = folder / "ingest.json"
    path.write_text(json.dumps(INGEST))
    return str(path)


def test_ingest_card_reads_what_ingest_writes() -> None:
    card = ingest_card(INGEST)
    assert card["vehicle"] == "ArduCopter V4.5.7 <octo>"
    assert card["flight"] == "flight.bin: ardupilot dataflash log, 204 s from 2024-05-01T10:00:00+00:00"
    assert card["wind alignment"] == (
        "anemometer clock offset +1.50 s (estimated), transport delay 1.74 s (geometry), turbulence 20 %"
    )
    with pytest.raises(DataError, match="sysid ingest --json"):
        ingest_card({"records": []})


def _bad_files(
    folder: Path, saved: tuple[Path, Path, IdentifiedModel, Verification]
) -> dict[str, tuple[list[str], str]]:
    model_path, validation_path, _, _ = saved
    (folder / "broken.json").write_text('{"schema": "flight-sysid/identified-model", ')
    newer = json.loads(model_path.read_text()) | {"schema_version": 99}
    (folder / "newer.json").write_text(json.dumps(newer))
    (folder / "summary.json").write_text(
        json.dumps({"model": "m.json", "records": [], "summary": {}, "overall": {"rmse": 1.0, "tic": 0.1}})
    )
    damaged = json.loads(validation_path.read_text())
    del damaged["records"][0]["time_s"]
    (folder / "damaged.json").write_text(json.dumps(damaged))
    (folder / "not-ingest.json").write_text("[1, 2]")
    return {
        "model not JSON": ([str(folder / "broken.json")], "cannot read the model file"),
        "model too new": ([str(folder / "newer.json")], "schema version 99"),
        "a validate summary": ([str(model_path), str(folder / "summary.json")], "sysid validate --json"),
        "damaged verification": ([str(model_path), str(folder / "damaged.json")], "incomplete or damaged"),
        "model as verification": ([str(model_path), str(model_path)], "not a flight-sysid verification file"),
        "not an ingest summary": (
            [str(model_path), "--ingest-summary", str(folder / "not-ingest.json")],
            "sysid ingest --json",
        ),
    }


@pytest.mark.parametrize(
    "case",
    [
        "model not JSON",
        "model too new",
        "a validate summary",
        "damaged verification",
        "model as verification",
        "not an ingest summary",
    ],
)
def test_bad_input_is_exit_1_and_writes_nothing(
    case: str, saved: tuple[Path, Path, IdentifiedModel, Verification], tmp_path: Path
) -> None:
    inputs = tmp_path / "in"
    inputs.mkdir()
    arguments, fragment = _bad_files(inputs, saved)[case]
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    result = CliRunner().invoke(cli, ["report", *arguments, "-o", str(out_dir / "r.html")])
    assert result.exit_code == 1, result.output
    assert fragment in result.stderr and "Traceback" not in result.output
    assert list(out_dir.iterdir()) == []


def test_a_missing_model_is_a_usage_error(tmp_path: Path) -> None:
    result = CliRunner().invoke(cli, ["report", str(tmp_path / "nope.json")])
    assert result.exit_code == 2 and "does not exist" in result.stderr


def test_fit_report_hook_writes_the_model_report(
    saved: tuple[Path, Path, IdentifiedModel, Verification], tmp_path: Path
) -> None:
    """``sysid fit --report`` calls ``write_model_report``: the page ``sysid report`` renders."""
    from reports.model_report import write_model_report

    _, _, model, _ = saved
    assert write_model_report(tmp_path / "fit.html", model) == tmp_path / "fit.html"
    assert _FOOTER.sub("", (tmp_path / "fit.html").read_text()) == _FOOTER.sub("", model_report_html(model))


@pytest.mark.parametrize(("max_cr", "verdict"), [(20.0, "acceptable"), (30.0, "good")])
def test_report_judges_by_the_max_cr_the_model_was_fitted_with(max_cr: float, verdict: str, tmp_path: Path) -> None:
    """Issue 13: the same model (X_u at CR 25 %) fitted with ``--max-cr 20`` or ``30``; the verdict followed 20 always."""
    model = builders.small_model(responses=False, accuracy={"X_u": (25.0, 3.0)})
    options = {"fit": {"max_cr_percent": max_cr, "max_insensitivity_percent": 10.0}}
    model = dataclasses.replace(model, provenance=dataclasses.replace(model.provenance, options=options))
    path = write_model(tmp_path / "model.json", model)
    result = CliRunner().invoke(cli, ["report", str(path), "--json", "-"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert summary["verdict"] == verdict
    assert f"CR ≤ {max_cr:g} %" in summary["sentence"] and f"CR ≤ {max_cr:g} %" in result.stderr


def test_report_help_has_an_example() -> None:
    result = CliRunner().invoke(cli, ["report", "--help"])
    assert result.exit_code == 0 and "sysid report model.json validation.json" in result.output


SCENARIO = """
[scenario]
description = "a pitch sweep and a pitch doublet of the Table 3.3 linear model"
vehicle = "linear-octo"
formats = ["dataflash"]
trials = 1
seed = 7
utc_start = "2024-05-01T10:00:00Z"
margin_s = 3.0
[anemometer]
distance_m = 4.6
rate_hz = 20.0
clock_offset_s = 0.0
[[condition]]
name = "calm"
mean_speed_m_s = 0.9
direction_from_deg = 300.0
turbulence_ratio = 0.2
[[maneuver]]
axis = "lon"
kind = "sweep"
amplitude = 8.0
duration_s = 34.0
[[maneuver]]
axis = "lon"
kind = "doublet"
amplitude = 15.0
duration_s = 2.0
"""


def _sections(page: str) -> list[str]:
    return re.findall(r"<h[23][^>]*>(.*?)</h[23]>", page)


@pytest.mark.slow
def test_fit_validate_and_report_from_the_command_line(tmp_path: Path) -> None:
    """fit → validate -o (saved verification) --report → report: the rebuilt page is the one validate wrote."""
    (tmp_path / "calm.toml").write_text(SCENARIO)
    sweep, doublet = [t.logs[0] for t in run_scenario(read_scenario(tmp_path / "calm.toml"), tmp_path / "flights")]
    model, validation = tmp_path / "model.json", tmp_path / "validation.json"
    fitted = CliRunner().invoke(cli, ["fit", str(sweep), "--model", "hover", "--partial", "-o", str(model), "-q"])
    assert fitted.exit_code == 0, fitted.output
    first = tmp_path / "validate.html"
    result = CliRunner().invoke(
        cli, ["validate", str(model), str(doublet), "-o", str(validation), "--report", str(first), "--json", "-", "-q"]
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert summary["output"] == str(validation) and summary["report"] == str(first)
    assert set(summary["summary"]) == {"u", "q", "theta", "ax"}  # the lon doublet, judged on the lon outputs
    assert summary["off_axis"] == {}  # a model of the pitch axis only: the others were not flown, so not simulated
    assert summary["records"][0]["excited"] == "delta_lon"
    assert summary["records"][0]["reference_shifts"].keys() == {"delta_lon"}
    assert "yaw: the model's yaw axis is unidentified (no sweep found in 1 log; " in " ".join(summary["notes"])
    saved = read_verification(validation)
    assert saved.model == "model.json" and saved.options["inputs"] == "all measured"
    assert [s.name for s in saved.verification.summary] == list(summary["summary"])
    rebuilt = tmp_path / "report.html"
    again = CliRunner().invoke(cli, ["report", str(model), str(validation), "-o", str(rebuilt), "-q"])
    assert again.exit_code == 0, again.output
    page, original = rebuilt.read_text(), first.read_text()
    assert _sections(page) == _sections(original)
    assert "Verification on doublets" in _sections(page) and "the model&#39;s lat axis is unidentified" in page
    assert _FOOTER.sub("", page) == _FOOTER.sub("", original)
    assert read_model(model).structure_name in page
