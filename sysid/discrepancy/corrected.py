"""The simulation's model with what the search found added: a corrected simulation.

``sysid discrepancy SIM REAL --model-out corrected.json`` writes it (:mod:`.model_files`); ``sysid
discrepancy corrected.json REAL2`` flies it along another real flight
(:func:`~.fitted_model.corrected_flight`) and searches again: a correction that holds answers ``none``
there.

The model is the search's own: the equation-error model of SIM (:class:`~.baseline.BaselineModel`, read
about the real vehicle's hover), the thrust trim, and each kept term in the order it was kept: a delay or
lag re-predicts the model through its inputs; a named linear term adds its regressors, built on the new
flight as on the first (``Term.make``), times its fitted coefficients; the model of the unknown adds its
library's regressors by name (centred on the flight: a constant is a sensor's bias). A term tied to one
flight's clock (a mass change at 120 s) acts at the same time of the next flight.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from sysid.discrepancy.baseline import BaselineModel

__all__ = ["UNEXPLAINED", "CorrectedModel", "ModelTerm"]

#: The model of the unknown's effect name.
UNEXPLAINED = "unexplained"


@dataclass(frozen=True, slots=True, kw_only=True)
class ModelTerm:
    """One kept term of a corrected simulation.

    Parameters
    ----------
    effect : str
        A catalogue name, or ``"unexplained"`` (the model of the unknown).
    value : float
        The value inside its shape (a delay, s; a lag, s; a ceiling, as logged), NaN if none.
    coefficients : Mapping[str, ndarray]
        Per output it acts on, its regressors' coefficients, shape (n_regressors,) (a transform: none).
    regressors : Mapping[str, tuple of str]
        ``unexplained`` only: per output, the keys of the model of the unknown's regressors, in column order.
    """

    effect: str
    value: float
    coefficients: Mapping[str, np.ndarray]
    regressors: Mapping[str, tuple[str, ...]] = field(default_factory=dict)


@dataclass(frozen=True, slots=True, kw_only=True)
class CorrectedModel:
    """The simulation's model with the kept terms: what the real vehicle does, as far as the search found.

    Parameters
    ----------
    baseline : BaselineModel
        The equation-error model of the simulated flights, read about the real vehicle's hover.
    thrust_trim : float
        Real less simulated thrust per input, as a share of the simulated (``thrust_scale - 1``).
    terms : tuple of ModelTerm
        In the order they were kept.
    made_from : tuple of str
        The simulated and real flights it was found on.

    See Also
    --------
    sysid.discrepancy.fitted_model.corrected_outputs : its outputs along a flight.
    sysid.discrepancy.model_files.write_corrected_model : its JSON file.
    """

    baseline: BaselineModel
    thrust_trim: float
    terms: tuple[ModelTerm, ...]
    made_from: tuple[str, ...] = ()
