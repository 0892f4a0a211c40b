"""A batch on Dask: survey every log, group them, fit and verify each group, compare with a reference, trend.

The driver sends paths and options and gets small results back
(:mod:`sysid.batch.results`); the workers read the logs. Work is spread by
``dask.distributed`` over whatever cluster the client is connected to: the
local one of :func:`~sysid.batch.cluster.batch_client`, or a scheduler
the user runs. A task that raises (a worker lost, a bug) is one failure
with its reason; the batch goes on.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from sysid.batch.drift import DriftOptions, find_drifts
from sysid.batch.groups import check_keys, group_logs
from sysid.batch.results import BatchResult, GroupFit, LogComparison, LogSurvey
from sysid.batch.tasks import BatchSettings, GroupReport, compare_log, fit_group, survey_log

__all__ = ["run_batch"]

Progress = Callable[[str, int, int], None]


def run_batch(
    logs: Sequence[str | Path],
    settings: BatchSettings,
    results: str | Path,
    client: Any,
    *,
    by: Sequence[str] = ("vehicle", "day"),
    mapping: Any = None,
    against: str | Path | None = None,
    report: GroupReport | None = None,
    drift: DriftOptions = DriftOptions(),
    progress: Progress | None = None,
) -> BatchResult:
    """Run the whole batch on the cluster `client` is connected to.

    Parameters
    ----------
    logs : sequence of str or Path
        The logs (any supported format).
    settings : BatchSettings
        Structure, conditioning and identification options.
    results : str or Path
        Folder for the groups' files and the cache (created).
    client : distributed.Client
        Connected to the cluster to run on.
    by : sequence of str, optional
        Grouping keys (:func:`~sysid.batch.groups.group_logs`).
    mapping : flightlogs.readers.log_mapping.LogMapping, optional
        The operator's vehicle/date/payload record of the logs.
    against : str or Path, optional
        Reference simulation (a log or a model JSON): each log is compared with it (``sysid discrepancy``).
    report : callable, optional
        Writes each group's HTML report (:data:`~sysid.batch.tasks.GroupReport`).
    drift : DriftOptions, optional
        How parameter drift is judged.
    progress : callable, optional
        ``progress(stage, done, total)`` as tasks finish.

    Returns
    -------
    BatchResult

    Raises
    ------
    DataError
        If a grouping key is unknown (before any fit is sent).
    """
    check_keys(by, mapping)  # before any work is sent
    folder = Path(results).resolve()
    folder.mkdir(parents=True, exist_ok=True)
    cache = str(folder / "cache")
    paths = [str(Path(p).resolve()) for p in logs]
    reference = None if against is None else str(Path(against).resolve())
    surveys = _gathered(
        client,
        [client.submit(survey_log, p, cache, settings.reading, pure=False) for p in paths],
        lambda k, err: LogSurvey(path=paths[k], sha256="", error=f"{paths[k]}: {err}"),
        "reading",
        progress,
    )
    groups = group_logs(surveys, by, mapping)
    readable = [s for s in surveys if s.error is None]
    fits = [client.submit(fit_group, g, settings, str(folder), report, pure=False) for g in groups]
    comparisons = [client.submit(compare_log, reference, s, pure=False) for s in readable] if reference else []

    def lost(k: int, err: str) -> GroupFit | LogComparison:
        if k < len(groups):
            g = groups[k]
            return GroupFit(key=g.key, vehicle=g.vehicle, date=g.date, logs=tuple(s.path for s in g.logs), error=err)
        return LogComparison(path=readable[k - len(groups)].path, error=err)

    done = _gathered(client, [*fits, *comparisons], lost, "fitting", progress)
    fitted = tuple(r for r in done[: len(groups)] if isinstance(r, GroupFit))
    return BatchResult(
        surveys=tuple(surveys),
        groups=fitted,
        comparisons=tuple(r for r in done[len(groups) :] if isinstance(r, LogComparison)),
        drifts=find_drifts(fitted, drift),
    )


def _gathered(
    client: Any, futures: list[Any], failed: Callable[[int, str], Any], stage: str, progress: Progress | None
) -> list[Any]:
    """The futures' results in order, as they finish; a task that raised becomes ``failed(index, reason)``."""
    from distributed import as_completed

    index = {f.key: k for k, f in enumerate(futures)}
    out: list[Any] = [None] * len(futures)
    if progress is not None:
        progress(stage, 0, len(futures))
    for n, future in enumerate(as_completed(futures), start=1):  # type: ignore[no-untyped-call]
        k = index[future.key]
        if future.status == "error":
            err = future.exception()
            out[k] = failed(k, f"the task failed on its worker ({type(err).__name__}: {err})")
        else:
            out[k] = future.result()
        future.release()
        if progress is not None:
            progress(stage, n, len(futures))
    return out
