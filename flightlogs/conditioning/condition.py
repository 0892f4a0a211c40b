"""Condition a flight for identification: align, resample, rotate, segment, remove trim.

The steps, in order (chapter 3 of the dissertation, section 3.3.3):

1. one uniform time base, by default at the rate of the fastest core signal;
2. the anemometer wind put on the log's clock (UTC pairing, clock offset,
   transport delay of Taylor's frozen turbulence, over a distance given or
   found from the anemometer's and the vehicle's GPS positions) and
   resampled onto it;
3. the body air-relative velocity ``u v w`` of eq. 3.1 and the wind in body
   axes ``wind_lon wind_lat``;
4. the flight cut where a core signal has a gap, never interpolated across;
5. maneuvers found (ArduPilot System ID runs, else detected from the mixer
   inputs with the controller's state feedback removed, see
   :mod:`flightlogs.maneuvers.excitation_recovery`, or given by the user) and hover stretches;
6. trim (mean over hover, else over the record) removed and kept.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal

import numpy as np

from flightlogs._memory import give_back_freed_memory
from flightlogs._moving import erode
from flightlogs.conditioning.align import WindAlignment, estimate_residual_offset, wind_log_time
from flightlogs.conditioning.lag import TransportDelay, transport_delay
from flightlogs.conditioning.resample import contiguous_spans, resample_signals, uniform_time_base
from flightlogs.errors import DataError, DataQualityWarning, SysidWarning, collected_warnings
from flightlogs.flightlog import FlightLog, Signal, WindMeasurement
from flightlogs.frames import air_velocity_body, wind_to_body_axes
from flightlogs.geo import bearing_and_distance, local_north_east
from flightlogs.maneuvers.excitation_recovery import ExcitationRecovery
from flightlogs.maneuvers.segments import Segment, SegmentDetector, segments_from_sid
from flightlogs.masks import true_runs
from flightlogs.record import Record
from flightlogs.signals import STATE_SIGNALS

__all__ = ["ConditioningOptions", "ConditionedFlight", "condition_flight", "CORE_SIGNALS"]

#: Signals whose gaps cut a record; the time base follows the fastest of them.
CORE_SIGNALS = (
    "p",
    "q",
    "r",
    "phi",
    "theta",
    "psi",
    "ax",
    "ay",
    "az",
    "delta_lat",
    "delta_lon",
    "delta_yaw",
    "delta_thr",
)
_MIXER = {"lat": "delta_lat", "lon": "delta_lon", "yaw": "delta_yaw", "thr": "delta_thr"}
#: The traces that show each axis's maneuvers, for detection: the input, the references, the response.
_SHOWN_BY = {
    "lat": ("delta_lat", "stick_lat", "phi_ref", "p_ref", "p", "phi"),
    "lon": ("delta_lon", "stick_lon", "theta_ref", "q_ref", "q", "theta"),
    "yaw": ("delta_yaw", "stick_yaw", "r_ref", "r"),
    "thr": ("delta_thr", "stick_thr", "az", "vd"),
}
#: Where the vehicle is: used for the anemometer geometry, not carried into the records.
_POSITION = ("latitude", "longitude")
_MAX_GPS_DISTANCE_M = 1000.0  # farther, the anemometer's position is more likely mistyped than meant
_MIN_CORRELATION_S = 20.0  # shortest stretch a residual clock offset is estimated over


@dataclass(frozen=True, slots=True, kw_only=True)
class ConditioningOptions:
    """Choices for :func:`condition_flight`; every default follows the dissertation.

    Parameters
    ----------
    rate_hz : float or None
        Rate of the common time base, Hz; None for the fastest core signal's.
    wind_offset_s : float or None
        Anemometer clock minus the log's reference clock (UTC, or the log's
        own clock without GPS time), s; None to rely on GPS time alone.
    estimate_wind_offset : bool
        Also apply the residual clock offset found by cross-correlation.
    residual_offset : bool
        Measure that residual offset (the wind cross-correlated with the autopilot's wind estimate or the
        attitude, :attr:`WindAlignment.residual`) even when it is not applied: an ingest reports it. A fit,
        which times the wind on the identification itself, turns it off (a sixth of conditioning a sweep).
        Estimating the offset or the transport delay measures it whatever this says.
    estimate_transport_delay : bool
        Find the transport delay by cross-correlation instead (the clock
        offset is then trusted); a delay and a clock offset shift the wind the
        same way, so only one of the two can be estimated.
    wind_distance_m : float or None
        Anemometer-to-vehicle distance, m (the dissertation: 4.6 m).
    wind_bearing_rad : float or None
        Direction from the anemometer to the vehicle, rad from north; None for
        straight upstream.
    anemometer_position_rad : tuple of (float, float) or None
        WGS-84 latitude and longitude of the anemometer, rad. Without
        `wind_distance_m` and `transport_delay_s`, the distance and bearing
        come from it to the vehicle's mean GNSS position (signals
        ``latitude``, ``longitude``) while the anemometer record overlaps the
        flight.
    transport_delay_s : float or None
        Transport delay to use instead of distance / mean speed, s.
    max_gap_samples : float
        A core signal silent for more than this many of its sample intervals
        splits the record.
    min_record_s : float
        Pieces shorter than this are dropped, s.
    segments : tuple of Segment or None
        Maneuvers given by the user; None to find them.
    """

    rate_hz: float | None = None
    wind_offset_s: float | None = None
    estimate_wind_offset: bool = False
    residual_offset: bool = True
    estimate_transport_delay: bool = False
    wind_distance_m: float | None = None
    wind_bearing_rad: float | None = None
    anemometer_position_rad: tuple[float, float] | None = None
    transport_delay_s: float | None = None
    max_gap_samples: float = 5
    min_record_s: float = 2.0
    segments: tuple[Segment, ...] | None = None

    def __post_init__(self) -> None:
        if self.estimate_wind_offset and self.estimate_transport_delay:
            raise ValueError(
                "estimate either the clock offset or the transport delay, not both: they shift the wind alike"
            )
        if self.anemometer_position_rad is not None:
            lat, lon = (float(v) for v in self.anemometer_position_rad)
            if not (abs(lat) <= np.pi / 2 and abs(lon) <= np.pi):
                raise ValueError(
                    f"anemometer_position_rad={self.anemometer_position_rad} must be a latitude "
                    "within ±π/2 and a longitude within ±π, rad"
                )
            object.__setattr__(self, "anemometer_position_rad", (lat, lon))


@dataclass(frozen=True, slots=True, kw_only=True)
class ConditionedFlight:
    """A flight ready for frequency responses.

    Parameters
    ----------
    source : Path
        The log.
    records : tuple of Record
        Contiguous pieces on one uniform time base, trim removed.
    segments : tuple of Segment
        Maneuvers and hover stretches, on the log clock.
    rate_hz : float
        Rate of the records, Hz.
    wind : WindAlignment or None
        How the anemometer was aligned, if one was given.
    warnings : tuple of str
        Gaps, doubtful wind, dropped signals (the messages of the warnings
        raised while conditioning).
    derived : tuple of str
        The signals computed from others, not measured (a motion-capture
        table's specific forces, :attr:`flightlogs.flightlog.Signal.derived`).
    """

    source: Path
    records: tuple[Record, ...]
    segments: tuple[Segment, ...]
    rate_hz: float
    wind: WindAlignment | None = None
    warnings: tuple[str, ...] = ()
    derived: tuple[str, ...] = ()


def condition_flight(
    log: FlightLog,
    wind: WindMeasurement | None = None,
    options: ConditioningOptions = ConditioningOptions(),
) -> ConditionedFlight:
    """Align, resample, rotate, segment and de-trim one flight.

    Parameters
    ----------
    log : FlightLog
        The flight, as read.
    wind : WindMeasurement, optional
        Anemometer record overlapping the flight (see :func:`flightlogs.conditioning.align.pair_winds`).
    options : ConditioningOptions, optional
        Rates, offsets, distances, user segments.

    Returns
    -------
    ConditionedFlight

    Raises
    ------
    DataError
        If the log has none of the core signals, no stretch long enough, or
        the wind cannot be aligned.

    Warns
    -----
    DataQualityWarning
        For gaps that cut the records, signals left out of a record, wind
        that cannot stand for the wind at the vehicle, a clock offset not
        estimated, u v w without wind; every message is also in ``warnings``.
    """
    if options.estimate_transport_delay and wind is not None:
        return _with_estimated_delay(log, wind, options)
    with collected_warnings() as caught:
        first = _one_pass(log, wind, options)
        if isinstance(first, ConditionedFlight):
            return replace(first, warnings=caught.messages)
        caught.discard()  # this pass only measured the clock offset: the passes with it corrected say what holds
    assert wind is not None, "only a flight with wind has its clock offset measured"
    return _with_estimated_offset(log, wind, options, first)


def _one_pass(
    log: FlightLog, wind: WindMeasurement | None, options: ConditioningOptions
) -> ConditionedFlight | WindAlignment:
    """One conditioning; or, when the clock offset is to be estimated, the alignment whose residual measures it."""
    core = {name: _unwrapped(log.signals[name]) for name in CORE_SIGNALS if name in log.signals}
    if not core:
        raise DataError(f"{log.path}: none of the core signals ({', '.join(CORE_SIGNALS)}) is in the log")
    others = {n: _unwrapped(s) for n, s in log.signals.items() if n not in core and n not in _POSITION + STATE_SIGNALS}
    alignment, wind_signals = (None, {}) if wind is None else _wind_signals(log, wind, options)
    cut_by = core | wind_signals
    time_base = uniform_time_base(cut_by, rate_hz=options.rate_hz)
    rate_hz = 1.0 / float(np.median(np.diff(time_base)))
    if alignment is not None:
        _say_wind_cut(log, core, time_base, alignment)
    spans = contiguous_spans(
        cut_by, time_base, max_gap_samples=options.max_gap_samples, min_duration_s=options.min_record_s
    )
    for message in spans.messages():
        warnings.warn(DataQualityWarning(message), stacklevel=2)
    if not spans.spans:
        raise DataError(
            f"{log.path}: no stretch of at least {options.min_record_s:g} s where every core signal has data"
        )
    values = resample_signals(cut_by | others, time_base, max_gap_samples=options.max_gap_samples)
    holds = {name: 1.5 / rate for name, rate in _rates(others).items() if rate > 0}
    for name in others:
        _hold_edges(values[name], time_base, holds.get(name, 0.0))
    if "excitation" in values:  # logged only while a System ID run injects it: zero elsewhere
        np.nan_to_num(values["excitation"], nan=0.0, copy=False)
    units = {name: sig.unit for name, sig in (cut_by | others).items()}
    if alignment is not None and (options.residual_offset or options.estimate_wind_offset):
        alignment = _residual(alignment, time_base, values, rate_hz)
        if options.estimate_wind_offset and alignment.residual is not None:
            return alignment
        if options.estimate_wind_offset:
            message = (
                f"{log.path}: the clock offset was not estimated: that needs {_MIN_CORRELATION_S:g} s "
                "where the wind and the autopilot's wind estimate or attitude are logged together; "
                f"the offset used is {alignment.clock_offset_s:+.3f} s ({alignment.clock_offset_source})"
            )
            warnings.warn(DataQualityWarning(message), stacklevel=2)
    _derived(values, units, wind_given=bool(wind_signals))
    give_back_freed_memory()  # the resampler's working arrays: segmentation's are larger
    segments = _segments(log, time_base, values, options, spans.spans)
    records = tuple(
        _record(log, time_base, values, units, span, segments, f"piece {k + 1} of {len(spans.spans)}", holds)
        for k, span in enumerate(spans.spans)
    )
    derived = tuple(sorted(name for name, signal in log.signals.items() if signal.derived))
    return ConditionedFlight(
        source=log.path, records=records, segments=segments, rate_hz=rate_hz, wind=alignment, derived=derived
    )


def _rates(signals: Mapping[str, Signal]) -> dict[str, float]:
    """Each signal's logged rate, Hz, worked out once per time base: the fields of a log message share theirs."""
    by_times: dict[int, float] = {}
    for signal in signals.values():
        if id(signal.time_s) not in by_times:
            by_times[id(signal.time_s)] = signal.rate_hz
    return {name: by_times[id(signal.time_s)] for name, signal in signals.items()}


_CUT_WARN = 0.2  # the anemometer's overlap cutting more than this fraction off the log is said


def _say_wind_cut(log: FlightLog, core: dict[str, Signal], time_base: np.ndarray, alignment: WindAlignment) -> None:
    """Warn when the anemometer's overlap cuts a fifth of the log or more: maneuvers outside it are in no record.

    Issue 14: 20 campaign doublet logs of 8 s, their anemometer clock 1.5 s
    off, lost 2.6 s each and 17 of their 20 doublets without a word.
    """
    first = max(float(signal.time_s[0]) for signal in core.values())
    last = min(float(signal.time_s[-1]) for signal in core.values())
    lost = max(0.0, float(time_base[0]) - first) + max(0.0, last - float(time_base[-1]))
    if lost > _CUT_WARN * (last - first):  # a transport delay's worth at either end is expected
        message = (
            f"{log.path}: records cut to the anemometer's overlap, {time_base[0]:.2f}-{time_base[-1]:.2f} s of the "
            f"log's {first:.2f}-{last:.2f} s ({lost:.1f} s lost; transport delay {alignment.transport.delay_s:.2f} s, "
            f"clock offset {alignment.clock_offset_s:+.3f} s from {alignment.clock_offset_source}): maneuvers "
            "outside it are not used; if the anemometer's clock is off, give `estimate_wind_offset` or `wind_offset_s`"
        )
        warnings.warn(DataQualityWarning(message), stacklevel=3)


def _hold_edges(column: np.ndarray, time_base: np.ndarray, max_hold_s: float) -> None:
    """Hold the first and last value of a slower signal over the few core samples it stops short of, in place.

    A 25 Hz estimate that ends 30 ms before the 100 Hz core signals would
    otherwise leave NaNs at the record's edge and be left out of it. In
    place: the column is a view into the resampler's block of its message,
    which a copy would keep alive beside it.
    """
    finite = np.flatnonzero(np.isfinite(column))
    if finite.size == 0:
        return
    first, last = finite[0], finite[-1]
    if time_base[first] - time_base[0] <= max_hold_s:
        column[:first] = column[first]
    if time_base[-1] - time_base[last] <= max_hold_s:
        column[last + 1 :] = column[last]


def _unwrapped(signal: Signal) -> Signal:
    """Heading and its setpoint made continuous before they are interpolated (no jumps at ±π)."""
    if signal.name not in ("psi", "psi_ref"):
        return signal
    return Signal(
        name=signal.name,
        time_s=signal.time_s,
        values=np.unwrap(signal.values),
        unit=signal.unit,
        source=f"{signal.source}, unwrapped",
    )


def _wind_signals(
    log: FlightLog, wind: WindMeasurement, options: ConditioningOptions
) -> tuple[WindAlignment, dict[str, Signal]]:
    if log.utc_offset_s is None and options.wind_offset_s is None:
        raise DataError(
            f"{log.path}: the log has no GPS time, so the anemometer cannot be aligned by UTC; "
            "give `wind_offset_s` (anemometer time minus log time, s)"
        )
    clock_offset = options.wind_offset_s or 0.0
    source: Literal["gps", "user"] = "user" if options.wind_offset_s is not None else "gps"
    reference: Literal["utc", "log"] = "utc" if log.utc_offset_s is not None else "log"
    start, end = log.time_range_s
    raw_time = wind_log_time(log, wind, clock_offset_s=clock_offset, transport_delay_s=0.0)
    during = (raw_time >= start) & (raw_time <= end)
    if during.sum() < 2:
        raise DataError(f"{wind.path}: the anemometer record does not overlap {log.path.name} in time")
    wind_ne = np.column_stack([wind.wind_n, wind.wind_e])
    delay = _transport_delay(log, wind_ne[during], raw_time[during], options)
    if not delay.frozen_turbulence_holds:
        message = (
            f"{wind.path}: sigma_M/M = {delay.turbulence_ratio:.2f} is not below 0.5, so Taylor's frozen "
            "turbulence does not hold: the anemometer wind is a poor stand-in for the wind at the vehicle"
        )
        warnings.warn(DataQualityWarning(message), stacklevel=2)
    time_s = raw_time + delay.delay_s
    overlap = float(min(end, time_s[-1]) - max(start, time_s[0]))
    alignment = WindAlignment(
        wind_path=Path(wind.path),
        reference=reference,
        clock_offset_s=clock_offset,
        clock_offset_source=source,
        transport=delay,
        overlap_s=overlap,
    )
    series = {
        name: Signal(
            name=name,
            time_s=time_s,
            values=column,
            unit="m/s",
            source=f"{Path(wind.path).name}:{label} (delayed {delay.delay_s:.3f} s)",
        )
        for name, column, label in (("wind_n", wind.wind_n, "north"), ("wind_e", wind.wind_e, "east"))
    }
    return alignment, series


def _transport_delay(
    log: FlightLog, wind_ne: np.ndarray, wind_time_s: np.ndarray, options: ConditioningOptions
) -> TransportDelay:
    """Distance / mean speed along the line, the line from the options or from GNSS positions."""
    if options.anemometer_position_rad is None or options.transport_delay_s is not None:
        return transport_delay(
            wind_ne,
            distance_m=options.wind_distance_m,
            bearing_rad=options.wind_bearing_rad,
            delay_s=options.transport_delay_s,
        )
    if options.wind_distance_m is not None:
        message = (
            "the anemometer-to-vehicle distance was given (`wind_distance_m`): the anemometer's position is not used"
        )
        warnings.warn(SysidWarning(message), stacklevel=2)
        return transport_delay(wind_ne, distance_m=options.wind_distance_m, bearing_rad=options.wind_bearing_rad)
    if options.wind_bearing_rad is not None:
        message = (
            "the bearing from the anemometer to the vehicle comes from their positions; `wind_bearing_rad` is not used"
        )
        warnings.warn(SysidWarning(message), stacklevel=2)
    bearing, distance = _gps_geometry(log, options.anemometer_position_rad, wind_time_s)
    return replace(transport_delay(wind_ne, distance_m=distance, bearing_rad=bearing), source="gps")


def _gps_geometry(log: FlightLog, anemometer_rad: tuple[float, float], wind_time_s: np.ndarray) -> tuple[float, float]:
    """Bearing (rad) and distance (m) from the anemometer to the vehicle's mean position while the wind overlaps."""
    if not set(_POSITION) <= log.signals.keys():
        raise DataError(
            f"{log.path}: the log holds no GNSS position (latitude, longitude), so the anemometer-to-vehicle "
            "distance cannot be found from the anemometer's position; give `wind_distance_m`"
        )
    lat_signal, lon_signal = log.signals["latitude"], log.signals["longitude"]
    time_s = lat_signal.time_s
    inside = (time_s >= wind_time_s[0]) & (time_s <= wind_time_s[-1])
    if not inside.any():
        inside = np.ones(time_s.size, dtype=bool)
    lat = lat_signal.values[inside]
    lon = np.interp(time_s[inside], lon_signal.time_s, lon_signal.values)
    mean_lat = float(lat.mean())
    mean_lon = float(np.arctan2(np.sin(lon).mean(), np.cos(lon).mean()))  # across ±180° too
    bearing, distance = bearing_and_distance(*anemometer_rad, mean_lat, mean_lon)
    if distance > _MAX_GPS_DISTANCE_M:
        raise DataError(
            f"{log.path}: the anemometer ({np.degrees(anemometer_rad[0]):.6f}, {np.degrees(anemometer_rad[1]):.6f}) "
            f"is {distance / 1000:.1f} km from the vehicle's mean GPS position ({np.degrees(mean_lat):.6f}, "
            f"{np.degrees(mean_lon):.6f}), too far for its wind to stand for the vehicle's; check the "
            "anemometer's position (latitude first, degrees) or give `wind_distance_m`"
        )
    north, east = local_north_east(lat, lon, mean_lat, mean_lon)
    spread = float(np.hypot(north, east).max())
    if spread > 0.5 * distance:
        message = (
            f"{log.path.name}: the vehicle moved up to {spread:.1f} m from its mean position, which is "
            f"{distance:.1f} m from the anemometer: one transport delay is a rough stand-in for a varying one"
        )
        warnings.warn(DataQualityWarning(message), stacklevel=2)
    return bearing, distance


def _residual(
    alignment: WindAlignment, time_base: np.ndarray, values: dict[str, np.ndarray], rate_hz: float
) -> WindAlignment:
    """Residual clock offset over the longest stretch where the wind and what it is compared with are logged."""
    for needed in (("est_wind_n", "est_wind_e"), ("phi", "theta", "psi")):
        if not set(needed) <= values.keys():
            continue
        columns = ("wind_n", "wind_e", *needed)
        start, stop = _longest_finite_run(np.all([np.isfinite(values[n]) for n in columns], axis=0))
        if stop - start < _MIN_CORRELATION_S * rate_hz:
            continue
        table = {n: values[n][start:stop] for n in columns}
        estimate, against = estimate_residual_offset(
            time_base[start:stop], np.column_stack([table["wind_n"], table["wind_e"]]), table, rate_hz
        )
        if estimate is not None:
            return replace(alignment, residual=estimate, residual_against=against)
    return alignment


def _longest_finite_run(mask: np.ndarray) -> tuple[int, int]:
    """Bounds [start, stop) of the longest run of True in `mask` ((0, 0) if none)."""
    return max(true_runs(mask), key=lambda run: run[1] - run[0], default=(0, 0))


_MAX_OFFSET_ITERATIONS = 6


def _with_estimated_offset(
    log: FlightLog, wind: WindMeasurement, options: ConditioningOptions, first: WindAlignment
) -> ConditionedFlight:
    """Condition again with the clock offset corrected by the residual found (vehicle lags by +lag).

    A large first residual is measured on a broad correlation peak, so the
    correction is repeated until what is left is under a tenth of a sample;
    only the last pass's warnings go on.
    """
    assert first.residual is not None
    corrected = first.clock_offset_s - first.residual.lag_s
    with collected_warnings() as caught:
        for _ in range(_MAX_OFFSET_ITERATIONS):
            caught.discard()  # an earlier pass's: superseded by this one
            moved = replace(options, wind_offset_s=corrected, estimate_wind_offset=False, residual_offset=True)
            again = condition_flight(log, wind, moved)
            assert again.wind is not None
            left = again.wind.residual
            if left is None or abs(left.lag_s) < 0.1 / again.rate_hz:
                break
            corrected -= left.lag_s
    assert again.wind is not None  # its residual is what is left after the correction, not the offset corrected
    return replace(again, wind=replace(again.wind, clock_offset_source="estimated"))


def _with_estimated_delay(log: FlightLog, wind: WindMeasurement, options: ConditioningOptions) -> ConditionedFlight:
    """Condition without a delay, take the vehicle's lag behind the wind as the delay, condition again."""
    with collected_warnings() as caught:
        undelayed = replace(options, transport_delay_s=0.0, estimate_transport_delay=False, residual_offset=True)
        first = condition_flight(log, wind, undelayed)
        caught.discard()  # the pass without a delay only measures it: the pass with it says what holds
    assert first.wind is not None
    if first.wind.residual is None:
        raise DataError(
            f"{log.path}: the transport delay cannot be estimated: the log has neither an autopilot wind "
            "estimate nor attitude to correlate the wind with; give `wind_distance_m` or `transport_delay_s`"
        )
    delay = first.wind.residual.lag_s
    if delay < 0:
        raise DataError(
            f"{log.path}: the vehicle sees the wind {-delay:.2f} s before the anemometer: it is not upstream "
            "(or its clock is off); give `wind_distance_m` or `transport_delay_s`"
        )
    again = condition_flight(log, wind, replace(options, transport_delay_s=delay, estimate_transport_delay=False))
    assert again.wind is not None
    transport = replace(again.wind.transport, source="correlation")
    return replace(again, wind=replace(again.wind, transport=transport))  # residual: what is left with the delay


def _derived(values: dict[str, np.ndarray], units: dict[str, str], *, wind_given: bool) -> None:
    """Add u v w (eq. 3.1) and, with wind, wind_lon wind_lat."""
    have = values.keys()
    wind_ne = np.column_stack([values["wind_n"], values["wind_e"]]) if wind_given else None
    if {"vn", "ve", "vd", "phi", "theta", "psi"} <= have:
        n = values["vn"].size
        uvw = air_velocity_body(
            np.column_stack([values["vn"], values["ve"], values["vd"]]),
            wind_ne if wind_ne is not None else np.zeros((n, 2)),
            values["phi"],
            values["theta"],
            values["psi"],
        )
        for k, name in enumerate("uvw"):
            values[name] = uvw[:, k]
            units[name] = "m/s"
        if wind_ne is None:
            message = "no wind given: u v w are ground-relative velocities in body axes"
            warnings.warn(DataQualityWarning(message), stacklevel=2)
    if wind_ne is not None and "psi" in have:
        body = wind_to_body_axes(wind_ne, values["psi"])
        values["wind_lon"], values["wind_lat"] = body[:, 0], body[:, 1]
        units["wind_lon"] = units["wind_lat"] = "m/s"


def _segments(
    log: FlightLog,
    time_base: np.ndarray,
    values: dict[str, np.ndarray],
    options: ConditioningOptions,
    pieces: Sequence[tuple[float, float]],
) -> tuple[Segment, ...]:
    """The maneuvers given, logged (SIDS) or detected, and the hovers: airborne stretches inside one record piece."""
    if options.segments is not None:
        return tuple(sorted(options.segments, key=lambda s: s.start_s))
    logged = segments_from_sid(log.system_id_runs) if log.system_id_runs else ()
    inputs = {axis: values[name] for axis, name in _MIXER.items() if name in values}
    shown = {axis: [name for name in names if name in values] for axis, names in _SHOWN_BY.items()}
    if not inputs and not any(shown.values()):
        return tuple(logged)
    between = _between(time_base, logged)
    quiet = np.zeros(time_base.size, dtype=bool)
    for start, stop in between:
        quiet[start:stop] = True
    # the sweeps are found in the logged traces, once; the steps in the excitation, refitted below
    detectors = [
        (start, stop, SegmentDetector(time_base[start:stop], responses=_finite_traces(values, shown, start, stop)))
        for start, stop in between
    ]
    flying, vd, flight_shown = _flight_state(log, time_base, values)
    within = np.zeros(time_base.size, dtype=bool)
    for first, last in pieces:
        within |= (time_base >= first) & (time_base <= last)

    def flown(found: Sequence[Segment]) -> list[Segment]:
        return [
            s
            for s in found
            if not any(_overlaps(s, run) for run in logged) and s.kind != "hover" and _flown(s, time_base, flying, vd)
        ]

    detected: list[Segment] = []
    fitted_on: np.ndarray | None = None
    recovery = ExcitationRecovery(inputs, values, time_s=time_base)
    for _ in range(2):  # fit the feedback where nothing is excited, detect, refit without the maneuvers flown
        unexcited = quiet & ~_near(time_base, flown(detected), 2.0)
        if fitted_on is not None and np.array_equal(unexcited, fitted_on):
            break  # nothing flown to leave out: the refit would repeat the first pass exactly
        fitted_on = unexcited
        excitation = recovery.estimate(unexcited, read=quiet)  # detection reads the stretches between the logged runs
        detected = [
            segment
            for start, stop, detector in detectors
            for segment in detector.detect({a: x[start:stop] for a, x in excitation.items()})
        ]
    kept = flown(detected)
    hovers = [piece for s in detected if s.kind == "hover" for piece in _airborne(s, time_base, flying & within)]
    hovers = hovers if flight_shown else []  # no thrust and no land detector: nothing shows the vehicle off the ground
    return tuple(sorted([*logged, *kept, *hovers], key=lambda s: s.start_s))


def _airborne(hover: Segment, time_base: np.ndarray, flying: np.ndarray) -> list[Segment]:
    """The parts of a quiet stretch where the vehicle flies (ground time is quiet too, but no trim)."""
    inside = flying & (time_base >= hover.start_s) & (time_base <= hover.end_s)
    return [
        replace(hover, start_s=float(time_base[a]), end_s=float(time_base[b - 1]))
        for a, b in true_runs(inside)
        if time_base[b - 1] - time_base[a] >= _MIN_HOVER_S
    ]


_THRUST_ON = 0.3  # flying: thrust above this fraction of its 95th percentile
_HOVER_THRUST = ("MPC_THR_HOVER", "MOT_THST_HOVER")  # the hover thrust, normalised, where the autopilot keeps it
_HOVER_FRACTION = 0.5  # flying: thrust above this fraction of the hover thrust, where it is known
_MIN_HOVER_S = 3.0  # shortest hover kept once ground time is taken out, s (as detect_segments')
_SETTLE_S = 2.0  # flying: this long after take-off and before landing are neither; the hover before a maneuver
_LEVEL_M_S = 0.5  # level hover: |mean vertical speed| over the _SETTLE_S before a maneuver below this


def _flight_state(
    log: FlightLog, time_base: np.ndarray, values: dict[str, np.ndarray]
) -> tuple[np.ndarray, np.ndarray, bool]:
    """Where the vehicle flies (armed, not landed, thrust on, away from take-off and landing), its vertical
    speed, m/s, and whether the log shows flight at all (a thrust or a land detector).

    Thrust is the mixer's, else the motors' mean; without either, or
    without a vertical speed, every sample passes that test (a maneuver is
    then judged by its own traces), but nothing shows the vehicle off the
    ground, so no hover is claimed. With a hover thrust among the parameters
    (``MPC_THR_HOVER``, ``MOT_THST_HOVER``) thrust is on from half of it.
    ``armed`` and ``landed`` (:data:`~flightlogs.signals.STATE_SIGNALS`),
    where the log has them, are held from each sample to the next: a bench
    board that is never armed, or a vehicle its land detector puts on the
    ground, does not fly whatever its thrust. A log that starts or ends in
    flight has no take-off or landing at its edges.
    """
    dt = float(np.median(np.diff(time_base))) if time_base.size > 1 else 1.0
    width = max(1, int(round(_SETTLE_S / dt)))
    flying = np.ones(time_base.size, dtype=bool)
    thrust = values.get("delta_thr")
    motors = [v for name, v in values.items() if name.startswith("motor_")]
    if thrust is None and motors:
        thrust = np.mean(motors, axis=0)
    shown = "landed" in log.signals or (thrust is not None and bool(np.isfinite(thrust).any()))
    if thrust is not None and np.isfinite(thrust).any():
        level_on = _THRUST_ON * float(np.nanpercentile(thrust, 95))
        hover = next((log.parameters[p] for p in _HOVER_THRUST if p in log.parameters), None)
        if hover is not None and thrust is values.get("delta_thr") and 0 < hover < 1:
            level_on = max(level_on, _HOVER_FRACTION * hover)
        on = np.nan_to_num(thrust, nan=-np.inf) > level_on if level_on > 0 else np.zeros(time_base.size, dtype=bool)
        flying = erode(on, width) if on.any() else on
    for name, flies_when in (("armed", 1.0), ("landed", 0.0)):
        if name in log.signals:
            state = _held(log.signals[name], time_base)
            flying &= erode(np.isnan(state) | (state == flies_when), width)
    vd = values.get("vd")
    climb = vd if vd is not None and np.isfinite(vd).all() else np.zeros(time_base.size)
    return flying, climb, shown


def _held(signal: Signal, time_base: np.ndarray) -> np.ndarray:
    """A state signal on `time_base`, each sample held until the next; NaN before its first."""
    index = np.searchsorted(signal.time_s, time_base, side="right") - 1
    held = signal.values[np.maximum(index, 0)].astype(np.float64)
    held[index < 0] = np.nan
    return held


def _flown(segment: Segment, time_base: np.ndarray, flying: np.ndarray, vd: np.ndarray) -> bool:
    """Whether `segment` is flown from a steady hover: flying throughout and just after, level just before.

    A take-off, a landing flare or a mission's climb is not a maneuver,
    however much its input looks like one. After a maneuver the loop may
    still be recovering height, so only the hover it starts from must be level.
    """
    around = (time_base >= segment.start_s - _SETTLE_S) & (time_base <= segment.end_s + _SETTLE_S)
    before = around & (time_base < segment.start_s)
    level = not before.any() or abs(float(np.mean(vd[before]))) < _LEVEL_M_S
    return bool(flying[around].all() and level)


def _finite_traces(
    values: dict[str, np.ndarray], shown: dict[str, list[str]], start: int, stop: int
) -> dict[str, dict[str, np.ndarray]]:
    """The traces of each axis on samples [start, stop) that are finite on most of them, gaps bridged.

    A trace with a gap (a lost message, a dropout the record was cut at)
    still shows the maneuvers around it: its gaps are filled by straight
    lines. One finite on less than `_MIN_FINITE` of the stretch is left out.
    """
    out: dict[str, dict[str, np.ndarray]] = {}
    for axis, names in shown.items():
        finite = {}
        for name in names:
            x = values[name][start:stop]
            ok = np.isfinite(x)
            if ok.all():
                finite[name] = x
            elif ok.mean() >= _MIN_FINITE:
                index = np.arange(x.size)
                finite[name] = np.interp(index, index[ok], x[ok])
        if finite:
            out[axis] = finite
    return out


_MIN_FINITE = 0.9  # a trace finite on less of a stretch is not used to find its maneuvers


def _near(time_base: np.ndarray, segments: Sequence[Segment], margin_s: float) -> np.ndarray:
    """Samples within `margin_s` of a maneuver (hover stretches excepted)."""
    mask = np.zeros(time_base.size, dtype=bool)
    for segment in segments:
        if segment.kind != "hover":
            mask |= (time_base >= segment.start_s - margin_s) & (time_base <= segment.end_s + margin_s)
    return mask


_MIN_DETECTION_S = 5.0


def _between(time_base: np.ndarray, logged: Sequence[Segment]) -> list[tuple[int, int]]:
    """Index ranges [start, stop) of the stretches outside the logged System ID runs (with 0.5 s margins).

    Detection runs on each separately, so a logged sweep neither merges with
    its neighbours nor sets their noise floor.
    """
    free = np.ones(time_base.size, dtype=bool)
    for run in logged:
        free &= (time_base < run.start_s - 0.5) | (time_base > run.end_s + 0.5)
    rate = 1.0 / float(np.median(np.diff(time_base)))
    return [(a, b) for a, b in true_runs(free) if (b - a) / rate >= _MIN_DETECTION_S]


def _overlaps(a: Segment, b: Segment) -> bool:
    return a.start_s < b.end_s and b.start_s < a.end_s


def _record(
    log: FlightLog,
    time_base: np.ndarray,
    values: dict[str, np.ndarray],
    units: dict[str, str],
    span: tuple[float, float],
    segments: Sequence[Segment],
    label: str,
    holds: Mapping[str, float] | None = None,
) -> Record:
    """One record: the conditioned values over `span`, trim removed.

    A slower signal whose samples stop short of a piece's edges (the core signals resume a sample after
    a logging dropout; a 10 Hz estimate a tenth of a second later) has its first and last value held
    over those edges, up to `holds` seconds (1.5 of its periods), as at the log's own edges; a signal
    not logged through the rest of the piece is left out of the record, with a warning.
    """
    first = int(np.searchsorted(time_base, span[0] - 1e-9, side="left"))
    stop = int(np.searchsorted(time_base, span[1] + 1e-9, side="right"))
    columns, taken = {}, set()
    for name, column in values.items():
        # the record takes its piece of the conditioned values, not a copy: they are not used after it
        piece = column[first:stop] if id(column) not in taken else column[first:stop].copy()
        taken.add(id(column))
        if holds and name in holds and not np.all(np.isfinite(piece)):
            piece = piece.copy()  # the hold is this record's: the column's NaNs stay for the neighbouring piece
            _hold_edges(piece, time_base[first:stop], holds[name])
        if np.all(np.isfinite(piece)):
            columns[name] = piece
        else:
            message = f"{name}: not logged through {label} ({span[0]:.2f}-{span[1]:.2f} s); left out of it"
            warnings.warn(DataQualityWarning(message), stacklevel=2)
    t = time_base[first:stop]
    quiet = np.zeros(t.size, dtype=bool)
    for segment in segments:
        if segment.kind == "hover":
            quiet |= (t >= segment.start_s) & (t <= segment.end_s)
    rows = quiet if quiet.sum() >= 10 else slice(None)
    trim = {}
    for name, piece in columns.items():  # each piece is this record's alone: the trim comes off in place
        trim[name] = float(np.mean(piece[rows]))
        piece -= trim[name]
    return Record(time_s=t, columns=columns, units=units, trim=trim, source=log.path, label=label)
