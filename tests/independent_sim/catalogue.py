"""The corpus: named cases, split into cases to tune a detector on and cases held out to test it.

A maneuver detector (or any front end) may be tuned on :data:`TUNING_CASES`
only; tests assert on :data:`HELDOUT_CASES`. The two lists share no case,
and each covers PX4 and ArduPilot logs, calm and strong wind, sweeps of
every design, doublets, 3-2-1-1s, multisines, piloted sweeps, a hover with
no maneuver and a log with one axis never excited.

The ``*-wind-clock-*`` cases fly in wind with an anemometer whose logger's
clock is off (``WindModel.clock_offset_s``, one of them by 0.0 s: nothing to
find) and a log that carries the autopilot's own wind estimate, lagging the
air by a first-order time constant (``WindModel.estimate_time_constant_s``);
``heldout-wind-calm`` is the calm airframe in a breath of wind (0.8 m/s,
turbulence 0.05 m/s): no G_w to find.

The ``*-long-low`` cases fly without position hold (attitude hold only) a long,
low pitch and roll attitude sweep each, from 0.15 rad/s with two periods
there first (issue 32): the speed derivatives' own band.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal

from independent_sim.maneuvers import (
    Axis,
    Chirp,
    Design,
    Doublet,
    Injection,
    Maneuver,
    Multisine,
    PilotedSweep,
    ThreeTwoOneOne,
)
from independent_sim.scenario import Case, FlightPlan, LogFormat, Reposition
from independent_sim.wind import WindModel

__all__ = ["TUNING_CASES", "HELDOUT_CASES", "ALL_CASES", "case_named"]

_Step = tuple[Axis, Design, float, Injection] | float  # a maneuver, or a pause (s)
_FIRST_S = 10.0  # first maneuver, s after take-off (the climb takes 6 s)
_TAIL_S = 12.0  # after the last maneuver: settle, descend (6 s), stand


def _flight(
    name: str,
    fmt: LogFormat,
    steps: Sequence[_Step],
    *,
    seed: int,
    description: str,
    heading_deg: float = 30.0,
    wind: WindModel | None = None,
    hover_s: float = 0.0,
    repositions: tuple[Reposition, ...] = (),
    condition: Literal["calm", "light", "strong"] | None = None,
    **options: object,
) -> Case:
    """A case whose maneuvers follow each other; a bare number in `steps` is a pause (s).

    The airframe is Table 3.3's strong-wind column when the case has `wind`, else the calm one,
    unless `condition` says otherwise (the calm airframe in a light breeze: ``"calm"`` with wind).
    """
    maneuvers, at = [], _FIRST_S
    for step in steps:
        if isinstance(step, (int, float)):
            at += float(step)
            continue
        axis, design, amplitude, injection = step
        maneuvers.append(Maneuver(axis=axis, design=design, start_s=at, amplitude=amplitude, injection=injection))
        at += design.duration_s
    duration = max(at + _TAIL_S, hover_s)
    return Case(
        name=name,
        fmt=fmt,
        plan=FlightPlan(duration_s=duration, repositions=repositions, log_start_us=30_000_000 + 1_250_000 * seed),
        maneuvers=tuple(maneuvers),
        condition=condition or ("strong" if wind is not None else "calm"),
        wind=wind,
        heading_deg=heading_deg,
        seed=seed,
        description=description,
        **options,  # type: ignore[arg-type]
    )


def _doublets(axes: Sequence[Axis], amplitude: float = 0.06, width_s: float = 1.0, pause_s: float = 6.0) -> list[_Step]:
    """A doublet on each axis in turn (yaw at 8 %), each followed by a pause."""
    out: list[_Step] = []
    for axis in axes:
        out += [(axis, Doublet(width_s=width_s), amplitude if axis != "yaw" else 0.08, "mixer"), pause_s]
    return out


_LOG = Chirp()  # 0.1-10 Hz, 34 s, fade-in 3 s: the dissertation's sweep
_STRONG = WindModel(mean_speed_m_s=5.4, from_deg=250.0)


def _long_low_steps() -> list[_Step]:
    """Pitch and roll attitude sweeps of 240 s from 0.15 rad/s (two periods there first) to 2 Hz, then yaw and thr."""
    low = Chirp(
        duration_s=240.0, f_min_hz=0.15 / (2 * math.pi), f_max_hz=2.0, fade_in_s=5.0, fade_out_s=2.0, dwell_periods=2.0
    )
    return [
        ("lon", low, 0.08, "attitude"),
        8.0,
        ("lat", low, 0.08, "attitude"),
        6.0,
        ("yaw", Chirp(duration_s=36.0, f_max_hz=5.0), 0.08, "mixer"),
        6.0,
        ("thr", Chirp(duration_s=30.0, f_max_hz=8.0), 0.05, "mixer"),
    ]


def _clock_steps(second_lon: Design, thrust: Design) -> list[_Step]:
    """Two lon sweeps around a thrust sweep, then doublets lon, thr, lon, thr (the clock cases' plan)."""
    return [
        ("lon", _LOG, 0.06, "mixer"),
        8.0,
        ("thr", thrust, 0.05, "mixer"),
        8.0,
        ("lon", second_lon, 0.07, "mixer"),
        8.0,
        *_doublets(["lon", "thr", "lon", "thr"]),
    ]


TUNING_CASES: tuple[Case, ...] = (
    _flight(
        "tune-px4-lon-lat-sweeps",
        "ulog",
        [("lon", _LOG, 0.06, "mixer"), 8.0, ("lat", _LOG, 0.07, "mixer"), 8.0, *_doublets(["lon", "lat"])],
        seed=101,
        description="PX4: log sweeps lon then lat at the mixer, then doublets",
    ),
    _flight(
        "tune-px4-yaw-thr-sweeps",
        "ulog",
        [
            ("yaw", Chirp(duration_s=40.0, f_max_hz=5.0, law="linear"), 0.08, "mixer"),
            8.0,
            ("thr", Chirp(duration_s=30.0, f_max_hz=8.0), 0.05, "mixer"),
            8.0,
            *_doublets(["yaw", "thr"]),
        ],
        seed=102,
        heading_deg=200.0,
        description="PX4: linear yaw sweep and log thrust sweep, doublets",
    ),
    _flight(
        "tune-ap-sweeps-down",
        "dataflash",
        [
            ("lon", Chirp(duration_s=40.0, direction="down", fade_in_s=1.0, fade_out_s=3.0), 0.06, "mixer"),
            6.0,
            ("lat", Chirp(duration_s=30.0, f_min_hz=0.2, f_max_hz=8.0, law="linear"), 0.05, "mixer"),
            6.0,
            ("lat", ThreeTwoOneOne(unit_s=0.4), 0.06, "mixer"),
            6.0,
        ],
        seed=103,
        heading_deg=-75.0,
        description="ArduPilot: falling log sweep lon, linear sweep lat, 3-2-1-1",
    ),
    _flight(
        "tune-ap-piloted",
        "dataflash",
        [
            ("lat", PilotedSweep(duration_s=45.0, f_min_hz=0.2, f_max_hz=3.0), 0.10, "attitude"),
            8.0,
            ("yaw", PilotedSweep(duration_s=40.0, f_min_hz=0.1, f_max_hz=2.0), 0.35, "rate"),
            8.0,
            ("thr", Multisine(duration_s=30.0, f_min_hz=0.2, f_max_hz=6.0), 0.05, "mixer"),
        ],
        seed=104,
        description="ArduPilot: piloted sweeps lat (attitude) and yaw (rate), thrust multisine",
    ),
    _flight(
        "tune-px4-hover",
        "ulog",
        [],
        seed=105,
        hover_s=90.0,
        repositions=(Reposition(start_s=25.0, north_m=2.0, east_m=-1.0), Reposition(start_s=55.0, north_m=-2.0)),
        description="PX4: take-off, hover with two repositions, landing; no maneuver",
    ),
    _flight(
        "tune-ap-no-lon",
        "dataflash",
        [
            ("lat", _LOG, 0.06, "mixer"),
            6.0,
            ("yaw", Chirp(duration_s=36.0, f_max_hz=6.0), 0.08, "mixer"),
            6.0,
            ("thr", Chirp(duration_s=30.0, f_max_hz=8.0, law="linear"), 0.05, "mixer"),
        ],
        seed=106,
        heading_deg=120.0,
        description="ArduPilot: lat, yaw and thr sweeps; lon never excited",
    ),
    _flight(
        "tune-px4-wind",
        "ulog",
        [
            ("lon", _LOG, 0.06, "mixer"),
            8.0,
            ("thr", Chirp(duration_s=30.0, f_max_hz=8.0), 0.05, "mixer"),
            8.0,
            *_doublets(["lon", "thr", "lon"]),
        ],
        seed=107,
        wind=_STRONG,
        description="PX4 in strong wind (5.4 m/s, Dryden): lon and thr sweeps, doublets; anemometer CSV",
    ),
    _flight(
        "tune-wind-clock-px4-ahead",
        "ulog",
        _clock_steps(Chirp(duration_s=36.0, law="linear", f_max_hz=6.0), Chirp(duration_s=30.0, f_max_hz=8.0)),
        seed=301,
        wind=WindModel(
            mean_speed_m_s=5.0, from_deg=135.0, sigma_m_s=0.7, clock_offset_s=1.7, estimate_time_constant_s=2.5
        ),
        description="PX4 in wind 5.0 m/s, anemometer clock 1.7 s ahead, wind estimate lagging 2.5 s: "
        "two lon sweeps, a thr sweep, doublets",
    ),
    _flight(
        "tune-wind-clock-ap-behind",
        "dataflash",
        _clock_steps(
            Chirp(duration_s=40.0, direction="down", fade_in_s=1.0, fade_out_s=3.0),
            Chirp(duration_s=30.0, f_max_hz=8.0, law="linear"),
        ),
        seed=302,
        wind=WindModel(
            mean_speed_m_s=5.6, from_deg=315.0, sigma_m_s=0.8, clock_offset_s=-0.9, estimate_time_constant_s=3.5
        ),
        description="ArduPilot in wind 5.6 m/s, anemometer clock 0.9 s behind, wind estimate lagging 3.5 s: "
        "two lon sweeps, a thr sweep, doublets",
    ),
    _flight(
        "tune-wind-calm",
        "dataflash",
        _clock_steps(Chirp(duration_s=34.0), Chirp(duration_s=30.0, f_max_hz=8.0)),
        seed=303,
        wind=WindModel(
            mean_speed_m_s=1.0, from_deg=40.0, sigma_m_s=0.08, clock_offset_s=-0.7, estimate_time_constant_s=2.5
        ),
        condition="calm",
        description="ArduPilot, the calm airframe in 1 m/s of wind (turbulence 0.08 m/s; no G_w), anemometer clock "
        "0.7 s behind, wind estimate lagging 2.5 s: two lon sweeps, a thr sweep, doublets",
    ),
    _flight(
        "tune-px4-long-low",
        "ulog",
        _long_low_steps(),
        seed=131,
        heading_deg=40.0,
        position_hold=False,
        description="PX4 in attitude hold (no position hold): long, low pitch and roll attitude sweeps, yaw, thr",
    ),
)

HELDOUT_CASES: tuple[Case, ...] = (
    _flight(
        "heldout-px4-sweeps",
        "ulog",
        [
            ("lat", Chirp(duration_s=36.0), 0.06, "mixer"),
            5.0,
            ("lon", Chirp(duration_s=34.0, law="linear", f_min_hz=0.15, f_max_hz=8.0), 0.07, "mixer"),
            5.0,
            (
                "yaw",
                Chirp(duration_s=40.0, f_max_hz=5.0, direction="down", fade_in_s=1.0, fade_out_s=3.0),
                0.08,
                "mixer",
            ),
            5.0,
            ("thr", Chirp(duration_s=30.0, f_max_hz=8.0), 0.05, "mixer"),
            6.0,
            *_doublets(["lat", "lon", "yaw", "thr"], width_s=0.8),
        ],
        seed=201,
        heading_deg=75.0,
        description="PX4: sweeps on all four axes back to back, then doublets",
    ),
    _flight(
        "heldout-px4-piloted",
        "ulog",
        [
            ("lon", PilotedSweep(duration_s=50.0, f_min_hz=0.15, f_max_hz=2.5, irregularity=0.3), 0.12, "attitude"),
            8.0,
            ("yaw", PilotedSweep(duration_s=40.0, f_min_hz=0.1, f_max_hz=2.0), 0.35, "rate"),
            8.0,
            ("lat", ThreeTwoOneOne(unit_s=0.35), 0.06, "mixer"),
            6.0,
            ("lon", ThreeTwoOneOne(unit_s=0.5), 0.06, "mixer"),
            6.0,
        ],
        seed=202,
        heading_deg=-140.0,
        description="PX4: piloted sweeps lon (attitude stick) and yaw (rate stick), 3-2-1-1s",
    ),
    _flight(
        "heldout-px4-multisine",
        "ulog",
        [
            ("lat", Multisine(duration_s=30.0, f_min_hz=0.2, f_max_hz=8.0), 0.06, "mixer"),
            6.0,
            ("lon", Multisine(duration_s=40.0, f_min_hz=0.1, f_max_hz=6.0, period_s=20.0), 0.06, "mixer"),
            6.0,
            ("yaw", Chirp(duration_s=36.0, f_max_hz=6.0, direction="down"), 0.08, "mixer"),
            6.0,
            *_doublets(["lat", "lon"], width_s=1.2),
        ],
        seed=203,
        heading_deg=10.0,
        description="PX4: multisines lat and lon, falling yaw sweep, doublets",
    ),
    _flight(
        "heldout-ap-sweeps",
        "dataflash",
        [
            ("lon", _LOG, 0.06, "mixer"),
            5.0,
            ("lat", Chirp(duration_s=40.0, law="linear", f_max_hz=6.0), 0.08, "mixer"),
            5.0,
            ("yaw", Chirp(duration_s=34.0, f_max_hz=6.0), 0.08, "mixer"),
            5.0,
            (
                "thr",
                Chirp(duration_s=30.0, f_max_hz=8.0, direction="down", fade_in_s=1.0, fade_out_s=3.0),
                0.05,
                "mixer",
            ),
            6.0,
            *_doublets(["lon", "lat", "yaw", "thr"]),
        ],
        seed=204,
        heading_deg=300.0,
        description="ArduPilot: sweeps on all four axes back to back, then doublets; no SIDD/SIDS",
    ),
    _flight(
        "heldout-ap-doublets",
        "dataflash",
        [
            *_doublets(["lat", "lon", "yaw", "thr"], width_s=1.0),
            ("lat", ThreeTwoOneOne(), 0.06, "mixer"),
            6.0,
            ("lon", ThreeTwoOneOne(), 0.06, "mixer"),
            6.0,
            *_doublets(["lon", "lat"], amplitude=-0.07, width_s=0.7),
            ("thr", Multisine(duration_s=30.0, f_min_hz=0.2, f_max_hz=5.0), 0.05, "mixer"),
        ],
        seed=205,
        heading_deg=160.0,
        description="ArduPilot: doublets (both signs) and 3-2-1-1s on every axis, thrust multisine",
    ),
    _flight(
        "heldout-px4-no-lat",
        "ulog",
        [
            ("lon", Chirp(duration_s=36.0), 0.06, "mixer"),
            6.0,
            ("yaw", Chirp(duration_s=36.0, f_max_hz=6.0), 0.08, "mixer"),
            6.0,
            ("thr", Chirp(duration_s=30.0, f_max_hz=8.0), 0.05, "mixer"),
            6.0,
            *_doublets(["lon", "yaw"]),
        ],
        seed=206,
        heading_deg=-30.0,
        px4_accel_topic="sensor_combined",
        description="PX4 (accelerometer in sensor_combined only): lon, yaw, thr; lat never excited",
    ),
    _flight(
        "heldout-ap-hover",
        "dataflash",
        [],
        seed=207,
        hover_s=75.0,
        repositions=(Reposition(start_s=30.0, east_m=2.5, duration_s=6.0),),
        description="ArduPilot: take-off, hover, one reposition, landing; no maneuver",
    ),
    _flight(
        "heldout-ap-wind",
        "dataflash",
        [
            ("lon", _LOG, 0.06, "mixer"),
            8.0,
            ("thr", Chirp(duration_s=30.0, f_max_hz=8.0), 0.05, "mixer"),
            8.0,
            *_doublets(["lon", "thr", "lon", "thr"]),
        ],
        seed=208,
        wind=WindModel(mean_speed_m_s=5.4, from_deg=20.0),
        description="ArduPilot in strong wind: lon and thr sweeps, doublets; anemometer CSV",
    ),
    _flight(
        "heldout-px4-wind",
        "ulog",
        [
            ("lon", Chirp(duration_s=36.0), 0.07, "mixer"),
            8.0,
            ("lat", _LOG, 0.06, "mixer"),
            8.0,
            *_doublets(["lon", "lat", "lon"]),
        ],
        seed=209,
        wind=WindModel(mean_speed_m_s=5.4, from_deg=290.0, sigma_m_s=0.75),
        description="PX4 in strong wind: lon and lat sweeps, doublets; anemometer CSV",
    ),
    _flight(
        "heldout-wind-clock-ap-ahead",
        "dataflash",
        _clock_steps(Chirp(duration_s=36.0), Chirp(duration_s=30.0, f_max_hz=8.0)),
        seed=311,
        wind=WindModel(
            mean_speed_m_s=4.6, from_deg=60.0, sigma_m_s=0.65, clock_offset_s=2.6, estimate_time_constant_s=3.0
        ),
        description="ArduPilot in wind 4.6 m/s, anemometer clock 2.6 s ahead, wind estimate lagging 3 s: "
        "two lon sweeps, a thr sweep, doublets",
    ),
    _flight(
        "heldout-wind-clock-px4-behind",
        "ulog",
        _clock_steps(
            Chirp(duration_s=34.0, law="linear", f_min_hz=0.15, f_max_hz=8.0),
            Chirp(duration_s=30.0, f_max_hz=8.0, direction="down", fade_in_s=1.0, fade_out_s=3.0),
        ),
        seed=312,
        wind=WindModel(
            mean_speed_m_s=5.8, from_deg=200.0, sigma_m_s=0.9, clock_offset_s=-2.3, estimate_time_constant_s=2.0
        ),
        description="PX4 in wind 5.8 m/s, anemometer clock 2.3 s behind, wind estimate lagging 2 s: "
        "two lon sweeps, a thr sweep, doublets",
    ),
    _flight(
        "heldout-wind-clock-px4-slight",
        "ulog",
        _clock_steps(
            Chirp(duration_s=40.0, direction="down", fade_in_s=1.0, fade_out_s=3.0),
            Chirp(duration_s=30.0, f_max_hz=8.0, law="linear"),
        ),
        seed=313,
        wind=WindModel(
            mean_speed_m_s=5.2, from_deg=340.0, sigma_m_s=0.75, clock_offset_s=0.4, estimate_time_constant_s=4.0
        ),
        description="PX4 in wind 5.2 m/s, anemometer clock 0.4 s ahead, wind estimate lagging 4 s: "
        "two lon sweeps, a thr sweep, doublets",
    ),
    _flight(
        "heldout-wind-clock-ap-none",
        "dataflash",
        _clock_steps(
            Chirp(duration_s=36.0, law="linear", f_max_hz=6.0), Chirp(duration_s=30.0, f_min_hz=0.2, f_max_hz=6.0)
        ),
        seed=314,
        wind=WindModel(
            mean_speed_m_s=5.4, from_deg=100.0, sigma_m_s=0.6, clock_offset_s=0.0, estimate_time_constant_s=2.5
        ),
        description="ArduPilot in wind 5.4 m/s, anemometer clock right (0.0 s: no false alarm), wind estimate "
        "lagging 2.5 s: two lon sweeps, a thr sweep, doublets",
    ),
    _flight(
        "heldout-wind-calm",
        "ulog",
        _clock_steps(Chirp(duration_s=36.0), Chirp(duration_s=30.0, f_max_hz=8.0)),
        seed=315,
        wind=WindModel(
            mean_speed_m_s=0.8, from_deg=170.0, sigma_m_s=0.05, clock_offset_s=1.2, estimate_time_constant_s=3.0
        ),
        condition="calm",
        description="PX4, the calm airframe in a breath of wind (0.8 m/s, turbulence 0.05 m/s; no G_w), anemometer "
        "clock 1.2 s ahead, wind estimate lagging 3 s: two lon sweeps, a thr sweep, doublets",
    ),
    _flight(
        "heldout-px4-long-low",
        "ulog",
        _long_low_steps(),
        seed=210,
        heading_deg=-65.0,
        position_hold=False,
        description="PX4 in attitude hold (no position hold): long, low pitch and roll attitude sweeps, yaw, thr",
    ),
)

ALL_CASES: tuple[Case, ...] = TUNING_CASES + HELDOUT_CASES


def case_named(name: str) -> Case:
    """The catalogue case called `name`.

    Parameters
    ----------
    name : str
        A name from :data:`TUNING_CASES` or :data:`HELDOUT_CASES`.

    Returns
    -------
    Case

    Raises
    ------
    KeyError
        If no case has that name (the message lists them).

    Examples
    --------
    >>> case_named("heldout-ap-hover").fmt
    'dataflash'
    """
    for case in ALL_CASES:
        if case.name == name:
            return case
    raise KeyError(f"no case {name!r}; cases are {', '.join(c.name for c in ALL_CASES)}")
