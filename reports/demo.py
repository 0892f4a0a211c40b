"""The demo: a simulated flight test run through the workbench, from the log to the HTML report.

:func:`run_demo` flies the chapter 3 octocopter's sweep + doublet flight in light wind (a ground
anemometer 4.6 m upstream whose clock is 1.5 s fast), ingests it, fits the hover-wind model to the
sweeps, verifies it on the doublets with and without its wind term and writes the report, each file
beside the others. :func:`run_discrepancy_demo` simulates a flight and a "real" twin whose motors
respond 30 ms later, and reports what the discrepancy search finds.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from flightlogs.conditioning.condition import ConditioningOptions
from flightlogs.store.campaign import ingest_campaign
from flightlogs.store.summary import campaign_summary
from flightlogs.writers.jsonio import write_json
from simulator.campaign.demo_flight import DEMO_ANEMOMETER_DISTANCE_M, FlightFiles
from sysid.discrepancy import DiscrepancyResult
from sysid.fit import IdentifiedModel, Verdict
from sysid.verify import Verification

__all__ = ["DemoRun", "DiscrepancyDemo", "run_demo", "run_discrepancy_demo"]

Progress = Callable[[str, int, int], None]


@dataclass(frozen=True, slots=True, kw_only=True)
class DemoRun:
    """What :func:`run_demo` made, file by file.

    Parameters
    ----------
    flight : FlightFiles
        The simulated log, anemometer record and truth.
    dataset, ingest_json : Path
        The HDF5 dataset and the ingest's summary (as ``sysid ingest --json`` writes it).
    ingest_summary : dict
        That summary.
    model : IdentifiedModel
        The hover-wind model fitted to the sweeps.
    model_path, fit_json : Path
        The model file and the fit's summary (as ``sysid fit --json`` writes it).
    verification : Verification
        The model on the doublets, with and without its wind term.
    validation_path : Path
        The verification file (``sysid report`` reads it).
    report : Path
        The HTML report.
    verdict : Verdict
        The model's verdict by the guidelines it was fitted with, with the verification.
    """

    flight: FlightFiles
    dataset: Path
    ingest_json: Path
    ingest_summary: dict[str, Any]
    model: IdentifiedModel
    model_path: Path
    fit_json: Path
    verification: Verification
    validation_path: Path
    report: Path
    verdict: Verdict


@dataclass(frozen=True, slots=True, kw_only=True)
class DiscrepancyDemo:
    """What :func:`run_discrepancy_demo` made.

    Parameters
    ----------
    simulation, real : Path
        The simulated flight and its "real" twin (the file name does not tell the effect).
    result : DiscrepancyResult
        What the search found.
    summary_json, report : Path
        The result as ``sysid discrepancy -o`` writes it, and its HTML report.
    """

    simulation: Path
    real: Path
    result: DiscrepancyResult
    summary_json: Path
    report: Path


def _step(progress: Progress | None, stage: str, done: int, total: int) -> None:
    if progress is not None:
        progress(stage, done, total)


def run_demo(out_dir: str | Path, *, progress: Progress | None = None) -> DemoRun:
    """Simulate the demo flight into `out_dir` and run the workbench on it, ending with the HTML report.

    Parameters
    ----------
    out_dir : str or Path
        Folder for the demo's files (it must exist).
    progress : callable, optional
        ``progress(stage, done, total)``: ``reading …`` stages in bytes of the log, the others in steps.

    Returns
    -------
    DemoRun
    """
    from flightlogs.store.dataset import write_dataset  # h5py: loaded only here
    from simulator.campaign.demo_flight import write_demo_flight
    from sysid.fit import IdentifyOptions, fit_summary, identify_flights, model_verdict, write_model
    from sysid.verify import VerificationOptions, verification_provenance, verify_identified
    from sysid.verify.io import write_verification

    from .ingest_card import ingest_card
    from .model_report import write_model_report

    out = Path(out_dir)
    _step(progress, "simulating", 0, 4)
    flight = write_demo_flight(out)
    conditioning = ConditioningOptions(wind_distance_m=DEMO_ANEMOMETER_DISTANCE_M, estimate_wind_offset=True)
    campaign = ingest_campaign([flight.log], [flight.wind_csv], options=conditioning, progress=progress)
    flights = campaign.require_flights()
    dataset, ingest_json = out / "dataset.h5", out / "ingest.json"
    write_dataset(dataset, campaign.logs, campaign.winds, list(flights))
    ingested = campaign_summary(campaign, dataset)
    write_json(ingest_json, ingested)
    _step(progress, "identifying", 1, 4)
    model = identify_flights(flights, "hover-wind", options=IdentifyOptions(), files=[dataset])
    model_path, fit_json = write_model(out / "model.json", model), out / "fit.json"
    write_json(fit_json, fit_summary(model) | {"output": str(model_path), "mat": None, "report": None})
    _step(progress, "verifying", 2, 4)
    # the bare airframe is unstable open loop: the initial state is estimated with the bias and reference shift
    options = VerificationOptions(initial_state="estimated")
    verification, _ = verify_identified(model, flights, options=options)
    saved = verification_provenance(options, sources=[dataset.name])
    validation_path = write_verification(out / "validation.json", verification, model=model_path, options=saved)
    _step(progress, "report", 3, 4)
    verdict = model_verdict(model, verification)
    report = write_model_report(
        out / "report.html",
        model,
        verification=verification,
        logs_summary=ingest_card(ingested, source=str(ingest_json)),
        verification_options=saved,
        verdict=verdict,
    )
    _step(progress, "done", 4, 4)
    return DemoRun(
        flight=flight,
        dataset=dataset,
        ingest_json=ingest_json,
        ingest_summary=ingested,
        model=model,
        model_path=model_path,
        fit_json=fit_json,
        verification=verification,
        validation_path=validation_path,
        report=report,
        verdict=verdict,
    )


def run_discrepancy_demo(out_dir: str | Path, *, progress: Progress | None = None) -> DiscrepancyDemo:
    """Simulate a flight and a "real" twin whose motors respond 30 ms later; search and report the gap.

    Parameters
    ----------
    out_dir : str or Path
        Folder for the demo's files (it must exist).
    progress : callable, optional
        ``progress(stage, done, total)`` of the search.

    Returns
    -------
    DiscrepancyDemo
    """
    from flightlogs.store.sources import conditioned_sources
    from simulator.campaign.discrepancy_pairs import write_pairs
    from sysid.discrepancy import discover_simulation

    from .discrepancy_report import write_discrepancy_report

    out = Path(out_dir)
    sim, reals = write_pairs(["time_delay"], out, seed=7)
    real = reals["time_delay"].replace(out / "real.ulg")  # the file name must not tell
    flown = conditioned_sources([real])
    found = discover_simulation(conditioned_sources([sim]), flown, progress=progress)
    summary_json = write_json(out / "discrepancy.json", found.result.to_dict())
    page = write_discrepancy_report(
        out / "discrepancy.html", found.result, found.comparisons(flown), model=found.model_name
    )
    return DiscrepancyDemo(simulation=sim, real=real, result=found.result, summary_json=summary_json, report=page)
