"""What a batch returns: each log's survey, each group's model and verification, each drift found.

Frozen dataclasses of numbers and paths, small enough to travel back from
a worker; the logs' data never does.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from sysid._json import finite_or_none, float_or_nan
from sysid.fit.result import ParameterEstimate

__all__ = ["LogSurvey", "GroupFit", "LogComparison", "Drift", "Failure", "BatchResult"]

_NUMBERS = ("value", "cr_percent", "insensitivity_percent")  # a parameter's numbers: NaN in, None in JSON


@dataclass(frozen=True, slots=True, kw_only=True)
class LogSurvey:
    """One log read through once: what tells its vehicle and day, or why it cannot be read.

    Parameters
    ----------
    path : str
        The log, absolute.
    sha256 : str
        Hex digest of its bytes (the cache's key).
    board_id : str
        The flight controller's unique id ("" when the log has none).
    utc_start : str or None
        UTC of its first sample, ISO 8601; None when it holds no GPS time.
    error : str or None
        One sentence when the log cannot be read; then the rest is empty.
    cached : bool
        Taken from the cache of an earlier run.
    """

    path: str
    sha256: str
    board_id: str = ""
    utc_start: str | None = None
    error: str | None = None
    cached: bool = False

    def to_dict(self) -> dict[str, Any]:
        """Its JSON entry (the batch cache keeps it)."""
        return {name: getattr(self, name) for name in _fields(self)}

    @classmethod
    def from_dict(cls, doc: Mapping[str, Any]) -> LogSurvey:
        """Rebuild it from :meth:`to_dict`."""
        return cls(**{name: doc[name] for name in _fields(cls) if name in doc})


@dataclass(frozen=True, slots=True, kw_only=True)
class GroupFit:
    """The model fitted to one group's sweeps and verified on its doublets.

    Parameters
    ----------
    key : str
        The group's name (``"V03 2024-06-07"``).
    vehicle : str
        The vehicle all its logs belong to ("mixed" when they do not agree).
    date : str or None
        Their day (ISO), None when unknown or mixed.
    logs : tuple of str
        Its logs.
    model_file, verification_file, report_file : str or None
        Files written beside the results table (None when not made).
    parameters : tuple of ParameterEstimate
        Every parameter of the structure (empty when the fit failed).
    cost_average : float
        J_ave (eq. 3.9); NaN when the fit failed.
    tic : float or None
        Theil inequality coefficient over the group's doublets; None when it has none (not verified).
    modes : str
        The model's modes, ``"name: omega_n rad/s, zeta"`` joined by ``"; "``.
    error : str or None
        One sentence when the group could not be fitted.
    cached : bool
        Taken from the cache of an earlier run.
    """

    key: str
    vehicle: str
    date: str | None
    logs: tuple[str, ...]
    model_file: str | None = None
    verification_file: str | None = None
    report_file: str | None = None
    parameters: tuple[ParameterEstimate, ...] = ()
    cost_average: float = math.nan
    tic: float | None = None
    modes: str = ""
    error: str | None = None
    cached: bool = False

    def to_dict(self) -> dict[str, Any]:
        """Its JSON entry (the batch cache keeps it); non-finite numbers as None."""
        doc = {name: getattr(self, name) for name in _fields(self)}
        doc["logs"] = list(self.logs)
        doc["cost_average"] = finite_or_none(self.cost_average)
        doc["parameters"] = [
            {name: getattr(p, name) for name in _fields(p)} | {k: finite_or_none(getattr(p, k)) for k in _NUMBERS}
            for p in self.parameters
        ]
        return doc

    @classmethod
    def from_dict(cls, doc: Mapping[str, Any]) -> GroupFit:
        """Rebuild it from :meth:`to_dict` (None as NaN)."""
        parameters = tuple(
            ParameterEstimate(**(dict(p) | {k: float_or_nan(p[k]) for k in _NUMBERS})) for p in doc["parameters"]
        )
        kept = {name: doc[name] for name in _fields(cls) if name in doc}
        return cls(
            **kept
            | {"logs": tuple(doc["logs"]), "parameters": parameters, "cost_average": float_or_nan(doc["cost_average"])}
        )


@dataclass(frozen=True, slots=True, kw_only=True)
class LogComparison:
    """One log compared with the reference simulation (``--against``).

    Parameters
    ----------
    path : str
        The real log.
    verdict : str
        The most important physics term missing from the simulation, or ``"none"``.
    effects : tuple of str
        The terms found, strongest first.
    thrust_scale : float
        The real flight's thrust per input over the simulation's (taken out before any term is tried):
        below 1 when the vehicle lifts less than the reference for the same command. NaN when not compared.
    error : str or None
        One sentence when the comparison could not be made.
    """

    path: str
    verdict: str = ""
    effects: tuple[str, ...] = ()
    thrust_scale: float = math.nan
    error: str | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Drift:
    """A parameter of one vehicle that moved by more than its Cramér–Rao bounds allow.

    Parameters
    ----------
    vehicle, parameter : str
        Where.
    before, after : str
        The last group still at the baseline and the first group beyond it.
    baseline : float
        The parameter's baseline (inverse-variance mean of the vehicle's first groups).
    baseline_bound : float
        Bound of the baseline, in the parameter's unit (from the scaled bounds of its groups).
    value : float
        Its value at `after`.
    bound : float
        Cramér–Rao bound at `after` times the rule's scale, in the parameter's unit.
    change_percent : float
        Change of the magnitude, ``100 (|value| - |baseline|) / |baseline|``: negative when the
        parameter shrinks towards zero (an effectiveness lost), whatever its sign.
    sigmas : float
        The change over the combined bound ``sqrt(bound² + baseline_bound²)``.
    confirmed : bool
        The group after `after` is beyond the baseline too, on the same side
        (False when `after` is the vehicle's last group).
    """

    vehicle: str
    parameter: str
    before: str
    after: str
    baseline: float
    baseline_bound: float
    value: float
    bound: float
    change_percent: float
    sigmas: float
    confirmed: bool

    @property
    def sentence(self) -> str:
        """One line: ``"Z_thr -89.9 -> -68.4, magnitude -24.0 % (5.1 combined bounds) at V03 2024-06-07, after
        V03 2024-06-06"``."""
        return (
            f"{self.parameter} {self.baseline:.4g} -> {self.value:.4g}, magnitude {self.change_percent:+.1f} % "
            f"({abs(self.sigmas):.1f} combined bounds) at {self.after}, after {self.before}"
            + ("" if self.confirmed else "; last flight, not yet confirmed")
        )

    def to_dict(self) -> dict[str, Any]:
        """Its JSON entry, with its :attr:`sentence` as ``text``."""
        return {name: getattr(self, name) for name in _fields(self)} | {"text": self.sentence}


@dataclass(frozen=True, slots=True, kw_only=True)
class Failure:
    """A log or a group the batch went on without.

    Parameters
    ----------
    what : str
        The log's path, or ``"group KEY"``.
    stage : {"read", "fit", "discrepancy"}
        Where it failed.
    reason : str
        One sentence.
    """

    what: str
    stage: str
    reason: str

    def to_dict(self) -> dict[str, str]:
        """Its JSON entry."""
        return {"what": self.what, "stage": self.stage, "reason": self.reason}


@dataclass(frozen=True, slots=True, kw_only=True)
class BatchResult:
    """Everything a batch found.

    Parameters
    ----------
    surveys : tuple of LogSurvey
        Every log, in the order given.
    groups : tuple of GroupFit
        Every group, by vehicle then date.
    comparisons : tuple of LogComparison
        With ``--against``: every readable log.
    drifts : tuple of Drift
        Parameters that moved, by vehicle.
    """

    surveys: tuple[LogSurvey, ...]
    groups: tuple[GroupFit, ...]
    comparisons: tuple[LogComparison, ...] = ()
    drifts: tuple[Drift, ...] = ()

    @property
    def failures(self) -> tuple[Failure, ...]:
        """Logs that could not be read, groups that could not be fitted, comparisons not made."""
        return (
            *(Failure(what=s.path, stage="read", reason=s.error) for s in self.surveys if s.error),
            *(Failure(what=_group_named(g), stage="fit", reason=g.error) for g in self.groups if g.error),
            *(Failure(what=c.path, stage="discrepancy", reason=c.error) for c in self.comparisons if c.error),
        )

    @property
    def cached(self) -> int:
        """Logs and groups taken from the cache."""
        return sum(s.cached for s in self.surveys) + sum(g.cached for g in self.groups)

    def digest(self) -> dict[str, Any]:
        """What ``sysid batch --json`` gives of it: counts, the drifts and the failures.

        Returns
        -------
        dict
            ``logs``, ``groups``, ``fitted``, ``cached`` (counts), ``drifts`` and ``failures`` (their
            :meth:`Drift.to_dict` and :meth:`Failure.to_dict`).
        """
        return {
            "logs": len(self.surveys),
            "groups": len(self.groups),
            "fitted": sum(g.error is None for g in self.groups),
            "cached": self.cached,
            "drifts": [d.to_dict() for d in self.drifts],
            "failures": [f.to_dict() for f in self.failures],
        }


def _group_named(group: GroupFit, shown: int = 5) -> str:
    """``group KEY (a.ulg, b.ulg and 3 more)``: a group by its key and the files it holds."""
    names = [Path(path).name for path in group.logs]
    more = f" and {len(names) - shown} more" if len(names) > shown else ""
    return f"group {group.key} ({', '.join(names[:shown])}{more})" if names else f"group {group.key}"


def _fields(item: Any) -> list[str]:
    """The field names of a dataclass or of its instance."""
    return [f.name for f in fields(item)]
