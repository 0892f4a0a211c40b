"""``sysid report``: rebuild the HTML model report from a model file and, optionally, a saved verification."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import click

from ._common import OutputPath, SysidCommand, emit_json, json_option

__all__ = ["report"]

_EPILOG = """\b
Examples:
  sysid report model.json -o model.html
  sysid report model.json validation.json -o report.html
  sysid report model.json validation.json --ingest-summary ingest.json -o report.html --json -
"""


def _read_json(path: Path) -> Any:
    from flightlogs.errors import DataError

    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise DataError(f"{path}: cannot read it as JSON ({err})") from None


@click.command(cls=SysidCommand, epilog=_EPILOG)
@click.argument("model_path", metavar="MODEL.json", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.argument(
    "validation_path",
    metavar="[VALIDATION.json]",
    required=False,
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
)
@click.option("-o", "--out", type=OutputPath(), help="HTML report to write (default: MODEL with .html).")
@click.option(
    "--ingest-summary",
    "ingest_path",
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    help="What 'sysid ingest --json' wrote: adds the vehicle, the flight and the wind alignment.",
)
@click.option("--title", help="Page title (default: 'Identified model: STRUCTURE').")
@json_option
@click.option("-q", "--quiet", is_flag=True, help="Print nothing but errors.")
def report(
    model_path: Path,
    validation_path: Path | None,
    out: Path | None,
    ingest_path: Path | None,
    title: str | None,
    json_path: str | None,
    quiet: bool,
) -> None:
    """Write the HTML report of MODEL.json (as 'sysid fit --report' does): verdict, responses with the model,
    parameters, costs, correlations, modes; with VALIDATION.json (a saved verification, as 'sysid validate -o'
    and 'sysid demo' write), also the doublets predicted with and without the wind term. One self-contained file."""
    from reports.html import write_html
    from reports.ingest_card import ingest_card
    from reports.model_report import model_report_html
    from sysid.fit import model_verdict, read_model
    from sysid.verify.io import read_verification, require_verified_model

    model = read_model(model_path)
    saved = read_verification(validation_path) if validation_path is not None else None
    if saved is not None:
        require_verified_model(saved, model_path, source=str(validation_path))
    card = ingest_card(_read_json(ingest_path), source=str(ingest_path)) if ingest_path is not None else None
    verification = saved.verification if saved is not None else None
    verdict = model_verdict(model, verification)  # by the guidelines the model was fitted with
    text = model_report_html(
        model,
        verification=verification,
        title=title,
        logs_summary=card,
        verification_options=saved.options if saved is not None else None,
        verdict=verdict,
    )
    target = write_html(out if out is not None else model_path.with_suffix(".html"), text)
    if not quiet:
        click.echo(verdict.sentence)
        click.echo(f"wrote {target}")
    emit_json(
        {
            "report": str(target),
            "model": str(model_path),
            "verification": str(validation_path) if validation_path is not None else None,
            "verdict": verdict.grade,
            "sentence": verdict.sentence,
        },
        json_path,
    )
