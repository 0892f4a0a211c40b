"""The vehicle: rigid body, rotors, mixer, motors and battery; presets; trim and linearisation.

The public names of :mod:`~simulator.vehicle.dynamics`, :mod:`~simulator.vehicle.identified`,
:mod:`~simulator.vehicle.linearize`, :mod:`~simulator.vehicle.multirotor` and
:mod:`~simulator.vehicle.presets` are re-exported here: write ``from simulator.vehicle import
name``. Modules with a leading underscore are private.
"""

from simulator.vehicle.dynamics import Conditions, vehicle_derivative
from simulator.vehicle.identified import CALM_HOVER, LIGHT_WIND_TERMS, STRONG_WIND_TERMS, G, wind_terms_for
from simulator.vehicle.linearize import (
    EQ33_STATES,
    MIXER_INPUTS,
    EigenComparison,
    LinearModel,
    Trim,
    compare_eigenvalues,
    hover_derivatives,
    linearize_hover,
    reference_model,
    trim_hover,
)
from simulator.vehicle.multirotor import (
    FIRST_ROTOR_STATE,
    Battery,
    Vehicle,
    mixer_commands,
    n_states,
    quaternion_from_euler,
    state_names,
)
from simulator.vehicle.presets import CRAZYFLIE, OCTO_S1000, crazyflie, octocopter, rotor_ring, vehicle_from_derivatives

__all__ = [
    "Conditions",
    "vehicle_derivative",
    "G",
    "CALM_HOVER",
    "LIGHT_WIND_TERMS",
    "STRONG_WIND_TERMS",
    "wind_terms_for",
    "EQ33_STATES",
    "MIXER_INPUTS",
    "Trim",
    "LinearModel",
    "EigenComparison",
    "trim_hover",
    "linearize_hover",
    "reference_model",
    "hover_derivatives",
    "compare_eigenvalues",
    "FIRST_ROTOR_STATE",
    "Battery",
    "Vehicle",
    "state_names",
    "n_states",
    "quaternion_from_euler",
    "mixer_commands",
    "rotor_ring",
    "vehicle_from_derivatives",
    "octocopter",
    "crazyflie",
    "OCTO_S1000",
    "CRAZYFLIE",
]
