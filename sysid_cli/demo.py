"""``sysid demo``: simulate a flight test and run the workbench on it."""

from __future__ import annotations

from pathlib import Path

import click

__all__ = ["demo"]

_EPILOG = """\b
Examples:
  sysid demo
  sysid demo -o /tmp/sysid-demo
"""


@click.command(epilog=_EPILOG)
@click.option("-o", "--out", "out_dir", type=click.Path(file_okay=False, path_type=Path),
              default=Path("sysid-demo"), show_default=True, help="Folder for the demo's files.")
@click.pass_context
def demo(ctx: click.Context, out_dir: Path) -> None:
    """Simulate a sweep + doublet flight of the chapter 3 octocopter in light wind (with a
    ground anemometer 4.6 m upstream whose clock is 1.5 s fast), then ingest it: align the
    wind, find the maneuvers and write the dataset. Prints where each file is."""
    from sysid.sim.scenarios import write_demo_flight

    from .ingest import ingest

    click.echo(f"simulating the demo flight into {out_dir}/ ...")
    files = write_demo_flight(out_dir)
    click.echo(f"  log        {files.log}\n  anemometer {files.wind_csv}\n  truth      {files.truth}")
    dataset = out_dir / "dataset.h5"
    click.echo("ingesting (align wind, resample, segment) ...")
    ctx.invoke(ingest, logs=(files.log,), wind_paths=(files.wind_csv,), wind_distance=4.6, wind_offset=None,
               estimate_wind_offset=True, out=dataset, json_path=str(out_dir / "ingest.json"), quiet=False,
               columns=None, wind_bearing=None, transport_delay=None, rate_hz=None, segments_file=None)
    click.echo(f"dataset: {dataset}\nsummary: {out_dir / 'ingest.json'}")
    click.echo("(identification, validation and the HTML report join the demo as they are built)")
