"""The work a batch sends to its workers: survey a log, fit a group, compare a log with the reference.

Each task is given paths and options, reads the logs itself and returns a
small result (:mod:`sysid.batch.results`): no flight data crosses the wire.
A log or group that cannot be used is a result with its one-sentence reason,
so the batch goes on; a project error is cached like a result (the same
bytes fail the same way), an unexpected one is not.
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from functools import lru_cache
from pathlib import Path
from typing import Any

from flightlogs.conditioning.condition import ConditioningOptions
from flightlogs.errors import DataError, SysidError, SysidWarning
from flightlogs.readers.dispatch import ReadOptions
from sysid.batch.cache import cache_key, load_fit, load_survey, save_fit, save_survey
from sysid.batch.groups import Group
from sysid.batch.results import GroupFit, LogComparison, LogSurvey
from sysid.fit.identify import IdentifyOptions

__all__ = ["BatchSettings", "GroupReport", "survey_log", "fit_group", "compare_log"]

#: Writes a group's HTML report: ``report(path, model, verification=..., title=...)``.
GroupReport = Callable[..., Any]


@dataclass(frozen=True, slots=True, kw_only=True)
class BatchSettings:
    """Everything that decides a group's fit besides its logs (part of its cache key).

    Parameters
    ----------
    structure : str
        A built-in structure's name or a structure file's path.
    structure_text : str
        The structure's TOML source (a file edited in place changes the key).
    conditioning : ConditioningOptions
        Wind alignment and resampling.
    identify : IdentifyOptions
        The identification's choices.
    wind_paths : tuple of str
        Anemometer files (each log takes the one overlapping it).
    wind_sha256 : tuple of str
        Their hashes.
    initial_state : str
        How the verification starts each doublet (``estimated``: with VERIFY's bias and shift).
    reading : ReadOptions
        The column map of tables among the logs, and whether a log of another vehicle is refused.
    """

    structure: str
    structure_text: str
    conditioning: ConditioningOptions = field(default_factory=ConditioningOptions)
    identify: IdentifyOptions = field(default_factory=IdentifyOptions)
    wind_paths: tuple[str, ...] = ()
    wind_sha256: tuple[str, ...] = ()
    initial_state: str = "estimated"
    reading: ReadOptions = field(default_factory=ReadOptions)

    def key_parts(self) -> tuple[str, ...]:
        """Text of everything that changes a fit, for :func:`~sysid.batch.cache.cache_key`."""
        return (
            self.structure_text,
            repr(self.conditioning),
            repr(self.identify),
            *self.wind_sha256,
            self.initial_state,
            repr(self.reading),
        )


def survey_log(path: str, cache: str, reading: ReadOptions = ReadOptions()) -> LogSurvey:
    """Hash and read one log: its vehicle's id and its start in UTC, or why it cannot be read.

    Parameters
    ----------
    path : str
        The log, absolute.
    cache : str
        The cache folder.
    reading : ReadOptions, optional
        How a table is read and another vehicle refused (:class:`BatchSettings`).

    Returns
    -------
    LogSurvey
    """
    from flightlogs.readers.dispatch import read_log
    from flightlogs.store.hashing import file_sha256

    try:
        sha256 = file_sha256(path)
    except OSError as err:
        return LogSurvey(path=path, sha256="", error=f"{path}: cannot be read ({err.strerror or err})")
    found = load_survey(Path(cache), sha256, path)
    if found is not None:
        return found
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SysidWarning)  # the fit reads the log again and keeps its warnings
            log = read_log(path, reading=reading)
    except SysidError as err:
        survey = LogSurvey(path=path, sha256=sha256, error=str(err))
    else:
        starts = [float(s.time_s[0]) for s in log.signals.values() if s.time_s.size]
        utc = None
        if log.utc_offset_s is not None and starts:
            utc = datetime.fromtimestamp(min(starts) + log.utc_offset_s, UTC).isoformat(timespec="seconds")
        survey = LogSurvey(path=path, sha256=sha256, board_id=log.board_id, utc_start=utc)
    save_survey(Path(cache), survey)
    return survey


def fit_group(group: Group, settings: BatchSettings, results: str, report: GroupReport | None = None) -> GroupFit:
    """Identify a model from the group's sweeps and verify it on its doublets; write its files.

    Parameters
    ----------
    group : Group
        The logs fitted together.
    settings : BatchSettings
        Structure and options.
    results : str
        The results folder: the model, verification and report go to ``groups/KEY/``, the cache to ``cache/``.
    report : callable, optional
        Writes the group's HTML report (see :data:`GroupReport`).

    Returns
    -------
    GroupFit
        With `error` set when the group cannot be fitted.
    """
    cache = Path(results) / "cache"
    key = cache_key(
        settings.key_parts(),
        [s.sha256 for s in group.logs],
        (group.key, group.vehicle, group.date or "", str(bool(report))),
    )
    found = load_fit(cache, key)
    if found is not None:
        return replace(found, logs=tuple(s.path for s in group.logs))
    folder = Path(results) / "groups" / _folder_name(group.key)
    base = GroupFit(key=group.key, vehicle=group.vehicle, date=group.date, logs=tuple(s.path for s in group.logs))
    try:
        fit = _fit(group, settings, folder, base, report)
    except SysidError as err:
        fit = replace(base, error=str(err))
    except Exception as err:
        return replace(base, error=f"internal error ({type(err).__name__}: {err}); please report it")
    save_fit(cache, key, fit)
    return fit


def _fit(group: Group, settings: BatchSettings, folder: Path, base: GroupFit, report: GroupReport | None) -> GroupFit:
    from flightlogs.store.campaign import ingest_campaign
    from sysid.fit import identify_flights, write_model
    from sysid.model.modes import modes
    from sysid.verify import VerificationOptions, axis_outputs, verify_flights
    from sysid.verify.io import write_verification

    paths = [Path(s.path) for s in group.logs]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SysidWarning)  # identify_flights keeps them in the model's notes
        campaign = ingest_campaign(
            paths,
            [Path(p) for p in settings.wind_paths],
            options=settings.conditioning,
            reading=settings.reading,
        )
        flights = campaign.require_flights()
        model = identify_flights(flights, settings.structure, options=settings.identify, files=paths)
        verification = None
        try:
            verification = verify_flights(
                model.linear_model(include_wind=False),
                flights,
                axes=axis_outputs(model),
                hint="",
                options=VerificationOptions(initial_state=settings.initial_state),  # type: ignore[arg-type]
                unidentified={a.input: a.reason for a in model.unidentified_axes},
            )
        except DataError:
            pass  # no doublet in the group: the model is not verified (tic None)
    folder.mkdir(parents=True, exist_ok=True)
    model_file = write_model(folder / "model.json", model)
    verification_file = None
    if verification is not None:
        options = {"initial_state": settings.initial_state, "judged": "on-axis outputs of each doublet's axis"}
        verification_file = write_verification(
            folder / "verification.json", verification, model=model_file, options=options
        )
    report_file = None
    if report is not None:
        report_file = report(
            folder / "report.html", model, verification=verification, title=f"{group.key}: {model.structure_name}"
        )
    return replace(
        base,
        model_file=str(model_file),
        verification_file=None if verification_file is None else str(verification_file),
        report_file=None if report_file is None else str(report_file),
        parameters=model.parameters,
        cost_average=model.cost.average,
        tic=None if verification is None else verification.tic,
        modes="; ".join(
            f"{m.mode}: {m.natural_frequency_rad_s:.3g} rad/s"
            + ("" if not math.isfinite(m.damping) else f", zeta {m.damping:.2f}")
            for m in modes(model.linear_model())
        ),
    )


def compare_log(reference: str, log: LogSurvey) -> LogComparison:
    """``sysid discrepancy REFERENCE LOG``: the physics the reference simulation leaves out of this flight.

    Parameters
    ----------
    reference : str
        A simulated log, or a model JSON from ``sysid fit -o``.
    log : LogSurvey
        The real flight.

    Returns
    -------
    LogComparison
    """
    from flightlogs.store.campaign import ingest_campaign
    from sysid.discrepancy import DiscrepancyOptions, discover, flights_series, model_flight

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SysidWarning)
            real = ingest_campaign([Path(log.path)], options=_NO_MANEUVERS).require_flights()
            kind, simulation = _reference(reference, Path(reference).stat().st_mtime_ns)
            misfit = _misfit(reference, Path(reference).stat().st_mtime_ns) if kind == "model" else None
            if kind == "model":
                real_series = flights_series(real)
                sim_series = [model_flight(simulation, s, source=Path(reference).name) for s in real_series]
            else:  # like with like (rates, derived specific forces)
                real_series = flights_series(real, like=simulation)
                sim_series = flights_series(simulation, like=real)
            result = discover(sim_series, real_series, DiscrepancyOptions(simulation_misfit=misfit))
    except SysidError as err:
        return LogComparison(path=log.path, error=str(err))
    effects = tuple(finding.effect for finding in result.findings)
    return LogComparison(path=log.path, verdict=result.verdict, effects=effects, thrust_scale=result.thrust_scale)


#: The discrepancy search needs no maneuvers found.
_NO_MANEUVERS = ConditioningOptions(segments=())


@lru_cache(maxsize=2)
def _reference(reference: str, _mtime_ns: int) -> tuple[str, Any]:
    """The reference read once per worker (keyed by its modification time too): a model, or the simulated flights."""
    from flightlogs.store.campaign import ingest_campaign
    from sysid.fit.model_file import read_model

    if reference.lower().endswith(".json"):
        return "model", read_model(reference).linear_model(include_wind=False)
    return "flights", tuple(ingest_campaign([Path(reference)], options=_NO_MANEUVERS).require_flights())


@lru_cache(maxsize=2)
def _misfit(reference: str, _mtime_ns: int) -> str | None:
    """Why the reference model is no close model of its own flights, read once per worker (as :func:`_reference`)."""
    from sysid.discrepancy import simulation_misfit

    return simulation_misfit(reference)


def _folder_name(key: str) -> str:
    """A group's key as a folder name: letters, digits, ``-`` and ``_``; spaces become ``_``."""
    return re.sub(r"[^A-Za-z0-9._-]+", "_", key).strip("._") or "group"
