"""Campaigns: scenario files, the built-in scenarios and the demo flight, flown and written to disk.

The public names of :mod:`~simulator.campaign.demo_flight`, :mod:`~simulator.campaign.fly` and
:mod:`~simulator.campaign.scenario` are re-exported here: write ``from simulator.campaign import
name``. Modules with a leading underscore are private.
"""

from simulator.campaign.demo_flight import FlightFiles, demo_maneuvers, write_demo_flight
from simulator.campaign.fly import TrialFiles, TrialPlan, plan_trials, run_scenario, scenario_trials
from simulator.campaign.scenario import (
    AnemometerSpec,
    ManeuverSpec,
    Scenario,
    WindCondition,
    builtin_scenarios,
    load_builtin,
    read_scenario,
)

__all__ = [
    "FlightFiles",
    "demo_maneuvers",
    "write_demo_flight",
    "TrialPlan",
    "TrialFiles",
    "plan_trials",
    "scenario_trials",
    "run_scenario",
    "WindCondition",
    "ManeuverSpec",
    "AnemometerSpec",
    "Scenario",
    "read_scenario",
    "builtin_scenarios",
    "load_builtin",
]
