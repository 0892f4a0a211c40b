"""The autopilot: cascaded hover control and the excitation it injects.

The public names of :mod:`~simulator.autopilot.control` and :mod:`~simulator.autopilot.excitation`
are re-exported here: write ``from simulator.autopilot import name``. Modules with a leading
underscore are private.
"""

from simulator.autopilot.control import (
    N_CONTROLLER_STATES,
    ControllerGains,
    HeightSteps,
    Injection,
    controller_step,
    design_gains,
    excitation_table,
    initial_controller_state,
)
from simulator.autopilot.excitation import (
    Axis,
    Maneuver,
    doublet,
    excitation_signal,
    multisine,
    sweep,
    three_two_one_one,
)

__all__ = [
    "ControllerGains",
    "design_gains",
    "Injection",
    "HeightSteps",
    "excitation_table",
    "initial_controller_state",
    "controller_step",
    "N_CONTROLLER_STATES",
    "Axis",
    "Maneuver",
    "sweep",
    "doublet",
    "excitation_signal",
    "three_two_one_one",
    "multisine",
]
