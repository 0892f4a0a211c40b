"""Discrepancy discovery: where a real flight departs from its simulation, the physics left out, and the proof.

:func:`discover` compares flights as :class:`FlightSeries` (:func:`flight_series`
from a conditioned flight's records) and returns a :class:`DiscrepancyResult`. A fitted model
takes the simulation's place through :func:`model_flight`.
"""

from sysid.discrepancy.catalogue import CATALOGUE, EFFECTS, Term
from sysid.discrepancy.describe import FAR_FROM_FLOOR
from sysid.discrepancy.fitted_model import model_flight, model_outputs
from sysid.discrepancy.responses import RATE_PAIRS, ResponseComparison, compare_model_responses, compare_responses
from sysid.discrepancy.result import Alternative, DiscrepancyResult, Finding, FittedParameter, Regime, Screening
from sysid.discrepancy.search import DiscrepancyOptions, discover
from sysid.discrepancy.series import FlightSeries, flight_series

__all__ = [
    "Alternative",
    "CATALOGUE",
    "EFFECTS",
    "Screening",
    "Term",
    "FAR_FROM_FLOOR",
    "DiscrepancyOptions",
    "DiscrepancyResult",
    "Finding",
    "FittedParameter",
    "FlightSeries",
    "RATE_PAIRS",
    "ResponseComparison",
    "Regime",
    "compare_model_responses",
    "compare_responses",
    "discover",
    "flight_series",
    "model_flight",
    "model_outputs",
]
