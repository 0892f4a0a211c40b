"""Tabular flight data through ``--map`` in the commands (issue 32, item 1).

A table is written from a log's own signals (CSV in ms and deg/s, Parquet),
so what the commands compute from it must equal what they compute from the
log: the roll sweep's frequency response of our simulator and of the
independent generator, and chapter 2's ground-effect points from a
motion-capture-style table with rotor speeds in rpm.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from independent_sim.fixtures import independent_corpus_fixture  # noqa: F401 (registers the fixture)

from flightlogs.readers import read_log
from sysid.freqresp import read_responses
from sysid_cli.main import cli

from builders import ROLL_TABLE_MAP, roll_table, simulated_roll_log


def _response(source: Path, segments: Path, out: Path, *extra: str) -> np.ndarray:
    result = CliRunner().invoke(
        cli,
        ["freqresp", str(source), *extra, "--segments", str(segments), "--pairs", "p/delta_lat", "-o", str(out), "-q"],
    )
    assert result.exit_code == 0, result.output
    (response,) = read_responses(out)
    assert response.fit_range is not None
    return np.asarray(response.response)


@pytest.mark.slow
def test_a_simulated_roll_sweep_as_csv_and_parquet_gives_the_logs_response(tmp_path: Path) -> None:
    log = simulated_roll_log(tmp_path)
    segments = tmp_path / "segments.csv"
    segments.write_text("start_s,end_s,axis,kind\n28.0,62.0,lat,sweep\n")
    csv, parquet = roll_table(read_log(log), tmp_path)
    logged = _response(log, segments, tmp_path / "log.h5")
    for table in (csv, parquet):
        from_table = _response(table, segments, tmp_path / f"{table.suffix[1:]}.h5", "--map", ROLL_TABLE_MAP)
        np.testing.assert_allclose(from_table, logged, rtol=1e-4)


@pytest.mark.slow
def test_the_independent_generators_roll_sweep_as_csv_gives_the_logs_response(
    independent_corpus,  # type: ignore[no-untyped-def]
    tmp_path: Path,
) -> None:
    files = independent_corpus.files("tune-px4-lon-lat-sweeps")
    csv, _ = roll_table(read_log(files.log), tmp_path)
    logged = _response(files.log, files.segments_csv, tmp_path / "log.h5")
    np.testing.assert_allclose(
        _response(csv, files.segments_csv, tmp_path / "csv.h5", "--map", ROLL_TABLE_MAP), logged, rtol=1e-4
    )


@pytest.mark.parametrize(
    ("content", "map_text", "message"),
    [
        (
            "t,p\n0,1\n0.02,2\n",
            "p=1",
            "error: column map: no time column (give time=<column>, e.g. time=0 or time=t:ms)",
        ),
        ("t,p\n0,1\n0.02,2\n0.01,3\n", "time=t,p=p", "bad.csv, line 4: time goes back in column 't' (0.01 after 0.02)"),
        ("t,p\n0,1\n0.02,2\n", "time=t,p=p:furlong/s", "error: column map: p is in rad/s; unknown unit 'furlong/s'"),
        ("t,p\n0,1\n0.02,2\n", "time=t,p=roll", "bad.csv: no column 'roll' for p (columns: t, p)"),
        ("t,p\n0,1\n0.02,2\n", None, "bad.csv: a table (CSV or Parquet), not a flight log"),
    ],
)
@pytest.mark.parametrize("command", ["ingest", "fit", "freqresp"])
def test_a_bad_table_is_one_sentence_exit_1_and_no_file(
    tmp_path: Path, command: str, content: str, map_text: str | None, message: str
) -> None:
    table, out = tmp_path / "bad.csv", tmp_path / "out.h5"
    table.write_text(content)
    args = [command, str(table), *(["--map", map_text] if map_text else []), "-o", str(out), "-q"]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 1, result.output
    assert message in result.stderr and result.stderr.count("\n") == 1 and "Traceback" not in result.output
    assert not out.exists()


@pytest.fixture(scope="module", name="chapter2")
def chapter2_fixture(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, Path]:
    """Chapter 2's flight test (hover steps down towards the ground) as its log and as a motion-capture table.

    The table is what a rig exports at 50 Hz: position in mm, velocities, attitude in degrees, rates in
    deg/s and each rotor's speed in rpm (the log's normalised commands are thrust, so rpm = k sqrt(command)).
    """
    from simulator.campaign.fly import run_scenario
    from simulator.campaign.scenario import load_builtin

    folder = tmp_path_factory.mktemp("chapter2-mocap")
    log_path = run_scenario(load_builtin("chapter2-ground-effect"), folder)[0].logs[0]
    log = read_log(log_path)
    start, end = log["height_agl"].time_s[0], log["height_agl"].time_s[-1]
    t = np.arange(start, end, 0.02)

    def at(name: str) -> np.ndarray:
        return np.interp(t, log[name].time_s, log[name].values)

    columns = {
        "t_us": np.round((t - start) * 1e6),
        "z_up_mm": 1000.0 * at("height_agl"),  # the rig's frame: z up from the floor
        **{f"v{axis}": at(f"v{axis}") for axis in ("n", "e", "d")},
        **{f"{angle}_deg": np.degrees(at(angle)) for angle in ("phi", "theta", "psi")},
        **{f"{rate}_dps": np.degrees(at(rate)) for rate in ("p", "q", "r")},
        **{f"rpm{k}": 25_000.0 * np.sqrt(np.clip(at(f"motor_{k}"), 0.0, None)) for k in range(1, 5)},
    }
    csv = folder / "mocap.csv"
    names = list(columns)
    rows = np.column_stack([columns[n] for n in names])
    csv.write_text(",".join(names) + "\n" + "".join(",".join(f"{v:.9g}" for v in row) + "\n" for row in rows))
    mapping = folder / "mocap.toml"
    mapping.write_text(
        "[columns]\ntime = 't_us:us'\nheight_agl = 'z_up_mm:mm'\n"
        + "".join(f"{n} = 'v{n[1]}'\n" for n in ("vn", "ve", "vd"))
        + "".join(f"{a} = '{a}_deg:deg'\n" for a in ("phi", "theta", "psi"))
        + "".join(f"{r} = '{r}_dps:deg/s'\n" for r in ("p", "q", "r"))
        + "".join(f"motor_{k} = 'rpm{k}:rpm'\n" for k in range(1, 5))
    )
    return log_path, csv, mapping


@pytest.mark.slow
def test_ground_effect_fit_reads_a_motion_capture_table(chapter2: tuple[Path, Path, Path]) -> None:
    """Every hover step of the table lies on eq. 2.5 as the log's do, and the fit recovers it.

    The rotor speeds give F0 = k_f sum rpm^2; k_f per rpm^2 is Table 2.1's per count times 65535 / 25000^2,
    so with the mass given F/F0 is the simulator's truth (the steps themselves may split differently
    from the log's: the 0.5 s blocks start at another time, and a step that creeps may read as two).
    """
    from sysid.groundeffect import formulas as laws

    _, csv, mapping = chapter2
    kf_per_rpm2 = 2.083e-6 * 65535.0 / 25_000.0**2
    args = ["ground-effect", "fit", str(csv), "--map", str(mapping), "--rotor-radius", "0.0225", "--mass", "0.03812"]
    result = CliRunner().invoke(cli, [*args, "--kf", repr(kf_per_rpm2), "--json", "-", "-q"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    truth = (laws.FITTED_4ROTOR_SLOPE, laws.FITTED_4ROTOR_INTERCEPT, laws.FITTED_4ROTOR_BREAKPOINT)
    height_ratio = np.array([step["height_m"] for step in summary["steps"]]) / 0.0225
    ratio = np.array([step["thrust_ratio"] for step in summary["steps"]])
    assert summary["n_points"] >= 10 and summary["best"] == "piecewise_linear"
    assert np.max(np.abs(ratio - laws.piecewise_linear(height_ratio, *truth))) <= 0.004
    fitted = summary["models"]["piecewise_linear"]["params"]
    np.testing.assert_allclose(list(fitted.values()), truth, rtol=0.05)
    assert "rotor speeds in rpm" in summary["f0_source"]


@pytest.mark.slow
def test_discrepancy_reads_the_table_and_says_what_a_motion_capture_lacks(chapter2: tuple[Path, Path, Path]) -> None:
    """The table is read through the map and its specific forces derived from its velocities; the mixer inputs
    need the rotor layout (``[rotors]``), which this map does not give: one sentence naming them and the way,
    exit 1. (With a layout, tests/cli/test_mocap_discrepancy.py.)"""
    log_path, csv, mapping = chapter2
    result = CliRunner().invoke(cli, ["discrepancy", str(log_path), str(csv), "--map", str(mapping), "-q"])
    assert result.exit_code == 1, result.output
    assert result.stderr.strip().splitlines()[-1] == (
        "error: mocap.csv: delta_lat, delta_lon, delta_yaw, delta_thr not logged; the discrepancy search needs them "
        "(a table derives the mixer inputs from its motors given a [rotors] layout in its map)"
    )
