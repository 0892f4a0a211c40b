"""Discrepancy discovery: where a real flight departs from its simulation, the physics left out, and the proof.

:func:`discover` compares flights as :class:`FlightSeries` (:func:`flights_series`
from conditioned flights, :func:`flight_series` from one flight's records) and returns a :class:`DiscrepancyResult`. A fitted model
takes the simulation's place through :func:`model_flight`; the search's corrected simulation
(``result.corrected``, :func:`write_corrected_model`) through :func:`simulated_flight`.
"""

from sysid.discrepancy.catalogue import CATALOGUE, EFFECTS, Term
from sysid.discrepancy.corrected import CorrectedModel
from sysid.discrepancy.describe import FAR_FROM_FLOOR
from sysid.discrepancy.fitted_model import model_flight, model_outputs, simulated_flight
from sysid.discrepancy.flights import SimulationDiscrepancy, discover_simulation
from sysid.discrepancy.model_files import (
    SimulationModel,
    read_corrected_model,
    read_simulation_model,
    simulation_misfit,
    write_corrected_model,
)
from sysid.discrepancy.responses import RATE_PAIRS, ResponseComparison, compare_model_responses, compare_responses
from sysid.discrepancy.result import Alternative, DiscrepancyResult, Finding, FittedParameter, Regime, Screening
from sysid.discrepancy.search import DiscrepancyOptions, discover
from sysid.discrepancy.series import FlightSeries, flight_series, flights_series

__all__ = [
    "SimulationDiscrepancy",
    "discover_simulation",
    "Alternative",
    "CorrectedModel",
    "SimulationModel",
    "read_corrected_model",
    "read_simulation_model",
    "simulated_flight",
    "simulation_misfit",
    "write_corrected_model",
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
    "flights_series",
    "model_flight",
    "model_outputs",
]
