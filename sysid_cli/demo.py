"""``sysid demo``: simulate a flight test and run the workbench on it, ending with the HTML report."""

from __future__ import annotations

from pathlib import Path

import click

from ._common import OutputPath, SysidCommand

__all__ = ["demo"]

_EPILOG = """\b
Examples:
  sysid demo
  sysid demo -o /tmp/sysid-demo
  sysid demo --discrepancy -o /tmp/gap-demo
"""


def _verify_doublets(model_path: Path, dataset: Path, out: Path) -> str:
    """Verify the model (with and without G_w) on the dataset's doublets, save it, and say how it went.

    VERIFY's bias, reference shift and initial state are estimated together (the bare airframe is unstable
    open loop, so a measured initial state alone lets small errors grow); the records are cut as
    ``sysid validate`` cuts them by default.
    """
    from flightlogs.store.dataset import read_dataset
    from sysid.fit import read_model
    from sysid.verify import VerificationOptions, verification_provenance, verify_identified
    from sysid.verify.io import write_verification

    options = VerificationOptions(initial_state="estimated")
    flights = read_dataset(dataset).conditioned
    verification, _ = verify_identified(read_model(model_path), flights, options=options)
    saved = verification_provenance(options, sources=[dataset.name])
    write_verification(out, verification, model=model_path, options=saved)
    worst = max(verification.summary, key=lambda s: s.tic)
    text = (
        f"  {len(verification.records)} doublets, each judged on its axis' outputs: overall TIC "
        f"{verification.tic:.2f} (worst output {worst.name} {worst.tic:.3f}; ≤ 0.25-0.3 is good)"
    )
    table = {"ax": "−13 to −16 %", "az": "−7 to −15 %"}  # dissertation Table 3.6
    for c in verification.wind_correction:
        if c.name in table or abs(c.reduction_percent) >= 5:
            text += f"\n  G_w changes the RMS error of {c.name} by {-c.reduction_percent:+.0f} %"
            text += f" (Table 3.6: {table[c.name]})" if c.name in table else ""
    return text


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
@click.pass_context
def demo(ctx: click.Context, out_dir: Path, discrepancy: bool) -> None:
    """Simulate a sweep + doublet flight of the chapter 3 octocopter in light wind (with a ground
    anemometer 4.6 m upstream whose clock is 1.5 s fast), ingest it (align the wind, find the
    maneuvers), fit the hover-wind model to the sweeps, verify it on the doublets with and without
    its wind term, and write the HTML report. Prints where each file is; the report's path last."""
    from flightlogs.writers.atomic import folder_in_place

    out_dir.parent.mkdir(parents=True, exist_ok=True)
    with folder_in_place(out_dir):  # interrupted or failed: the folder as it was
        if discrepancy:
            _discrepancy_demo(ctx, out_dir)
        else:
            _demo(ctx, out_dir)


def _demo(ctx: click.Context, out_dir: Path) -> None:
    """The chapter 3 flight: simulate, ingest, fit, verify, report."""
    from simulator.campaign.demo_flight import write_demo_flight

    from .fit import fit
    from .ingest import ingest
    from .report import report

    click.echo(f"simulating the demo flight into {out_dir}/ ...")
    files = write_demo_flight(out_dir)
    click.echo(f"  log        {files.log}\n  anemometer {files.wind_csv}\n  truth      {files.truth}")
    dataset, ingest_json = out_dir / "dataset.h5", out_dir / "ingest.json"
    click.echo("ingesting (align wind, resample, segment) ...")
    ctx.invoke(
        ingest,
        logs=(files.log,),
        wind_paths=(files.wind_csv,),
        wind_distance=4.6,
        wind_offset=None,
        estimate_wind_offset=True,
        out=dataset,
        json_path=str(ingest_json),
        quiet=False,
        columns=None,
        wind_bearing=None,
        transport_delay=None,
        rate_hz=None,
        segments_file=None,
    )
    click.echo(f"dataset: {dataset}\nsummary: {ingest_json}")
    model_path, validation_path, page = out_dir / "model.json", out_dir / "validation.json", out_dir / "report.html"
    click.echo("identifying the hover-wind model from the sweeps (eq. 3.9, then the wind step of eq. 3.14) ...")
    ctx.invoke(
        fit,
        logs=(dataset,),
        model_name="hover-wind",
        initial={},
        constants={},
        out=model_path,
        json_path=str(out_dir / "fit.json"),
        quiet=False,
    )
    click.echo("verifying on the doublets, with and without the wind term ...")
    click.echo(_verify_doublets(model_path, dataset, validation_path))
    click.echo(f"verification: {validation_path}")
    ctx.invoke(
        report,
        model_path=model_path,
        validation_path=validation_path,
        out=page,
        ingest_path=ingest_json,
        title=None,
        json_path=None,
        quiet=False,
    )
    click.echo(f"report: {page.resolve()}")


def _discrepancy_demo(ctx: click.Context, out_dir: Path) -> None:
    """A SIM / REAL pair with a concealed 30 ms delay, discovered and reported."""
    from simulator.campaign.discrepancy_pairs import write_pairs

    from .discrepancy import discrepancy

    click.echo(f"simulating a flight and its 'real' twin into {out_dir}/ (about a minute) ...")
    sim, reals = write_pairs(["time_delay"], out_dir, seed=7)
    real = out_dir / "real.ulg"
    reals["time_delay"].replace(real)  # the file name must not tell
    click.echo(f"  simulation {sim}\n  flight     {real}")
    page = out_dir / "discrepancy.html"
    ctx.invoke(
        discrepancy,
        logs=(sim, real),
        real_logs=(),
        wind_paths=(),
        wind_distance=None,
        wind_offset=None,
        rotor_radius=None,
        out=out_dir / "discrepancy.json",
        report=page,
        json_path=None,
        quiet=False,
    )
    click.echo(f"report: {page.resolve()}")
