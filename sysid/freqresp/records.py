"""From conditioned flights to the records and pairs a set of responses is computed on."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from types import MappingProxyType

import numpy as np

from flightlogs.conditioning.condition import ConditionedFlight
from flightlogs.errors import DataError
from flightlogs.maneuvers.segments import AXES
from flightlogs.record import Record
from flightlogs.signals import COMMAND_AXES
from sysid.freqresp.estimate import frequency_responses
from sysid.freqresp.options import ResponseOptions
from sysid.freqresp.response import FrequencyResponse

__all__ = [
    "DEFAULT_PAIRS",
    "EXCITATION",
    "maneuver_records",
    "maneuver_band",
    "quiet_records",
    "within_band",
    "parse_pairs",
    "default_pairs",
    "reference_options",
    "FlightResponses",
    "flight_responses",
]

#: Outputs per mixer axis, after the chapter 3 model (eqs. 3.10-3.13, accelerations by eq. 3.7); inputs ``delta_<axis>``.
DEFAULT_PAIRS: Mapping[str, tuple[str, ...]] = MappingProxyType(
    {
        "lon": ("q", "ax", "theta", "u"),
        "lat": ("p", "ay", "phi", "v"),
        "yaw": ("r", "psi"),
        "thr": ("az", "w"),
    }
)
_MIN_PIECE_SAMPLES = 16
#: The canonical signal holding the injected excitation (ArduPilot SIDD), used as reference when logged.
EXCITATION = "excitation"


def maneuver_records(
    flights: Sequence[ConditionedFlight], axis: str, *, kind: str = "sweep", margin_s: float = 1.0
) -> list[Record]:
    """The record pieces covering each maneuver of `kind` on `axis`, flight by flight, in time order.

    Parameters
    ----------
    flights : sequence of ConditionedFlight
        Conditioned flights (records and segments on the log clock).
    axis : {"lat", "lon", "yaw", "thr"}
        Mixer axis excited.
    kind : str, optional
        Maneuver kind (``"sweep"``, ``"doublet"``, ``"3211"``, ``"multisine"``).
    margin_s : float, optional
        Trim flight kept before and after each maneuver, s, never reaching
        into another maneuver: the response to the last of a sweep outlasts
        it, and windows ending on the sweep's top frequencies would taper it
        away (default 1 s).

    Returns
    -------
    list of Record
        One piece per maneuver and record it overlaps (a maneuver cut by a
        gap gives two pieces); pieces under 16 samples are left out.

    Raises
    ------
    DataError
        If `axis` is not a mixer axis or `margin_s` is negative.
    """
    if axis not in AXES:
        raise DataError(f"axis {axis!r} is not a mixer axis ({', '.join(AXES)})")
    if not margin_s >= 0:
        raise DataError(f"margin_s={margin_s} must be >= 0")
    pieces: list[Record] = []
    for flight in flights:
        maneuvers = [s for s in flight.segments if s.kind != "hover"]
        for segment in maneuvers:
            if segment.axis != axis or segment.kind != kind:
                continue
            before = max([s.end_s for s in maneuvers if s.end_s <= segment.start_s], default=-np.inf)
            after = min([s.start_s for s in maneuvers if s.start_s >= segment.end_s], default=np.inf)
            first = max(segment.start_s - margin_s, before)
            last = min(segment.end_s + margin_s, after)
            for record in flight.records:
                start, end = max(first, record.start_s), min(last, record.end_s)
                if end <= start or record.samples_between(start, end) < _MIN_PIECE_SAMPLES:
                    continue
                label = f"{flight.source.name} {axis} {kind} {segment.start_s:.2f}-{segment.end_s:.2f} s"
                pieces.append(record.between(start, end, label=label))
    return pieces


def quiet_records(
    flights: Sequence[ConditionedFlight],
    axis: str,
    *,
    before_s: float = 2.0,
    after_s: float = 5.0,
    min_s: float = 4.0,
) -> list[Record]:
    """Flight with no maneuver on `axis`: the pieces of the other axes' maneuvers and of hover, in time order.

    In closed loop the mixer input of `axis` carries the autopilot's
    feedback of sensor noise and disturbances all the time; flown with no
    excitation on `axis`, these pieces measure that feedback alone (its
    "floor"), which :func:`~sysid.freqresp.frequency_responses` removes from
    the maneuvers' spectra. Only the other maneuvers (with the 1 s margin
    :func:`maneuver_records` keeps) and hover segments count, so take-off,
    landing and time on the ground never do.

    Parameters
    ----------
    flights : sequence of ConditionedFlight
        Conditioned flights.
    axis : {"lat", "lon", "yaw", "thr"}
        Mixer axis whose maneuvers are kept out.
    before_s, after_s : float, optional
        Flight kept out before and after each maneuver on `axis`, s (the
        response outlasts the excitation; default 2 s and 5 s).
    min_s : float, optional
        Shortest piece kept, s.

    Returns
    -------
    list of Record
        Pieces of the flights' records.

    Raises
    ------
    DataError
        If `axis` is not a mixer axis.
    """
    if axis not in AXES:
        raise DataError(f"axis {axis!r} is not a mixer axis ({', '.join(AXES)})")
    pieces: list[Record] = []
    for flight in flights:
        spans = sorted(
            (s.start_s - (0.0 if s.kind == "hover" else 1.0), s.end_s + (0.0 if s.kind == "hover" else 1.0))
            for s in flight.segments
            if s.axis != axis
        )
        excited = [(s.start_s - before_s, s.end_s + after_s) for s in flight.segments if s.axis == axis]
        for start, end in _merged(spans):
            for first, last in _without((start, end), excited):
                for record in flight.records:
                    a, b = max(first, record.start_s), min(last, record.end_s)
                    if b - a >= min_s and record.samples_between(a, b) >= _MIN_PIECE_SAMPLES:
                        pieces.append(record.between(a, b, label=f"{flight.source.name} no {axis} {a:.2f}-{b:.2f} s"))
    return pieces


def _merged(spans: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    out: list[tuple[float, float]] = []
    for start, end in spans:
        if out and start <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], end))
        else:
            out.append((start, end))
    return out


def _without(span: tuple[float, float], holes: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    parts = [span]
    for low, high in holes:
        parts = [piece for a, b in parts for piece in ((a, min(b, low)), (max(a, high), b)) if piece[1] > piece[0]]
    return parts


def maneuver_band(
    flights: Sequence[ConditionedFlight], axis: str, *, kind: str = "sweep"
) -> tuple[float, float] | None:
    """The band the maneuvers of `kind` on `axis` excite, rad/s, from their segments (None if one does not say).

    Outside it the mixer input carries only the autopilot's feedback of
    sensor noise and disturbances, which in closed loop is coherent with the
    output (``y / x = -1 / C``, the controller's inverse) and not the
    airframe's response: a sweep's responses are computed over its band only
    (Tischler & Remple: the identification range lies within the frequency
    range of the excitation).

    Parameters
    ----------
    flights : sequence of ConditionedFlight
        Conditioned flights.
    axis : {"lat", "lon", "yaw", "thr"}
        Mixer axis.
    kind : str, optional
        Maneuver kind.

    Returns
    -------
    tuple of float or None
        ``(2 pi min f_min_hz, 2 pi max f_max_hz)`` over the segments, or None
        when there is none or one lacks ``f_min_hz`` or ``f_max_hz``.
    """
    segments = [s for f in flights for s in f.segments if s.axis == axis and s.kind == kind]
    lows = [s.f_min_hz for s in segments if s.f_min_hz is not None and s.f_max_hz is not None]
    highs = [s.f_max_hz for s in segments if s.f_min_hz is not None and s.f_max_hz is not None]
    if not segments or len(lows) < len(segments):
        return None
    return 2.0 * np.pi * min(lows), 2.0 * np.pi * max(highs)


def within_band(options: ResponseOptions, band: tuple[float, float] | None) -> ResponseOptions:
    """`options` with the grid kept within `band` (rad/s) when the responses are computed without a reference.

    The band matters to the direct estimate ``G_xy / G_xx`` only: out of it the
    input carries nothing but the feedback (:func:`maneuver_band`). With a
    reference the instrumental-variable estimate has no such bias, and its
    coherence says how far the excitation reaches. A band outside the grid
    leaves it as it is.

    Parameters
    ----------
    options : ResponseOptions
        Options of one axis's responses.
    band : tuple of float or None
        ``(omega_low, omega_high)``, rad/s, or None.

    Returns
    -------
    ResponseOptions
    """
    if band is None or options.reference is not None or band[0] >= options.omega_max or band[1] <= options.omega_min:
        return options
    low, high = max(options.omega_min, band[0]), min(options.omega_max, band[1])
    return replace(options, omega_min=min(low, high / 2.0), omega_max=high)


def parse_pairs(text: str) -> tuple[tuple[str, str], ...]:
    """``"q/delta_lon,ax/delta_lon"`` -> ``(("q", "delta_lon"), ("ax", "delta_lon"))`` (output, input).

    Parameters
    ----------
    text : str
        Comma-separated ``output/input`` pairs.

    Returns
    -------
    tuple of (str, str)
        ``(output, input)`` in the order given, duplicates removed.

    Raises
    ------
    ValueError
        If an item is not ``output/input``.

    Examples
    --------
    >>> parse_pairs("q/delta_lon, ax/delta_lon")
    (('q', 'delta_lon'), ('ax', 'delta_lon'))
    """
    pairs: list[tuple[str, str]] = []
    for item in text.split(","):
        output, sep, input_ = (part.strip() for part in item.partition("/"))
        if not sep or not output or not input_ or "/" in input_:
            raise ValueError(f"{item.strip()!r} is not OUTPUT/INPUT (e.g. q/delta_lon)")
        if (output, input_) not in pairs:
            pairs.append((output, input_))
    return tuple(pairs)


def default_pairs(flights: Sequence[ConditionedFlight], *, kind: str = "sweep") -> tuple[tuple[str, str], ...]:
    """``DEFAULT_PAIRS[axis]`` against ``delta_<axis>`` for every axis with a maneuver of `kind`.

    Outputs not logged in every piece are left out.

    Parameters
    ----------
    flights : sequence of ConditionedFlight
        Conditioned flights.
    kind : str, optional
        Maneuver kind.

    Returns
    -------
    tuple of (str, str)
        ``(output, input)`` pairs, axes in canonical order.
    """
    pairs: list[tuple[str, str]] = []
    for axis in AXES:
        pieces = maneuver_records(flights, axis, kind=kind)
        if not pieces:
            continue
        logged = set.intersection(*(set(piece.signals) for piece in pieces))
        pairs.extend((output, f"delta_{axis}") for output in DEFAULT_PAIRS[axis] if output in logged)
    return tuple(pairs)


@dataclass(frozen=True, slots=True, kw_only=True)
class FlightResponses:
    """Responses computed from flights, with what they were computed on.

    Parameters
    ----------
    responses : tuple of FrequencyResponse
        One per pair asked for, in that order.
    pieces : Mapping[str, int]
        Number of record pieces used per axis.
    notes : tuple of str, optional
        One sentence per axis on what the responses were computed against:
        the logged excitation as reference, or the mixer input and why.
    """

    responses: tuple[FrequencyResponse, ...]
    pieces: Mapping[str, int]
    notes: tuple[str, ...] = ()


def flight_responses(
    flights: Sequence[ConditionedFlight],
    pairs: Sequence[tuple[str, str]] | None = None,
    *,
    axis: str | None = None,
    kind: str = "sweep",
    options: ResponseOptions = ResponseOptions(),
    use_excitation: bool = True,
) -> FlightResponses:
    """Frequency responses of the pairs on the maneuvers of their axis.

    Pairs are grouped by axis: the axis of a mixer input ``delta_<axis>``, or
    `axis` for every pair when given. Within an axis all inputs named are
    computed together, so an output paired with two inputs (``ax/delta_lon``
    and ``ax/wind_lon``) gets responses conditioned on the other input.

    Each axis's grid keeps within its maneuvers' band when their segments
    give one and there is no reference (:func:`within_band`), and the flight
    without that axis's maneuvers (:func:`quiet_records`) gives the
    autopilot's feedback floor removed from the responses computed without a
    reference from mixer inputs alone (with a measured disturbance such as
    the wind among the inputs, conditioning on it takes its feedback out).

    Where every piece of an axis carries a varying ``excitation`` (ArduPilot
    logs its System ID chirp as SIDD) and the axis's mixer input is among the
    inputs, that excitation is the reference of the mixer input's responses
    (``ResponseOptions.reference``: ``H = G_ry / G_rx``, free of the bias the
    feedback of noise and turbulence puts into ``G_xy / G_xx``). Otherwise
    (PX4 logs no excitation, doublets are not logged) the responses are
    computed from the mixer input itself; `notes` says which, per axis.

    Parameters
    ----------
    flights : sequence of ConditionedFlight
        Conditioned flights.
    pairs : sequence of (str, str), optional
        ``(output, input)``; default :func:`default_pairs`.
    axis : {"lat", "lon", "yaw", "thr"}, optional
        Maneuvers to use for every pair (needed when an input is not a mixer input).
    kind : str, optional
        Maneuver kind.
    options : ResponseOptions, optional
        Grid and windows. A `reference` set here is used on every axis (a
        piece without it is then an error).
    use_excitation : bool, optional
        Use the logged excitation as reference where it can be (default
        True); False computes every response from the inputs themselves.

    Returns
    -------
    FlightResponses

    Raises
    ------
    DataError
        If no pair is given or found, a pair's axis cannot be told, or an axis has no maneuver of `kind`.
    MissingSignalError
        If a record lacks a signal named.
    """
    chosen = tuple(pairs) if pairs is not None else default_pairs(flights, kind=kind)
    if not chosen:
        raise DataError(f"no {kind} on any axis in {_names(flights)}: nothing to compute responses from")
    groups: dict[str, list[tuple[str, str]]] = {}
    for output, input_ in chosen:
        groups.setdefault(axis or _axis_of(input_, chosen), []).append((output, input_))
    found: dict[tuple[str, str], FrequencyResponse] = {}
    pieces: dict[str, int] = {}
    notes: list[str] = []
    for group_axis, group in groups.items():
        records = maneuver_records(flights, group_axis, kind=kind)
        if not records:
            raise DataError(f"no {kind} on axis {group_axis} in {_names(flights)}")
        mixer = f"delta_{group_axis}"
        inputs = list(dict.fromkeys(input_ for _, input_ in group))
        inputs.sort(key=lambda name: name != mixer)  # the reference stands in for the first input: the mixer's
        outputs = list(dict.fromkeys(output for output, _ in group))
        chosen_options, note = reference_options(records, group_axis, inputs, kind, options, use_excitation)
        notes.append(note)
        chosen_options = within_band(chosen_options, maneuver_band(flights, group_axis, kind=kind))
        needed = {*inputs, *outputs}
        mixers_only = all(i.startswith("delta_") for i in inputs)  # a measured disturbance is conditioned on
        quiet = [r for r in quiet_records(flights, group_axis) if needed <= set(r.signals)] if mixers_only else []
        for response in frequency_responses(records, inputs, outputs, chosen_options, quiet=quiet):
            found[(response.output, response.input)] = response
        pieces[group_axis] = len(records)
    return FlightResponses(
        responses=tuple(found[pair] for pair in chosen), pieces=MappingProxyType(pieces), notes=tuple(notes)
    )


def reference_options(
    records: Sequence[Record],
    axis: str,
    inputs: Sequence[str],
    kind: str,
    options: ResponseOptions,
    use_excitation: bool = True,
) -> tuple[ResponseOptions, str]:
    """The options for one axis's responses (excitation as reference or not) and a note saying which and why.

    The logged ``excitation`` becomes the reference of the mixer input's
    responses when every record carries a varying one and the first input is
    the axis's mixer input.

    Parameters
    ----------
    records : sequence of Record
        The maneuver pieces of the axis.
    axis : {"lat", "lon", "yaw", "thr"}
        Mixer axis.
    inputs : sequence of str
        Inputs of the responses, the mixer input first.
    kind : str
        Maneuver kind, for the note (``"sweep"``).
    options : ResponseOptions
        Options asked for; a reference set there is kept.
    use_excitation : bool, optional
        False to compute from the mixer input itself.

    Returns
    -------
    options : ResponseOptions
        With ``reference`` set where the excitation is used.
    note : str
        One sentence for the report.
    """
    first = inputs[0]
    if options.reference is not None:
        return options, f"{axis}: {options.reference} is the reference of the {first} responses (as asked)."
    if not use_excitation:
        return options, f"{axis}: responses computed from {first} itself (reference not used, as asked)."
    mixer = f"delta_{axis}"
    if first != mixer:
        return options, f"{axis}: no mixer input {mixer} among the inputs: responses computed from {first} itself."
    carrying = [r for r in records if EXCITATION in r.signals and np.ptp(r[EXCITATION]) > 0]
    if len(carrying) == len(records):
        return replace(options, reference=EXCITATION), (
            f"{axis}: the logged {EXCITATION} (SIDD) is the reference of the {mixer} responses, H = G_ry / G_rx."
        )
    which = "none" if not carrying else f"only {len(carrying)} of {len(records)}"
    return options, (
        f"{axis}: {which} of the {kind} pieces carry a logged {EXCITATION} (only ArduPilot's System ID mode logs one, SIDD): responses "
        f"computed from the mixer input {mixer}, which in closed loop also carries the feedback of "
        f"noise and turbulence."
    )


def _axis_of(input_: str, pairs: Sequence[tuple[str, str]]) -> str:
    """The axis whose maneuvers an input's responses come from: its own (a mixer input, a reference), else the pairs'."""
    if input_ in COMMAND_AXES:
        return COMMAND_AXES[input_]
    axes = {COMMAND_AXES[i] for _, i in pairs if i in COMMAND_AXES}
    if len(axes) == 1:
        return axes.pop()
    raise DataError(f"cannot tell which maneuvers to use for input {input_}: give the axis (lat, lon, yaw or thr)")


def _names(flights: Sequence[ConditionedFlight]) -> str:
    return ", ".join(flight.source.name for flight in flights) or "no flight"
