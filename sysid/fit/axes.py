"""Which axes of a structure an identification identified, and for the others why not and what to do.

An axis is a control input of the structure, named without its ``delta_``
prefix (``lon`` for ``delta_lon``). It is identified when gated responses
of its input informed every parameter its part of the model reads
(:func:`sysid.model.axes.axis_parts`); otherwise it is unidentified, its
parameters are ``unidentified`` (no value), and the model is not simulated
on it. :func:`diagnose_axis` says which step left an axis without a response:
no maneuver of the axis at all, records that lack a signal, or responses that
all failed the coherence gating of eq. 3.8.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

from flightlogs.conditioning.condition import ConditionedFlight
from flightlogs.record import Record
from sysid.freqresp import FrequencyResponse
from sysid.freqresp.gating import DroppedResponse, Gating, GatingResult
from sysid.model.structure import ModelStructure

__all__ = [
    "AxisStatus",
    "axis_name",
    "diagnose_axis",
    "structure_axes",
    "merge_axes",
    "unidentified_message",
    "partial_warning",
    "axes_from_parameters",
]

AxisState = Literal["identified", "unidentified"]


def axis_name(signal: str) -> str:
    """The axis of a control input signal: ``delta_lon`` -> ``lon`` (other names as they are).

    Parameters
    ----------
    signal : str
        A control input's signal.

    Examples
    --------
    >>> axis_name("delta_lon"), axis_name("collective")
    ('lon', 'collective')
    """
    return signal.removeprefix("delta_")


@dataclass(frozen=True, slots=True, kw_only=True)
class AxisStatus:
    """Whether one axis (control input) of a model was identified, and if not why.

    Parameters
    ----------
    axis : str
        Axis name (``lon``).
    input : str
        Its control input signal (``delta_lon``).
    status : {"identified", "unidentified"}
        Identified: its responses informed every parameter of its part of the model.
    reason : str
        Why it is unidentified, in words (``"no sweep found in 3 logs; the
        delta_lon input never passed the sweep test"``); empty when identified.
    remedy : str
        What the user can do about it; empty when identified.

    Examples
    --------
    >>> AxisStatus(axis="lon", input="delta_lon", status="unidentified", reason="no sweep found in 3 logs").sentence
    'lon: no sweep found in 3 logs'
    """

    axis: str
    input: str
    status: AxisState
    reason: str = ""
    remedy: str = ""

    def __post_init__(self) -> None:
        if self.status not in ("identified", "unidentified"):
            raise ValueError(f"status={self.status!r} must be 'identified' or 'unidentified'")
        if self.status == "unidentified" and not self.reason:
            raise ValueError(f"axis {self.axis}: an unidentified axis needs a reason")

    @property
    def identified(self) -> bool:
        """Whether the axis was identified."""
        return self.status == "identified"

    @property
    def sentence(self) -> str:
        """``"lon: <reason>; <remedy>"`` (the reason alone when there is no remedy)."""
        return f"{self.axis}: {self.reason}" + (f"; {self.remedy}" if self.remedy else "")


def _plural(n: int, word: str) -> str:
    return f"{n} {word}{'' if n == 1 else 's'}"


def diagnose_axis(
    signal: str,
    *,
    kind: str,
    flights: Sequence[ConditionedFlight],
    records: Sequence[Record],
    responses: Sequence[FrequencyResponse],
    dropped: Sequence[DroppedResponse],
    gating: Gating,
    segments_hint: str = "give the maneuvers with `segments`",
) -> AxisStatus:
    """The status of one axis from what the identification found for it, before the fit.

    Parameters
    ----------
    signal : str
        The axis' control input (``delta_lon``).
    kind : str
        Maneuver kind fitted (``sweep``).
    flights : sequence of ConditionedFlight
        Every flight given, with its segments.
    records : sequence of Record
        The records of the axis' maneuvers of `kind`.
    responses : sequence of FrequencyResponse
        The responses computed from them (of `signal`).
    dropped : sequence of DroppedResponse
        Those of `responses` that gating dropped, with the reason.
    gating : Gating
        The gating rule of eq. 3.8 (gamma^2 and decades).
    segments_hint : str, optional
        How to give maneuvers that were not detected.

    Returns
    -------
    AxisStatus
        Identified when a response of the axis passed gating (the fit may still
        find a parameter of it uninformed).
    """
    axis = axis_name(signal)
    logs = len({f.source for f in flights})
    in_logs = f"in {_plural(logs, 'log')}"
    gated_out = {d.pair for d in dropped}
    kept = [r for r in responses if r.pair not in gated_out]
    if kept:
        return AxisStatus(axis=axis, input=signal, status="identified")
    if not records:
        others = sorted({s.kind for f in flights for s in f.segments if s.axis == axis and s.kind != kind})
        given = any(s.source == "user" for f in flights for s in f.segments)
        test = (
            f"the maneuvers given name no {axis} {kind}"
            if given
            else f"the {signal} input never passed the {kind} test"
            + (f" (a {' and a '.join(others)} of this axis was found)" if others else "")
        )
        return AxisStatus(
            axis=axis,
            input=signal,
            status="unidentified",
            reason=f"no {kind} found {in_logs}; {test}",
            remedy=segments_hint,
        )
    if not responses:
        return AxisStatus(
            axis=axis,
            input=signal,
            status="unidentified",
            reason=f"{_plural(len(records), kind + ' record')} {in_logs}, but they lack {signal} or every output "
            "fitted on this axis",
            remedy=f"log {signal} and the axis' outputs",
        )
    why = " ".join(d.reason for d in dropped if d.input == signal).rstrip(".")
    return AxisStatus(
        axis=axis,
        input=signal,
        status="unidentified",
        reason=f"{_plural(len(records), kind)} {in_logs}, but no response passed the coherence gating "
        f"(γ² ≥ {gating.min_coherence:g} over ≥ {gating.min_decades:g} decade): {why}",
        remedy=f"fly a longer or stronger {kind} on this axis, or lower `min_coherence`",
    )


def structure_axes(
    structure: ModelStructure,
    flights: Sequence[ConditionedFlight],
    records: Mapping[str, Sequence[Record]],
    responses: Sequence[FrequencyResponse],
    gated: GatingResult,
    *,
    kind: str,
    gating: Gating,
) -> tuple[AxisStatus, ...]:
    """:func:`diagnose_axis` for every control input of `structure`, in its order.

    Parameters
    ----------
    structure : ModelStructure
        The structure fitted.
    flights : sequence of ConditionedFlight
        Every flight given.
    records : Mapping[str, sequence of Record]
        The maneuver records of each axis (``lon``) that has any.
    responses : sequence of FrequencyResponse
        Every response computed, before gating.
    gated : GatingResult
        What gating kept and dropped.
    kind : str
        Maneuver kind fitted.
    gating : Gating
        The gating rule of eq. 3.8.

    Returns
    -------
    tuple of AxisStatus
    """
    signals = dict.fromkeys(c.signal for c in structure.control_inputs)
    return tuple(
        diagnose_axis(
            signal,
            kind=kind,
            flights=flights,
            records=records.get(axis_name(signal), ()),
            responses=[r for r in responses if r.input == signal],
            dropped=[d for d in gated.dropped if d.input == signal],
            gating=gating,
        )
        for signal in signals
    )


def merge_axes(found: Sequence[AxisStatus], fitted: Sequence[AxisStatus]) -> tuple[AxisStatus, ...]:
    """The statuses after the fit: the reason found before it where it has one, else the fit's.

    Parameters
    ----------
    found : sequence of AxisStatus
        From :func:`structure_axes` (why an axis had no gated response).
    fitted : sequence of AxisStatus
        From the fit (an axis with responses may still leave a parameter uninformed).

    Returns
    -------
    tuple of AxisStatus
        In the order of `fitted`.
    """
    before = {a.input: a for a in found}
    out = []
    for axis in fitted:
        earlier = before.get(axis.input)
        if not axis.identified and earlier is not None and not earlier.identified:
            out.append(earlier)
        elif not axis.identified:
            remedy = "fit responses that inform them"
            out.append(
                AxisStatus(axis=axis.axis, input=axis.input, status=axis.status, reason=axis.reason, remedy=remedy)
            )
        else:
            out.append(axis)
    return tuple(out)


def partial_warning(axes: Sequence[AxisStatus], *, model: str) -> str:
    """The warning of a model written with ``--partial``: which axes it covers and which it does not.

    Parameters
    ----------
    axes : sequence of AxisStatus
        The model's axes, identified and not, in the structure's order.
    model : str
        Name of the model's structure, for the sentence.

    Examples
    --------
    >>> lon = AxisStatus(axis="lon", input="delta_lon", status="unidentified", reason="no sweep found in 3 logs")
    >>> yaw = AxisStatus(axis="yaw", input="delta_yaw", status="identified")
    >>> partial_warning([lon, yaw], model="hover")
    'model hover is partial: it covers yaw only; unidentified, so without values and not simulated: lon (no sweep found in 3 logs)'
    """
    covered = ", ".join(a.axis for a in axes if a.identified) or "no axis"
    missing = "; ".join(f"{a.axis} ({a.reason})" for a in axes if not a.identified)
    return f"model {model} is partial: it covers {covered} only; unidentified, so without values and not simulated: {missing}"


def unidentified_message(axes: Sequence[AxisStatus], *, model: str, partial: bool = False) -> str:
    """The error of a fit that left axes unidentified: one sentence per axis, naming it, why, and what to do.

    Parameters
    ----------
    axes : sequence of AxisStatus
        Every axis of the structure; each unidentified one gets its sentence.
    model : str
        Name of the structure fitted, for the first line.
    partial : bool, optional
        Whether a partial model was asked for (then no axis was identified: the advice is not to ask for it).

    Examples
    --------
    >>> lon = AxisStatus(axis="lon", input="delta_lon", status="unidentified", reason="no sweep found in 3 logs",
    ...                  remedy="give the maneuvers with `segments`")
    >>> print(unidentified_message([lon], model="hover"))
    model hover: 1 of its 1 axes cannot be identified.
    lon: no sweep found in 3 logs; give the maneuvers with `segments`, or `partial` to write a model of the other axes.
    >>> print(unidentified_message([lon], model="hover", partial=True))
    model hover: 1 of its 1 axes cannot be identified, so a partial model has no axis to write.
    lon: no sweep found in 3 logs; give the maneuvers with `segments`.
    """
    missing = [a for a in axes if not a.identified]
    head = f"model {model}: {len(missing)} of its {len(axes)} axes cannot be identified."
    if partial:  # asked for, and there is no axis to write
        head = head[:-1] + ", so a partial model has no axis to write."
        return "\n".join([head] + [a.sentence + "." for a in missing])
    advice = "`partial` to write a model of the other axes"
    return "\n".join([head] + [a.sentence + (", or " if a.remedy else "; ") + advice + "." for a in missing])


def axes_from_parameters(parts: Mapping[str, Sequence[str]], statuses: Mapping[str, str]) -> tuple[AxisStatus, ...]:
    """Axis statuses of a model file that does not record them: an axis with an estimated parameter is identified.

    Parameters
    ----------
    parts : Mapping[str, sequence of str]
        Parameters of each control input's part, by signal (:func:`sysid.model.axes.axis_parts`).
    statuses : Mapping[str, str]
        Status of every parameter, by name.

    Returns
    -------
    tuple of AxisStatus
    """
    out = []
    for signal, names in parts.items():
        estimated = any(statuses.get(n) == "estimated" for n in names)
        unidentified = [n for n in names if statuses.get(n) == "unidentified"]
        if estimated and not unidentified:
            out.append(AxisStatus(axis=axis_name(signal), input=signal, status="identified"))
        else:
            reason = (
                f"parameter{'s' if len(unidentified) > 1 else ''} {', '.join(unidentified)} unidentified"
                if unidentified
                else "no parameter of this axis was estimated"
            )
            out.append(AxisStatus(axis=axis_name(signal), input=signal, status="unidentified", reason=reason))
    return tuple(out)
