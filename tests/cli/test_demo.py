"""``sysid demo`` end to end (simulate, ingest, fit, verify, report), and ``sysid ingest`` with an anemometer."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner
from markupsafe import escape

from flightlogs.store.dataset import read_dataset
from simulator.campaign.demo_flight import write_demo_flight
from sysid.fit import model_verdict, read_model
from sysid.verify import axis_outputs
from sysid.verify.io import read_verification
from sysid_cli.main import cli


@pytest.fixture(scope="module")
def demo_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """The whole demo, once: its folder and what it printed."""
    out = tmp_path_factory.mktemp("demo")
    result = CliRunner().invoke(cli, ["demo", "-o", str(out)])
    assert result.exit_code == 0, result.output
    return out, result.output


@pytest.fixture(scope="module")
def demo_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The demo's flight files alone (what the ingest tests need), without running the demo."""
    out = tmp_path_factory.mktemp("flight")
    write_demo_flight(out)
    return out


@pytest.mark.slow
def test_demo_writes_the_flight_and_the_aligned_dataset(demo_run: tuple[Path, str]) -> None:
    demo_dir, output = demo_run
    assert f"wrote {demo_dir / 'dataset.h5'}" in output
    # each table states its units: the signals', the wind step's residual RMS
    assert any(
        line.split()[:3] == ["signal", "samples", "rate"] and line.split()[-2:] == ["unit", "source"]
        for line in output.splitlines()
    )
    (wind_line,) = [line for line in output.splitlines() if "wind step residual RMS" in line]
    assert wind_line.count("m/s^2") == 2, wind_line
    truth = json.loads((demo_dir / "truth.json").read_text())
    summary = json.loads((demo_dir / "ingest.json").read_text())
    alignment = summary["wind_alignment"]
    assert alignment["clock_offset_source"] == "estimated"
    assert abs(alignment["clock_offset_s"] - truth["anemometer"]["clock_offset_s"]) < 0.01
    assert abs(alignment["transport_delay_s"] - truth["anemometer"]["transport_delay_s"]) < 0.01
    assert [s["axis"] for s in summary["segments"] if s["kind"] == "sweep"] == ["lon", "lat", "yaw", "thr"]
    dataset = read_dataset(demo_dir / "dataset.h5")
    (flight,) = dataset.conditioned
    assert flight.wind is not None and flight.wind.clock_offset_s == pytest.approx(
        alignment["clock_offset_s"], abs=1e-4
    )
    assert [s.kind for s in flight.segments] == [s["kind"] for s in summary["segments"]]
    (record,) = flight.records
    assert record.time_s.size == summary["records"][0]["samples"]
    assert {"u", "v", "w", "wind_lon", "wind_lat"} <= set(record.signals)


_FOOTER = re.compile(r"<footer>.*?</footer>", re.S)


@pytest.mark.slow
def test_demo_ends_with_the_report_and_sysid_report_rebuilds_it(demo_run: tuple[Path, str], tmp_path: Path) -> None:
    """The last line is the report's path; the model, the verification and the page agree with each other."""
    demo_dir, output = demo_run
    page = demo_dir / "report.html"
    assert output.rstrip().splitlines()[-1] == f"report: {page.resolve()}"
    model = read_model(demo_dir / "model.json")
    saved = read_verification(demo_dir / "validation.json")
    assert model.structure_name == "hover-wind" and model.wind is not None
    assert saved.model == "model.json" and saved.options["initial_state"] == "estimated"
    assert {r.label.split()[1] for r in saved.verification.records} == {"lon", "lat", "yaw", "thr"}  # every doublet
    assert saved.verification.wind_correction  # verified with and without G_w
    axes = axis_outputs(model)
    for record in saved.verification.records:  # simulated from every input, judged on its axis' outputs
        assert record.inputs == model.linear_model().inputs
        assert record.excited is not None and [o.name for o in record.judged] == list(axes[record.excited])
    for summary in saved.verification.summary:  # issue 7: TIC <= 0.25 on every on-axis output
        assert summary.tic <= 0.25, summary
    assert saved.verification.correction("az").reduction_percent >= 7.0  # Table 3.6, on the heave doublet
    verdict = model_verdict(model, saved.verification)
    assert verdict.grade == "good"
    assert verdict.sentence in output
    text = page.read_text()
    assert '<p class="verdict ' in text and str(escape(verdict.sentence)) in text  # as the template escapes it
    assert "ArduCopter" in text and 'id="verification"' in text
    rebuilt = tmp_path / "rebuilt.html"
    result = CliRunner().invoke(
        cli,
        [
            "report",
            str(demo_dir / "model.json"),
            str(demo_dir / "validation.json"),
            "--ingest-summary",
            str(demo_dir / "ingest.json"),
            "-o",
            str(rebuilt),
            "-q",
        ],
    )
    assert result.exit_code == 0, result.output
    assert _FOOTER.sub("", rebuilt.read_text()) == _FOOTER.sub("", text)


@pytest.mark.parametrize(
    ("extra", "fragment"),
    [
        (["--wind-distance", "4.6", "--wind-offset", "10800"], "if the anemometer clock is off, give --wind-offset"),
        ([], "the anemometer-to-vehicle distance (--wind-distance) or a delay (--transport-delay)"),  # the library
        # names ConditioningOptions' fields (`wind_distance_m`): the command line its flags (issue 33)
    ],
)
def test_wind_that_cannot_be_aligned_is_exit_1(demo_dir: Path, tmp_path: Path, extra: list[str], fragment: str) -> None:
    out = tmp_path / "set.h5"
    result = CliRunner().invoke(
        cli,
        ["ingest", str(demo_dir / "flight.bin"), "--wind", str(demo_dir / "anemometer.csv"), "-o", str(out), *extra],
    )
    assert result.exit_code == 1
    assert "Traceback" not in result.output and fragment in result.stderr and "`" not in result.stderr
    assert not out.exists()


def test_a_field_the_command_has_no_flag_for_stays_named(demo_dir: Path) -> None:
    """``sysid discrepancy`` reads wind but has no --transport-delay: the advice says so, in the JSON error too."""
    args = ["discrepancy", str(demo_dir / "flight.bin"), str(demo_dir / "flight.bin")]
    result = CliRunner().invoke(cli, [*args, "--wind", str(demo_dir / "anemometer.csv"), "--json", "-"])
    assert result.exit_code == 1, result.output
    expected = "(--wind-distance) or a delay (`transport_delay_s`, not an option of sysid discrepancy)"
    assert expected in result.stderr and expected in json.loads(result.stdout)["error"]


def test_a_wind_folder_pairs_each_log_by_utc(demo_dir: Path, tmp_path: Path) -> None:
    folder = tmp_path / "anemometers"
    folder.mkdir()
    (folder / "a.csv").write_text((demo_dir / "anemometer.csv").read_text())
    (folder / "b.csv").write_text(
        "utc,speed_m_s,direction_deg\n2020-01-01T00:00:00Z,1.0,90\n2020-01-01T00:00:01Z,1.0,90\n"
    )
    result = CliRunner().invoke(
        cli,
        ["ingest", str(demo_dir / "flight.bin"), "--wind", str(folder), "--wind-distance", "4.6", "--json", "-", "-q"],
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert Path(summary["wind_alignment"]["wind_file"]).name == "a.csv"
    assert len(summary["wind"]) == 2


def test_anemometer_position_gives_the_transport_delay_from_gps(demo_dir: Path) -> None:
    """``--anemometer-at`` (deg): distance and bearing to the vehicle's mean GPS position, delay within a sample."""
    truth = json.loads((demo_dir / "truth.json").read_text())["anemometer"]
    lat, lon = truth["position_deg"]
    result = CliRunner().invoke(
        cli,
        [
            "ingest",
            str(demo_dir / "flight.bin"),
            "--wind",
            str(demo_dir / "anemometer.csv"),
            "--anemometer-at",
            f"{lat:.9f},{lon:.9f}",
            "--wind-offset",
            str(truth["clock_offset_s"]),
            "--json",
            "-",
            "-q",
        ],
    )
    assert result.exit_code == 0, result.output
    alignment = json.loads(result.stdout)["wind_alignment"]
    assert alignment["transport_delay_source"] == "gps"
    assert abs(alignment["distance_m"] - truth["distance_m"]) < 0.05
    assert abs(alignment["transport_delay_s"] - truth["transport_delay_s"]) < 0.01


@pytest.mark.parametrize(
    ("value", "fragment"),
    [
        ("35.0", "not LAT,LON"),
        ("35.0;-106.9", "not LAT,LON"),
        ("north,west", "not LAT,LON"),
        ("-106.9,35.0", "latitude must lie within"),
        ("nan,1", "latitude must lie within"),
    ],
)
def test_a_bad_anemometer_position_is_a_usage_error(demo_dir: Path, value: str, fragment: str) -> None:
    result = CliRunner().invoke(
        cli,
        [
            "ingest",
            str(demo_dir / "flight.bin"),
            "--wind",
            str(demo_dir / "anemometer.csv"),
            f"--anemometer-at={value}",
        ],
    )
    assert result.exit_code == 2
    assert "--anemometer-at" in result.stderr and fragment in result.stderr


def test_transport_delay_by_correlation_from_the_command_line(demo_dir: Path) -> None:
    truth = json.loads((demo_dir / "truth.json").read_text())["anemometer"]
    result = CliRunner().invoke(
        cli,
        [
            "ingest",
            str(demo_dir / "flight.bin"),
            "--wind",
            str(demo_dir / "anemometer.csv"),
            "--wind-offset",
            str(truth["clock_offset_s"]),
            "--estimate-transport-delay",
            "--json",
            "-",
            "-q",
        ],
    )
    assert result.exit_code == 0, result.output
    alignment = json.loads(result.stdout)["wind_alignment"]
    assert alignment["transport_delay_source"] == "correlation"
    assert abs(alignment["transport_delay_s"] - truth["transport_delay_s"]) < 0.01
    both = CliRunner().invoke(
        cli,
        [
            "ingest",
            str(demo_dir / "flight.bin"),
            "--wind",
            str(demo_dir / "anemometer.csv"),
            "--estimate-wind-offset",
            "--estimate-transport-delay",
        ],
    )
    assert both.exit_code == 2 and "pick one" in both.output


def test_a_segments_file_overrides_detection(demo_dir: Path, tmp_path: Path) -> None:
    segments = tmp_path / "maneuvers.csv"
    segments.write_text("start_s,end_s,axis,kind\n26.0,60.0,lon,sweep\n66.0,68.0,lon,doublet\n")
    result = CliRunner().invoke(
        cli, ["ingest", str(demo_dir / "flight.bin"), "--segments", str(segments), "--json", "-", "-q"]
    )
    assert result.exit_code == 0, result.output
    found = [
        (s["axis"], s["kind"], s["start_s"], s["end_s"], s["source"]) for s in json.loads(result.stdout)["segments"]
    ]
    assert found == [("lon", "sweep", 26.0, 60.0, "user"), ("lon", "doublet", 66.0, 68.0, "user")]
    segments.write_text("start_s,end_s,axis\n50,45,lon\n")
    bad = CliRunner().invoke(cli, ["ingest", str(demo_dir / "flight.bin"), "--segments", str(segments)])
    assert bad.exit_code == 1 and f"{segments.name}:2" in bad.stderr
