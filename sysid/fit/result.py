"""The identified model: structure, estimates with their accuracy, costs, data used and provenance."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Literal

import numpy as np

from flightlogs.errors import ModelError
from sysid.fit.axes import AxisStatus, axes_from_parameters
from sysid.fit.cost import CostSummary
from sysid.fit.guidelines import Guidelines
from sysid.fit.reduce import ReductionStep
from sysid.freqresp import FrequencyResponse, Gating
from sysid.model.assemble import Assembler
from sysid.model.axes import axis_parts, restrict_model
from sysid.model.statespace import DelayedStateSpace
from sysid.model.structure import InputChannel, ModelStructure
from sysid.model.toml_format import parse_structure

__all__ = [
    "ParameterStatus",
    "PARAMETER_STATUSES",
    "ParameterEstimate",
    "WindClockOffset",
    "WindFit",
    "WindTrace",
    "Provenance",
    "IdentifiedModel",
]

ParameterStatus = Literal["estimated", "fixed", "dropped", "unidentified"]
#: Every parameter status, in the order tables list them.
PARAMETER_STATUSES: tuple[ParameterStatus, ...] = ("estimated", "fixed", "dropped", "unidentified")


@dataclass(frozen=True, slots=True, kw_only=True)
class ParameterEstimate:
    """One parameter of an identified model.

    Parameters
    ----------
    name : str
        Parameter name (``X_u``, ``tau_lon``, ``X_w_lon``).
    value : float
        Final value, in `unit`; NaN when unidentified.
    cr_percent : float
        Cramér–Rao bound as % of ``|value|`` (NaN unless estimated).
    insensitivity_percent : float
        Insensitivity as % of ``|value|`` (NaN unless estimated).
    status : {"estimated", "fixed", "dropped", "unidentified"}
        Estimated; held at a value the structure gives (not free, or fixed
        by structure reduction); removed by structure reduction (set to its
        drop value, normally 0); or unidentified: no gated response informed
        it, so it has no value.
    unit : str
        Unit, with control derivatives per unit of the logged input
        (``rad/s^2 per normalised (-1..1)``).
    stage : {"frequency", "wind"}
        Fitted to the frequency responses (F, G_u) or in the wind step
        (G_w and wind delays, eq. 3.14).
    """

    name: str
    value: float
    cr_percent: float = math.nan
    insensitivity_percent: float = math.nan
    status: ParameterStatus = "estimated"
    unit: str = ""
    stage: Literal["frequency", "wind"] = "frequency"

    def __post_init__(self) -> None:
        if self.status not in PARAMETER_STATUSES:
            raise ValueError(f"status={self.status!r} must be one of {', '.join(PARAMETER_STATUSES)}")
        if self.stage not in ("frequency", "wind"):
            raise ValueError(f"stage={self.stage!r} must be 'frequency' or 'wind'")
        if self.unidentified != math.isnan(self.value):
            raise ValueError(f"parameter {self.name}: the value is NaN exactly when it is unidentified")

    @property
    def fixed(self) -> bool:
        """Held at a value, not estimated."""
        return self.status == "fixed"

    @property
    def dropped(self) -> bool:
        """Removed by structure reduction."""
        return self.status == "dropped"

    @property
    def unidentified(self) -> bool:
        """Informed by no gated response: it has no value."""
        return self.status == "unidentified"

    @property
    def cramer_rao(self) -> float:
        """Cramér–Rao bound in the parameter's unit."""
        return abs(self.value) * self.cr_percent / 100.0


@dataclass(frozen=True, slots=True, kw_only=True)
class WindClockOffset:
    """The anemometer clock offset measured from the wind step's residual.

    Parameters
    ----------
    shift_s : ndarray, shape (n_trial,)
        Trial moves of the wind along the log's clock, s (positive: the
        vehicle meets the air later than the conditioning placed it), in
        increasing order: the coarse and the fine pass together.
    cost : ndarray, shape (n_trial,)
        Weighted residual sum of squares per sample left after the best G_w
        gains at each trial (dimensionless: each output weighted by its own
        residual level).
    cost_without_wind : float
        The same with no wind term.
    best_shift_s : float
        The trial of least cost, refined by a parabola through its
        neighbours, s.
    sigma_s : float
        Its standard deviation from the cost's curvature, s (inf when the
        cost has no minimum there).
    used_clock_offset_s : float
        Anemometer clock minus reference clock the conditioning used, s
        (the median over the flights).
    transport_delay_s : float
        Anemometer-to-vehicle delay the conditioning applied (distance /
        mean speed, or given), s, the median over the flights: the scan
        moves the wind on top of it, and cannot tell a clock offset from an
        error of it.
    measured : bool
        Whether the wind carries the information to claim the offset.
    reason : str
        Why it is not claimed ("" when it is).
    samples : int
        Samples in the cost.
    """

    shift_s: np.ndarray
    cost: np.ndarray
    cost_without_wind: float
    best_shift_s: float
    sigma_s: float
    used_clock_offset_s: float
    transport_delay_s: float
    measured: bool
    reason: str
    samples: int

    @property
    def clock_offset_s(self) -> float:
        """Anemometer clock minus reference clock the residual points to, s."""
        return self.used_clock_offset_s - self.best_shift_s

    @property
    def contrast(self) -> float:
        """How much the timing of the wind matters: the residual at the best move below its median over the scan.

        A fraction of that median: 0 when the cost is flat (calm air, no wind information). The median is
        that of the cost at 101 evenly spaced moves across the scan (its coarse trials), so that the fine
        trials about the minimum, as many as the search took, do not pull it down.
        """
        even = np.interp(np.linspace(self.shift_s[0], self.shift_s[-1], 101), self.shift_s, self.cost)
        median = float(np.median(even))
        return 1.0 - self.cost_at(self.best_shift_s) / median if median > 0 else 0.0

    def cost_at(self, shift_s: float) -> float:
        """Cost at a move of the wind, interpolated between trials."""
        return float(np.interp(shift_s, self.shift_s, self.cost))


@dataclass(frozen=True, slots=True, kw_only=True)
class WindTrace:
    """One wind record's along-nose wind at the anemometer, where the vehicle met it, and as the accelerometers felt it.

    Parameters
    ----------
    record : str
        The record's label.
    time_s : ndarray, shape (n_samples,)
        Log clock, s (about 10 Hz).
    at_anemometer_m_s : ndarray, shape (n_samples,)
        Along-nose wind the anemometer read at each instant (its clock
        corrected), less the record's mean, m/s.
    at_vehicle_m_s : ndarray, shape (n_samples,)
        The same air where the vehicle met it, `transport_delay_s` later, m/s.
    from_accelerations_m_s : ndarray, shape (n_samples,)
        `output`'s residual of eq. 3.14 without the wind terms divided by
        `gain`, low-passed at `smoothing_hz`, m/s: the wind the vehicle's
        accelerations say it met.
    output : str
        The accelerometer output read (``ax``).
    gain : float
        The G_w gain of the along-nose wind on it, 1/s.
    transport_delay_s : float
        The record's anemometer-to-vehicle delay, s.
    smoothing_hz : float
        Low-pass of the wind and of the residual read as wind, Hz.
    """

    record: str
    time_s: np.ndarray
    at_anemometer_m_s: np.ndarray
    at_vehicle_m_s: np.ndarray
    from_accelerations_m_s: np.ndarray
    output: str
    gain: float
    transport_delay_s: float
    smoothing_hz: float

    def __post_init__(self) -> None:
        n = self.time_s.shape
        if not self.at_anemometer_m_s.shape == self.at_vehicle_m_s.shape == self.from_accelerations_m_s.shape == n:
            raise ValueError("time_s and the three winds must have one sample each")


@dataclass(frozen=True, slots=True, kw_only=True)
class WindFit:
    """How well the wind terms explain the one-step-prediction residual of eq. 3.14.

    Parameters
    ----------
    outputs : tuple of str
        Outputs whose residual was fitted (``ax``, ``az``).
    rms_before : tuple of float
        RMS of each residual without the wind terms, output units.
    rms_after : tuple of float
        RMS with them.
    samples : int
        Samples used.
    clock_offset : WindClockOffset or None
        The anemometer clock offset scanned from the same residual, when the
        records carry the wind to move.
    trace : WindTrace or None
        One record's wind at the anemometer, at the vehicle and from the
        accelerations (None when no G_w gain on ax was estimated).
    """

    outputs: tuple[str, ...]
    rms_before: tuple[float, ...]
    rms_after: tuple[float, ...]
    samples: int
    clock_offset: WindClockOffset | None = None
    trace: WindTrace | None = None

    def __post_init__(self) -> None:
        if not len(self.outputs) == len(self.rms_before) == len(self.rms_after):
            raise ValueError("outputs, rms_before and rms_after must have one entry per output")


@dataclass(frozen=True, slots=True, kw_only=True)
class Provenance:
    """Where an identified model came from.

    Parameters
    ----------
    files : tuple of str
        Logs and anemometer files read.
    sha256 : Mapping[str, str]
        SHA-256 of each file, by path.
    options : Mapping[str, Any]
        Options of the identification (JSON-compatible values); those of the
        fit under ``fit``, with the CR% and I% limits it applied
        (``max_cr_percent``, ``max_insensitivity_percent``).
    versions : Mapping[str, str]
        Versions of flight-sysid, numpy, scipy.
    created_utc : str
        ISO 8601 time of the identification.
    maneuvers : tuple of str
        How each fitted maneuver was found, one ``"kind axis source"`` per
        distinct triple (``"sweep lat sids"``, ``"broadband lon detected"``):
        the verdict weighs it (:func:`~sysid.fit.guidelines.model_verdict`).
    """

    files: tuple[str, ...] = ()
    sha256: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    options: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    versions: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    created_utc: str = ""
    maneuvers: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class IdentifiedModel:
    """A fitted model structure with everything needed to use, judge and re-plot it.

    Parameters
    ----------
    structure_name : str
        Name of the structure (``hover``).
    structure_text : str
        The structure's TOML source.
    parameters : tuple of ParameterEstimate
        Every parameter of the structure.
    correlation_names : tuple of str
        Parameters of the correlation matrix, in order (the estimated ones).
    correlation : ndarray, shape (n_estimated, n_estimated)
        Correlation matrix (F/G_u block, then the wind block; no
        correlation across the two steps is estimated).
    cost : CostSummary
        J_ave and per-pair costs (eq. 3.9).
    responses : tuple of FrequencyResponse
        The gated responses fitted.
    trim : Mapping[str, float]
        Trim of the flight (means removed from the records), SI / as logged.
    constants : Mapping[str, float]
        Trim constants the matrices were built with (``g U0 W0 theta0`` ...).
    reduction : tuple of ReductionStep
        Structure-reduction log.
    provenance : Provenance
        Files, hashes, options and versions.
    wind : WindFit or None
        Outcome of the wind step, when one was run.
    input_units : Mapping[str, str]
        Unit of each logged input signal (``delta_lon``: ``normalised (-1..1)``).
    notes : tuple of str
        Remarks of the identification (responses dropped by gating and why).
    axes : tuple of AxisStatus
        Each control input's axis, identified or not and why; empty for a
        model that does not record them (then :attr:`axis_status` derives them:
        an axis with an estimated parameter and none unidentified is identified).
    """

    structure_name: str
    structure_text: str
    parameters: tuple[ParameterEstimate, ...]
    correlation_names: tuple[str, ...]
    correlation: np.ndarray
    cost: CostSummary
    responses: tuple[FrequencyResponse, ...] = ()
    trim: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({}))
    constants: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({}))
    reduction: tuple[ReductionStep, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)
    wind: WindFit | None = None
    input_units: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    notes: tuple[str, ...] = ()
    axes: tuple[AxisStatus, ...] = ()

    def __post_init__(self) -> None:
        n = len(self.correlation_names)
        if np.shape(self.correlation) != (n, n):
            raise ValueError(f"correlation has shape {np.shape(self.correlation)}, expected ({n}, {n})")
        names = [p.name for p in self.parameters]
        if len(set(names)) != len(names):
            raise ValueError("parameter names must be unique")
        for name in ("trim", "constants", "input_units"):
            object.__setattr__(self, name, MappingProxyType(dict(getattr(self, name))))

    @property
    def structure(self) -> ModelStructure:
        """The structure, parsed again from `structure_text`."""
        return parse_structure(self.structure_text, source=self.structure_name)

    @property
    def guidelines(self) -> Guidelines:
        """The guidelines the model was identified with, to judge it by.

        The CR% and I% limits of its fit, as `provenance` records them
        (:meth:`Guidelines.from_options`); Tischler's for the other limits,
        and for a model whose options do not say (a file written before
        they were recorded, a model assembled without provenance).

        Raises
        ------
        ValueError
            If the recorded limits are not positive numbers.
        """
        return Guidelines.from_options(self.provenance.options)

    @property
    def gating(self) -> Gating | None:
        """The gating rule its responses passed, as `provenance` records it; None where it does not say.

        Files written before :class:`~sysid.freqresp.Gating` record ``min_coherence`` and
        ``min_decades`` among the options themselves; a rule that is not valid reads as None.
        """
        options = self.provenance.options
        recorded = options.get("gating", options)
        if not isinstance(recorded, Mapping) or not isinstance(recorded.get("min_coherence"), (int, float)):
            return None
        given = {
            k: float(recorded[k]) for k in ("min_coherence", "min_decades") if isinstance(recorded.get(k), (int, float))
        }
        try:
            return Gating(**given)
        except ValueError:
            return None

    @property
    def values(self) -> dict[str, float]:
        """Every parameter's value, by name (NaN for the unidentified)."""
        return {p.name: p.value for p in self.parameters}

    @property
    def axis_status(self) -> tuple[AxisStatus, ...]:
        """Each control input's axis: `axes` as recorded, or derived from the parameters for a file without them."""
        if self.axes:
            return self.axes
        parts = {signal: part.parameters for signal, part in axis_parts(self.structure, self._usable_values()).items()}
        return axes_from_parameters(parts, {p.name: p.status for p in self.parameters})

    @property
    def unidentified_axes(self) -> tuple[AxisStatus, ...]:
        """The axes not identified (the model is not simulated on them)."""
        return tuple(a for a in self.axis_status if not a.identified)

    def _usable_values(self) -> dict[str, float]:
        """Values to assemble with: an unidentified parameter at the structure's starting value (cut away later)."""
        declared = self.structure.values()
        return {p.name: declared[p.name] if p.unidentified else p.value for p in self.parameters}

    def parameter(self, name: str) -> ParameterEstimate:
        """The estimate of parameter `name`.

        Parameters
        ----------
        name : str
            Parameter name.

        Raises
        ------
        ModelError
            If the model has no such parameter.
        """
        for p in self.parameters:
            if p.name == name:
                return p
        raise ModelError(f"model {self.structure_name} has no parameter {name!r}")

    @property
    def measured_clock_offset_s(self) -> float | None:
        """Anemometer clock offset the wind step measured, s; None when it did not (or had no wind)."""
        clock = self.wind.clock_offset if self.wind is not None else None
        return clock.clock_offset_s if clock is not None and clock.measured else None

    def linear_model(self, *, include_wind: bool = True) -> DelayedStateSpace:
        """The identified model as a :class:`DelayedStateSpace`.

        Parameters
        ----------
        include_wind : bool, optional
            Keep the wind inputs (``G_w``, named by their signal, e.g.
            ``wind_lon`` twice when it enters u and w with different delays);
            False for the model of F and G_u alone.

        Returns
        -------
        DelayedStateSpace
            States, inputs and outputs named as in the structure; `trim`
            holds the flight's trim. A model with unidentified axes is the
            model of its identified axes only: the states and outputs of the
            others' parts (:func:`sysid.model.axes.axis_parts`), their inputs,
            and the wind inputs with an unidentified parameter are left out.

        Raises
        ------
        ModelError
            If no axis is identified, or the identified axes' part reads an unidentified parameter.
        """
        structure = self.structure
        if not any(p.unidentified for p in self.parameters):
            assembler = Assembler(
                structure, free=(), fixed=self.values, constants=self.constants, include_wind=include_wind
            )
            return assembler.state_space(np.zeros(0), trim=self.trim)
        return self._identified_part(include_wind)

    def _identified_part(self, include_wind: bool) -> DelayedStateSpace:
        """The model of the identified axes: assembled with placeholders, cut, and checked not to read them."""
        structure = self.structure
        unidentified = {p.name for p in self.parameters if p.unidentified}
        missing = {a.input for a in self.unidentified_axes}
        parts = axis_parts(structure, self._usable_values())
        kept = [signal for signal in parts if signal not in missing]
        if not kept:
            raise ModelError(f"model {self.structure_name} has no identified axis to simulate")
        states = {s for signal in kept for s in parts[signal].states}
        outputs = {o for signal in kept for o in parts[signal].outputs}
        channels = [c for c in structure.inputs if include_wind or not c.wind]  # the assembled model's inputs
        inputs = [
            k
            for k, c in enumerate(channels)
            if (c.wind and not self._wind_channel_reads(structure, c, unidentified))
            or (not c.wind and c.signal not in missing)
        ]
        cuts = []
        for shift in (0.0, 1.0):  # a placeholder that moved the cut model would be a parameter it reads
            values = self._usable_values() | {n: structure.values()[n] + shift for n in unidentified}
            assembler = Assembler(structure, free=(), fixed=values, constants=self.constants, include_wind=include_wind)
            whole = assembler.state_space(np.zeros(0), trim=self.trim)
            cuts.append(restrict_model(whole, states=states, outputs=outputs, inputs=inputs))
        first, second = cuts
        if not all(
            np.array_equal(getattr(first, m), getattr(second, m)) for m in ("a", "b", "c", "d", "input_delays_s")
        ):
            raise ModelError(
                f"model {self.structure_name}: its identified axes read unidentified parameters "
                f"({', '.join(sorted(unidentified))})"
            )
        return first

    @staticmethod
    def _wind_channel_reads(structure: ModelStructure, channel: InputChannel, names: set[str]) -> bool:
        """Whether a wind channel's delay or G_w column reads one of `names`."""
        column = structure.inputs.index(channel)
        read = set(channel.delay.names)
        for entry in structure.entries:
            if entry.matrix == "G_w" and entry.column == column:
                read |= entry.expression.names
        return bool(read & names)
