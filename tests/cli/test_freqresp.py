"""``sysid freqresp`` on the simulator's demo flight (sweeps and doublets on every axis, light wind)."""

from __future__ import annotations

import json
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from independent_sim.fixtures import independent_corpus_fixture  # noqa: F401 (registers the fixture)

from simulator.autopilot.excitation import Maneuver
from simulator.campaign.demo_flight import write_demo_flight
from simulator.flights.linear import simulate_hover
from simulator.output.px4 import write_px4_log
from simulator.vehicle.identified import CALM_HOVER
from sysid.freqresp import DEFAULT_PAIRS, read_responses
from sysid_cli.main import cli


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("freqresp-demo")
    files = write_demo_flight(folder)
    dataset = folder / "dataset.h5"
    result = CliRunner().invoke(cli, ["ingest", str(files.log), "-o", str(dataset), "-q"])
    assert result.exit_code == 0, result.output
    return {"log": files.log, "wind": files.wind_csv, "dataset": dataset}


def test_default_pairs_from_a_dataset_with_outputs_reopened(demo: dict[str, Path], tmp_path: Path) -> None:
    out, plot = tmp_path / "fr.h5", tmp_path / "fr.svg"
    result = CliRunner().invoke(
        cli, ["freqresp", str(demo["dataset"]), "-o", str(out), "--plot", str(plot), "--json", "-"]
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    expected = [f"{output}/delta_{axis}" for axis in ("lat", "lon", "yaw", "thr") for output in DEFAULT_PAIRS[axis]]
    assert [entry["pair"] for entry in summary["responses"]] == expected
    assert summary["pieces"] == {"lat": 1, "lon": 1, "yaw": 1, "thr": 1}
    responses = read_responses(out)
    assert [r.pair for r in responses] == expected
    by_pair = {r.pair: r for r in responses}
    for entry in summary["responses"]:
        response = by_pair[entry["pair"]]
        if entry["kept"]:
            assert response.fit_range is not None
            assert response.fit_range == pytest.approx(tuple(entry["fit_range_rad_s"]))
            lo, hi = response.fit_range
            inside = (response.omega >= lo) & (response.omega <= hi)
            assert entry["mean_coherence"] == pytest.approx(float(np.mean(response.coherence[inside])))
            assert np.log10(hi / lo) >= 0.3 and entry["reason"] is None
        else:
            assert response.fit_range is None and entry["reason"].startswith(entry["pair"])
    for pair in ("q/delta_lon", "p/delta_lat", "r/delta_yaw", "az/delta_thr"):  # on-axis rates and accelerations
        lo, hi = by_pair[pair].fit_range or (1.0, 1.0)
        assert np.log10(hi / lo) > 1.0, pair
    assert "q/delta_lon" in plot.read_text() and "kept" in result.stderr
    # the simulator's ArduPilot log carries SIDD: the excitation is every axis's reference, said so
    assert all(entry["reference"] == "excitation" for entry in summary["responses"])
    assert all(r.reference == "excitation" for r in responses)
    # one piece per axis: the whole-record member now comes from that one record (its noise from neighbouring bins)
    assert all(by_pair[pair].whole_record for pair in ("q/delta_lon", "p/delta_lat", "r/delta_yaw", "az/delta_thr"))
    assert (
        summary["notes"][1] == "lon: the logged excitation (SIDD) is the reference of the delta_lon responses, "
        "H = G_ry / G_rx."
    )
    assert summary["options"]["reference"] is None and summary["options"]["whole_record"] is True


def test_the_reference_can_be_switched_off(demo: dict[str, Path]) -> None:
    result = CliRunner().invoke(
        cli,
        [
            "freqresp",
            str(demo["dataset"]),
            "--pairs",
            "q/delta_lon",
            "--reference",
            "none",
            "--no-whole-record",
            "--json",
            "-",
            "-q",
        ],
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert summary["responses"][0]["reference"] is None and summary["options"]["whole_record"] is False
    assert summary["notes"] == ["lon: responses computed from delta_lon itself (reference not used, as asked)."]


def test_a_px4_log_has_no_excitation_and_the_mixer_input_is_used(tmp_path: Path) -> None:
    """PX4 logs no injected excitation: the responses come from the mixer input, and the notes say so."""
    flight = simulate_hover(
        50.0,
        (Maneuver(axis="lon", kind="sweep", start_s=8.0, amplitude=8.0, duration_s=34.0),),
        parameters=CALM_HOVER,
        seed=2,
    )
    log = write_px4_log(flight, tmp_path / "sweep.ulg", utc_start=datetime(2024, 5, 1, 10, tzinfo=UTC))
    result = CliRunner().invoke(cli, ["freqresp", str(log), "--pairs", "q/delta_lon", "--json", "-", "-q"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert summary["responses"][0]["reference"] is None and summary["responses"][0]["kept"]
    assert summary["notes"] == [
        "lon: none of the sweep pieces carry a logged excitation (only ArduPilot's System ID mode logs one, SIDD): responses "
        "computed from the mixer input delta_lon, which in closed loop also carries the "
        "feedback of noise and turbulence."
    ]


def test_logs_are_ingested_on_the_fly_and_wind_inputs_conditioned(demo: dict[str, Path]) -> None:
    result = CliRunner().invoke(
        cli,
        [
            "freqresp",
            str(demo["log"]),
            "--wind",
            str(demo["wind"]),
            "--wind-distance",
            "4.6",
            "--wind-offset",
            "1.5",
            "--pairs",
            "ax/delta_lon,ax/wind_lon",
            "--min-coherence",
            "0.6",
            "--windows",
            "4,8,16",
            "--json",
            "-",
            "-q",
        ],
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    control, wind = summary["responses"]
    assert (control["pair"], control["conditioned_on"]) == ("ax/delta_lon", ["wind_lon"])
    assert (wind["pair"], wind["conditioned_on"]) == ("ax/wind_lon", ["delta_lon"])
    assert control["kept"] and control["windows_s"] == [4.0, 8.0, 16.0]
    assert summary["options"]["min_coherence"] == 0.6 and summary["output"] is None


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--pairs", "q/delta_lon,zz/delta_lon"], "has no signal zz"),
        (["--kind", "multisine"], "no multisine on any axis"),
        (["--pairs", "q/delta_lon", "--kind", "3211"], "no 3211 on axis lon"),
        (["--windows", "90"], "longer than every record"),
        (["--omega-max", "400"], "above the Nyquist frequency"),
        (["--pairs", "q/delta_lon", "--reference", "sidd"], "has no signal sidd"),
    ],
)
def test_bad_data_is_exit_1_with_one_sentence_and_no_file(
    demo: dict[str, Path], tmp_path: Path, args: list[str], fragment: str
) -> None:
    out, plot = tmp_path / "fr.h5", tmp_path / "fr.svg"
    result = CliRunner().invoke(cli, ["freqresp", str(demo["dataset"]), "-o", str(out), "--plot", str(plot), *args])
    assert result.exit_code == 1, result.output
    assert fragment in result.stderr and "Traceback" not in result.output
    assert result.stderr.count("\n") == 1
    assert not out.exists() and not plot.exists()


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--pairs", "q"], "OUTPUT/INPUT"),
        (["--windows", "2,x"], "comma-separated list of seconds"),
        (["--omega-min", "50", "--omega-max", "10"], "must be below --omega-max"),
        (["--wind-distance", "4.6"], "--wind-distance goes with logs"),
    ],
)
def test_usage_errors_are_exit_2(demo: dict[str, Path], args: list[str], fragment: str) -> None:
    result = CliRunner().invoke(cli, ["freqresp", str(demo["dataset"]), *args])
    assert result.exit_code == 2, result.output
    assert fragment in result.stderr


def test_help_has_an_example() -> None:
    result = CliRunner().invoke(cli, ["freqresp", "--help"])
    assert result.exit_code == 0 and "sysid freqresp flight.h5 --pairs q/delta_lon" in result.output


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:no wind given:flightlogs.errors.DataQualityWarning")
def test_segments_given_choose_the_maneuvers_of_a_log(independent_corpus, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """Issue 14: freqresp takes --segments as ingest does; only the sweep the file names is used, and the
    same option with a dataset is a usage error (the dataset's segments were fixed at ingest)."""
    files = independent_corpus.files("heldout-px4-no-lat")  # lon, yaw, thr sweeps; a log our simulator did not write
    lon_only = tmp_path / "lon.csv"
    lon_only.write_text("\n".join(files.segments_csv.read_text().splitlines()[:2]) + "\n")  # header + the lon sweep
    runner = CliRunner()
    result = runner.invoke(
        cli, ["freqresp", str(files.log), "--segments", str(lon_only), "--json", "-", "-q"], catch_exceptions=False
    )
    assert result.exit_code == 0, result.output
    pairs = {entry["pair"] for entry in json.loads(result.stdout)["responses"]}
    assert "q/delta_lon" in pairs and not any(pair.endswith(("/delta_yaw", "/delta_thr")) for pair in pairs)
    dataset = tmp_path / "x.h5"
    assert runner.invoke(cli, ["ingest", str(files.log), "-o", str(dataset), "-q"]).exit_code == 0
    refused = runner.invoke(cli, ["freqresp", str(dataset), "--segments", str(lon_only)])
    assert refused.exit_code == 2 and "--segments" in refused.output
