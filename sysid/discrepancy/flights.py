"""The discrepancy search from what a user has: simulated flights or one model file, and real flights."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from flightlogs.conditioning.condition import ConditionedFlight
from sysid.discrepancy.fitted_model import simulated_flight
from sysid.discrepancy.model_files import SimulationModel, read_simulation_model, simulation_misfit
from sysid.discrepancy.responses import ResponseComparison, compare_model_responses, compare_responses
from sysid.discrepancy.result import DiscrepancyResult
from sysid.discrepancy.search import DiscrepancyOptions, discover
from sysid.discrepancy.series import flights_series
from sysid.model.statespace import DelayedStateSpace

__all__ = ["SimulationDiscrepancy", "discover_simulation"]


@dataclass(frozen=True, slots=True, kw_only=True)
class SimulationDiscrepancy:
    """What the search found, and the simulation it was run against.

    Parameters
    ----------
    result : DiscrepancyResult
        The findings.
    simulated : tuple of ConditionedFlight
        The simulated flights; empty when the simulation is a model file.
    model : DelayedStateSpace or CorrectedModel or None
        The model file's simulation, evaluated along the real flights; None for simulated flights.
    model_name : str or None
        Its file's name.
    """

    result: DiscrepancyResult
    simulated: tuple[ConditionedFlight, ...] = ()
    model: SimulationModel | None = None
    model_name: str | None = None

    def comparisons(self, real: Sequence[ConditionedFlight]) -> tuple[ResponseComparison, ...]:
        """The frequency responses a report draws: the real flights' against the simulation's.

        Parameters
        ----------
        real : sequence of ConditionedFlight
            The real flights searched (with their sweeps found).

        Returns
        -------
        tuple of ResponseComparison
            Empty for a corrected simulation, which has no frequency response of its own.
        """
        if self.model is None:
            return compare_responses(self.simulated, real)
        return compare_model_responses(self.model, real) if isinstance(self.model, DelayedStateSpace) else ()


def discover_simulation(
    simulation: Sequence[ConditionedFlight] | str | Path,
    real: Sequence[ConditionedFlight],
    *,
    options: DiscrepancyOptions = DiscrepancyOptions(),
    progress: Callable[[str, int, int], None] | None = None,
) -> SimulationDiscrepancy:
    """Search where a simulation and real flights differ: ``sysid discrepancy SIM REAL``.

    Simulated flights and real ones are compared like with like (:func:`~sysid.discrepancy.flights_series`:
    the slower rate, specific forces derived alike where one side derives them). A model file (from
    ``sysid fit -o``, or a corrected simulation) is evaluated along each real flight instead; a fitted model
    beyond the J guideline is not close enough to judge (``options.simulation_misfit``, read from the file).

    Parameters
    ----------
    simulation : sequence of ConditionedFlight, or str or Path
        The simulated flights, or one model file.
    real : sequence of ConditionedFlight
        The real flights.
    options : DiscrepancyOptions, optional
        Search choices (its ``simulation_misfit`` is set from a model file).
    progress : callable, optional
        ``progress(stage, done, total)``.

    Returns
    -------
    SimulationDiscrepancy

    Raises
    ------
    DataError, ModelError
        On flights that cannot be compared or a model file that cannot be read.
    """
    if isinstance(simulation, (str, Path)):
        path = Path(simulation)
        model = read_simulation_model(path)
        real_series = flights_series(real)
        simulated_series = [simulated_flight(model, s, source=path.name) for s in real_series]
        options = replace(options, simulation_misfit=simulation_misfit(path))
        found = discover(simulated_series, real_series, options, progress=progress)
        return SimulationDiscrepancy(result=found, model=model, model_name=path.name)
    simulated = tuple(simulation)
    real_series = flights_series(real, like=simulated)  # like with like: a table's rate, its derived forces
    found = discover(flights_series(simulated, like=real), real_series, options, progress=progress)
    return SimulationDiscrepancy(result=found, simulated=simulated)
