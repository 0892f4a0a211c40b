"""Verify a model on flight logs or conditioned flights: cut the doublets, simulate (what ``sysid validate`` runs)."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from flightlogs.conditioning.condition import ConditionedFlight, ConditioningOptions
from flightlogs.errors import DataError
from flightlogs.readers.dispatch import ReadOptions
from flightlogs.store.sources import conditioned_sources, is_dataset
from sysid.fit.result import IdentifiedModel
from sysid.fit.wind_offset import smoothed_flights
from sysid.model.statespace import DelayedStateSpace
from sysid.verify.engine import VerificationOptions, verify
from sysid.verify.records import (
    AFTER_S,
    BEFORE_S,
    MIXER_INPUTS,
    DoubletRecords,
    check_given_doublets,
    doublet_records,
)
from sysid.verify.results import Verification
from sysid.verify.submodel import axis_outputs

__all__ = [
    "SEGMENTS_HINT",
    "Validation",
    "verify_logs",
    "verify_flights",
    "verify_identified",
    "verification_provenance",
]

#: What a message says to do when no doublet is found in logs (a caller with a dataset says otherwise).
SEGMENTS_HINT = "give their times with `segments` if they were not detected"


@dataclass(frozen=True, slots=True, kw_only=True)
class Validation:
    """A model verified on the doublets of flights it was not fitted to: what ``sysid validate`` makes.

    Parameters
    ----------
    verification : Verification
        The verification, with the wind term where the flights carry the wind.
    provenance : dict
        How it was made (:func:`verification_provenance`), as its file and the report record it.
    notes : tuple of str
        What the reader should know: the clock offset taken from the model's fit, the wind term not
        verified, the axes without a doublet.
    """

    verification: Verification
    provenance: dict[str, Any]
    notes: tuple[str, ...]


def verify_logs(
    identified: IdentifiedModel,
    sources: Sequence[str | Path],
    *,
    wind_paths: Sequence[str | Path] = (),
    conditioning: ConditioningOptions = ConditioningOptions(),
    segments_path: str | Path | None = None,
    options: VerificationOptions = VerificationOptions(),
    before_s: float = BEFORE_S,
    after_s: float = AFTER_S,
    progress: Callable[[str, int, int], None] | None = None,
    reading: ReadOptions = ReadOptions(),
) -> Validation:
    """Verify an identified model on the doublets of logs or datasets: ``sysid validate``.

    With anemometer files and no clock offset given, the wind is aligned
    with the offset the model's own fit measured (said in the notes).

    Parameters
    ----------
    identified : IdentifiedModel
        The model, as :func:`sysid.fit.read_model` reads it.
    sources : sequence of str or Path
        Flight logs with doublets not used in the fit, or HDF5 datasets of them.
    wind_paths : sequence of str or Path, optional
        Anemometer CSV files or folders of them (logs only): the wind term is verified too.
    conditioning : ConditioningOptions, optional
        Alignment, rate and segment choices (as for the ingest).
    segments_path : str or Path, optional
        The file `conditioning.segments` was read from: each doublet it gives is checked to lie in a flight.
    options : VerificationOptions, optional
        Bias, reference shift, initial state and instability choices.
    before_s, after_s : float, optional
        Quiet stretch kept before and response after each doublet, s.
    progress : callable, optional
        ``progress(file_name, done, total)`` while reading logs, bytes.
    reading : ReadOptions, optional
        How tables among the logs are read, and whether a log of another vehicle is refused.

    Returns
    -------
    Validation

    Raises
    ------
    DataError
        If a source cannot be used, a given doublet lies outside every flight, or no flight holds a doublet
        on an axis of the model.
    """
    measured = identified.measured_clock_offset_s if wind_paths and conditioning.wind_offset_s is None else None
    conditioning = replace(conditioning, residual_offset=False)  # no flight's alignment is returned
    if measured is not None:
        conditioning = replace(conditioning, wind_offset_s=measured)
    flights = conditioned_sources(sources, wind_paths, options=conditioning, progress=progress, reading=reading)
    if segments_path is not None and conditioning.segments is not None:
        check_given_doublets(Path(segments_path), conditioning.segments, flights)
    hint = (
        ""
        if segments_path is not None
        else "give their times to the ingest that wrote the dataset, in a segments file"
        if sources and is_dataset(sources[0])
        else SEGMENTS_HINT
    )
    verification, said = verify_identified(
        identified, flights, options=options, before_s=before_s, after_s=after_s, hint=hint
    )
    notes = []
    if measured is not None:
        notes.append(
            f"anemometer clock offset {measured:+.2f} s, as the model's fit measured it (`wind_offset_s` to override)"
        )
    names = {"sources": [Path(p).name for p in sources], "winds": [Path(p).name for p in wind_paths]}
    provenance = verification_provenance(options, before_s=before_s, after_s=after_s, **names)
    return Validation(verification=verification, provenance=provenance, notes=(*notes, *said))


def verify_flights(
    model: DelayedStateSpace,
    flights: Sequence[ConditionedFlight],
    *,
    wind_model: DelayedStateSpace | None = None,
    axes: Mapping[str, Sequence[str]] | None = None,
    options: VerificationOptions = VerificationOptions(),
    before_s: float = BEFORE_S,
    after_s: float = AFTER_S,
    hint: str = SEGMENTS_HINT,
    unidentified: Mapping[str, str] | None = None,
) -> Verification:
    """Verify `model` (and `wind_model`) on every doublet of conditioned flights.

    Parameters
    ----------
    model : DelayedStateSpace
        The model without the wind term (or the only one).
    flights : sequence of ConditionedFlight
        Flights with doublets not used in the fit (from logs or a dataset).
    wind_model : DelayedStateSpace, optional
        The model with G_w; the flights must hold its wind inputs.
    axes : Mapping[str, sequence of str], optional
        On-axis outputs of each mixer input.
    options : VerificationOptions, optional
        Bias, reference shift, initial state and instability choices.
    before_s, after_s : float, optional
        Quiet stretch kept before and response after each doublet, s.
    hint : str, optional
        What the message says to do when no doublet is found ("" for nothing).
    unidentified : Mapping[str, str], optional
        Mixer inputs of axes the identification left unidentified (``model``
        lacks them), with the reason: their doublets are not verified, and
        ``Verification.unverified`` says so.

    Returns
    -------
    Verification
        ``unverified`` names every axis of the model without a doublet, and every unidentified axis.

    Raises
    ------
    DataError
        If no flight holds a doublet on an axis of the model (naming the unidentified axes too).
    """
    cut = doublet_records(flights, before_s=before_s, after_s=after_s)
    kept = [k for k, name in enumerate(cut.excited) if name in model.inputs]  # axes the model does not have
    unverified = _unverified(model, flights, cut, unidentified or {})
    if not kept:
        names = ", ".join(dict.fromkeys(flight.source.name for flight in flights))
        raise DataError(
            f"no doublet found in {names} on an axis of the model ({', '.join(model.inputs)}): "
            "validation needs doublets not used in the fit"
            + (f" ({hint})" if hint else "")
            + "".join(f"; {text}" for text in unverified if text.split(":")[0] not in _axis_names(model))
        )
    verification = verify(
        model,
        [cut.records[k] for k in kept],
        wind_model=wind_model,
        excited=[cut.excited[k] for k in kept],
        axes=axes,
        options=options,
    )
    return replace(verification, unverified=tuple(unverified))


def verify_identified(
    identified: IdentifiedModel,
    flights: Sequence[ConditionedFlight],
    *,
    options: VerificationOptions = VerificationOptions(),
    before_s: float = BEFORE_S,
    after_s: float = AFTER_S,
    hint: str = SEGMENTS_HINT,
) -> tuple[Verification, tuple[str, ...]]:
    """Verify an identified model on the flights' doublets: ``sysid validate``, and the demo's verification.

    Each doublet is judged on the outputs of its axis (:func:`~sysid.verify.axis_outputs`); the model's wind
    term G_w is verified too where every record carries the wind it reads, and said not to be otherwise.

    Parameters
    ----------
    identified : IdentifiedModel
        The model, as :func:`sysid.fit.read_model` reads it.
    flights : sequence of ConditionedFlight
        Flights with doublets not used in the fit.
    options : VerificationOptions, optional
        Bias, reference shift, initial state and instability choices.
    before_s, after_s : float, optional
        Quiet stretch kept before and response after each doublet, s.
    hint : str, optional
        What the message says to do when no doublet is found.

    Returns
    -------
    Verification
        With the wind term, where the flights carry the wind.
    tuple of str
        Notes: the wind term not verified, and the axes without a doublet.

    Raises
    ------
    DataError
        If no flight holds a doublet on an axis of the model.
    """
    model, with_wind = identified.linear_model(include_wind=False), identified.linear_model(include_wind=True)
    wind_inputs = sorted(name for name in with_wind.inputs if name not in model.inputs)
    carried = {name for flight in flights for record in flight.records for name in record.signals}
    use_wind = bool(wind_inputs) and set(wind_inputs) <= carried
    notes = []
    if wind_inputs and not use_wind:
        notes.append(
            f"the model's wind term is not verified: the records carry no {', '.join(wind_inputs)} "
            "(the flights conditioned with an anemometer, `wind_paths`)"
        )
    if use_wind:
        flights = smoothed_flights(flights)  # G_w's inputs are the wind the fit regressed on
    verification = verify_flights(
        model,
        flights,
        wind_model=with_wind if use_wind else None,
        axes=axis_outputs(identified),
        options=options,
        before_s=before_s,
        after_s=after_s,
        hint=hint,
        unidentified={a.input: a.reason for a in identified.unidentified_axes},
    )
    return verification, (*notes, *verification.unverified)


def verification_provenance(
    options: VerificationOptions,
    *,
    before_s: float = BEFORE_S,
    after_s: float = AFTER_S,
    sources: Sequence[str] = (),
    winds: Sequence[str] = (),
) -> dict[str, Any]:
    """How a verification was made, as its file and the report record it.

    Parameters
    ----------
    options : VerificationOptions
        The options it was made with.
    before_s, after_s : float, optional
        The doublet cut, s.
    sources, winds : sequence of str, optional
        Names of the logs (or dataset) and anemometer files.

    Returns
    -------
    dict
    """
    return {
        "initial_state": options.initial_state,
        "before_s": before_s,
        "after_s": after_s,
        "inputs": "all measured",
        "judged": "on-axis outputs of each doublet's axis",
        "logs": list(sources),
        "wind": list(winds),
    }


def _axis_names(model: DelayedStateSpace) -> set[str]:
    return {axis for axis, signal in MIXER_INPUTS.items() if signal in model.inputs}


def _unverified(
    model: DelayedStateSpace,
    flights: Sequence[ConditionedFlight],
    cut: DoubletRecords,
    unidentified: Mapping[str, str],
) -> list[str]:
    """One sentence per mixer axis of the model without a doublet, and per unidentified axis."""
    logs = len({f.source for f in flights})
    in_logs = f"in {logs} log{'' if logs == 1 else 's'}"
    out = []
    for axis, signal in MIXER_INPUTS.items():
        doublets = sum(name == signal for name in cut.excited)
        if signal in unidentified:
            seen = (
                f"its {doublets} doublet{' is' if doublets == 1 else 's are'} not verified"
                if doublets
                else "not verified (no doublet either)"
            )
            out.append(f"{axis}: the model's {axis} axis is unidentified ({unidentified[signal]}); {seen}")
        elif signal in model.inputs and not doublets:
            out.append(f"{axis}: no doublet {in_logs}; not verified")
    return out
