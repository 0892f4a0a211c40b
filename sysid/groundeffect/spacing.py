"""Rotor-spacing study: the same fit over data sets taken at several rotor separations (Tables 2.2-2.3).

Chapter 2 lengthened the Crazyflie's arms to separate the rotors by 0-50 mm
more. With two rotors it reports eq. 2.2's rho per spacing (Table 2.2);
with four it compares the "quadratic" law (eq. 2.2, inverse-square in Z)
with the piecewise-linear law (eq. 2.5's form) and finds piecewise linear
better below 30 mm and quadratic from 30 mm (Table 2.3). Here each data set
is fitted with every family and, per spacing, the families compared are
ranked by the information criterion of the fit (AICc by default), which
accounts for the piecewise law's extra parameter; R^2 is reported as in the
dissertation.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from flightlogs.errors import DataError
from sysid.groundeffect.fitting import FitConfig, fit_ground_effect
from sysid.groundeffect.models import MODEL_NAMES, GroundEffectFit, ModelName
from sysid.groundeffect.records import ThrustRatioData

__all__ = ["SpacingStudy", "spacing_study", "default_families", "spacing_summary"]


def default_families(rotors: int) -> tuple[ModelName, ...]:
    """Families compared in the study: eq. 2.2 for two rotors; piecewise linear then eq. 2.2 for more.

    Parameters
    ----------
    rotors : int
        Rotors running on the rig (chapter 2: 2 or 4).

    Returns
    -------
    tuple of str
        For more than two rotors, ``("piecewise_linear", "corrected")``: the
        transition is from the first to the second as the spacing grows.
    """
    return ("corrected",) if rotors <= 2 else ("piecewise_linear", "corrected")


@dataclass(frozen=True, slots=True, kw_only=True)
class SpacingStudy:
    """Fits over a series of rotor spacings, the family chosen at each and the transition.

    Parameters
    ----------
    spacings_m : ndarray, shape (n_sets,)
        Rotor-separation increment of each data set, m, increasing.
    fits : tuple of GroundEffectFit
        One per spacing, every family fitted.
    families : tuple of str
        Families compared (see :func:`default_families`).
    chosen : tuple of str
        Family with the lowest criterion among `families`, per spacing.
    transition_m : float or None
        Smallest spacing from which the last family is chosen at every
        spacing while the first is chosen at every smaller one; None when the
        choices do not switch once (or one family only is compared).
    rotors : int
        Rotors running.
    """

    spacings_m: np.ndarray
    fits: tuple[GroundEffectFit, ...]
    families: tuple[str, ...]
    chosen: tuple[str, ...]
    transition_m: float | None
    rotors: int

    def __post_init__(self) -> None:
        spacings = np.asarray(self.spacings_m, dtype=np.float64)
        if spacings.ndim != 1 or spacings.size != len(self.fits) or spacings.size != len(self.chosen):
            raise ValueError(
                f"spacings_m {spacings.shape}, {len(self.fits)} fits and {len(self.chosen)} choices differ"
            )
        if np.any(np.diff(spacings) <= 0):
            raise ValueError(f"spacings_m {spacings.tolist()} must increase")
        object.__setattr__(self, "spacings_m", spacings)
        object.__setattr__(self, "fits", tuple(self.fits))
        object.__setattr__(self, "chosen", tuple(self.chosen))

    def r2(self, family: str) -> np.ndarray:
        """R^2 of a family at each spacing, shape (n_sets,).

        Parameters
        ----------
        family : str
            Family name.

        Returns
        -------
        ndarray
        """
        return np.array([fit.model(family).r2 for fit in self.fits])

    def rmse(self, family: str) -> np.ndarray:
        """RMSE of a family at each spacing, shape (n_sets,).

        Parameters
        ----------
        family : str
            Family name.

        Returns
        -------
        ndarray
        """
        return np.array([fit.model(family).rmse for fit in self.fits])

    def parameter(self, family: str, name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """A parameter of a family at each spacing, with its confidence interval.

        Parameters
        ----------
        family : str
            Family name.
        name : str
            Parameter name (e.g. ``"rho"``).

        Returns
        -------
        values, ci_low, ci_high : ndarray, shape (n_sets,)
        """
        rows = []
        for fit in self.fits:
            m = fit.model(family)
            i = m.param_names.index(name)
            rows.append((m.values[i], m.ci_low[i], m.ci_high[i]))
        values, low, high = (np.array(column) for column in zip(*rows))
        return values, low, high


def spacing_study(
    datasets: Sequence[ThrustRatioData],
    spacings_m: Sequence[float] | np.ndarray,
    *,
    rotors: int = 4,
    families: tuple[ModelName, ...] | None = None,
    config: FitConfig | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> SpacingStudy:
    """Fit every data set, choose among `families` at each spacing and locate the transition.

    Parameters
    ----------
    datasets : sequence of ThrustRatioData
        One per spacing.
    spacings_m : sequence of float, shape (n_sets,)
        Rotor-separation increment of each, m (any order; sorted here).
    rotors : int, optional
        Rotors running (2: Table 2.2; 4: Table 2.3).
    families : tuple of str, optional
        Families compared; default :func:`default_families`.
    config : FitConfig, optional
        Criterion and confidence; every family of `families` is fitted in
        addition to those of ``config.models``.
    progress : callable, optional
        ``progress(done, total)`` after each data set.

    Returns
    -------
    SpacingStudy

    Raises
    ------
    DataError
        If the counts differ, a spacing repeats, or fewer than two data sets are given.
    """
    spacings = np.asarray(spacings_m, dtype=np.float64)
    if spacings.shape != (len(datasets),):
        raise DataError(f"{len(datasets)} data sets but {spacings.size} spacings; give one spacing per data set")
    if len(datasets) < 2 or np.unique(spacings).size != spacings.size:
        raise DataError(f"a spacing study needs at least two data sets at distinct spacings, got {spacings.tolist()}")
    compared = families or default_families(rotors)
    base = config or FitConfig()
    models = tuple(m for m in MODEL_NAMES if m in base.models or m in compared)
    fit_config = FitConfig(models=models, criterion=base.criterion, confidence=base.confidence)
    order = np.argsort(spacings)
    fits = []
    for done, i in enumerate(order, 1):
        fits.append(fit_ground_effect(datasets[i], fit_config))
        if progress is not None:
            progress(done, len(order))
    chosen = tuple(min(compared, key=lambda name: fit.model(name).criterion(fit_config.criterion)) for fit in fits)
    return SpacingStudy(
        spacings_m=spacings[order],
        fits=tuple(fits),
        families=tuple(compared),
        chosen=chosen,
        transition_m=_transition(spacings[order], chosen, compared),
        rotors=rotors,
    )


def _transition(spacings: np.ndarray, chosen: tuple[str, ...], families: tuple[str, ...]) -> float | None:
    """First spacing of the last family's run when the first family holds every spacing before it."""
    if len(families) < 2:
        return None
    first, last = families[0], families[-1]
    for k in range(1, len(chosen)):
        if all(c == first for c in chosen[:k]) and all(c == last for c in chosen[k:]):
            return float(spacings[k])
    return None


def spacing_summary(study: SpacingStudy) -> dict[str, Any]:
    """A JSON-ready summary: spacings (mm), choices, transition, and each set's models.

    Parameters
    ----------
    study : SpacingStudy
        The study.

    Returns
    -------
    dict
        ``spacing_mm``, ``rotors``, ``families``, ``chosen``, ``transition_mm``
        and ``sets`` (per spacing: ``source``, ``best``, ``models.NAME.params|ci|rmse|r2|aicc|bic``).
    """
    sets = []
    for spacing, fit, chosen in zip(study.spacings_m, study.fits, study.chosen):
        models = {
            m.name: {"params": m.params, "ci": m.intervals, "rmse": m.rmse, "r2": m.r2, "aicc": m.aicc, "bic": m.bic}
            for m in fit.models
        }
        sets.append(
            {
                "spacing_mm": float(spacing) * 1e3,
                "source": fit.data.source,
                "n_points": fit.data.n_points,
                "chosen": chosen,
                "best": fit.best,
                "models": models,
            }
        )
    return {
        "rotors": study.rotors,
        "families": list(study.families),
        "criterion": study.fits[0].criterion,
        "spacing_mm": (study.spacings_m * 1e3).tolist(),
        "chosen": list(study.chosen),
        "transition_mm": None if study.transition_m is None else study.transition_m * 1e3,
        "sets": sets,
    }
