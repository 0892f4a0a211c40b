"""``sysid fit`` end to end on simulator logs: exit codes, JSON fields, the model file it writes."""

from __future__ import annotations

import json
import re
from dataclasses import replace
from pathlib import Path

import pytest
from click.testing import CliRunner
from scipy import io as sio

from simulator.campaign.fly import run_scenario
from simulator.campaign.scenario import load_builtin
from sysid.fit import read_model
from sysid_cli.main import cli


@pytest.fixture(scope="module")
def flights(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("fit-cli")
    run_scenario(replace(load_builtin("linear-sweeps"), trials=1, seed=5), folder / "calm")
    return folder / "calm"


def test_fit_writes_a_model_and_the_summary(runner: CliRunner, flights: Path, tmp_path: Path) -> None:
    out, mat = tmp_path / "model.json", tmp_path / "model.mat"
    logs = [str(p) for p in sorted(flights.glob("*.bin"))]
    result = runner.invoke(
        cli,
        [
            "fit",
            *logs,
            "--wind",
            str(flights),
            "--wind-distance",
            "4.6",
            "--model",
            "hover",
            "-o",
            str(out),
            "--mat",
            str(mat),
            "--json",
            "-",
        ],
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    model = read_model(out)
    for p in model.parameters:
        entry = summary["parameters"][p.name]
        assert entry["value"] == p.value
        assert (entry["cr_percent"] is None) == (p.status != "estimated")
    assert summary["cost"]["average"] == model.cost.average and summary["cost"]["responses"]
    assert {"real", "imag", "damping", "natural_frequency_rad_s", "mode"} <= set(summary["eigenvalues"][0])
    assert "N_r" in summary["dropped"] and summary["output"] == str(out)
    assert "J_ave" in result.stderr and "per normalised (-1..1)" in result.stderr  # the table went to stderr
    assert sio.loadmat(mat)["A"].shape == model.linear_model().a.shape
    assert len(model.provenance.files) == 8 and model.provenance.options["fit"]["starts"] == 1


def test_report_option_judges_by_the_limits_given(runner: CliRunner, flights: Path, tmp_path: Path) -> None:
    """The --max-cr and --max-insensitivity of the fit travel with the model, into its report and its file."""
    report, out = tmp_path / "fit.html", tmp_path / "model.json"
    logs = [str(p) for p in sorted(flights.glob("*lon*.bin"))]
    command = ["fit", *logs, "--partial", "--max-cr", "35", "--max-insensitivity", "12", "-o", str(out)]
    command += ["--report", str(report)]
    result = runner.invoke(cli, [*command, "-q"])
    assert result.exit_code == 0, result.output
    page = report.read_text(encoding="utf-8")
    assert page.lstrip().lower().startswith("<!doctype html>")
    assert "guidelines CR ≤ 35 % and I ≤ 12 %" in page and "CR ≤ 20 %" not in page
    guidelines = read_model(out).guidelines
    assert (guidelines.max_cr_percent, guidelines.max_insensitivity_percent) == (35.0, 12.0)


def test_fit_reads_an_ingested_dataset(runner: CliRunner, flights: Path, tmp_path: Path) -> None:
    dataset = tmp_path / "set.h5"
    logs = [str(p) for p in sorted(flights.glob("*lon*.bin"))]
    ingested = runner.invoke(
        cli, ["ingest", *logs, "--wind", str(flights), "--wind-distance", "4.6", "-o", str(dataset), "-q"]
    )
    assert ingested.exit_code == 0, ingested.output
    result = runner.invoke(cli, ["fit", str(dataset), "--partial", "--json", "-", "-q"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert set(summary["cost"]["responses"]) >= {"q/delta_lon", "ax/delta_lon"}
    assert summary["parameters"]["M_lon"]["status"] == "estimated"
    lateral = summary["parameters"]["L_lat"]  # no lateral sweep in the dataset: no value, never the starting one
    assert lateral["status"] == "unidentified" and lateral["value"] is None


@pytest.mark.parametrize(
    ("extra", "code", "message"),
    [
        (["--kind", "multisine"], 1, "no multisine"),
        (["--model", "hovre"], 1, "neither a built-in structure"),
        (["--set", "X_u"], 2, "NAME=VALUE"),
        (["--set", "X_v=1"], 1, "no parameter 'X_v'"),
        (["--starts", "0"], 2, "0"),
    ],
)
def test_fit_errors(runner: CliRunner, flights: Path, extra: list[str], code: int, message: str) -> None:
    log = str(sorted(flights.glob("*lon*.bin"))[0])
    result = runner.invoke(cli, ["fit", log, "-q", *extra])
    assert result.exit_code == code, result.output
    assert message in result.output


def test_an_axis_without_a_sweep_is_an_error_naming_it(runner: CliRunner, flights: Path, tmp_path: Path) -> None:
    """Issue 14: the structure's starting values were printed as results with exit 0. Now: exit 1, one sentence
    per missing axis saying why and what to do, and no file written."""
    logs = [str(p) for p in sorted(flights.glob("*l[ao][nt]-*.bin"))]  # the lateral and pitch sweeps only
    out = tmp_path / "model.json"
    result = runner.invoke(cli, ["fit", *logs, "-o", str(out), "-q"])
    assert result.exit_code == 1, result.output
    assert "model hover: 2 of its 4 axes cannot be identified." in result.output
    assert (
        "yaw: no sweep found in 2 logs; the delta_yaw input never passed the sweep test; give the maneuvers with "
        "--segments, or --partial to write a model of the other axes." in result.output
    )
    assert "thr: no sweep found in 2 logs" in result.output and "Traceback" not in result.output
    assert not out.exists()


def test_partial_writes_a_model_of_the_identified_axes(runner: CliRunner, flights: Path, tmp_path: Path) -> None:
    logs = [str(p) for p in sorted(flights.glob("*l[ao][nt]-*.bin"))]
    out = tmp_path / "model.json"
    result = runner.invoke(cli, ["fit", *logs, "--partial", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "warning: model hover is partial: it covers lat, lon only" in result.stderr
    assert re.search(r"N_yaw +— +- +- +unidentified", result.stdout)  # no value, never the starting one
    doc = json.loads(out.read_text())
    axes = {a["axis"]: a for a in doc["axes"]}
    assert axes["yaw"]["status"] == "unidentified" and axes["lon"]["status"] == "identified"
    assert axes["yaw"]["reason"] == "no sweep found in 2 logs; the delta_yaw input never passed the sweep test"
    assert doc["parameters"]["N_yaw"] == doc["parameters"]["N_yaw"] | {"value": None, "status": "unidentified"}
    model = read_model(out)
    assert [a.axis for a in model.unidentified_axes] == ["yaw", "thr"]
    assert model.linear_model().inputs == ("delta_lat", "delta_lon")


def test_the_windows_are_chosen_from_fit_as_from_freqresp(runner: CliRunner, flights: Path, tmp_path: Path) -> None:
    """Issue 33: ``--windows`` is the option ``sysid freqresp`` has (one definition): every response the model
    was fitted to used those windows (the longest a record cannot hold left out)."""
    logs = [str(p) for p in sorted(flights.glob("*l[ao][nt]-*.bin"))]
    out = tmp_path / "model.json"
    result = runner.invoke(cli, ["fit", *logs, "--partial", "--windows", "2.5,5,10", "-o", str(out), "-q"])
    assert result.exit_code == 0, result.output
    windows = {tuple(r["windows_s"]) for r in json.loads(out.read_text())["responses"]}
    assert windows == {(2.5, 5.0, 10.0)}
    bad = runner.invoke(cli, ["fit", *logs, "--windows", "2,-1"])
    assert bad.exit_code == 2 and "-1: window lengths must be positive seconds" in bad.output


def test_help_has_an_example(runner: CliRunner) -> None:
    result = runner.invoke(cli, ["fit", "--help"])
    assert result.exit_code == 0 and "sysid fit sweeps/*.bin" in result.output
    help_text = " ".join(result.output.split())
    assert "[default: 20.0; x>0]" in help_text and "[default: 10.0; x>0]" in help_text  # Tischler's CR% and I%


def test_the_maneuvers_can_be_given_with_segments(runner: CliRunner, flights: Path, tmp_path: Path) -> None:
    """--segments replaces detection: the pitch sweep given by its times is fitted; an axis the file does not
    name is reported as such."""
    log = sorted(flights.glob("*lon-sweep*.bin"))[0]
    truth = json.loads(log.with_name(log.stem + "-truth.json").read_text())
    (sweep,) = truth["maneuvers"]
    given = tmp_path / "segments.csv"
    given.write_text(f"start_s,end_s,axis,kind\n{sweep['start_s']},{sweep['end_s']},lon,sweep\n")
    result = runner.invoke(cli, ["fit", str(log), "--segments", str(given), "--partial", "--json", "-", "-q"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert {"q/delta_lon", "ax/delta_lon"} <= set(summary["cost"]["responses"])
    assert [a["axis"] for a in summary["axes"] if a["status"] == "identified"] == ["lon"]
    strict = runner.invoke(cli, ["fit", str(log), "--segments", str(given), "-q"])
    assert strict.exit_code == 1
    assert "lat: no sweep found in 1 log; the maneuvers given name no lat sweep; give the maneuvers" in strict.output
