"""``sysid demo``: the built-in end-to-end run (placeholder until the simulator lands)."""

from __future__ import annotations

from pathlib import Path

import click

__all__ = ["demo"]


@click.command()
@click.option(
    "-o", "--out", "out_dir", type=click.Path(file_okay=False, path_type=Path),
    default=Path("sysid-demo"), show_default=True, help="Folder for the demo's files.",
)
def demo(out_dir: Path) -> None:
    """Run the built-in demonstration."""
    raise click.ClickException("demo not built yet")
