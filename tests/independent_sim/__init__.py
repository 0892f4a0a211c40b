"""An independent test corpus: a second flight simulator that writes ordinary PX4 and ArduPilot logs.

Issue 14 item 4. Tests of maneuver detection and identification must include
logs that the workbench's own simulator (``simulator``) did not write. This
package is that second source, deliberately different and sharing no code
with ``simulator`` or ``sysid`` (it imports neither; it uses only the format
encoders of :mod:`flightlogs.writers`, which are round-trip tested against
pyulog and pymavlink):

* plant (:mod:`.plant`): the chapter 3 hover octocopter linearised as Table
  3.3 (eqs. 3.2, 3.10-3.13, g = 9.81), in the parameter names and units of the
  ``hover`` and ``hover-wind`` structures, control derivatives per unit of the
  logged mixer input (Table 3.3 × 100);
* integration (:mod:`._zoh`): exact zero-order-hold discretisation with
  fractional input delays (modified z-transform), our own matrix exponential;
* autopilot (:mod:`.control`): a PX4-like cascade (position P → velocity PI →
  attitude P → rate PID with a filtered gyro), assembled with the plant,
  actuator lag and delays into one discrete LTI system; PX4 at 250 Hz,
  ArduPilot at 400 Hz with other gains;
* excitation (:mod:`.excitation`, :mod:`.maneuvers`): linear and
  logarithmic chirps up and down with fades, piloted sweeps (stick at the
  attitude or rate setpoint), doublets, 3-2-1-1s, multisines; injected after
  the rate controller and never logged;
* wind (:mod:`.wind`): Dryden turbulence, frozen past an anemometer 4.6 m
  upstream (20 Hz, ±0.3 m/s, a CSV the workbench reads);
* physics outside the linear plant (:mod:`.effects`), for discrepancy pairs
  (:mod:`.pairs`): a ground cushion, battery fade, a payload picked up, a CG
  off the thrust axis, and the calm airframe in a steady wind; more of the
  search's catalogue with laws of our own (:mod:`.effects_more`: worn motors,
  quadratic drag, climb inflow, translational lift, a thrust ceiling, gyro and
  accelerometer scale errors); physics outside that catalogue, whose right
  answer is ``unexplained`` (:mod:`.effects_outside`: a swinging payload, mixer
  cross-coupling, a speed pitch moment); all forced step by step (:mod:`.forcing`);
* real sensors' nuisances (:mod:`.nuisances`): rotor vibration aliased into
  the accelerometers, drifting gyro biases, logging dropouts in every topic;
* logs (:mod:`.px4_log`, :mod:`.ardupilot_log`): realistic topics and rates;
* corpus (:mod:`.corpus`, :mod:`.catalogue`): :func:`write_case` and the
  named :data:`TUNING_CASES` / :data:`HELDOUT_CASES`;
* pytest fixtures (:mod:`.fixtures`).

Examples
--------
>>> from independent_sim import HELDOUT_CASES, hover_plant
>>> hover_plant("calm").parameters()["M_lon"]  # rad/s² per unit of vehicle_torque_setpoint.xyz[1]
52.51
>>> sorted({case.fmt for case in HELDOUT_CASES})
['dataflash', 'ulog']
"""

from independent_sim.catalogue import ALL_CASES, HELDOUT_CASES, TUNING_CASES, case_named
from independent_sim.corpus import PARAMETER_UNITS, CaseFiles, Truth, truth_of, write_case
from independent_sim.effects_more import (
    AccelScale,
    AirframeDrag,
    ClimbInflow,
    GyroScale,
    MotorWear,
    ThrustCeiling,
    TranslationalLift,
)
from independent_sim.effects_outside import MixerCrossCoupling, SpeedPitchMoment, SwingingPayload
from independent_sim.excitation import (
    Excitation,
    chirp,
    doublet,
    multisine,
    piloted_sweep,
    three_two_one_one,
)
from independent_sim.flight import Flight, ManeuverTruth
from independent_sim.forcing import AnyEffect
from independent_sim.maneuvers import Chirp, Doublet, Maneuver, Multisine, PilotedSweep, ThreeTwoOneOne
from independent_sim.nuisances import DEFAULT_NUISANCES, Nuisances
from independent_sim.pairs import open_pair_case
from independent_sim.plant import HoverPlant, Trim, hover_plant, linear_plant
from independent_sim.scenario import Case, FlightPlan, NoiseModel, Reposition
from independent_sim.simulate import simulate
from independent_sim.wind import WindModel

__all__ = [
    "ALL_CASES",
    "HELDOUT_CASES",
    "TUNING_CASES",
    "case_named",
    "PARAMETER_UNITS",
    "CaseFiles",
    "Truth",
    "truth_of",
    "write_case",
    "Chirp",
    "Doublet",
    "Excitation",
    "Maneuver",
    "Multisine",
    "PilotedSweep",
    "ThreeTwoOneOne",
    "chirp",
    "doublet",
    "multisine",
    "piloted_sweep",
    "three_two_one_one",
    "HoverPlant",
    "Trim",
    "hover_plant",
    "linear_plant",
    "Case",
    "FlightPlan",
    "NoiseModel",
    "Reposition",
    "Flight",
    "ManeuverTruth",
    "simulate",
    "WindModel",
    "AnyEffect",
    "MotorWear",
    "AirframeDrag",
    "ClimbInflow",
    "TranslationalLift",
    "ThrustCeiling",
    "GyroScale",
    "AccelScale",
    "SwingingPayload",
    "MixerCrossCoupling",
    "SpeedPitchMoment",
    "Nuisances",
    "DEFAULT_NUISANCES",
    "open_pair_case",
]
