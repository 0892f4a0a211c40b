"""What the discrepancy search found: frozen results, and their JSON form for scripts."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from sysid.discrepancy.corrected import CorrectedModel

__all__ = ["Alternative", "FittedParameter", "Regime", "FindingTraces", "Finding", "Screening", "DiscrepancyResult"]


@dataclass(frozen=True, slots=True, kw_only=True)
class FindingTraces:
    """What the report draws of a finding (not in the JSON).

    Parameters
    ----------
    time_s : ndarray, shape (n,)
        Flight clock, s.
    regime : ndarray, shape (n,)
        The regime variable, in its unit.
    before, after : Mapping of str to ndarray, each shape (n,)
        Held-out residual of each of the finding's outputs without and with it.
    """

    time_s: np.ndarray
    regime: np.ndarray
    before: dict[str, np.ndarray]
    after: dict[str, np.ndarray]


@dataclass(frozen=True, slots=True, kw_only=True)
class FittedParameter:
    """One parameter of a found effect.

    Parameters
    ----------
    name : str
        E.g. ``delay_s``, ``time_constant_s``, ``mass_ratio``.
    value, uncertainty : float
        Estimate and its standard deviation (residual correlation accounted for), in `unit`.
    unit : str
        SI unit.
    """

    name: str
    value: float
    uncertainty: float
    unit: str


@dataclass(frozen=True, slots=True, kw_only=True)
class Regime:
    """Where in the flight an effect acts.

    Parameters
    ----------
    variable : str
        ``height_agl``, ``ground_speed``, ``wind_speed``, ``delta_thr``, ``battery_v`` or ``time`` (flight clock).
    unit : str
        Its unit.
    low, high : float
        The range holding 80 % of the effect's contribution.
    """

    variable: str
    unit: str
    low: float
    high: float


@dataclass(frozen=True, slots=True, kw_only=True)
class Alternative:
    """Another explanation of a finding's residual, as good within its uncertainty.

    Parameters
    ----------
    effect : str
        The other term (a catalogue name, or ``unexplained``).
    explained_variance : float
        Its held-out score on the finding's outputs, 0-1.
    """

    effect: str
    explained_variance: float


@dataclass(frozen=True, slots=True, kw_only=True)
class Screening:
    """One term as the search screened it at the first step.

    Parameters
    ----------
    effect : str
        The term.
    score : float
        Share of the noise-weighted held-out residual of its outputs it removes (0-1, can be negative).
    threshold : float
        The score it had to pass (a floor, or a multiple of what it gains on held-out simulated flight).
    where_it_acts : float
        Share of the residual it removes on the samples holding 80 % of its contribution.
    """

    effect: str
    score: float
    threshold: float
    where_it_acts: float

    @property
    def passed(self) -> bool:
        """Whether its score passed the threshold."""
        return self.score > self.threshold


@dataclass(frozen=True, slots=True, kw_only=True)
class Finding:
    """One effect the simulation leaves out, modelled and proven on held-out data.

    Parameters
    ----------
    effect : str
        One of :data:`~sysid.discrepancy.catalogue.EFFECTS`, or ``unexplained``: a residual no term of the
        catalogue explains, modelled by a sparse combination of the flight's states and inputs.
    outputs : tuple of str
        Outputs it acts on.
    band_rad_s : tuple of float
        Frequency band holding 90 % of its contribution's power, rad/s.
    regime : Regime
        Where in the flight it acts.
    explained_variance : float
        Share of the residual (noise-normalised) of its outputs it explains on held-out blocks, 0-1.
    parameters : tuple of FittedParameter
        Its fitted parameters.
    rmse_before, rmse_after : dict of str to float
        Held-out residual RMS per output without and with it (and the findings before it), in output units.
    improvement_percent : float
        Held-out cut of the residual RMS of its outputs, %.
    evidence : str
        One sentence.
    alternatives : tuple of Alternative
        Other terms that explain the same residual about as well (then the finding is ambiguous).
    traces : FindingTraces or None
        What the report draws (not in the JSON).
    """

    effect: str
    outputs: tuple[str, ...]
    band_rad_s: tuple[float, float]
    regime: Regime
    explained_variance: float
    parameters: tuple[FittedParameter, ...]
    rmse_before: dict[str, float]
    rmse_after: dict[str, float]
    improvement_percent: float
    evidence: str
    alternatives: tuple[Alternative, ...] = ()
    traces: FindingTraces | None = field(default=None, repr=False, compare=False)

    @property
    def modelled(self) -> bool:
        """Whether it is modelled (has fitted parameters), not only located: a residual no model of the flight
        explains (a load swinging under the vehicle) is located on its outputs and removes nothing."""
        return bool(self.parameters)


@dataclass(frozen=True, slots=True, kw_only=True)
class DiscrepancyResult:
    """The answer for one SIM / REAL pair.

    Parameters
    ----------
    verdict : str
        The most important effect, or ``"none"``.
    findings : tuple of Finding
        By importance (held-out improvement).
    summary : str
        Plain-language sentences, the first naming the verdict.
    screened : tuple of Screening
        Every term tried at the first step, its held-out score and the threshold it had to pass.
    noise_floor : dict of str to float
        RMS of each output's residual on held-out SIM data (model error and noise alone).
    sim, real : tuple of str
        The flights compared.
    thrust_scale : float
        Real thrust per input over the simulated one, a constant fitted before any term (a trim, not a finding).
    unexplained : dict of str to float
        Per output, the real flight's held-out residual RMS with every finding modelled, over the noise floor:
        about 1 when the findings account for the difference, far above it when the simulation is not a close
        model of the real vehicle or an effect outside the library remains.
    corrected : CorrectedModel or None
        The simulation's model with the kept terms (not in the JSON; ``--model-out`` writes it).
    """

    verdict: str
    findings: tuple[Finding, ...]
    summary: str
    screened: tuple[Screening, ...]
    noise_floor: dict[str, float]
    sim: tuple[str, ...]
    real: tuple[str, ...]
    thrust_scale: float = 1.0
    unexplained: dict[str, float] = field(default_factory=dict)
    corrected: CorrectedModel | None = field(default=None, repr=False, compare=False)

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: ``verdict``, ``findings[]`` (empty when the verdict is ``none``) and the context."""
        return {
            "verdict": self.verdict,
            "summary": self.summary,
            "findings": [
                {
                    "effect": f.effect,
                    "outputs": list(f.outputs),
                    "band_rad_s": list(f.band_rad_s),
                    "regime": {
                        "variable": f.regime.variable,
                        "unit": f.regime.unit,
                        "range": [f.regime.low, f.regime.high],
                    },
                    "explained_variance": f.explained_variance,
                    "parameters": {
                        p.name: {"value": p.value, "uncertainty": p.uncertainty, "unit": p.unit} for p in f.parameters
                    },
                    "rmse_before": f.rmse_before,
                    "rmse_after": f.rmse_after,
                    "improvement_percent": f.improvement_percent,
                    "modelled": f.modelled,
                    "evidence": f.evidence,
                    "alternatives": [
                        {"effect": a.effect, "explained_variance": a.explained_variance} for a in f.alternatives
                    ],
                }
                for f in self.findings
            ],
            "screened": {
                t.effect: {"score": t.score, "threshold": t.threshold, "where_it_acts": t.where_it_acts}
                for t in self.screened
            },
            "noise_floor": self.noise_floor,
            "sim": list(self.sim),
            "real": list(self.real),
            "thrust_scale": self.thrust_scale,
            "unexplained": self.unexplained,
        }
