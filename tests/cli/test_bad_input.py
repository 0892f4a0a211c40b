"""Bad input on the command line: one sentence naming the option or file, exit 2 (usage) or 1 (data), no
traceback, and no output written or clobbered."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner, Result

from simulator.campaign.demo_flight import write_demo_flight
from sysid_cli.main import cli

_CLASS_NAME = re.compile(r"\b\w+(Error|Exception)\b")


def _clean(result: Result, code: int, *named: str) -> None:
    """Exit `code`, every string of `named` in the message, no traceback or exception class name."""
    assert result.exit_code == code, result.output
    assert "Traceback" not in result.output and not _CLASS_NAME.search(result.output), result.output
    for text in named:
        assert text in result.output, result.output


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The demo flight, its dataset (`sysid ingest -o`) and a hover model fitted to its sweeps."""
    folder = tmp_path_factory.mktemp("bad-input")
    files = write_demo_flight(folder)
    dataset, model = folder / "dataset.h5", folder / "model.json"
    for args in (
        ["ingest", str(files.log), "-o", str(dataset), "-q"],
        ["fit", str(dataset), "--model", "hover", "-o", str(model), "-q"],
    ):
        result = CliRunner().invoke(cli, args)
        assert result.exit_code == 0, result.output
    return {"log": files.log, "wind": files.wind_csv, "dataset": dataset, "model": model}


def _commands(d: dict[str, Path]) -> dict[str, list[str]]:
    """Every command with an output in the missing folder ``nodir`` (relative to the working folder)."""
    log, ds, model = str(d["log"]), str(d["dataset"]), str(d["model"])
    return {
        "ingest -o": ["ingest", log, "-o", "nodir/x.h5"],
        "ingest --json": ["ingest", log, "--json", "nodir/x.json"],
        "fit --report": ["fit", ds, "-o", "fit_fresh.json", "--report", "nodir/x.html"],
        "fit --mat": ["fit", ds, "-o", "fit_fresh.json", "--mat", "nodir/x.mat"],
        "freqresp --plot": ["freqresp", ds, "-o", "fr.h5", "--plot", "nodir/x.svg"],
        "validate --report": ["validate", model, ds, "-o", "v.json", "--report", "nodir/x.html"],
        "report -o": ["report", model, "-o", "nodir/x.html"],
        "modes --json": ["modes", model, "--json", "nodir/x.json"],
        "ground-effect fit": [
            "ground-effect",
            "fit",
            log,
            "--rotor-radius",
            "0.0225",
            "-o",
            "ge.json",
            "--report",
            "nodir/x.html",
        ],
        "ground-effect spacing": [
            "ground-effect",
            "spacing",
            log,
            log,
            "--spacing",
            "0,10",
            "--rotor-radius",
            "0.0225",
            "--report",
            "nodir/x.html",
        ],
        "mrac compare": ["mrac", "compare", "--report", "r.html", "-o", "nodir/x.json"],
        "simulate -o": ["simulate", "sitl-nominal", "-o", "nodir/x"],
        "demo -o": ["demo", "-o", "nodir/x"],
    }


@pytest.mark.parametrize("name", list(_commands({k: Path(k) for k in ("log", "dataset", "model")})))
def test_an_output_in_a_missing_folder_fails_first_and_writes_nothing(
    demo: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str
) -> None:
    """Checked while parsing (exit 2), so no other output of the command (fit_fresh.json ...) appears."""
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(cli, _commands(demo)[name])
    _clean(result, 2, "nodir/x", "folder nodir does not exist")
    assert list(tmp_path.iterdir()) == []


def test_a_folder_output_under_a_file_or_on_a_file_is_a_usage_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    Path("keep.h5").write_text("keep")
    _clean(CliRunner().invoke(cli, ["demo", "-o", "keep.h5/sub"]), 2, "keep.h5/sub", "keep.h5 is a file")
    _clean(CliRunner().invoke(cli, ["simulate", "sitl-nominal", "-o", "keep.h5"]), 2, "keep.h5")
    assert [p.name for p in tmp_path.iterdir()] == ["keep.h5"] and Path("keep.h5").read_text() == "keep"


def test_json_to_stdout_is_still_accepted(demo: dict[str, Path]) -> None:
    result = CliRunner().invoke(cli, ["modes", str(demo["model"]), "--json", "-", "-q"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["eigenvalues"]


@pytest.mark.parametrize(
    ("trials", "named"),
    [
        ("99", "99: scenario sitl-nominal has trials 0-1 only"),
        ("0,7-9", "7, 8, 9: scenario sitl-nominal has trials 0-1"),
        ("3-1", "'3-1' is a reversed range"),
    ],
)
def test_simulate_rejects_trials_the_scenario_lacks_and_keeps_the_index(
    tmp_path: Path, trials: str, named: str
) -> None:
    out = tmp_path / "simx"
    out.mkdir()
    (out / "campaign.json").write_text('{"trials": ["kept"]}\n')
    result = CliRunner().invoke(cli, ["simulate", "sitl-nominal", "--trials", trials, "-o", str(out)])
    _clean(result, 2, "--trials", named)
    assert [p.name for p in out.iterdir()] == ["campaign.json"]
    assert (out / "campaign.json").read_text() == '{"trials": ["kept"]}\n'


def test_ingest_bounds_the_rate(demo: dict[str, Path], tmp_path: Path) -> None:
    out = tmp_path / "x.h5"
    result = CliRunner().invoke(cli, ["ingest", str(demo["log"]), "--rate", "1e9", "-o", str(out)])
    _clean(result, 2, "--rate", "10000")
    assert not out.exists()


def test_ingest_names_the_valid_column_keys(demo: dict[str, Path]) -> None:
    result = CliRunner().invoke(
        cli, ["ingest", str(demo["log"]), "--wind", str(demo["wind"]), "--columns", "time=UTC,foo=bar"]
    )
    _clean(result, 2, "--columns", "foo: not a column key", "speed=COL,direction=COL")


def test_ingest_writes_nothing_when_no_log_can_be_conditioned(demo: dict[str, Path], tmp_path: Path) -> None:
    broken = tmp_path / "trunc100.bin"
    broken.write_bytes(demo["log"].read_bytes()[:100])
    out, summary = tmp_path / "x.h5", tmp_path / "x.json"
    result = CliRunner().invoke(cli, ["ingest", str(broken), "-o", str(out), "--json", str(summary)])
    _clean(result, 1, "no log could be conditioned", "trunc100.bin")
    assert not out.exists() and not summary.exists()
    # one good log among them: written, with the bad one warned about
    result = CliRunner().invoke(cli, ["ingest", str(demo["log"]), str(broken), "-o", str(out), "--json", "-", "-q"])
    assert result.exit_code == 0, result.output
    entries = json.loads(result.stdout)["logs"]
    assert any("not conditioned: " in w and "trunc100.bin" in w for w in entries[1]["warnings"])
    assert out.exists()
    # without -o the log is only looked at: its signals are listed, with the reason it cannot be conditioned
    result = CliRunner().invoke(cli, ["ingest", str(broken), "--json", "-", "-q"])
    assert result.exit_code == 0, result.output
    assert any("not conditioned: " in w for w in json.loads(result.stdout)["logs"][0]["warnings"])


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (["--omega-min", "50", "--omega-max", "1"], ["--omega-min", "50 rad/s must be below --omega-max (1 rad/s)"]),
        (["--windows", "-2,4"], ["--windows", "-2: window lengths must be positive seconds"]),
        (["--windows", "4,nan"], ["--windows", "nan: window lengths must be positive"]),
    ],
)
def test_freqresp_names_the_option_at_fault(
    demo: dict[str, Path], tmp_path: Path, args: list[str], named: list[str]
) -> None:
    out = tmp_path / "fr.h5"
    result = CliRunner().invoke(cli, ["freqresp", str(demo["dataset"]), "-o", str(out), *args])
    _clean(result, 2, *named)
    assert "self." not in result.output and "window_lengths_s" not in result.output
    assert not out.exists()


def test_fit_kind_is_a_choice(demo: dict[str, Path]) -> None:
    result = CliRunner().invoke(cli, ["fit", str(demo["dataset"]), "--kind", "bogus"])
    _clean(result, 2, "--kind", "'bogus' is not one of 'sweep', 'multisine', '3211', 'doublet'")


def test_validate_takes_a_dataset_as_it_takes_the_log(demo: dict[str, Path]) -> None:
    """The dataset was ingested with the defaults, so it holds the flight `validate` conditions from the log."""
    runs = [
        CliRunner().invoke(cli, ["validate", str(demo["model"]), str(source), "--json", "-", "-q"])
        for source in (demo["dataset"], demo["log"])
    ]
    for result in runs:
        assert result.exit_code == 0, result.output
    from_dataset, from_log = (json.loads(r.stdout) for r in runs)
    assert [r["label"] for r in from_dataset["records"]] == [r["label"] for r in from_log["records"]]
    assert len(from_dataset["records"]) == 4  # a doublet on every axis
    assert from_dataset["overall"] == pytest.approx(from_log["overall"], rel=1e-9)


def test_validate_of_a_dataset_rejects_the_log_options(demo: dict[str, Path], tmp_path: Path) -> None:
    result = CliRunner().invoke(
        cli,
        [
            "validate",
            str(demo["model"]),
            str(demo["dataset"]),
            "--wind",
            str(demo["wind"]),
            "-o",
            str(tmp_path / "v.json"),
        ],
    )
    _clean(result, 2, "--wind", "a dataset already holds its aligned wind")
    assert list(tmp_path.iterdir()) == []


def test_validate_names_the_segment_outside_the_log(demo: dict[str, Path], tmp_path: Path) -> None:
    segments = tmp_path / "seg_bad4.csv"
    segments.write_text("start_s,end_s,axis,kind\n5000,5002,lon,doublet\n")
    out = tmp_path / "v.json"
    result = CliRunner().invoke(
        cli, ["validate", str(demo["model"]), str(demo["log"]), "--segments", str(segments), "-o", str(out)]
    )
    _clean(result, 1, "seg_bad4.csv line 2", "lon doublet at 5000-5002 s", "flight.bin")
    assert "give their times with --segments" not in result.output
    assert not out.exists()


@pytest.mark.parametrize(
    ("spacing", "named"),
    [
        ("10,10", "10 mm given twice"),
        ("-5,10", "-5 mm: spacings must be finite and not negative"),
        ("10", "2 files but 1 spacings"),
    ],
)
def test_ground_effect_spacing_is_checked_in_mm(tmp_path: Path, spacing: str, named: str) -> None:
    rig = tmp_path / "rig.csv"
    rig.write_text("height_m,thrust_n\n0.1,0.4\n")
    report = tmp_path / "s.html"
    result = CliRunner().invoke(
        cli,
        [
            "ground-effect",
            "spacing",
            str(rig),
            str(rig),
            f"--spacing={spacing}",
            "--rotor-radius",
            "0.0225",
            "--report",
            str(report),
        ],
    )
    _clean(result, 2, "--spacing", named)
    assert not report.exists()


@pytest.mark.parametrize(
    ("command", "named"),
    [
        (["freqresp", "DATASET", "--pairs", ""], ["--pairs", "empty: give OUTPUT/INPUT pairs"]),
        (["freqresp", "DATASET", "--pairs", " , "], ["--pairs", "empty: give OUTPUT/INPUT pairs"]),
        (["ground-effect", "fit", "RIG", "--rotor-radius", "0.0225", "--models", ""], ["--models", "empty: choose"]),
    ],
)
def test_an_empty_list_option_is_a_usage_error_not_the_default(
    demo: dict[str, Path], tmp_path: Path, command: list[str], named: list[str]
) -> None:
    rig = tmp_path / "rig.csv"
    rig.write_text("height_m,thrust_n\n0.1,0.4\n")
    args = [str(demo["dataset"]) if a == "DATASET" else str(rig) if a == "RIG" else a for a in command]
    _clean(CliRunner().invoke(cli, args), 2, *named)


def test_fit_of_a_dataset_rejects_the_log_options(demo: dict[str, Path], tmp_path: Path) -> None:
    """A dataset already holds its aligned wind: a wind option with it would be silently ignored."""
    out = tmp_path / "m.json"
    result = CliRunner().invoke(cli, ["fit", str(demo["dataset"]), "--wind-distance", "4.6", "-o", str(out)])
    _clean(result, 2, "--wind-distance goes with logs")
    assert not out.exists()
