"""``sysid modes``: eigenvalues, damping, frequency and time to double/half of a model."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from ._common import SysidCommand, emit_json, json_option
from ._tables import print_modes
from .fit import parse_assignments

__all__ = ["modes"]

_EPILOG = """\b
Examples:
  sysid modes model.json
  sysid modes --model hover --set X_u=-0.3172 --set M_u=0.769 --set Y_v=-0.2787 --set L_v=-0.7406 --json -
"""


@click.command(cls=SysidCommand, epilog=_EPILOG)
@click.argument("model_file", required=False, type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option(
    "--model",
    "structure_name",
    metavar="NAME|FILE",
    help="A structure (built-in name or TOML file) to take the modes of, with --set values.",
)
@click.option(
    "--set",
    "values",
    multiple=True,
    callback=parse_assignments,
    metavar="NAME=VALUE",
    help="Parameter value (repeatable); parameters not set are taken as dropped (0).",
)
@click.option(
    "--trim",
    "constants",
    multiple=True,
    callback=parse_assignments,
    metavar="NAME=VALUE",
    help="Trim constant, e.g. U0=2.24 (default zero trim, g = 9.81).",
)
@json_option
@click.option("-q", "--quiet", is_flag=True, help="No table.")
def modes(
    model_file: Path | None,
    structure_name: str | None,
    values: dict[str, float],
    constants: dict[str, float],
    json_path: str | None,
    quiet: bool,
) -> None:
    """Modes of MODEL_FILE (from ``sysid fit -o``), or of a structure with published parameter values:
    eigenvalues, damping, natural frequency, time to double or half, and which motion each belongs to."""
    from sysid.fit import mode_summary, read_model
    from sysid.model import load_structure, structure_model
    from sysid.model.modes import modes as find_modes

    if (model_file is None) == (structure_name is None):
        raise click.UsageError("give either MODEL_FILE or --model NAME with --set values")
    unset: tuple[str, ...] = ()
    unidentified: list[str] = []
    if model_file is not None:
        if values or constants:
            raise click.UsageError("--set and --trim go with --model, not with a model file")
        identified = read_model(model_file)
        linear = identified.linear_model()
        unidentified = [a.axis for a in identified.unidentified_axes]
        source = str(model_file)
    else:
        assert structure_name is not None
        linear, unset = structure_model(load_structure(structure_name), values, constants=constants)
        source = structure_name
    summary: dict[str, Any] = {
        "model": source,
        "eigenvalues": mode_summary(find_modes(linear)),
        "unset": list(unset),
        "unidentified_axes": unidentified,
    }
    if not quiet:
        click.echo(f"modes of {source}" + (f" (not set, taken as dropped: {', '.join(unset)})" if unset else ""))
        if unidentified:
            click.echo(
                f"  the {', '.join(unidentified)} axes are unidentified: their modes are not known and not listed"
            )
        print_modes(summary["eigenvalues"], click.echo)
    emit_json(summary, json_path)
