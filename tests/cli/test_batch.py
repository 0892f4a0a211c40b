"""``sysid batch`` on a simulated fleet: drift flagged at the right flight, the damaged log listed, the cache,
a scheduler and workers started on their own giving the local run's results, and the 200-log campaign."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from simulator.campaign.fleet import FleetPlan, fleet_log_name, write_fleet

_CLI = [sys.executable, "-c", "from sysid_cli.main import cli; cli()"]
#: A few vehicles: the second wears out from its 5th flight, the third's 2nd log is damaged.
_SMALL = FleetPlan(vehicles=3, flights=8, degrading_vehicle=2, degradation_starts=5, corrupted=(3, 2), seed=4)


def _batch(*args: str | Path, timeout: float = 600) -> subprocess.CompletedProcess[str]:
    env = os.environ | {"PYTHONWARNINGS": "ignore"}  # the suite makes warnings errors; a user's run does not
    return subprocess.run(
        [*_CLI, "batch", *map(str, args)], capture_output=True, text=True, timeout=timeout, check=False, env=env
    )


@pytest.fixture(scope="module")
def fleet(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("fleet")
    write_fleet(folder, _SMALL)
    return folder


@pytest.fixture(scope="module")
def local_run(
    fleet: Path, tmp_path_factory: pytest.TempPathFactory
) -> tuple[Path, dict, subprocess.CompletedProcess[str]]:
    out = tmp_path_factory.mktemp("local") / "results"
    report = out.parent / "fleet.html"
    done = _batch(
        fleet,
        "--mapping",
        fleet / "fleet.csv",
        "-o",
        out,
        "--workers",
        "2",
        "--report",
        report,
        "--no-group-reports",
        "--json",
        "-",
    )
    assert done.returncode == 0, done.stderr
    return out, json.loads(done.stdout), done


def test_the_fleet_is_what_its_plan_says(fleet: Path) -> None:
    truth = json.loads((fleet / "truth.json").read_text())["logs"]
    assert len(truth) == 24 and len({e["board_id"] for e in truth}) == 3  # one board per vehicle
    mapping = pd.read_csv(fleet / "fleet.csv")
    assert mapping["file"].tolist() == [e["file"] for e in truth] and mapping["vehicle"].nunique() == 3
    healthy = {e["vehicle"]: e["parameters"]["Z_thr"] for e in truth if e["flight"] == 1}
    for e in truth:
        loss = _SMALL.thrust_loss(int(e["vehicle"][1:]), e["flight"])
        assert e["thrust_loss"] == loss and e["parameters"]["Z_thr"] == pytest.approx(
            healthy[e["vehicle"]] * (1 - loss)
        )
    assert [e["flight"] for e in truth if e["thrust_loss"] > 0] == [5, 6, 7, 8]  # V02 only
    damaged = (fleet / "V03" / fleet_log_name(3, 2)).read_bytes()
    assert not any(damaged[: 1 << 16]) and any(damaged[1 << 16 :])


def test_the_worn_vehicle_is_flagged_at_its_first_worn_flight_and_no_healthy_one(local_run) -> None:
    _, summary, done = local_run
    flagged = [d for d in summary["drifts"] if d["confirmed"]]
    assert [(d["vehicle"], d["parameter"], d["before"], d["after"]) for d in flagged] == [
        ("V02", "Z_thr", "V02 2024-06-06", "V02 2024-06-07")  # flights 4 and 5
    ]
    assert flagged[0]["change_percent"] == pytest.approx(-100 * _SMALL.thrust_loss(2, 5), abs=3.0)  # 25 % lost
    assert "drift: V02: Z_thr" in done.stderr  # the summary goes to stderr with --json -


def test_the_damaged_log_is_listed_with_its_reason_and_the_rest_fitted(local_run, fleet: Path) -> None:
    out, summary, _ = local_run
    damaged = fleet / "V03" / fleet_log_name(3, 2)
    assert summary["failures"] == [
        {
            "what": str(damaged),
            "stage": "read",
            "reason": f"{damaged}: not a PX4 ULog, ArduPilot DataFlash or MAVLink telemetry log "
            "(first bytes 00 00 00 00 00 00 00 00).",
        }
    ]
    assert summary["logs"] == 24 and summary["groups"] == summary["fitted"] == 23
    assert pd.read_csv(out / "failures.csv")["what"].tolist() == [str(damaged)]


def test_the_table_holds_each_groups_model_and_its_verification(local_run, fleet: Path) -> None:
    out, _, _ = local_run
    table = pd.read_parquet(out / "results.parquet")
    csv = pd.read_csv(out / "results.csv", keep_default_na=False, na_values={c: [""] for c in ("value", "tic")})
    for column in ("group", "parameter", "status", "modes"):
        assert csv[column].astype(str).tolist() == table[column].astype(str).tolist()
    for column in ("value", "cramer_rao_percent", "cost_average", "tic"):  # the CSV's numbers are the Parquet's
        pd.testing.assert_series_equal(pd.to_numeric(csv[column]), table[column], check_dtype=False, rtol=1e-15)
    assert set(table["group"]) == {f"V{v:02d} 2024-06-{2 + f:02d}" for v in (1, 2, 3) for f in range(1, 9)} - {
        "V03 2024-06-04"
    }
    truth = {e["file"]: e for e in json.loads((fleet / "truth.json").read_text())["logs"]}
    row = table[(table["group"] == "V02 2024-06-10") & (table["parameter"] == "Z_thr")].iloc[0]
    model = json.loads((out / "groups" / "V02_2024-06-10" / "model.json").read_text())
    assert row["value"] == model["parameters"]["Z_thr"]["value"]  # the table is the model file's
    flown = truth[f"V02/{fleet_log_name(2, 8)}"]["parameters"]["Z_thr"] * 100  # per % of mixer input -> per unit
    assert row["value"] == pytest.approx(flown, rel=0.08)  # the worn value, identified
    assert (table["tic"] > 0).all() and (table["tic"] < 0.3).all()  # every group verified on its doublets
    estimated = table[table["status"] == "estimated"]
    assert estimated["cramer_rao_percent"].between(0, 20).all() and len(estimated) >= 13 * 23
    assert table.loc[table["status"] != "estimated", "cramer_rao_percent"].isna().all()  # no bound made up
    assert (out / "groups" / "V02_2024-06-10" / "verification.json").is_file()


def test_the_fleet_report_shows_the_drift_and_the_failure(local_run, fleet: Path) -> None:
    out, _, _ = local_run
    html = (out.parent / "fleet.html").read_text()
    assert "1 parameter flagged on 1 vehicle" in html
    assert "V02 2024-06-07" in html and "not a PX4 ULog" in html
    assert html.count("<svg") == 3  # a trend figure per vehicle
    assert "report.html" not in html  # --no-group-reports: none made, none linked


def test_a_rerun_takes_everything_from_the_cache_and_writes_the_same_table(
    local_run, fleet: Path, tmp_path: Path
) -> None:
    out, summary, _ = local_run
    before = pd.read_parquet(out / "results.parquet")
    started = time.perf_counter()
    done = _batch(
        fleet, "--mapping", fleet / "fleet.csv", "-o", out, "--workers", "1", "--no-group-reports", "--json", "-", "-q"
    )
    assert done.returncode == 0, done.stderr
    again = json.loads(done.stdout)
    assert again["cached"] == 24 + 23  # every log's survey (the damaged one's reason too) and every group
    pd.testing.assert_frame_equal(pd.read_parquet(out / "results.parquet"), before)
    assert again["drifts"] == summary["drifts"]
    assert time.perf_counter() - started < summary["seconds"]


@pytest.mark.long  # 31 s of scheduler and worker start-up: run by .ci/run with -m long
def test_a_scheduler_and_two_workers_started_apart_give_the_local_runs_results(
    local_run, fleet: Path, tmp_path: Path
) -> None:
    out, _, _ = local_run
    scheduler_file = tmp_path / "scheduler.json"
    dask = [str(Path(sys.executable).with_name("dask"))]
    env = os.environ | {"FLIGHT_SYSID_THREADS": "1", "PYTHONWARNINGS": "ignore"}
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL, "env": env}
    processes = [
        subprocess.Popen(
            [
                *dask,
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                "0",
                "--no-dashboard",
                "--scheduler-file",
                str(scheduler_file),
            ],
            **quiet,
        )
    ]
    try:
        for _ in range(100):
            if scheduler_file.is_file() and scheduler_file.stat().st_size:
                break
            time.sleep(0.1)
        address = json.loads(scheduler_file.read_text())["address"]
        for _ in range(2):
            processes.append(
                subprocess.Popen(
                    [*dask, "worker", address, "--nthreads", "1", "--no-dashboard", "--host", "127.0.0.1"], **quiet
                )
            )
        from distributed import Client

        with Client(address, timeout="30s") as client:
            client.wait_for_workers(2, timeout=60)
            assert len(client.scheduler_info()["workers"]) == 2
        remote = tmp_path / "remote"
        done = _batch(  # two vehicles of the local run, every flight: the same groups and trends
            fleet / "V01",
            fleet / "V02",
            "--mapping",
            fleet / "fleet.csv",
            "-o",
            remote,
            "--scheduler",
            address,
            "--no-group-reports",
            "--json",
            "-",
            "-q",
        )
        assert done.returncode == 0, done.stderr
        assert json.loads(done.stdout)["workers"] == 2 and json.loads(done.stdout)["cached"] == 0
        local, far = pd.read_parquet(out / "results.parquet"), pd.read_parquet(remote / "results.parquet")
        local = local[local["vehicle"].isin(["V01", "V02"])].reset_index(drop=True)
        assert len(far) == len(local) > 16 * 13
        pd.testing.assert_frame_equal(far, local)  # every value, bit for bit
    finally:
        for process in reversed(processes):
            process.send_signal(signal.SIGTERM)
        for process in processes:
            try:
                process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                process.kill()


def test_an_unreachable_scheduler_and_an_unknown_key_are_one_sentence(fleet: Path, tmp_path: Path) -> None:
    done = _batch(fleet / "V01", "-o", tmp_path / "a", "--scheduler", "tcp://127.0.0.1:1", "--json", "-")
    assert done.returncode == 1 and "Traceback" not in done.stderr
    assert "cannot reach the Dask scheduler at tcp://127.0.0.1:1" in done.stderr
    done = _batch(fleet / "V01", "-o", tmp_path / "b", "--group-by", "battery", "--workers", "1")
    assert done.returncode == 1 and "Traceback" not in done.stderr
    assert "cannot group by battery" in done.stderr
    done = _batch(tmp_path, "-o", tmp_path / "c")
    assert done.returncode == 2 and "no log (.ulg, .bin, .tlog) in" in done.stderr
    done = _batch(fleet / "V01", "-o", tmp_path / "d", "--workers", "2", "--scheduler", "tcp://127.0.0.1:1")
    assert done.returncode == 2 and "--workers sizes the local cluster" in done.stderr


@pytest.mark.long
@pytest.mark.timeout(1200)
def test_two_hundred_logs_in_one_command(tmp_path: Path) -> None:
    """The issue's campaign: 20 vehicles, 10 flights each, V03's motors wearing from its 5th flight, V12's 3rd log damaged."""
    plan = FleetPlan()
    files = write_fleet(tmp_path / "fleet", plan)
    assert len(files.logs) == 200
    out = tmp_path / "results"
    done = _batch(
        tmp_path / "fleet",
        "--mapping",
        files.mapping_csv,
        "-o",
        out,
        "--no-group-reports",
        "--json",
        "-",
        "-q",
        timeout=1100,
    )
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout)
    assert summary["logs"] == 200 and summary["fitted"] == 199
    assert [(f["what"], f["stage"]) for f in summary["failures"]] == [
        (str(tmp_path / "fleet" / "V12" / fleet_log_name(12, 3)), "read")
    ]
    flagged = [(d["vehicle"], d["parameter"], d["before"], d["after"]) for d in summary["drifts"] if d["confirmed"]]
    assert flagged == [("V03", "Z_thr", "V03 2024-06-06", "V03 2024-06-07")]
    # issue 33: every group fitted within the J_ave guideline (w/delta_lon in still air was 12 % of them over 100)
    table = pd.read_csv(out / "results.csv").drop_duplicates("group")
    fitted = table[table["error"].isna()]
    assert len(fitted) == 199 and fitted["cost_average"].max() <= 100.0, fitted.nlargest(3, "cost_average")


def test_each_log_is_compared_with_the_reference_as_sysid_discrepancy_compares_it(fleet: Path, tmp_path: Path) -> None:
    """``--against``: the table's discrepancy column is, log by log, what ``sysid discrepancy REF LOG`` finds."""
    out = tmp_path / "results"
    logs = [fleet / "V02" / fleet_log_name(2, 7)]
    reference = fleet / "V02" / fleet_log_name(2, 1)
    done = _batch(*logs, "-o", out, "--against", reference, "--group-by", "file", "--no-group-reports", "-q")
    assert done.returncode == 0, done.stderr
    table = pd.read_csv(out / "results.csv").drop_duplicates("group").set_index("group")
    for log in logs:
        alone = subprocess.run(
            [*_CLI, "discrepancy", str(reference), str(log), "--json", "-", "-q"],
            capture_output=True,
            text=True,
            check=True,
            env=os.environ | {"PYTHONWARNINGS": "ignore"},
        )
        found = json.loads(alone.stdout)
        effects = ", ".join(f["effect"] for f in found["findings"]) or "none"
        expected = f"{log.name}: {effects} (thrust scale {found['thrust_scale']:.3f})"
        assert table.loc[log.name, "discrepancy"] == expected


def test_a_group_with_wind_is_the_model_sysid_fit_makes_of_its_logs(tmp_path: Path) -> None:
    """The batch's fit is ``sysid fit``'s, wind step included: same logs, same options, same numbers."""
    from simulator.campaign.demo_flight import write_demo_flight

    files = write_demo_flight(tmp_path / "demo", seed=2)
    wind = ["--wind", str(files.wind_csv), "--wind-distance", "4.6", "--estimate-wind-offset", "--model", "hover-wind"]
    fleet_report = tmp_path / "fleet.html"
    done = _batch(files.log, *wind, "-o", tmp_path / "results", "--workers", "1", "--report", fleet_report, "-q")
    assert done.returncode == 0, done.stderr
    single = subprocess.run(
        [*_CLI, "fit", str(files.log), *wind, "-o", str(tmp_path / "model.json"), "-q"],
        capture_output=True,
        text=True,
        check=False,
        env=os.environ | {"PYTHONWARNINGS": "ignore"},
    )
    assert single.returncode == 0, single.stderr
    (folder,) = (tmp_path / "results" / "groups").iterdir()  # no board id: vehicle "unknown", the log's UTC day
    assert folder.name == "unknown_2024-05-01"
    batch_model = json.loads((folder / "model.json").read_text())["parameters"]
    fit_model = json.loads((tmp_path / "model.json").read_text())["parameters"]
    assert batch_model == fit_model
    assert batch_model["Z_w_lon"]["value"] == pytest.approx(0.8451, rel=0.05)  # Table 3.5, light wind
    # the group's own report beside its model, linked from the fleet report
    assert "hover-wind" in (folder / "report.html").read_text()
    assert 'href="results/groups/unknown_2024-05-01/report.html"' in fleet_report.read_text()


@pytest.mark.parametrize("when", ["starting", "running"])
def test_a_batch_interrupted_leaves_its_earlier_table_and_no_worker(fleet: Path, tmp_path: Path, when: str) -> None:
    """Ctrl-C while the local cluster starts (its first worker process just spawned) or while logs are fitted.

    SIGTERM takes the same path (tests/cli/test_interrupts.py). While the cluster started, ``distributed``'s
    exit handler used to print a traceback after the one line (a worker still starting cannot be closed).
    """
    signum, code, name = signal.SIGINT, 130, "SIGINT"
    out = tmp_path / "results"
    out.mkdir()
    (out / "results.csv").write_text("earlier run")
    process = subprocess.Popen(
        [*_CLI, "batch", str(fleet), "-o", str(out), "--workers", "2", "--no-group-reports", "-q"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=os.environ | {"PYTHONWARNINGS": "ignore"},
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),  # as from a shell
    )
    if when == "starting":
        deadline = time.monotonic() + 60
        while not _descendants(process.pid) and time.monotonic() < deadline:
            time.sleep(0.02)
    else:
        time.sleep(6)  # the cluster started, logs being read or fitted: 24 logs take 15 s or more
    assert process.poll() is None, "the batch ended before the signal"
    workers = _descendants(process.pid)
    assert len(workers) >= (1 if when == "starting" else 2)  # the local cluster's processes (and what they started)
    process.send_signal(signum)
    _, err = process.communicate(timeout=60)
    assert process.returncode == code and "Traceback" not in err, err
    assert [line for line in err.splitlines() if line.strip()] == [
        f"interrupted ({name}): no file was left half-written"
    ]
    assert (out / "results.csv").read_text() == "earlier run"  # the table of the earlier run, as it was
    assert not (out / "results.parquet").exists()
    time.sleep(1)
    assert [pid for pid in workers if Path(f"/proc/{pid}").exists() and _state(pid) != "Z"] == []  # none left


def _descendants(pid: int) -> list[int]:
    """Every process started by `pid`, and by those, ..."""
    found, todo = [], [pid]
    while todo:
        children = Path(f"/proc/{todo.pop()}/task")
        for task in children.iterdir() if children.exists() else ():
            listed = (task / "children").read_text().split() if (task / "children").exists() else []
            found += [int(c) for c in listed]
            todo += [int(c) for c in listed]
    return found


def _state(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return "Z"


def test_a_batch_that_fits_nothing_fails_and_says_so(tmp_path: Path, real_data: Path) -> None:
    """Issue 33: an ordinary flight (no sweep) fits no group: exit 1 in one red sentence pointing at the failures
    table, which names the group by its files; no green "drift: none flagged"; the fleet report may lie inside
    -o, a folder the batch creates."""
    log = real_data / "pyulog" / "sample.ulg"
    out = tmp_path / "results"
    done = _batch(log, "-o", out, "--report", out / "fleet.html", "--workers", "1", "--json", "-")
    assert done.returncode == 1, done.stderr
    summary = json.loads(done.stdout)
    assert (summary["groups"], summary["fitted"]) == (1, 0)
    (failure,) = summary["failures"]
    assert failure["stage"] == "fit" and failure["what"].endswith("(sample.ulg)")
    assert done.stderr.strip().splitlines()[-1] == (
        f"error: none of the 1 group(s) was fitted; why, log by log: {out / 'failures.csv'}"
    )
    assert "drift: none flagged" not in done.stderr and (out / "fleet.html").is_file()
    elsewhere = _batch(log, "-o", out, "--report", tmp_path / "nowhere" / "fleet.html", "--workers", "1")
    assert elsewhere.returncode == 2 and "is not inside the results folder" in elsewhere.stderr
