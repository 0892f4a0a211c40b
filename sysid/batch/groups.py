"""Logs grouped into fits: one model from the sweeps of each vehicle's day (or file, or any key).

A log's vehicle is the operator's mapping file's ``vehicle``, else the
flight controller's unique id in the log; its day the mapping's ``date``,
else the UTC date of its first sample. A vehicle or day known from neither is
"unknown", never guessed.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from flightlogs.errors import DataError
from flightlogs.readers.log_mapping import LogMapping
from sysid.batch.results import LogSurvey

__all__ = ["BUILTIN_KEYS", "Group", "check_keys", "log_keys", "group_logs"]

#: Keys every log has; a mapping file adds its columns.
BUILTIN_KEYS = ("vehicle", "day", "file")
_UNKNOWN = "unknown"


@dataclass(frozen=True, slots=True, kw_only=True)
class Group:
    """Logs fitted together.

    Parameters
    ----------
    key : str
        Its name: the values of the grouping keys joined by spaces.
    vehicle : str
        The vehicle of all its logs, or "mixed".
    date : str or None
        Their day (ISO), None when unknown or mixed.
    logs : tuple of LogSurvey
        Its logs, in the order given.
    """

    key: str
    vehicle: str
    date: str | None
    logs: tuple[LogSurvey, ...]


def log_keys(survey: LogSurvey, mapping: LogMapping | None = None) -> dict[str, str]:
    """The grouping keys of one readable log: vehicle, day, file and the mapping's columns.

    Parameters
    ----------
    survey : LogSurvey
        The log.
    mapping : LogMapping, optional
        The operator's mapping file.

    Returns
    -------
    dict of str to str
        ``"unknown"`` where neither the mapping nor the log tells.
    """
    given: Mapping[str, str] = mapping.keys_of(survey.path) if mapping is not None else {}
    keys = dict(given)
    keys["vehicle"] = given.get("vehicle") or survey.board_id or _UNKNOWN
    keys["day"] = given.get("date") or (survey.utc_start[:10] if survey.utc_start else _UNKNOWN)
    keys["file"] = Path(survey.path).name
    return keys


def check_keys(by: Sequence[str], mapping: LogMapping | None = None) -> None:
    """Refuse grouping keys that are neither built in nor a column of the mapping file.

    Parameters
    ----------
    by : sequence of str
        The keys.
    mapping : LogMapping, optional
        The operator's mapping file.

    Raises
    ------
    DataError
        Naming the unknown keys (or none given) and what a key may be.
    """
    known = (*BUILTIN_KEYS, *(mapping.columns if mapping is not None else ()))
    unknown = [key for key in by if key not in known]
    if unknown or not by:
        where = f"a column of {mapping.source}" if mapping is not None else "given by a mapping file (`mapping`)"
        raise DataError(
            f"cannot group by {', '.join(unknown) or 'nothing'}: a key is one of {', '.join(BUILTIN_KEYS)} or {where}"
        )


def group_logs(surveys: Sequence[LogSurvey], by: Sequence[str], mapping: LogMapping | None = None) -> tuple[Group, ...]:
    """Group the readable logs by the values of the keys `by`.

    Parameters
    ----------
    surveys : sequence of LogSurvey
        Every log; those that could not be read are left out.
    by : sequence of str
        Keys: ``vehicle``, ``day``, ``file`` or a column of the mapping file.
    mapping : LogMapping, optional
        The operator's mapping file.

    Returns
    -------
    tuple of Group
        By vehicle, then day, then key.

    Raises
    ------
    DataError
        If a key is neither built in nor a column of the mapping file.
    """
    check_keys(by, mapping)
    members: dict[str, list[tuple[LogSurvey, dict[str, str]]]] = {}
    for survey in surveys:
        if survey.error is None:
            keys = log_keys(survey, mapping)
            members.setdefault(" ".join(keys.get(k, _UNKNOWN) for k in by), []).append((survey, keys))
    groups = []
    for key, logs in members.items():
        vehicles = {keys["vehicle"] for _, keys in logs}
        days = {keys["day"] for _, keys in logs}
        day = days.pop() if len(days) == 1 else None
        groups.append(
            Group(
                key=key,
                vehicle=vehicles.pop() if len(vehicles) == 1 else "mixed",
                date=None if day == _UNKNOWN else day,
                logs=tuple(survey for survey, _ in logs),
            )
        )
    return tuple(sorted(groups, key=lambda g: (g.vehicle, g.date or "", g.key)))
