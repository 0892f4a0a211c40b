"""The anemometer's clock offset, found by what it is for: the wind that best explains eq. 3.14's residual.

An anemometer logger's clock is rarely on UTC to the second, and the
autopilot's own wind estimate (a smoothed EKF state) and the attitude the
vehicle leans into the wind with both lag the air by a second or more in
closed loop: correlating the anemometer with either measures that lag as
well as the clock (issue 31). The wind step's residual has no such lag: the
accelerations answer the air through G_w within the wind delays (tens of
ms, Table 3.5). So the offset is scanned for the value whose wind, moved
along the log's clock, leaves the least of that residual once the G_w gains
are solved for it (linear least squares at each trial, the wind delays held
at their starting values), over all the campaign's wind records at once
(one logger, one clock):

- a coarse pass over ±5 s in 0.1 s steps on the records thinned to about
  20 Hz, then a fine pass in 10 ms steps about the coarse minimum at the
  records' own rate, out from it only as far as the least cost needs three
  steps each side (within ±0.15 s: :func:`_fine_costs`);
- moving the wind moves u v w too (eq. 3.1: the air-relative velocity is the
  ground velocity less the wind), and their terms in the residual with it;
- the offset's standard deviation is that of a least-squares parameter,
  from the cost's curvature at the minimum, ``sigma^2 = 2 s^2 / J''``, with
  ``s^2`` the weighted residual's variance inflated for its
  autocorrelation (Bartlett, as the wind step's Cramér–Rao bounds).

The scan claims an offset only when the wind carries information: the
minimum inside the scanned range, sharp (sigma at most
:data:`MAX_SIGMA_S`), and deep (the residual there at least
:data:`MIN_CONTRAST` below its median over the scan). Otherwise the offset
in use is kept, with the reason said; and when the wind cannot be timed at
all (too shallow, or at the scan's edge: calm air) the G_w terms are not
fitted either (:func:`untimed_wind`). The wind the scan and the wind step
regress on is low-passed at :data:`SMOOTHING_HZ` (zero phase): the
anemometer's own noise would otherwise shrink every estimate on it.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from flightlogs.conditioning.condition import ConditionedFlight
from flightlogs.errors import FitWarning
from flightlogs.frames import air_velocity_per_wind, wind_to_body_axes
from flightlogs.parallel import map_forked, worker_count
from flightlogs.record import Record
from sysid._filters import butterworth_zero_phase
from sysid.fit.result import WindClockOffset
from sysid.fit.wind import residual_inflation, wind_cost
from sysid.model.structure import ModelStructure

__all__ = [
    "MAX_SIGMA_S",
    "MIN_CONTRAST",
    "MIN_DISAGREEMENT_S",
    "SCAN_HALF_WIDTH_S",
    "SMOOTHING_HZ",
    "CostOf",
    "moved_flights",
    "moved_wind",
    "offset_given",
    "scan_wind_offset",
    "smoothed",
    "smoothed_flights",
    "timed_wind",
    "untimed_wind",
]

#: Half-width of the coarse scan, s: clock offsets of loggers set by hand, and the EKF's lag, are seconds.
SCAN_HALF_WIDTH_S = 5.0
_COARSE_STEP_S = 0.1
_COARSE_RATE_HZ = 20.0  # the coarse pass thins the records: the wind's turbulence is below 2 Hz
_FINE_HALF_WIDTH_S = 0.15
_FINE_STEP_S = 0.01
#: Largest standard deviation of an offset that is claimed, s.
MAX_SIGMA_S = 0.1
#: Least contrast of the residual's minimum (:attr:`WindClockOffset.contrast`) for the offset to be claimed.
MIN_CONTRAST = 0.03
_ANGLES = ("phi", "theta", "psi")
_NE = ("wind_n", "wind_e")


class CostOf(Protocol):
    """The residual's cost as a function of the records' moved signals (:class:`sysid.fit.wind.WindCost`)."""

    def __call__(self, changed: Sequence[Mapping[str, np.ndarray]]) -> tuple[float, float, np.ndarray]:
        """(cost with the best G_w gains, cost without wind, weighted residual after) of one mapping of moved
        signals (n_samples,) per record."""

    def costs(self, changed: Iterable[Mapping[str, np.ndarray]]) -> np.ndarray:
        """The cost with the best gains of several moves, shape (n_moves,), from one mapping of moved signals
        (n_moves, n_samples) per record."""


@dataclass(frozen=True, slots=True)
class _Moved:
    """One record's view of the wind: its piece's wind, and how u v w answer a change of it."""

    record: Record
    piece_time_s: np.ndarray
    piece_wind_ne: np.ndarray
    north: np.ndarray
    east: np.ndarray
    north_body: np.ndarray
    east_body: np.ndarray

    @classmethod
    def of(cls, record: Record, piece_time_s: np.ndarray, piece_wind_ne: np.ndarray) -> _Moved:
        """`record` with its piece's time (n_piece,) and wind (n_piece, 2); u v w per unit of wind, (n, 3) each,
        and wind_lon, wind_lat per unit of wind, (n, 2) each (the attitude's rotation, worked out once per record)."""
        angles = [record.absolute(n) for n in _ANGLES]
        per_wind = air_velocity_per_wind(*angles)
        unit = np.ones(record.time_s.size)
        return cls(
            record=record,
            piece_time_s=piece_time_s,
            piece_wind_ne=piece_wind_ne,
            north=np.ascontiguousarray(per_wind[:, :, 0]),
            east=np.ascontiguousarray(per_wind[:, :, 1]),
            north_body=wind_to_body_axes(np.column_stack([unit, 0.0 * unit]), angles[2]),
            east_body=wind_to_body_axes(np.column_stack([0.0 * unit, unit]), angles[2]),
        )

    def _rows(self, rows: slice, record: Record) -> _Moved:
        """The same for `record`, which is this one's `rows`: the rotations taken, not worked out again."""
        return replace(
            self,
            record=record,
            **{n: np.ascontiguousarray(getattr(self, n)[rows]) for n in ("north", "east", "north_body", "east_body")},
        )

    def every(self, rate_hz: float) -> _Moved:
        """The same with the record thinned to about `rate_hz` (every k-th sample), for a coarse look."""
        record = self.record
        k = max(int(record.rate_hz // rate_hz), 1)
        if k == 1:
            return self
        rows = slice(None, None, k)
        return self._rows(
            rows, replace(record, time_s=record.time_s[rows], columns={n: v[rows] for n, v in record.columns.items()})
        )

    def cut(self, first: int, last: int) -> _Moved:
        """The same, the record cut to its rows `first` to `last` (included)."""
        record = self.record
        cut = record.between(float(record.time_s[first]), float(record.time_s[last]), label=record.label)
        assert cut.time_s.size == last - first + 1  # a record's times increase: those rows
        return self._rows(slice(first, last + 1), cut)

    def reaches(self, shift_s: float) -> np.ndarray:
        """Rows of the record whose wind, moved by `shift_s`, lies inside the piece, shape (n_samples,) bool."""
        t = self.record.time_s - shift_s
        inside: np.ndarray = (t >= self.piece_time_s[0]) & (t <= self.piece_time_s[-1])
        return inside

    def columns(self, shift_s: float | np.ndarray) -> dict[str, np.ndarray]:
        """The record's wind signals and u v w with its piece's wind moved by `shift_s`, s: each (n_samples,), or
        (n_moves, n_samples) for moves of shape (n_moves,)."""
        record = self.record
        t = record.time_s - np.asarray(shift_s, dtype=np.float64)[..., None]
        change_n, change_e = (np.interp(t, self.piece_time_s, c) - record[s] for c, s in zip(self.piece_wind_ne.T, _NE))
        out = {"wind_n": record["wind_n"] + change_n, "wind_e": record["wind_e"] + change_e}
        for k, name in enumerate("uvw"):
            if name in record.signals:
                out[name] = record[name] + (change_n * self.north[:, k] + change_e * self.east[:, k])
        for k, name in enumerate(("wind_lon", "wind_lat")):  # wind_to_body_axes(change, psi)
            if name in record.signals:
                out[name] = record[name] + (change_n * self.north_body[:, k] + change_e * self.east_body[:, k])
        return out


def _piece_of(record: Record, flights: Sequence[ConditionedFlight]) -> Record | None:
    for flight in flights:
        if flight.source != record.source:
            continue
        for piece in flight.records:
            if piece.start_s <= record.start_s + 1e-9 and record.end_s <= piece.end_s + 1e-9:
                return piece
    return None


def _movable(records: Sequence[Record], flights: Sequence[ConditionedFlight], *, smooth: bool) -> list[_Moved]:
    needed = {"wind_n", "wind_e", *_ANGLES}
    out, winds = [], {}
    for record in records:
        piece = _piece_of(record, flights)
        if piece is not None and needed <= set(record.signals) and {"wind_n", "wind_e"} <= set(piece.signals):
            if id(piece) not in winds:  # a piece holds several records: its wind is smoothed once
                wind = np.column_stack([piece["wind_n"], piece["wind_e"]])
                winds[id(piece)] = smoothed(wind, piece.rate_hz) if smooth else wind
            out.append(_Moved.of(record, piece.time_s, winds[id(piece)]))
    return out


#: Low-pass of the anemometer's wind in the wind step, Hz: turbulence at hover wind speeds has under 1 % of
#: its power above it (Dryden, L = 33.7 m, 2-8 m/s), the anemometer's own noise most of its.
SMOOTHING_HZ = 2.0
_SMOOTHING_ORDER = 4
_SMOOTHING_PAD = 15  # sosfiltfilt's default for two biquads with zeros at z = -1: 3 (2 * 2 + 1)


def smoothed(wind_ne: np.ndarray, rate_hz: float) -> np.ndarray:
    """Zero-phase 4th-order Butterworth low-pass of the wind at :data:`SMOOTHING_HZ`.

    The anemometer's noise reaches u v w and the wind regressor alike:
    regressed on, white noise shrinks every estimate on the wind by
    var(noise) / var(wind), 4-8 % for a ±0.3 m/s sensor in 0.6-0.9 m/s of
    turbulence. Zero phase: the record is filtered whole, after the flight.

    Parameters
    ----------
    wind_ne : ndarray, shape (n_samples, n_columns)
        Wind components, m/s, evenly sampled.
    rate_hz : float
        Their sample rate, Hz.

    Returns
    -------
    ndarray, shape (n_samples, n_columns)
        The same low-passed; as given when under 32 samples or sampled under 4 times the cut-off.
    """
    if wind_ne.shape[0] < 32 or rate_hz <= 4 * SMOOTHING_HZ:
        return wind_ne
    # scipy.signal's sosfiltfilt(butter(4, ..., output="sos"), axis=0) to rounding, without its 0.5-0.75 s import
    columns = [
        butterworth_zero_phase(column, SMOOTHING_HZ, rate_hz, order=_SMOOTHING_ORDER, pad=_SMOOTHING_PAD)
        for column in np.asarray(wind_ne, dtype=np.float64).T
    ]
    return np.column_stack(columns)


def moved_wind(
    records: Sequence[Record], flights: Sequence[ConditionedFlight], shift_s: float, *, smooth: bool = True
) -> list[Record]:
    """The records with their wind moved `shift_s` later along the log's clock, and u v w with it.

    Parameters
    ----------
    records : sequence of Record
        Records of the wind step (pieces of the flights' records).
    flights : sequence of ConditionedFlight
        Their flights: the wind outside a record is read from its piece.
    shift_s : float
        Move, s (positive: the vehicle meets the air later).
    smooth : bool, optional
        Low-pass the wind first (:data:`SMOOTHING_HZ`, zero phase), as the wind step regresses on it.

    Returns
    -------
    list of Record
        Each record cut to the rows whose moved wind lies in its piece; a
        record that cannot be moved (no piece, no wind) or keeps under 16
        rows is left out.
    """
    out = []
    for moved in _movable(records, flights, smooth=smooth):
        rows = moved.reaches(shift_s)
        if rows.sum() < 16:
            continue
        whole, t = (
            replace(moved.record, columns=dict(moved.record.columns) | moved.columns(shift_s)),
            moved.record.time_s,
        )
        first, last = np.flatnonzero(rows)[[0, -1]]
        out.append(whole.between(float(t[first]), float(t[last]), label=whole.label))
    return out


def offset_given(flights: Sequence[ConditionedFlight]) -> bool:
    """Whether the user gave every flight's anemometer clock offset (``--wind-offset``).

    Parameters
    ----------
    flights : sequence of ConditionedFlight
        Conditioned flights (those without wind are not asked).

    Returns
    -------
    bool
    """
    return all(f.wind.clock_offset_source == "user" for f in flights if f.wind is not None)


def moved_flights(flights: Sequence[ConditionedFlight], shift_s: float) -> list[ConditionedFlight]:
    """The flights with their wind moved `shift_s` later and the clock offset changed to match.

    Parameters
    ----------
    flights : sequence of ConditionedFlight
        Conditioned flights; those without wind are returned as they are.
    shift_s : float
        Move, s (positive: the vehicle meets the air later, the anemometer's clock is that much ahead).

    Returns
    -------
    list of ConditionedFlight
        Each record cut to the rows its moved wind reaches; the alignment's
        offset is the one in use less `shift_s`, its source ``estimated``.
    """
    out = []
    for flight in flights:
        if flight.wind is None:
            out.append(flight)
            continue
        records = tuple(moved_wind(flight.records, [flight], shift_s, smooth=False))
        wind = replace(
            flight.wind, clock_offset_s=flight.wind.clock_offset_s - shift_s, clock_offset_source="estimated"
        )
        out.append(replace(flight, records=records, wind=wind))
    return out


def smoothed_flights(flights: Sequence[ConditionedFlight]) -> list[ConditionedFlight]:
    """The flights with their anemometer wind low-passed as the wind step regresses on it, u v w with it.

    G_w is identified on the wind low-passed at :data:`SMOOTHING_HZ`: the
    model's wind inputs are that wind. Driven with the anemometer's raw
    reading instead, a model passes the sensor's noise through its G_w
    gains straight to the accelerations (on the independent generator's
    ArduPilot case, 0.14 m/s^2 RMS of az at 2-10 Hz that the vehicle never
    felt), so a verification drives it with the same wind as the fit.

    Parameters
    ----------
    flights : sequence of ConditionedFlight
        Conditioned flights; those without wind, and records without the wind and the attitude, are kept as
        they are.

    Returns
    -------
    list of ConditionedFlight
        The same flights, clock and alignment unchanged, every record's
        ``wind_n``, ``wind_e``, ``wind_lon``, ``wind_lat`` and ``u v w`` those of the low-passed wind.
    """
    out = []
    for flight in flights:
        if flight.wind is None:
            out.append(flight)
            continue
        smooth = {id(moved.record): moved for moved in _movable(flight.records, [flight], smooth=True)}
        records = tuple(
            replace(r, columns=dict(r.columns) | smooth[id(r)].columns(0.0)) if id(r) in smooth else r
            for r in flight.records
        )
        out.append(replace(flight, records=records))
    return out


def scan_wind_offset(
    records: Sequence[Record],
    flights: Sequence[ConditionedFlight],
    cost_for: Callable[[Sequence[Record]], CostOf | None],
    *,
    half_width_s: float = SCAN_HALF_WIDTH_S,
) -> WindClockOffset | None:
    """Scan the move of the wind that leaves the least eq. 3.14 residual after the G_w gains.

    Parameters
    ----------
    records : sequence of Record
        Records of the wind step.
    flights : sequence of ConditionedFlight
        Their flights (the wind beyond a record, and the clock offset used).
    cost_for : callable
        ``cost_for(records)``: the cost of those records as a function of their moved signals
        (:func:`sysid.fit.wind.wind_cost`), or None when it cannot be computed.
    half_width_s : float, optional
        Half-width of the coarse scan, s.

    Returns
    -------
    WindClockOffset or None
        None when no record carries the wind and the attitude, with room in
        its flight's piece for the moves scanned.
    """
    edge = half_width_s + _FINE_HALF_WIDTH_S
    movable = []
    for moved in _movable(records, flights, smooth=True):  # one set of rows for every trial: those every move reaches
        rows = np.flatnonzero(moved.reaches(-edge) & moved.reaches(edge))
        if rows.size >= 16:
            movable.append(moved.cut(int(rows[0]), int(rows[-1])))
    if not movable:
        return None
    used = [f.wind.clock_offset_s for f in flights if f.wind is not None]
    delays = [f.wind.transport.delay_s for f in flights if f.wind is not None]
    cost_of = cost_for([m.record for m in movable])
    sparse = [m.every(_COARSE_RATE_HZ) for m in movable]
    coarse_cost_of = cost_for([m.record for m in sparse])
    if cost_of is None or coarse_cost_of is None:
        return None

    def at(shift: float) -> tuple[float, float, np.ndarray]:
        return cost_of([m.columns(shift) for m in movable])

    coarse = np.round(np.arange(-half_width_s, half_width_s + 1e-9, _COARSE_STEP_S), 10)
    rough = _costs(coarse, coarse_cost_of, sparse)
    centre = min(rough, key=rough.__getitem__)
    costs = _fine_costs(centre, cost_of, movable)
    level = costs[centre] / rough[centre]  # the coarse pass's samples and weights, brought to the fine pass's
    costs |= {s: c * level for s, c in rough.items() if s not in costs}
    shift = np.array(sorted(costs))
    cost = np.array([costs[s] for s in shift])
    best, curvature = _parabola(shift, cost, int(np.argmin(cost)))
    _, without, after = at(best)
    n = after.shape[0]
    sigma = math.sqrt(2.0 * residual_inflation(after) / (n * curvature)) if curvature > 0 else math.inf
    scan = WindClockOffset(
        shift_s=shift,
        cost=cost,
        cost_without_wind=without,
        best_shift_s=best,
        sigma_s=sigma,
        used_clock_offset_s=float(np.median(used)) if used else 0.0,
        transport_delay_s=float(np.median(delays)) if delays else math.nan,
        measured=False,
        reason="",
        samples=n,
    )
    reason = _unclaimed(scan, half_width_s)
    return replace(scan, measured=not reason, reason=reason)


def _costs(shifts: np.ndarray, cost_of: CostOf, movable: Sequence[_Moved]) -> dict[float, float]:
    """The cost at each move of the wind, s, by shift: the moves split over the cores, all the moves of a
    record at once (:meth:`CostOf.costs`)."""
    chunks = np.array_split(shifts, worker_count(shifts.size // _LEAST_MOVES_A_CORE))

    def chunk(k: int) -> np.ndarray:
        return cost_of.costs(m.columns(chunks[k]) for m in movable)

    found = np.concatenate(list(map_forked(chunk, len(chunks))))
    return dict(zip((float(s) for s in shifts), (float(c) for c in found)))


_LEAST_MOVES_A_CORE = 20  # fewer (the fine pass's) cost less in one process than a worker's start


def _fine_costs(centre: float, cost_of: CostOf, movable: Sequence[_Moved]) -> dict[float, float]:
    """The fine pass about the coarse minimum `centre`, s: the cost at fine steps out from it, each way only as
    far as needed for the least of them to have the parabola's neighbours (:func:`_parabola`) on both sides,
    within ±:data:`_FINE_HALF_WIDTH_S`.

    The coarse pass brackets the minimum within a coarse step, and the residual of a wind low-passed at 2 Hz
    changes over tenths of a second: a few fine steps about the centre find the least of the whole fine grid
    (8-10 of its 31 costs on the chapter 3 campaign and the generator's six windy cases, 16 on a calm one;
    the same minimum, the same offset and model, on all of them).
    """
    grid = np.round(centre + np.arange(-_FINE_HALF_WIDTH_S, _FINE_HALF_WIDTH_S + 1e-9, _FINE_STEP_S), 10)
    middle = grid.size // 2
    low, high = middle - _NEIGHBOURS, middle + _NEIGHBOURS
    costs = _costs(grid[low : high + 1], cost_of, movable)
    while True:
        best = middle + int(round((min(costs, key=costs.__getitem__) - centre) / _FINE_STEP_S))
        wanted = (max(best - _NEIGHBOURS, 0), min(best + _NEIGHBOURS, grid.size - 1))
        more = [*range(wanted[0], low), *range(high + 1, wanted[1] + 1)]
        if not more:
            return costs
        low, high = min(low, wanted[0]), max(high, wanted[1])
        costs |= _costs(grid[more], cost_of, movable)


_NEIGHBOURS = 3  # fine steps each side of the least cost that the parabola is fitted through


def _parabola(shift: np.ndarray, cost: np.ndarray, k: int) -> tuple[float, float]:
    """Vertex and second derivative of the parabola through the minimum and its neighbours (fine steps)."""
    near = np.flatnonzero(np.abs(shift - shift[k]) <= _NEIGHBOURS * _FINE_STEP_S + 1e-9)
    if near.size < 3:
        return float(shift[k]), 0.0
    a, b, _ = np.polyfit(shift[near] - shift[k], cost[near], 2)
    if a <= 0:
        return float(shift[k]), 0.0
    vertex = float(np.clip(-b / (2 * a), -_NEIGHBOURS * _FINE_STEP_S, _NEIGHBOURS * _FINE_STEP_S))
    return float(shift[k]) + vertex, 2.0 * float(a)


def untimed_wind(clock: WindClockOffset | None) -> str:
    """Why G_w cannot be fitted on wind that cannot be timed (calm air, an offset beyond the scan); "" when it can.

    A wind whose timing does not change the residual carries no information
    the G_w terms could be fitted to: what a regression on it finds is the
    anemometer's own noise, which reaches the residual through u v w (a
    calm-air flight gave X_w_lon = -0.27 ± 0.02, X_u's share of that noise).

    Parameters
    ----------
    clock : WindClockOffset or None
        The scan (None: not run, nothing to say).

    Returns
    -------
    str
        The reason, for :func:`sysid.fit.wind.unfitted_wind`.
    """
    if clock is None or clock.measured or not clock.reason:
        return ""
    if clock.contrast < MIN_CONTRAST or _at_edge(clock, SCAN_HALF_WIDTH_S):
        return f"the anemometer's wind cannot be timed against the flight: {clock.reason}"
    return ""


def _at_edge(scan: WindClockOffset, half_width_s: float) -> bool:
    return abs(scan.best_shift_s) > half_width_s - _COARSE_STEP_S


def _unclaimed(scan: WindClockOffset, half_width_s: float) -> str:
    if _at_edge(scan, half_width_s):
        return (
            f"the residual is least at the edge of the ±{half_width_s:g} s scanned "
            f"({scan.best_shift_s:+.2f} s): no minimum inside it; give `wind_offset_s`"
        )
    if scan.contrast < MIN_CONTRAST:
        return (
            f"the residual at its best timing is only {100 * scan.contrast:.1f} % below its median over the scan "
            f"(under {100 * MIN_CONTRAST:g} %): too little wind information to time it"
        )
    if not scan.sigma_s <= MAX_SIGMA_S:
        return f"the residual's minimum is too flat to time the wind (±{scan.sigma_s:.2f} s, over {MAX_SIGMA_S:g} s)"
    return ""


#: A given offset this far from the one measured (and 3 sigma) is said, s.
MIN_DISAGREEMENT_S = 0.2


def timed_wind(
    structure: ModelStructure,
    values: Mapping[str, float],
    constants: Mapping[str, float],
    records: Sequence[Record],
    flights: Sequence[ConditionedFlight],
    outputs: Sequence[str],
) -> tuple[list[Record], WindClockOffset | None, list[str]]:
    """The records the wind step fits, with the wind where the residual says the vehicle met it.

    The clock offset is scanned (:func:`scan_wind_offset`). Measured, it is
    applied unless every flight's offset was given by the user
    (``--wind-offset``); a given offset the residual disagrees with (by more
    than 3 sigma and :data:`MIN_DISAGREEMENT_S`) is kept, with a warning
    giving the offset measured and the residual at each. Not measured (calm
    air, no minimum), the offset in use is kept and the reason is a note.

    Parameters
    ----------
    structure : ModelStructure
        A structure with wind inputs.
    values : Mapping[str, float]
        F and G_u values (step 1).
    constants : Mapping[str, float]
        Trim constants, SI.
    records : sequence of Record
        Records of the wind step, as conditioned.
    flights : sequence of ConditionedFlight
        Their flights.
    outputs : sequence of str
        Outputs whose residual is fitted.

    Returns
    -------
    tuple
        The records (the wind moved when an offset is applied), the scan
        (None when it could not be run) and notes for the model.

    Warns
    -----
    FitWarning
        When a given offset disagrees with the one measured.
    """
    scan = scan_wind_offset(records, flights, lambda cut: wind_cost(structure, values, constants, cut, outputs))
    if scan is None:
        return list(records), None, []
    used = scan.used_clock_offset_s
    if not scan.measured:
        kept = moved_wind(records, flights, 0.0)
        return kept, scan, [f"anemometer clock offset not measured: {scan.reason}; {used:+.2f} s kept"]
    measured = f"{scan.clock_offset_s:+.2f} ± {scan.sigma_s:.2f} s"
    if not offset_given(flights):
        moved = moved_wind(records, flights, scan.best_shift_s)
        note = (
            f"anemometer clock offset {measured}, measured from the residual of eq. 3.14 "
            f"(there {100 * scan.contrast:.0f} % below its median over ±{SCAN_HALF_WIDTH_S:g} s); {used:+.2f} s was in use"
        )
        return moved, scan, [note]
    apart = abs(scan.best_shift_s)
    if apart > max(3 * scan.sigma_s, MIN_DISAGREEMENT_S):
        more = 100 * (scan.cost_at(0.0) / scan.cost_at(scan.best_shift_s) - 1)
        message = (
            f"the anemometer clock offset given, {used:+.2f} s, is {apart:.2f} s from the {measured} where the wind "
            f"best explains the accelerations (the residual of eq. 3.14 is {more:.0f} % larger at the offset given, "
            f"over {scan.samples} samples); the wind terms are fitted at the offset given: check it, "
            f"or leave `wind_offset_s` out to use the one measured"
        )
        warnings.warn(FitWarning(message), stacklevel=2)
        return moved_wind(records, flights, 0.0), scan, [message]
    return (
        moved_wind(records, flights, 0.0),
        scan,
        [f"anemometer clock offset given, {used:+.2f} s, agrees with {measured} measured"],
    )
