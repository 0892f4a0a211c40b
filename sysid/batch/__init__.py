"""Fleet and campaign batches on Dask: hundreds of logs fitted in parallel, parameters trended, drift flagged.

:func:`run_batch` runs a batch on a ``distributed.Client`` (:func:`batch_client`
makes one: a local cluster, or a scheduler's); :func:`group_logs` decides which
logs are fitted together and :func:`find_drifts` which parameters moved.
"""

from sysid.batch.cluster import batch_client
from sysid.batch.drift import DriftOptions, find_drifts, parameter_series
from sysid.batch.groups import BUILTIN_KEYS, Group, group_logs, log_keys
from sysid.batch.results import BatchResult, Drift, Failure, GroupFit, LogComparison, LogSurvey
from sysid.batch.run import run_batch
from sysid.batch.tasks import BatchSettings, compare_log, fit_group, survey_log

__all__ = [
    "batch_client",
    "DriftOptions",
    "find_drifts",
    "parameter_series",
    "BUILTIN_KEYS",
    "Group",
    "group_logs",
    "log_keys",
    "BatchResult",
    "Drift",
    "Failure",
    "GroupFit",
    "LogComparison",
    "LogSurvey",
    "run_batch",
    "BatchSettings",
    "compare_log",
    "fit_group",
    "survey_log",
]
