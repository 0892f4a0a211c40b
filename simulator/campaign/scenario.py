"""Scenario files: what a simulated flight-test campaign flies, in TOML.

A scenario names the vehicle, the wind conditions, the maneuvers of each
trial, how many trials, the anemometer and the log formats to write::

    [scenario]
    name = "chapter3-campaign"
    description = "..."
    vehicle = "octo-s1000"        # or "quad-x500", "crazyflie"
    formats = ["dataflash"]       # and/or "ulog"
    trials = 5                    # repeats of every (condition, maneuver) pair
    seed = 1
    utc_start = "2024-05-01T10:00:00Z"

    [anemometer]
    distance_m = 4.6
    rate_hz = 20.0
    clock_offset_s = 1.5

    [[condition]]
    name = "light"
    mean_speed_m_s = 2.7
    direction_from_deg = 300.0
    turbulence_ratio = 0.2

    [[maneuver]]
    axis = "lon"                  # lat, lon, yaw, thr
    kind = "sweep"                # sweep, doublet, 3211, multisine, height_steps
    amplitude = 8.0               # % of the mixer input
    duration_s = 34.0

Every (condition, maneuver) pair is flown `trials` times, each trial one
log file with trim margins before and after the maneuver.
"""

from __future__ import annotations

import tomllib
from dataclasses import MISSING, dataclass, field, fields
from datetime import UTC, datetime
from importlib import resources
from pathlib import Path
from typing import Any, Literal, TypeVar, get_args

from flightlogs.errors import DataError

__all__ = [
    "WindCondition",
    "ManeuverSpec",
    "AnemometerSpec",
    "Scenario",
    "read_scenario",
    "builtin_scenarios",
    "load_builtin",
]

_T = TypeVar("_T")

VehicleName = Literal["octo-s1000", "quad-x500", "crazyflie", "linear-octo"]
LogFormatName = Literal["dataflash", "ulog"]
ManeuverKind = Literal["sweep", "doublet", "3211", "multisine", "height_steps"]
_AXES = ("lat", "lon", "yaw", "thr")


@dataclass(frozen=True, slots=True, kw_only=True)
class WindCondition:
    """One wind condition of a campaign.

    Parameters
    ----------
    name : str
        Label, e.g. ``"calm"``.
    mean_speed_m_s : float
        Mean horizontal wind M, m/s.
    direction_from_deg : float
        Meteorological direction the wind comes from, deg.
    turbulence_ratio : float
        sigma_M / M of the turbulence.
    """

    name: str
    mean_speed_m_s: float
    direction_from_deg: float = 270.0
    turbulence_ratio: float = 0.2

    def __post_init__(self) -> None:
        if self.mean_speed_m_s < 0 or self.turbulence_ratio < 0:
            raise DataError(f"wind condition {self.name!r}: speed and turbulence ratio must be ≥ 0")


@dataclass(frozen=True, slots=True, kw_only=True)
class ManeuverSpec:
    """One maneuver flown in every trial of a condition.

    Parameters
    ----------
    axis : {"lat", "lon", "yaw", "thr"}
        Mixer axis (ignored by height steps).
    kind : {"sweep", "doublet", "3211", "multisine", "height_steps"}
        What is flown.
    amplitude : float
        Peak excitation, % of the mixer input; for height steps, unused.
    duration_s : float
        Length of the maneuver, s.
    f_start_hz, f_stop_hz : float
        Sweep (or multisine) band, Hz.
    fade_in_s : float
        Sweep fade-in, s.
    heights_m : tuple of float
        Height sequence of ``height_steps``, m, each held `hold_s`.
    hold_s : float
        Hold time of each height step, s.
    """

    axis: str
    kind: ManeuverKind
    amplitude: float = 0.0
    duration_s: float = 0.0
    f_start_hz: float = 0.1
    f_stop_hz: float = 10.0
    fade_in_s: float = 5.0
    heights_m: tuple[float, ...] = ()
    hold_s: float = 10.0

    def __post_init__(self) -> None:
        if self.kind not in get_args(ManeuverKind):
            raise DataError(f"unknown maneuver kind {self.kind!r} (expected {', '.join(get_args(ManeuverKind))})")
        if self.kind != "height_steps" and self.axis not in _AXES:
            raise DataError(f"unknown axis {self.axis!r} (expected {', '.join(_AXES)})")
        if self.kind == "height_steps" and not self.heights_m:
            raise DataError("height_steps needs heights_m")
        if self.kind != "height_steps" and self.duration_s <= 0:
            raise DataError(f"{self.kind} on {self.axis}: duration_s must be > 0")
        object.__setattr__(self, "heights_m", tuple(float(h) for h in self.heights_m))


@dataclass(frozen=True, slots=True, kw_only=True)
class AnemometerSpec:
    """The ground anemometer of a campaign.

    Parameters
    ----------
    distance_m : float
        Distance upstream of the vehicle, m.
    rate_hz : float
        Output rate, Hz.
    clock_offset_s : float
        Its clock minus UTC, s.
    """

    distance_m: float = 4.6
    rate_hz: float = 20.0
    clock_offset_s: float = 0.0


@dataclass(frozen=True, slots=True, kw_only=True)
class Scenario:
    """A simulated flight-test campaign.

    Parameters
    ----------
    name : str
        Identifier (file stem for built-ins).
    description : str
        One paragraph for ``sysid simulate --list``.
    vehicle : {"octo-s1000", "quad-x500", "crazyflie", "linear-octo"}
        Vehicle preset; ``linear-octo`` flies the Table 3.3 linear model exactly.
    conditions : tuple of WindCondition
        Wind conditions.
    maneuvers : tuple of ManeuverSpec
        Maneuvers; each trial flies one.
    trials : int
        Repeats of every (condition, maneuver) pair.
    formats : tuple of {"dataflash", "ulog"}
        Log formats written per trial.
    anemometer : AnemometerSpec or None
        Ground anemometer, if one records the wind.
    seed : int
        Seed of the first trial (the others follow).
    utc_start : datetime
        UTC of the first trial; trials follow each other.
    margin_s : float
        Trim time before and after each maneuver, s.
    effects : dict
        Environment switches and parameters (ground_effect, rotor_drag, mass_change, ...).
    """

    name: str
    description: str
    vehicle: VehicleName
    conditions: tuple[WindCondition, ...]
    maneuvers: tuple[ManeuverSpec, ...]
    trials: int = 1
    formats: tuple[LogFormatName, ...] = ("dataflash",)
    anemometer: AnemometerSpec | None = None
    seed: int = 1
    utc_start: datetime = datetime(2024, 5, 1, 10, 0, 0, tzinfo=UTC)
    margin_s: float = 3.0
    effects: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.vehicle not in get_args(VehicleName):
            raise DataError(f"unknown vehicle {self.vehicle!r} (expected {', '.join(get_args(VehicleName))})")
        bad = [f for f in self.formats if f not in get_args(LogFormatName)]
        if bad:
            raise DataError(f"unknown log format(s) {bad} (expected dataflash, ulog)")
        if self.trials < 1 or not self.conditions or not self.maneuvers:
            raise DataError(f"scenario {self.name!r} needs trials ≥ 1, a condition and a maneuver")

    @property
    def n_trials(self) -> int:
        """Trials in total: conditions × maneuvers × repeats."""
        return len(self.conditions) * len(self.maneuvers) * self.trials


def read_scenario(path: str | Path) -> Scenario:
    """Read a scenario TOML file.

    Parameters
    ----------
    path : str or Path
        The ``.toml`` file.

    Returns
    -------
    Scenario

    Raises
    ------
    DataError
        If the file is not TOML or a table holds an unknown key or a bad value;
        the message names the file and the table.
    """
    path = Path(path)
    try:
        raw = tomllib.loads(path.read_text())
    except (OSError, UnicodeDecodeError) as err:
        raise DataError(f"{path}: cannot be read ({err})") from err
    except tomllib.TOMLDecodeError as err:
        raise DataError(f"{path}: not valid TOML ({err})") from err
    return _scenario_from(raw, path)


_TABLES = ("scenario", "condition", "maneuver", "anemometer", "effects")
_SIMPLE = {
    "float": ((int, float), "a number"),
    "int": ((int,), "a whole number"),
    "str": ((str,), "text"),
    "VehicleName": ((str,), "text"),
    "ManeuverKind": ((str,), "text"),
}


def _scenario_from(raw: dict[str, Any], path: Path) -> Scenario:
    def build(kind: type[_T], table: Any, where: str, inner: dict[str, Any] | None = None) -> _T:
        _check_table(path, kind, table, where, tuple(inner or ()))
        try:
            return kind(**table, **(inner or {}))
        except TypeError as err:
            raise DataError(f"{path}: [{where}] has a value of the wrong type") from err
        except DataError as err:
            raise DataError(f"{path}: [{where}] {err}") from None

    head = raw.get("scenario", {})
    head = dict(head) if isinstance(head, dict) else head
    if isinstance(head, dict):
        if "utc_start" in head and isinstance(head["utc_start"], str):
            try:
                head["utc_start"] = datetime.fromisoformat(head["utc_start"].replace("Z", "+00:00"))
            except ValueError as err:
                raise DataError(
                    f"{path}: [scenario] utc_start {head['utc_start']!r} is not an ISO 8601 time "
                    "(e.g. 2024-05-01T10:00:00Z)"
                ) from err
        if isinstance(head.get("formats", ()), (list, tuple)):
            head["formats"] = tuple(head.get("formats", ("dataflash",)))
        head.setdefault("name", path.stem)
        head.setdefault("description", "")
    conditions = tuple(build(WindCondition, c, "condition") for c in _tables(path, raw, "condition"))
    maneuvers = tuple(build(ManeuverSpec, m, "maneuver") for m in _tables(path, raw, "maneuver"))
    anemometer = build(AnemometerSpec, raw["anemometer"], "anemometer") if "anemometer" in raw else None
    effects = raw.get("effects", {})
    if not isinstance(effects, dict):
        raise DataError(f"{path}: effects must be a table ([effects])")
    scenario = build(
        Scenario,
        head,
        "scenario",
        {"conditions": conditions, "maneuvers": maneuvers, "anemometer": anemometer, "effects": dict(effects)},
    )
    stray = [k for k in raw if k not in _TABLES]
    if stray:
        raise DataError(
            f"{path}: {stray[0]} is outside any table; a scenario file has "
            "[scenario], [[condition]], [[maneuver]], [anemometer] and [effects]"
        )
    return scenario


def _tables(path: Path, raw: dict[str, Any], key: str) -> list[Any]:
    """The array of tables ``[[key]]``."""
    tables = raw.get(key, [])
    if not isinstance(tables, list):
        raise DataError(f"{path}: {key} must be an array of tables ([[{key}]])")
    return tables


def _check_table(path: Path, kind: type, table: Any, where: str, inner: tuple[str, ...]) -> None:
    """Every required field of `kind` given, no unknown key, simple fields of their type; else a DataError."""
    if not isinstance(table, dict):
        raise DataError(f"{path}: {where} must be a table ([{where}])")
    known = {f.name: f for f in fields(kind) if f.init and f.name not in inner}
    unknown = [k for k in table if k not in known]
    if unknown:
        raise DataError(f"{path}: [{where}] has no field {unknown[0]!r} (fields: {', '.join(known)})")
    missing = [
        name for name, f in known.items() if name not in table and f.default is MISSING and f.default_factory is MISSING
    ]
    if missing:
        needs = " and ".join(("an " if m[0] in "aeiou" else "a ") + m for m in missing)
        raise DataError(f"{path}: [{where}] needs {needs}")
    for name, value in table.items():
        types, what = _SIMPLE.get(str(known[name].type), ((object,), ""))
        if isinstance(value, bool) or not isinstance(value, types):
            if what:
                raise DataError(f"{path}: [{where}] {name} is {value!r}, not {what}")


def builtin_scenarios() -> dict[str, Path]:
    """Built-in scenario files by name (``sysid simulate --list``)."""
    folder = resources.files("simulator.campaign") / "builtin"
    return {Path(str(item)).stem: Path(str(item)) for item in folder.iterdir() if str(item).endswith(".toml")}


def load_builtin(name: str) -> Scenario:
    """Read a built-in scenario by name.

    Parameters
    ----------
    name : str
        One of :func:`builtin_scenarios`.

    Raises
    ------
    DataError
        If there is no built-in scenario of that name.
    """
    known = builtin_scenarios()
    if name not in known:
        raise DataError(f"no built-in scenario {name!r}; built-in: {', '.join(sorted(known))}")
    return read_scenario(known[name])
