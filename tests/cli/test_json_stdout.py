"""``--json -`` on every command: stdout holds the JSON document alone, every human line goes to stderr.

The mechanism is :func:`sysid_cli._common.json_owns_stdout`, run by :class:`sysid_cli._common.SysidCommand`
around every command; the table below runs each command (and subcommand) that takes ``--json`` once, on
small inputs, and a test walks the command group so that a new command cannot be left out of the table.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import click
import numpy as np
import pytest
from click.testing import CliRunner

from simulator.campaign.fly import run_scenario
from simulator.campaign.scenario import read_scenario
from sysid.fit import write_model
from sysid.groundeffect import formulas as laws
from sysid_cli._common import SysidCommand
from sysid_cli.main import cli

import builders

#: A short flight of each kind: a pitch doublet (12 s) and the shortest pitch sweep the sweep test accepts.
SCENARIO = """\
[scenario]
description = "a short pitch doublet and a short pitch sweep"
vehicle = "linear-octo"
formats = ["ulog"]
trials = 1
seed = 7
margin_s = 5.0
[[condition]]
name = "breeze"
mean_speed_m_s = 1.0
turbulence_ratio = 0.2
[[maneuver]]
axis = "lon"
kind = "doublet"
amplitude = 15.0
duration_s = 2.0
[[maneuver]]
axis = "lon"
kind = "sweep"
amplitude = 8.0
duration_s = 18.0
f_start_hz = 0.3
f_stop_hz = 6.0
fade_in_s = 1.0
"""

R = 0.0225  # m: the Crazyflie's rotor radius
HEIGHTS_CM = np.arange(2.5, 20.51, 1.0)

#: Every command that takes ``--json``, on the inputs of :func:`inputs` (``{name}``), split at spaces and then
#: filled in; outputs go to the working folder. None is quiet: each has human lines, which must not reach stdout.
CASES: dict[str, str] = {
    "ingest": "ingest {doublet} -o dataset.h5",
    "freqresp": "freqresp {sweep} --pairs q/delta_lon -o responses.h5",
    "fit": "fit {sweep} --partial -o model.json",
    "validate": "validate {model} {doublet} -o validation.json",
    "modes": "modes {model}",
    "modes --model": "modes --model hover",
    "report": "report {model} -o report.html",
    "simulate": "simulate {scenario} --trials 0 -o flights",
    "simulate --list": "simulate --list",
    "ground-effect fit": f"ground-effect fit {{rig}} --rotor-radius {R} -o ge.json",
    "ground-effect spacing": f"ground-effect spacing {{rig}} {{rig_spaced}} --spacing 0,10 --rotor-radius {R}",
    "mrac compare": "mrac compare --height-ratio 3 --trials 1 --pid-phase 2 --mrac-phase 2",
    "discrepancy": "discrepancy {doublet} {sweep} -o findings.json",  # printed "verdict: ..." before the JSON
    "batch": "batch {sweep} -o batch --workers 1 --group-by file --no-group-reports --partial",
}


def _rig_csv(path: Path, ratio: np.ndarray) -> Path:
    """A thrust stand's file, one reading a height: F/F0 = `ratio` at F0 = 0.374 N, in cm and grams of force."""
    thrust_g = 0.374 * ratio / 9.80665e-3
    path.write_text("height_cm,thrust_g\n" + "".join(f"{h:.1f},{f:.4f}\n" for h, f in zip(HEIGHTS_CM, thrust_g)))
    return path


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The two short flights, their scenario, a small model (no fit) and two thrust-stand files."""
    folder = tmp_path_factory.mktemp("json-stdout")
    scenario = folder / "short.toml"
    scenario.write_text(SCENARIO)
    doublet, sweep = (trial.logs[0] for trial in run_scenario(read_scenario(scenario), folder / "flights"))
    model = write_model(folder / "model.json", builders.small_model(responses=False))
    x = HEIGHTS_CM / 100 / R
    eq_2_5 = laws.piecewise_linear(
        x, laws.FITTED_4ROTOR_SLOPE, laws.FITTED_4ROTOR_INTERCEPT, laws.FITTED_4ROTOR_BREAKPOINT
    )
    return {
        "doublet": doublet,
        "sweep": sweep,
        "scenario": scenario,
        "model": model,
        "rig": _rig_csv(folder / "rig_0mm.csv", eq_2_5),
        "rig_spaced": _rig_csv(folder / "rig_10mm.csv", laws.corrected(x, 3.0)),
    }


_CLI = [sys.executable, "-c", "from sysid_cli.main import cli; cli()"]
#: Run as a user runs them, in a process of their own: a local Dask cluster, when another one (tests/cli/test_batch.py)
#: holds port 8787, warns and leaves a socket open, which this suite's warning filters would turn into errors.
_OWN_PROCESS = {"batch"}


def _run(args: list[str], folder: Path, *, own_process: bool) -> tuple[int, str, str]:
    """Exit code, stdout and stderr of ``sysid ARGS`` run in `folder`."""
    if own_process:
        env = os.environ | {"PYTHONWARNINGS": "ignore"}
        done = subprocess.run([*_CLI, *args], capture_output=True, text=True, cwd=folder, env=env, timeout=300)
        return done.returncode, done.stdout, done.stderr
    result = CliRunner().invoke(cli, args)
    return result.exit_code, result.stdout, result.stderr


@pytest.mark.parametrize("name", list(CASES))
def test_json_to_stdout_is_the_json_alone(
    inputs: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str
) -> None:
    monkeypatch.chdir(tmp_path)
    args = [arg.format(**inputs) for arg in CASES[name].split()]
    code, stdout, stderr = _run([*args, "--json", "-"], tmp_path, own_process=name in _OWN_PROCESS)
    assert code == 0, stdout + stderr
    assert isinstance(json.loads(stdout), dict), stdout  # one document, nothing before or after it
    assert stderr.strip()  # the human lines are still shown, on stderr


def test_a_command_in_its_own_process_writes_only_json_on_its_stdout(tmp_path: Path) -> None:
    """The real streams rather than click's runner: ``sysid modes --model hover --json - | jq`` works."""
    code, stdout, stderr = _run(["modes", "--model", "hover", "--json", "-"], tmp_path, own_process=True)
    assert code == 0, stderr
    assert json.loads(stdout)["model"] == "hover"
    assert stderr.startswith("modes of hover")


@pytest.mark.parametrize("own_process", [False, True])
@pytest.mark.parametrize("command", ["ingest", "fit", "validate", "discrepancy"])
def test_a_failure_with_json_to_stdout_is_json_too(tmp_path: Path, command: str, own_process: bool) -> None:
    """Issue 33: ``--json -`` that fails prints ``{"error": ..., "exit_code": 1}`` on stdout (the sentence it
    prints on stderr), so a pipe into jq reads why; without ``--json -`` stdout stays empty."""
    bad = tmp_path / "bad.ulg"
    bad.write_bytes(b"not a log at all")
    args = {"discrepancy": [command, str(bad), str(bad)], "validate": [command, str(bad), str(bad)]}.get(
        command, [command, str(bad)]
    )
    code, stdout, stderr = _run([*args, "--json", "-"], tmp_path, own_process=own_process)
    assert code == 1
    sentence = stderr.strip().splitlines()[-1]
    assert sentence.startswith("error: ") and "bad.ulg" in sentence
    assert json.loads(stdout) == {"error": sentence.removeprefix("error: "), "exit_code": 1}
    code, stdout, _ = _run(args, tmp_path, own_process=own_process)
    assert code == 1 and stdout == ""


def _json_commands(group: click.Group, ctx: click.Context, prefix: tuple[str, ...] = ()) -> dict[str, click.Command]:
    """Every command under `group`, groups walked into, that has a ``--json`` option: by its path."""
    found: dict[str, click.Command] = {}
    for name in group.list_commands(ctx):
        command = group.get_command(ctx, name)
        assert command is not None, name
        if isinstance(command, click.Group):
            found |= _json_commands(command, click.Context(command, parent=ctx, info_name=name), (*prefix, name))
        elif any("--json" in param.opts for param in command.params):
            found[" ".join((*prefix, name))] = command
    return found


def test_every_command_with_json_is_in_the_table_and_owns_stdout_through_sysid_command() -> None:
    commands = _json_commands(cli, click.Context(cli, info_name="sysid"))
    assert {"discrepancy", "ground-effect fit", "mrac compare"} <= set(commands)  # the walk reaches subcommands
    missing = [p for p in commands if not any(f"{args} ".startswith(f"{p} ") for args in CASES.values())]
    assert not missing, f"add {missing} to CASES"
    plain = sorted(path for path, command in commands.items() if not isinstance(command, SysidCommand))
    assert not plain, f"{plain}: give cls=SysidCommand, which sends the human lines to stderr with --json -"
