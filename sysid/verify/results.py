"""What a time-domain verification returns: per output, per record, pooled, and the wind correction."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Protocol, TypeVar

import numpy as np

from sysid._json import finite_or_none, float_array, float_or_nan, json_floats

__all__ = [
    "rms_error",
    "theil_inequality",
    "mode_names",
    "OutputVerification",
    "RecordVerification",
    "OutputSummary",
    "WindCorrection",
    "Verification",
]


def rms_error(measured: np.ndarray, simulated: np.ndarray) -> float:
    """Root-mean-square difference of two time series.

    Parameters
    ----------
    measured, simulated : ndarray, shape (n_samples,)
        The same signal measured and predicted, same unit.

    Returns
    -------
    float
        ``sqrt(mean((measured - simulated)**2))``, in the signal's unit.

    Examples
    --------
    >>> rms_error(np.array([1.0, -1.0]), np.zeros(2))
    1.0
    """
    return float(np.sqrt(np.mean((np.asarray(measured) - np.asarray(simulated)) ** 2)))


def theil_inequality(measured: np.ndarray, simulated: np.ndarray) -> float:
    """Theil inequality coefficient: 0 for a perfect prediction, 1 for the worst.

    Parameters
    ----------
    measured, simulated : ndarray, shape (n_samples,)
        The same signal measured and predicted, same unit.

    Returns
    -------
    float
        ``rms(measured - simulated) / (rms(measured) + rms(simulated))``; NaN
        when both are zero.

    Notes
    -----
    Tischler & Remple, section 15.3 (Jategaonkar 2006, eq. 11.12). The limits
    of good predictive accuracy are `tic_good` and `tic_acceptable` of
    :class:`sysid.fit.Guidelines`.

    Examples
    --------
    >>> theil_inequality(np.array([1.0, -1.0]), np.array([1.0, -1.0]))
    0.0
    >>> theil_inequality(np.array([1.0, -1.0]), -np.array([1.0, -1.0]))
    1.0
    """
    measured, simulated = np.asarray(measured, dtype=float), np.asarray(simulated, dtype=float)
    scale = np.sqrt(np.mean(measured**2)) + np.sqrt(np.mean(simulated**2))
    return float(rms_error(measured, simulated) / scale) if scale > 0 else float("nan")


class _Named(Protocol):
    @property
    def name(self) -> str: ...


_N = TypeVar("_N", bound=_Named)


def _named(items: tuple[_N, ...], name: str, missing: str) -> _N:
    """The item called `name`; KeyError(`missing`) when there is none."""
    for item in items:
        if item.name == name:
            return item
    raise KeyError(missing)


def _vector(value: np.ndarray, name: str, n: int) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    if array.shape != (n,):
        raise ValueError(f"{name} has shape {array.shape}, expected ({n},) like time_s")
    return array


def _optional(value: Any) -> float | None:
    """A JSON number that may be absent: None stays None."""
    return None if value is None else float(value)


def mode_names(labels: Sequence[str]) -> str:
    """Mode labels as words: ``"pitch mode"``, ``"pitch and roll modes"``; ``"modes"`` for none.

    Parameters
    ----------
    labels : sequence of str
        Mode labels (``"pitch"``, ``"roll"``).

    Examples
    --------
    >>> mode_names(("pitch",)), mode_names(("pitch", "roll", "heave"))
    ('pitch mode', 'pitch, roll and heave modes')
    """
    labels = list(dict.fromkeys(labels))
    if not labels:
        return "modes"
    if len(labels) == 1:
        return f"{labels[0]} mode"
    return f"{', '.join(labels[:-1])} and {labels[-1]} modes"


@dataclass(frozen=True, slots=True, kw_only=True)
class OutputVerification:
    """One output of one record: measured against the model's simulation.

    Parameters
    ----------
    name : str
        Canonical signal name.
    unit : str
        Its unit (the record's).
    measured : ndarray, shape (n_samples,)
        Measured perturbation from trim.
    simulated : ndarray, shape (n_samples,)
        Model output from the measured inputs, bias and reference shifts applied.
    bias : float
        Estimated output bias, in `unit`.
    rmse : float
        RMS of ``measured - simulated``, in `unit`.
    tic : float
        Theil inequality coefficient.
    predicted : ndarray, shape (n_samples,) or None, optional
        One-step-ahead prediction (bias removed), when computed.
    prediction_rmse, prediction_tic : float or None, optional
        RMS error (in `unit`) and TIC of the one-step-ahead prediction.
    """

    name: str
    unit: str
    measured: np.ndarray
    simulated: np.ndarray
    bias: float
    rmse: float
    tic: float
    predicted: np.ndarray | None = None
    prediction_rmse: float | None = None
    prediction_tic: float | None = None

    def __post_init__(self) -> None:
        n = np.shape(self.measured)[0] if np.ndim(self.measured) == 1 else -1
        if n < 1:
            raise ValueError(f"{self.name}: measured must be a non-empty 1-D array")
        object.__setattr__(self, "measured", _vector(self.measured, "measured", n))
        object.__setattr__(self, "simulated", _vector(self.simulated, "simulated", n))
        if self.predicted is not None:
            object.__setattr__(self, "predicted", _vector(self.predicted, "predicted", n))

    def to_dict(self, *, histories: bool = True) -> dict[str, Any]:
        """Its JSON entry: name, unit, bias, RMS error and TIC (non-finite as None), with the time histories.

        Parameters
        ----------
        histories : bool, optional
            Include ``measured``, ``simulated`` and ``predicted`` (the verification file does; ``--json`` not).

        Returns
        -------
        dict
        """
        entry: dict[str, Any] = {"name": self.name, "unit": self.unit}
        if histories:
            entry |= {"measured": json_floats(self.measured), "simulated": json_floats(self.simulated)}
            entry["predicted"] = None if self.predicted is None else json_floats(self.predicted)
        entry |= {"bias": finite_or_none(self.bias), "rmse": finite_or_none(self.rmse), "tic": finite_or_none(self.tic)}
        entry["prediction_rmse"] = finite_or_none(self.prediction_rmse)
        entry["prediction_tic"] = finite_or_none(self.prediction_tic)
        return entry

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> OutputVerification:
        """Rebuild it from :meth:`to_dict` with its histories (missing numbers as NaN)."""
        predicted = d.get("predicted")
        return cls(
            name=d["name"],
            unit=d["unit"],
            measured=float_array(d["measured"]),
            simulated=float_array(d["simulated"]),
            bias=float_or_nan(d["bias"]),
            rmse=float_or_nan(d["rmse"]),
            tic=float_or_nan(d["tic"]),
            predicted=None if predicted is None else float_array(predicted),
            prediction_rmse=_optional(d.get("prediction_rmse")),
            prediction_tic=_optional(d.get("prediction_tic")),
        )


@dataclass(frozen=True, slots=True, kw_only=True)
class RecordVerification:
    """A model simulated over one record.

    Parameters
    ----------
    label : str
        The record's label.
    source : Path
        The log it came from.
    time_s : ndarray, shape (n_samples,)
        Sample times, s (log clock).
    inputs : tuple of str
        Model inputs used, in model order.
    outputs : tuple of OutputVerification
        One per model output found in the record.
    reference_shifts : Mapping[str, float]
        Estimated constant shift of each input (distinct names), in the input's unit.
    rmse : float
        Overall weighted RMS error J_rms (angles in deg, angular rates in
        deg/s, other signals in SI).
    tic : float
        Overall Theil inequality coefficient on the same weighted signals.
    growth : float
        Open-loop growth ``exp(max(Re λ, 0) · duration)`` of the model over the record.
    unstable : bool
        True when `growth` exceeds the options' limit: the simulation may
        diverge from small errors, and the one-step-ahead prediction error is
        reported as well.
    notice : str, optional
        Why the record is flagged, for people; empty when it is not.
    excited : str or None, optional
        The mixer input the record excites (``"delta_lon"``), when known.
    off_axis : tuple of str, optional
        Outputs shown for information only: not of the excited axis, so not
        judged (left out of `rmse`, `tic` and the pooled summary); default none.
    unstable_modes : tuple of str, optional
        Labels of the unstable modes the judged outputs depend on
        (``("pitch",)``; see :func:`sysid.model.modes.modes`), largest growth first;
        a heave record names pitch when the trim couples it in (``w' = U0 q``).
    """

    label: str
    source: Path
    time_s: np.ndarray
    inputs: tuple[str, ...]
    outputs: tuple[OutputVerification, ...]
    reference_shifts: Mapping[str, float]
    rmse: float
    tic: float
    growth: float
    unstable: bool
    notice: str = ""
    excited: str | None = None
    off_axis: tuple[str, ...] = ()
    unstable_modes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        time_s = np.asarray(self.time_s, dtype=float)
        if time_s.ndim != 1:
            raise ValueError(f"record {self.label!r}: time_s must be 1-D")
        names = [o.name for o in self.outputs]
        unknown = [n for n in self.off_axis if n not in names]
        if unknown or (self.outputs and len(set(self.off_axis)) == len(names)):
            raise ValueError(
                f"record {self.label!r}: off_axis {tuple(self.off_axis)} must name some, not all, of "
                f"its outputs {tuple(names)}"
            )
        object.__setattr__(self, "off_axis", tuple(self.off_axis))
        object.__setattr__(self, "unstable_modes", tuple(self.unstable_modes))
        for output in self.outputs:
            if output.measured.shape != time_s.shape:
                raise ValueError(
                    f"record {self.label!r}: output {output.name} has {output.measured.size} samples, "
                    f"time_s {time_s.size}"
                )
        object.__setattr__(self, "time_s", time_s)
        object.__setattr__(self, "reference_shifts", MappingProxyType(dict(self.reference_shifts)))

    def output(self, name: str) -> OutputVerification:
        """The verification of one output.

        Parameters
        ----------
        name : str
            Canonical signal name.

        Raises
        ------
        KeyError
            If the output was not verified on this record.
        """
        return _named(self.outputs, name, f"record {self.label!r} has no verified output {name!r}")

    @property
    def judged(self) -> tuple[OutputVerification, ...]:
        """The outputs of the excited axis, which the record is judged on."""
        return tuple(o for o in self.outputs if o.name not in self.off_axis)

    @property
    def informative(self) -> tuple[OutputVerification, ...]:
        """The off-axis outputs, shown for information only."""
        return tuple(o for o in self.outputs if o.name in self.off_axis)

    def to_dict(self, *, histories: bool = True) -> dict[str, Any]:
        """Its JSON entry, as the verification file and ``sysid validate --json`` give it.

        Parameters
        ----------
        histories : bool, optional
            Include ``time_s`` and each output's time histories (the file does); without them,
            ``start_s`` and ``end_s`` say where the record lies (``--json``).

        Returns
        -------
        dict
            Non-finite numbers as None; ``on_axis`` names the outputs it is judged on.
        """
        entry: dict[str, Any] = {"label": self.label, "source": str(self.source)}
        if histories:
            entry["time_s"] = json_floats(self.time_s)
        else:
            entry |= {"start_s": float(self.time_s[0]), "end_s": float(self.time_s[-1])}
        return entry | {
            "inputs": list(self.inputs),
            "outputs": [o.to_dict(histories=histories) for o in self.outputs],
            "reference_shifts": {k: finite_or_none(v) for k, v in self.reference_shifts.items()},
            "rmse": finite_or_none(self.rmse),
            "tic": finite_or_none(self.tic),
            "growth": finite_or_none(self.growth),
            "unstable": bool(self.unstable),
            "notice": self.notice,
            "excited": self.excited,
            "on_axis": [o.name for o in self.judged],
            "off_axis": list(self.off_axis),
            "unstable_modes": list(self.unstable_modes),
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> RecordVerification:
        """Rebuild it from :meth:`to_dict` with its histories (missing numbers as NaN)."""
        return cls(
            label=d["label"],
            source=Path(d["source"]),
            time_s=float_array(d["time_s"]),
            inputs=tuple(d["inputs"]),
            outputs=tuple(OutputVerification.from_dict(o) for o in d["outputs"]),
            reference_shifts={k: float_or_nan(v) for k, v in d["reference_shifts"].items()},
            rmse=float_or_nan(d["rmse"]),
            tic=float_or_nan(d["tic"]),
            growth=float_or_nan(d["growth"]),
            unstable=bool(d["unstable"]),
            notice=d.get("notice", ""),
            excited=d.get("excited"),
            off_axis=tuple(d.get("off_axis", ())),
            unstable_modes=tuple(d.get("unstable_modes", ())),
        )


@dataclass(frozen=True, slots=True, kw_only=True)
class OutputSummary:
    """One output pooled over every record that verified it.

    Parameters
    ----------
    name : str
        Canonical signal name.
    unit : str
        Its unit.
    rmse : float
        RMS error over all samples of all records, in `unit`.
    tic : float
        Theil inequality coefficient over the same samples.
    n_records : int
        Records pooled.
    n_samples : int
        Samples pooled.
    prediction_rmse, prediction_tic : float or None, optional
        The same for the one-step-ahead prediction, over the records where it was computed.
    """

    name: str
    unit: str
    rmse: float
    tic: float
    n_records: int
    n_samples: int
    prediction_rmse: float | None = None
    prediction_tic: float | None = None

    def to_dict(self) -> dict[str, str | int | float | None]:
        """Its JSON form, the same in the verification file and in ``sysid validate --json`` (NaN as null)."""
        return {
            "name": self.name,
            "unit": self.unit,
            "rmse": finite_or_none(self.rmse),
            "tic": finite_or_none(self.tic),
            "n_records": self.n_records,
            "n_samples": self.n_samples,
            "prediction_rmse": finite_or_none(self.prediction_rmse),
            "prediction_tic": finite_or_none(self.prediction_tic),
        }

    @classmethod
    def from_dict(cls, doc: Mapping[str, Any]) -> OutputSummary:
        """Read :meth:`to_dict`'s form."""
        return cls(
            name=str(doc["name"]),
            unit=str(doc["unit"]),
            rmse=float_or_nan(doc["rmse"]),
            tic=float_or_nan(doc["tic"]),
            n_records=int(doc["n_records"]),
            n_samples=int(doc["n_samples"]),
            prediction_rmse=_optional(doc.get("prediction_rmse")),
            prediction_tic=_optional(doc.get("prediction_tic")),
        )


@dataclass(frozen=True, slots=True, kw_only=True)
class WindCorrection:
    """What the wind term G_w buys on one output (dissertation Table 3.6), over all of it and in the wind's band.

    Parameters
    ----------
    name : str
        Canonical signal name.
    unit : str
        Its unit.
    rmse_without : float
        Pooled RMS error of the model without G_w, in `unit`.
    rmse_with : float
        Pooled RMS error of the model with G_w, in `unit`.
    band_hz : float, optional
        Upper edge of the wind's band, Hz: the wind step low-passes the anemometer's wind there, so
        G_w predicts nothing above it (NaN: not computed).
    rmse_without_in_band, rmse_with_in_band : float, optional
        The same errors low-passed at `band_hz` (zero phase) before pooling, in `unit`: what G_w can
        correct, without the errors of faster dynamics it cannot (a thrust response's at 2-10 Hz).

    Attributes
    ----------
    reduction_percent : float
        ``100 (1 - rmse_with / rmse_without)``: the dissertation's 13-16 % on
        a_x and 7-15 % on a_z (Table 3.6); NaN when `rmse_without` is 0.
    reduction_in_band_percent : float
        The same of the errors in the wind's band; NaN when not computed.

    Examples
    --------
    >>> strong = WindCorrection(name="ax", unit="m/s^2", rmse_without=0.4129, rmse_with=0.3480)  # Table 3.6, strong wind
    >>> round(strong.reduction_percent, 1)
    15.7
    >>> WindCorrection.from_dict(strong.to_dict()) == strong
    True
    """

    name: str
    unit: str
    rmse_without: float
    rmse_with: float
    band_hz: float = math.nan
    rmse_without_in_band: float = math.nan
    rmse_with_in_band: float = math.nan
    reduction_percent: float = field(init=False)
    reduction_in_band_percent: float = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "reduction_percent", _reduction(self.rmse_without, self.rmse_with))
        object.__setattr__(
            self, "reduction_in_band_percent", _reduction(self.rmse_without_in_band, self.rmse_with_in_band)
        )

    def to_dict(self) -> dict[str, str | float | None]:
        """Its JSON form, the same in the verification file and in ``sysid validate --json`` (NaN as null)."""
        numbers = {
            "rmse_without": self.rmse_without,
            "rmse_with": self.rmse_with,
            "reduction_percent": self.reduction_percent,
            "band_hz": self.band_hz,
            "rmse_without_in_band": self.rmse_without_in_band,
            "rmse_with_in_band": self.rmse_with_in_band,
            "reduction_in_band_percent": self.reduction_in_band_percent,
        }
        return {"name": self.name, "unit": self.unit} | {k: finite_or_none(v) for k, v in numbers.items()}

    @classmethod
    def from_dict(cls, doc: Mapping[str, Any]) -> WindCorrection:
        """Read :meth:`to_dict`'s form (the band's fields may be missing: files written before them)."""

        def number(key: str) -> float:
            return float_or_nan(doc.get(key))

        return cls(
            name=str(doc["name"]),
            unit=str(doc["unit"]),
            rmse_without=number("rmse_without"),
            rmse_with=number("rmse_with"),
            band_hz=number("band_hz"),
            rmse_without_in_band=number("rmse_without_in_band"),
            rmse_with_in_band=number("rmse_with_in_band"),
        )


def _reduction(without: float, with_: float) -> float:
    return 100.0 * (1.0 - with_ / without) if without > 0 else math.nan


@dataclass(frozen=True, slots=True, kw_only=True)
class Verification:
    """A model verified on records it was not fitted to.

    Parameters
    ----------
    records : tuple of RecordVerification
        The model verified, per record (the wind model when one was given).
    summary : tuple of OutputSummary
        Per output, pooled over the records where it is on-axis (judged).
    rmse : float
        Overall weighted RMS error J_rms over every record's on-axis outputs.
    tic : float
        Overall Theil inequality coefficient on the same weighted signals.
    without_wind : tuple of RecordVerification, optional
        The model without G_w on the same records, when a wind model was given.
    wind_correction : tuple of WindCorrection, optional
        Per output common to both models, over the records where it is on-axis.
    off_axis : tuple of OutputSummary, optional
        Per output, pooled over the records where it is off-axis: for
        information, not judged.
    unverified : tuple of str, optional
        One sentence per axis of the model not verified, and why (``"lat: no
        doublet in 2 logs; not verified"``; an unidentified axis is never verified).
    """

    records: tuple[RecordVerification, ...]
    summary: tuple[OutputSummary, ...]
    rmse: float
    tic: float
    without_wind: tuple[RecordVerification, ...] = ()
    wind_correction: tuple[WindCorrection, ...] = ()
    off_axis: tuple[OutputSummary, ...] = ()
    unverified: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.without_wind and len(self.without_wind) != len(self.records):
            raise ValueError(f"{len(self.without_wind)} records without wind for {len(self.records)} records")

    @property
    def unstable(self) -> bool:
        """True when any record's simulation is flagged as diverging open loop."""
        return any(r.unstable for r in (*self.records, *self.without_wind))

    def record_notes(self) -> tuple[str, ...]:
        """What a reader of the records should know, one sentence each.

        Records that diverge open loop share one sentence when there are
        several (the model's unstable modes, the largest growth, their
        labels); every other record's own notice follows, prefixed with its label.

        Returns
        -------
        tuple of str
        """
        unstable = [r for r in self.records if r.unstable]
        notes = []
        if len(unstable) > 1:  # one note, not the same sentence per record
            growth = max(r.growth for r in unstable)
            names = mode_names([m for r in unstable for m in r.unstable_modes])
            notes.append(
                f"the model is unstable open loop in its {names} and grows up to {growth:.0f}-fold over "
                f"{len(unstable)} records ({'; '.join(r.label for r in unstable)}): small input or initial-state "
                "errors diverge there, so judge them also by the one-step-ahead prediction error "
                "(`prediction_rmse`, `prediction_tic`)"
            )
        notes += [f"{r.label}: {r.notice}" for r in self.records if r.notice and (len(unstable) < 2 or not r.unstable)]
        return tuple(notes)

    def output(self, name: str) -> OutputSummary:
        """The pooled verification of one output.

        Parameters
        ----------
        name : str
            Canonical signal name.

        Raises
        ------
        KeyError
            If no record verified that output.
        """
        return _named(self.summary, name, f"no record verified output {name!r}")

    def correction(self, name: str) -> WindCorrection:
        """The wind correction of one output.

        Parameters
        ----------
        name : str
            Canonical signal name.

        Raises
        ------
        KeyError
            If there is no wind model or it does not share that output.
        """
        return _named(self.wind_correction, name, f"no wind correction for output {name!r}")

    def digest(self) -> dict[str, Any]:
        """What ``sysid validate --json`` gives of it: each record without its time histories, each output's
        entry as the verification file's (:meth:`OutputSummary.to_dict`), by name.

        Returns
        -------
        dict
            ``records``, ``summary``, ``off_axis``, ``overall``, ``unstable`` and, with a wind model,
            ``wind_correction``.
        """
        digest: dict[str, Any] = {
            "records": [r.to_dict(histories=False) for r in self.records],
            "summary": {s.name: s.to_dict() for s in self.summary},
            "off_axis": {s.name: s.to_dict() for s in self.off_axis},
            "overall": {"rmse": self.rmse, "tic": self.tic},
            "unstable": self.unstable,
        }
        if self.wind_correction:
            digest["wind_correction"] = {c.name: c.to_dict() for c in self.wind_correction}
        return digest
