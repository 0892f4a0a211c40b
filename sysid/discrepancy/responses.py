"""The real flight's frequency responses against the simulation's, on the sweeps both flew.

Where in frequency the two differ tells the physics apart (issue 15, "locate"): a phase lag that
grows linearly with frequency at equal magnitude is a delay, an extra roll-off with its phase a lag,
a flat magnitude change a control effectiveness. The responses are the composite chirp-z estimates
of :func:`sysid.freqresp.flight_responses` on each flight's detected sweeps; a fitted model in the
simulation's place gives its own exact response at the real response's frequencies.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from flightlogs.conditioning.condition import ConditionedFlight
from flightlogs.errors import SysidError
from sysid.freqresp import FrequencyResponse, flight_responses
from sysid.model.statespace import DelayedStateSpace

__all__ = ["RATE_PAIRS", "ResponseComparison", "compare_responses", "compare_model_responses"]

#: (output, input) pairs compared: each axis's rate against its mixer input.
RATE_PAIRS: tuple[tuple[str, str], ...] = (("p", "delta_lat"), ("q", "delta_lon"), ("r", "delta_yaw"))


@dataclass(frozen=True, slots=True, kw_only=True)
class ResponseComparison:
    """One pair's response in the real flight and in the simulation.

    Parameters
    ----------
    real : FrequencyResponse
        The real flights' composite response (rad/s).
    sim : FrequencyResponse or None
        The simulated flights' (on its own grid); None where the simulation is a model.
    sim_on_real_omega : ndarray of complex, shape (n_freq,)
        The simulation's response at the real response's frequencies: a simulated flight's with
        log-magnitude and unwrapped phase interpolated (NaN outside its grid), a model's exact.
    sim_label : str, optional
        What the simulation is, for legends (``simulation``, ``model``).
    """

    real: FrequencyResponse
    sim: FrequencyResponse | None
    sim_on_real_omega: np.ndarray
    sim_label: str = "simulation"

    @property
    def pair(self) -> str:
        """``output/input``."""
        return self.real.pair


def compare_responses(
    sim: Sequence[ConditionedFlight],
    real: Sequence[ConditionedFlight],
    pairs: Sequence[tuple[str, str]] = RATE_PAIRS,
) -> tuple[ResponseComparison, ...]:
    """The pairs whose sweeps both the simulation and the real flights flew, real against simulated.

    Parameters
    ----------
    sim, real : sequence of ConditionedFlight
        Simulated and real flights (conditioned, their maneuvers detected).
    pairs : sequence of (str, str), optional
        ``(output, input)``; default :data:`RATE_PAIRS`.

    Returns
    -------
    tuple of ResponseComparison
        One per pair with a sweep in both (a pair without is left out: nothing to compare).
    """
    out = []
    for pair in pairs:
        try:
            (simulated,) = flight_responses(sim, [pair]).responses
            (flown,) = flight_responses(real, [pair]).responses
        except SysidError:  # no sweep of this axis on one side
            continue
        out.append(ResponseComparison(real=flown, sim=simulated, sim_on_real_omega=_resampled(simulated, flown.omega)))
    return tuple(out)


def compare_model_responses(
    model: DelayedStateSpace,
    real: Sequence[ConditionedFlight],
    pairs: Sequence[tuple[str, str]] = RATE_PAIRS,
) -> tuple[ResponseComparison, ...]:
    """The pairs the real flights swept, against a model's own response (delays included).

    Parameters
    ----------
    model : DelayedStateSpace
        The model in the simulation's place.
    real : sequence of ConditionedFlight
        Real flights (conditioned, their maneuvers detected).
    pairs : sequence of (str, str), optional
        ``(output, input)``; default :data:`RATE_PAIRS`.

    Returns
    -------
    tuple of ResponseComparison
        One per pair with a sweep in the real flights and both signals in the model.
    """
    out = []
    for output, input_ in pairs:
        if output not in model.outputs or input_ not in model.inputs:
            continue
        try:
            (flown,) = flight_responses(real, [(output, input_)]).responses
        except SysidError:  # no sweep of this axis
            continue
        exact = model.frequency_response(flown.omega)[:, model.outputs.index(output), model.inputs.index(input_)]
        out.append(ResponseComparison(real=flown, sim=None, sim_on_real_omega=exact, sim_label="model"))
    return tuple(out)


def _resampled(response: FrequencyResponse, omega: np.ndarray) -> np.ndarray:
    inside = (omega >= response.omega[0]) & (omega <= response.omega[-1])
    log_w = np.log(response.omega)
    magnitude = np.exp(np.interp(np.log(omega), log_w, np.log(np.maximum(np.abs(response.response), 1e-300))))
    phase = np.interp(np.log(omega), log_w, np.unwrap(np.angle(response.response)))
    return np.where(inside, magnitude * np.exp(1j * phase), np.nan + 0j)
