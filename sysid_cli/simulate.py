"""``sysid simulate``: fly a scenario in the simulator and write real-format logs."""

from __future__ import annotations

from pathlib import Path

import click

from flightlogs.writers.atomic import atomic_folder

from ._common import OutputPath, SysidCommand, emit_json, json_option, progress_bar

__all__ = ["simulate"]

_EPILOG = """\b
Examples:
  sysid simulate --list
  sysid simulate chapter3-campaign -o campaign/
  sysid simulate my-scenario.toml -o out/ --trials 0-3 --json -
"""


def _trial_range(_ctx: click.Context, _param: click.Parameter, value: str | None) -> list[int] | None:
    if not value:
        return None
    picked: list[int] = []
    for part in value.split(","):
        first, sep, last = part.partition("-")
        try:
            low, high = (int(first), int(last)) if sep else (int(first), int(first))
        except ValueError:
            raise click.BadParameter(f"{part!r} is not a trial number or range like 0-3") from None
        if low > high:
            raise click.BadParameter(f"{part!r} is a reversed range: write {high}-{low}")
        picked.extend(range(low, high + 1))
    return picked


def _check_trials(trials: list[int] | None, n_trials: int, name: str) -> None:
    """Usage error unless every picked trial index is one of the scenario's (0 to n_trials - 1)."""
    outside = sorted({t for t in trials or [] if not 0 <= t < n_trials})
    if outside:
        valid = "0" if n_trials == 1 else f"0-{n_trials - 1}"
        raise click.BadParameter(
            f"{', '.join(map(str, outside))}: scenario {name} has trials {valid} only", param_hint="--trials"
        )


@click.command(cls=SysidCommand, epilog=_EPILOG)
@click.argument("scenario", required=False)
@click.option(
    "-o",
    "--out",
    "out_dir",
    type=OutputPath(folder=True),
    default=None,
    help="Folder for the logs, anemometer files, truth and campaign.json (default: the scenario name).",
)
@click.option("--list", "list_only", is_flag=True, help="List the built-in scenarios and exit.")
@click.option(
    "--trials", callback=_trial_range, help="Only these trials, e.g. 0-3,7 (numbered from 0, as `--json` lists them)."
)
@json_option
@click.option("-q", "--quiet", is_flag=True, help="No progress bar and no summary.")
def simulate(
    scenario: str | None,
    out_dir: Path | None,
    list_only: bool,
    trials: list[int] | None,
    json_path: str | None,
    quiet: bool,
) -> None:
    """Fly SCENARIO (a built-in name or a TOML file) and write each trial's logs (ArduPilot .bin,
    PX4 .ulg), the ground anemometer's CSV and a truth JSON."""
    from simulator.campaign.fly import run_scenario
    from simulator.campaign.scenario import builtin_scenarios, load_builtin, read_scenario

    if list_only:
        listed = {name: read_scenario(path).description for name, path in sorted(builtin_scenarios().items())}
        for name, description in listed.items():
            click.echo(f"{name:<24} {description}")
        emit_json({"scenarios": [{"name": n, "description": d} for n, d in listed.items()]}, json_path)
        return
    if scenario is None:
        raise click.UsageError("give a SCENARIO (a built-in name or a .toml file), or --list")
    plan = read_scenario(scenario) if scenario.endswith(".toml") else load_builtin(scenario)
    _check_trials(trials, plan.n_trials, plan.name)
    folder = out_dir if out_dir is not None else Path(plan.name)
    with progress_bar(f"simulating {plan.name}", quiet=quiet) as bar, atomic_folder(folder) as tmp:
        written = run_scenario(plan, tmp, progress=bar, trials=trials)  # the folder appears once complete
    summary = {
        "scenario": plan.name,
        "out": str(folder),
        "trials": [
            {
                "name": t.plan.name,
                "logs": [str(folder / p.name) for p in t.logs],
                "anemometer": str(folder / t.wind_csv.name) if t.wind_csv else None,
                "truth": str(folder / t.truth.name),
            }
            for t in written
        ],
    }
    if not quiet:
        click.echo(f"{plan.name}: {len(written)} trials written to {folder}/ (index: {folder / 'campaign.json'})")
    emit_json(summary, json_path)
