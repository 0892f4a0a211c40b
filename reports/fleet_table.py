"""The batch's results table: a row per group and parameter, as Parquet (pandas + pyarrow) and CSV.

Columns: ``group, vehicle, date, logs, parameter, value, cramer_rao_percent,
insensitivity_percent, status, unit, cost_average, tic, modes, discrepancy,
drift``. An unidentified parameter has no value (empty, NaN), never a
number; ``tic`` is empty for a group without doublets (not verified). A group
that could not be fitted has one row, its parameter empty and its reason in
``error``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from flightlogs.writers.atomic import atomic_output
from sysid.batch import BatchResult

__all__ = ["COLUMNS", "results_table", "failures_table", "write_tables"]

COLUMNS = (
    "group",
    "vehicle",
    "date",
    "logs",
    "parameter",
    "value",
    "cramer_rao_percent",
    "insensitivity_percent",
    "status",
    "unit",
    "cost_average",
    "tic",
    "modes",
    "discrepancy",
    "drift",
    "error",
)


def results_table(result: BatchResult) -> Any:
    """A ``pandas.DataFrame`` with a row per group and parameter (:data:`COLUMNS`).

    Parameters
    ----------
    result : BatchResult
        The batch.

    Returns
    -------
    pandas.DataFrame
    """
    import pandas as pd

    verdicts = {
        c.path: f"{', '.join(c.effects) or 'none'} (thrust scale {c.thrust_scale:.3f})"
        if c.error is None
        else f"not compared: {c.error}"
        for c in result.comparisons
    }
    drifts = {(d.vehicle, d.parameter, d.after): d for d in result.drifts}
    rows = []
    for g in result.groups:
        head = {
            "group": g.key,
            "vehicle": g.vehicle,
            "date": g.date,
            "logs": len(g.logs),
            "cost_average": g.cost_average,
            "tic": math.nan if g.tic is None else g.tic,
            "modes": g.modes,
            "discrepancy": "; ".join(f"{Path(p).name}: {verdicts[p]}" for p in g.logs if p in verdicts),
            "error": g.error or "",
        }
        if g.error is not None:
            rows.append(head | {"parameter": "", "status": "", "unit": "", "drift": ""})
            continue
        for p in g.parameters:
            drift = drifts.get((g.vehicle, p.name, g.key))
            rows.append(
                head
                | {
                    "parameter": p.name,
                    "value": p.value,
                    "cramer_rao_percent": p.cr_percent,
                    "insensitivity_percent": p.insensitivity_percent,
                    "status": p.status,
                    "unit": p.unit,
                    "drift": "" if drift is None else drift.sentence,
                }
            )
    frame = pd.DataFrame(rows, columns=list(COLUMNS))
    return frame.astype({"value": float, "cramer_rao_percent": float, "insensitivity_percent": float})


def failures_table(result: BatchResult) -> Any:
    """A ``pandas.DataFrame`` of the logs and groups the batch went on without: ``what, stage, reason``.

    Parameters
    ----------
    result : BatchResult
        The batch.
    """
    import pandas as pd

    return pd.DataFrame([(f.what, f.stage, f.reason) for f in result.failures], columns=["what", "stage", "reason"])


def write_tables(folder: str | Path, result: BatchResult) -> tuple[Path, Path, Path]:
    """Write ``results.parquet``, ``results.csv`` and ``failures.csv`` into `folder`, each atomically.

    Parameters
    ----------
    folder : str or Path
        The results folder (it exists).
    result : BatchResult
        The batch.

    Returns
    -------
    tuple of Path
        The three files.
    """
    folder = Path(folder)
    table, failures = results_table(result), failures_table(result)
    paths = (folder / "results.parquet", folder / "results.csv", folder / "failures.csv")
    with atomic_output(paths[0]) as tmp:
        table.to_parquet(tmp, index=False, engine="pyarrow")
    with atomic_output(paths[1]) as tmp:
        table.to_csv(tmp, index=False)
    with atomic_output(paths[2]) as tmp:
        failures.to_csv(tmp, index=False)
    return paths
