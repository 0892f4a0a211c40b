"""``sysid demo``: simulate a flight test and run the workbench on it, ending with the HTML report."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import click

from ._common import OutputPath, SysidCommand, staged_progress
from ._tables import print_discrepancy, print_fit, print_ingest

if TYPE_CHECKING:  # the library is imported when the command runs: `sysid --help` stays fast
    from sysid.verify import Verification

__all__ = ["demo"]

_EPILOG = """\b
Examples:
  sysid demo
  sysid demo -o /tmp/sysid-demo
  sysid demo --discrepancy -o /tmp/gap-demo
"""


def _wind_lines(verification: Verification) -> str:
    """How much G_w changes each output's RMS error, beside the dissertation's Table 3.6."""
    table = {"ax": "−13 to −16 %", "az": "−7 to −15 %"}  # dissertation Table 3.6
    lines = ""
    for c in verification.wind_correction:
        if c.name in table or abs(c.reduction_percent) >= 5:
            lines += f"\n  G_w changes the RMS error of {c.name} by {-c.reduction_percent:+.0f} %"
            lines += f" (Table 3.6: {table[c.name]})" if c.name in table else ""
    return lines


@click.command(cls=SysidCommand, epilog=_EPILOG)
@click.option(
    "-o",
    "--out",
    "out_dir",
    type=OutputPath(folder=True),
    default=Path("sysid-demo"),
    show_default=True,
    help="Folder for the demo's files.",
)
@click.option(
    "--discrepancy",
    is_flag=True,
    help="Instead: simulate a flight and a 'real' one whose motors respond 30 ms later (nothing says so), "
    "run `sysid discrepancy` on them and write its report.",
)
@click.option("-q", "--quiet", is_flag=True, help="No progress bar.")
def demo(out_dir: Path, discrepancy: bool, quiet: bool) -> None:
    """Simulate a sweep + doublet flight of the chapter 3 octocopter in light wind (with a ground
    anemometer 4.6 m upstream whose clock is 1.5 s fast), ingest it (align the wind, find the
    maneuvers), fit the hover-wind model to the sweeps, verify it on the doublets with and without
    its wind term, and write the HTML report. Prints where each file is; the report's path last."""
    from flightlogs.writers.atomic import folder_in_place

    out_dir.parent.mkdir(parents=True, exist_ok=True)
    with folder_in_place(out_dir):  # interrupted or failed: the folder as it was
        if discrepancy:
            _discrepancy_demo(out_dir, quiet)
        else:
            _demo(out_dir, quiet)


def _demo(out_dir: Path, quiet: bool) -> None:
    """The chapter 3 flight: simulate, ingest, fit, verify, report; then each step's table."""
    from reports.demo import run_demo
    from sysid.fit import fit_summary

    with staged_progress("demo", quiet=quiet) as progress:
        run = run_demo(out_dir, progress=progress)
    flight = run.flight
    click.echo(f"simulated the demo flight into {out_dir}/\n  log        {flight.log}\n  anemometer {flight.wind_csv}")
    click.echo(f"  truth      {flight.truth}\ningested (wind aligned, resampled, maneuvers found):")
    print_ingest(run.ingest_summary)
    click.echo("identified the hover-wind model from the sweeps (eq. 3.9, then the wind step of eq. 3.14):")
    print_fit(fit_summary(run.model), run.model.guidelines)
    worst = max(run.verification.summary, key=lambda s: s.tic)
    click.echo(
        f"verified on the doublets, with and without the wind term:\n  {len(run.verification.records)} doublets, "
        f"each judged on its axis' outputs: overall TIC {run.verification.tic:.2f} (worst output {worst.name} "
        f"{worst.tic:.3f}; ≤ 0.25-0.3 is good)" + _wind_lines(run.verification)
    )
    for path in (run.ingest_json, run.model_path, run.fit_json, run.validation_path):
        click.echo(f"wrote {path}")
    click.echo(f"{run.verdict.sentence}\nreport: {run.report.resolve()}")


def _discrepancy_demo(out_dir: Path, quiet: bool) -> None:
    """A SIM / REAL pair with a concealed 30 ms delay, discovered and reported."""
    from reports.demo import run_discrepancy_demo

    click.echo(f"simulating a flight and its 'real' twin into {out_dir}/ (about a minute) ...")
    with staged_progress("discrepancy", quiet=quiet) as progress:
        run = run_discrepancy_demo(out_dir, progress=progress)
    click.echo(f"  simulation {run.simulation}\n  flight     {run.real}")
    print_discrepancy(run.result)
    click.echo(f"wrote {run.summary_json}\nreport: {run.report.resolve()}")
