"""The world around the vehicle: ground effect, wind and turbulence, payload, CG offset, sensors.

The public names of :mod:`~simulator.world.environment` and :mod:`~simulator.world.wind_field` are
re-exported here: write ``from simulator.world import name``. Modules with a leading underscore are
private.
"""

from simulator.world.environment import (
    Anemometer,
    Environment,
    GroundEffect,
    GroundEffectModel,
    PayloadChange,
    SensorNoise,
    ground_effect_function,
    thrust_ratio,
)
from simulator.world.wind_field import BatchWindField, Dryden, FrozenField, Gust, Wind, dryden_psd, realize_field

__all__ = [
    "GroundEffectModel",
    "GroundEffect",
    "thrust_ratio",
    "ground_effect_function",
    "Anemometer",
    "PayloadChange",
    "SensorNoise",
    "Environment",
    "Dryden",
    "Gust",
    "Wind",
    "FrozenField",
    "dryden_psd",
    "realize_field",
    "BatchWindField",
]
