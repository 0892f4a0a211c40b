"""``sysid mrac``: the altitude loop near the ground, PID against PID + MRAC (chapter 2, section 2.5)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from ._common import LibraryDefault, OutputPath, SysidCommand, emit_json, json_option, progress_bar

__all__ = ["mrac"]

_GROUP_EPILOG = """\b
Examples:
  sysid mrac compare --height-ratio 4 --trials 3 --report mrac.html --json -
  sysid mrac compare --height-ratio 4,3,2,22 -o results.json
  sysid mrac compare --ground-effect ge-model.json --report fitted.html
"""

_COMPARE_EPILOG = """\b
Examples:
  sysid mrac compare --height-ratio 4 --trials 3 --report mrac.html --json -
  sysid mrac compare --height-ratio 4,3,2 --height-ratio 22 -o results.json
  sysid mrac compare --ground-effect ge-model.json --report fitted.html   (a model from 'sysid ground-effect fit -o')

\b
JSON: controllers.{pid,mrac_linear,mrac_rbf}.{rise_time_s, steady_state_error_m,
mse_m2, overshoot_percent, settling_time_s}.{mean,std,n} over every case, phase and
trial; cases[].phases.{takeoff,landing} the same per case, with rise_time_over_pid
and mse_rbf_over_linear. -o adds every trial's indices.
"""


def _ratios(_ctx: click.Context, _param: click.Parameter, value: tuple[str, ...]) -> tuple[float, ...]:
    if not value:
        return (4.0, 3.0, 2.0)
    ratios: list[float] = []
    for item in value:
        for part in item.split(","):
            try:
                ratio = float(part)
            except ValueError:
                raise click.BadParameter(f"{part!r} is not a number (give Z/R like 4 or a list like 4,3,2)") from None
            if not ratio > 0:
                raise click.BadParameter(f"Z/R = {part} must be > 0")
            ratios.append(ratio)
    return tuple(ratios)


@click.group(epilog=_GROUP_EPILOG)
def mrac() -> None:
    """Model reference adaptive control of the altitude near the ground (chapter 2, eqs. 2.15-2.26)."""


@mrac.command(cls=SysidCommand, epilog=_COMPARE_EPILOG)
@click.option(
    "--height-ratio",
    "height_ratios",
    multiple=True,
    callback=_ratios,
    metavar="Z/R[,Z/R...]",
    help="Case(s): Z/R of the rotors at the top of the take-off in ground effect, at the hover "
    "height out of it (from 10 up: a 6.2 cm step). Repeatable. [default: 4,3,2]",
)
@click.option(
    "--trials",
    type=click.IntRange(min=1),
    cls=LibraryDefault,
    default_from=("simulator.mrac.compare", "CompareConfig", "trials"),
    show_default=True,
    help="Trials per case and controller (they differ by the noise seed).",
)
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the trials' noise seeds.")
@click.option(
    "--pid-phase",
    type=click.FloatRange(min=2.0),
    cls=LibraryDefault,
    default_from=("simulator.mrac.compare", "CompareConfig", "pid_phase_s"),
    show_default=True,
    metavar="S",
    help="Length of the PID's take-off and of its landing, s.",
)
@click.option(
    "--mrac-phase",
    type=click.FloatRange(min=2.0),
    cls=LibraryDefault,
    default_from=("simulator.mrac.compare", "CompareConfig", "mrac_phase_s"),
    show_default=True,
    metavar="S",
    help="Length of each MRAC phase, s.",
)
@click.option(
    "--ground-effect",
    "ground_effect_path",
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    help="A fitted ground-effect model (JSON from 'sysid ground-effect fit -o') acting on the vehicle "
    "instead of eq. 2.5.",
)
@click.option("--report", "report_path", type=OutputPath(), help="Write the HTML report here.")
@click.option(
    "-o",
    "--out",
    "out_path",
    type=OutputPath(),
    help="Write the results (summary and every trial's indices) as JSON here.",
)
@json_option
@click.option("-q", "--quiet", is_flag=True, help="No progress bar and no summary.")
def compare(
    height_ratios: tuple[float, ...],
    trials: int,
    seed: int,
    pid_phase: float,
    mrac_phase: float,
    ground_effect_path: Path | None,
    report_path: Path | None,
    out_path: Path | None,
    json_path: str | None,
    quiet: bool,
) -> None:
    """Fly take-off and landing steps with PID, MRAC (linear) and MRAC (RBF) in the simulator with ground
    effect, and report rise time, steady-state error, MSE to the reference model, overshoot and settling
    time (Tables 2.6-2.8)."""
    from simulator.mrac import CompareConfig, compare_controllers, comparison_json

    law, label = None, None
    if ground_effect_path is not None:
        from sysid.groundeffect import read_ground_effect_model

        law = read_ground_effect_model(ground_effect_path)
        label = f"{law.model} fitted to {law.source or ground_effect_path.name} ({ground_effect_path.name})"
    config = CompareConfig(
        height_ratios=height_ratios, trials=trials, seed=seed, pid_phase_s=pid_phase, mrac_phase_s=mrac_phase
    )
    with progress_bar("flying", quiet=quiet) as bar:
        comparison = compare_controllers(config, ground_effect=law, ground_effect_label=label, progress=bar)
    if out_path is not None:
        from flightlogs.writers.jsonio import write_json

        write_json(out_path, comparison_json(comparison, per_trial=True), indent=2)  # written atomically
    if report_path is not None:
        from reports.mrac_report import write_mrac_report

        write_mrac_report(report_path, comparison)
    summary = comparison_json(comparison)
    if not quiet:
        _echo(summary)
    emit_json(summary, json_path)


def _echo(summary: dict[str, Any]) -> None:
    """Rise times per case and phase, and the MRAC/PID ratios."""
    for case in summary["cases"]:
        for phase, entry in case["phases"].items():
            rises = ", ".join(
                f"{name} {s['rise_time_s']['mean']:.2f} s" if s["rise_time_s"]["n"] else f"{name} —"
                for name, s in entry["controllers"].items()
            )
            ratios = entry.get("rise_time_over_pid", {})
            extra = (
                "; rise/PID " + ", ".join(f"{n} {r:.2f}" if r == r else f"{n} —" for n, r in ratios.items())
                if ratios
                else ""
            )
            click.echo(f"Z/R {case['height_ratio']:g} {phase}: rise {rises}{extra}")
