"""Flights: batches of nonlinear trials, linear-model hover flights and heave-only flights.

The public names of :mod:`~simulator.flights.altitude`, :mod:`~simulator.flights.linear` and
:mod:`~simulator.flights.nonlinear` are re-exported here: write ``from simulator.flights import
name``. Modules with a leading underscore are private.
"""

from simulator.flights.altitude import (
    CRAZYFLIE_ALTITUDE,
    CRAZYFLIE_GEAR_HEIGHT_M,
    MOCAP_NOISE,
    AltitudeController,
    AltitudeRun,
    AltitudeVehicle,
    ThrustRatioModel,
    simulate_altitude,
)
from simulator.flights.linear import SimulatedFlight, WindField, simulate_hover
from simulator.flights.nonlinear import NonlinearFlight, Trial, simulate_flights, truth_parameters

__all__ = [
    "ThrustRatioModel",
    "AltitudeController",
    "AltitudeVehicle",
    "CRAZYFLIE_GEAR_HEIGHT_M",
    "CRAZYFLIE_ALTITUDE",
    "MOCAP_NOISE",
    "AltitudeRun",
    "simulate_altitude",
    "WindField",
    "SimulatedFlight",
    "simulate_hover",
    "Trial",
    "NonlinearFlight",
    "simulate_flights",
    "truth_parameters",
]
