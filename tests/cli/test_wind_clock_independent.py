"""Issue 31: the wind step on data as it comes, on the independent generator's held-out windy cases.

An anemometer logger's clock off by 0-2.6 s (either sign), an autopilot wind
estimate lagging the air by a 2-4 s time constant, PX4 and ArduPilot; the
thresholds of :mod:`sysid.fit.wind_offset` were set on the chapter 3
campaign and the generator's ``tune-wind-clock-*`` cases, never on these.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from independent_sim.corpus import CaseFiles, Truth
from independent_sim.fixtures import independent_corpus_fixture  # noqa: F401 (registers the fixture)

from sysid_cli.main import cli

WINDY = (
    "heldout-wind-clock-ap-ahead",
    "heldout-wind-clock-px4-behind",
    "heldout-wind-clock-px4-slight",
    "heldout-wind-clock-ap-none",
)


def _wind(files: CaseFiles) -> list[str]:
    """The anemometer, its distance, and the maneuvers (sweeps in 6 m/s of wind are not all detected: issue 32)."""
    return ["--segments", str(files.segments_csv), "--wind", str(files.anemometer_csv), "--wind-distance", "4.6"]


def _fit(files: CaseFiles, folder: Path, *extra: str) -> tuple[dict, str]:
    """``sysid fit`` of the case's log with its anemometer: the model file's document and what went to stderr."""
    model = folder / "model.json"
    done = CliRunner().invoke(
        cli, ["fit", str(files.log), *_wind(files), *extra, "--model", "hover-wind", "--partial", "-o", str(model)]
    )
    assert done.exit_code == 0, done.output
    return json.loads(model.read_text()), done.stderr


@dataclass(frozen=True)
class _Outcome:
    """One held-out case fitted and validated: its truth, its model file and its validation summary."""

    truth: Truth
    model: dict
    validation: dict
    report: str
    true_wind_validation: dict


@pytest.fixture(scope="module", name="outcomes")
def outcomes_fixture(independent_corpus, tmp_path_factory: pytest.TempPathFactory) -> dict[str, _Outcome]:  # type: ignore[no-untyped-def]
    """Each windy held-out case fitted, then validated with that model (the offset the fit measured)."""
    out = {}
    for name in WINDY:
        files, folder = independent_corpus.files(name), tmp_path_factory.mktemp(name)
        model, _ = _fit(files, folder, "--report", str(folder / "report.html"))
        summary = folder / "validation.json"
        checked = CliRunner().invoke(
            cli, ["validate", str(folder / "model.json"), str(files.log), *_wind(files), "--json", str(summary), "-q"]
        )
        assert checked.exit_code == 0, checked.output
        report = (folder / "report.html").read_text(encoding="utf-8")
        out[name] = _Outcome(
            truth=files.truth,
            model=model,
            validation=json.loads(summary.read_text()),
            report=report,
            true_wind_validation=_validated_true_wind(files, folder, model),
        )
    return out


def _validated_true_wind(files: CaseFiles, folder: Path, model: dict) -> dict:
    """The validation of the same model file with the wind step's parameters (G_w, and X_u and Z_w estimated
    again with it) at the generator's true values, step 1's as fitted: what a perfect wind step would cut."""
    document = json.loads(json.dumps(model))
    for name, parameter in document["parameters"].items():
        if parameter["value"] is not None and parameter["stage"] == "wind" and name in files.truth.parameters:
            parameter["value"] = files.truth.parameters[name]
    (folder / "truth.json").write_text(json.dumps(document))
    summary = folder / "truth-validation.json"
    checked = CliRunner().invoke(
        cli, ["validate", str(folder / "truth.json"), str(files.log), *_wind(files), "--json", str(summary), "-q"]
    )
    assert checked.exit_code == 0, checked.output
    return json.loads(summary.read_text())


@pytest.mark.slow
@pytest.mark.parametrize("name", WINDY)
def test_the_clock_offset_and_the_transport_delay_are_found(outcomes: dict[str, _Outcome], name: str) -> None:
    """Measured on the four: offsets within 0.03 s of +2.6, -2.3, +0.4, 0.0; delays within 0.01 s."""
    truth, clock = outcomes[name].truth.wind, outcomes[name].model["wind"]["clock_offset"]
    assert truth is not None and clock["measured"], clock["reason"]
    assert abs(clock["clock_offset_s"] - truth["clock_offset_s"]) <= 0.2, (clock["clock_offset_s"], truth)
    assert abs(clock["transport_delay_s"] - truth["transport_delay_s"]) <= 0.15, (clock["transport_delay_s"], truth)
    assert any("as the model's fit measured it" in note for note in outcomes[name].validation["notes"])
    notes = outcomes[name].model["notes"]  # the pass before the offset was applied said "partial" once more
    assert len(notes) == len(set(notes)), notes


@pytest.mark.slow
def test_the_report_draws_the_cost_against_the_offset(outcomes: dict[str, _Outcome]) -> None:
    outcome = outcomes["heldout-wind-clock-ap-ahead"]
    section = outcome.report.split('id="clock-offset"', 1)[1].split("<h2", 1)[0]
    found = outcome.model["wind"]["clock_offset"]
    assert "<svg" in section and f"Found {found['clock_offset_s']:+.2f} ± {found['sigma_s']:.2f} s." in section
    assert f"anemometer clock offset {found['clock_offset_s']:+.2f}" in outcome.report  # the card's wind line


@pytest.mark.slow
@pytest.mark.parametrize("name", WINDY)
def test_the_wind_the_vehicle_met_is_the_one_its_accelerations_felt(outcomes: dict[str, _Outcome], name: str) -> None:
    """The report's trace: the anemometer's wind moved to the vehicle follows the ax residual read as wind (r 0.99
    on the tuning cases; the reading unmoved 0.75-0.77), and the accelerations lag the anemometer by the transport
    delay (the lag of their greatest cross-correlation, at the trace's 10 Hz)."""
    trace = outcomes[name].model["wind"]["trace"]
    felt = np.array(trace["from_accelerations_m_s"])
    reading = np.array(trace["at_anemometer_m_s"])
    at_vehicle = float(np.corrcoef(trace["at_vehicle_m_s"], felt)[0, 1])
    assert at_vehicle >= 0.9 and at_vehicle > float(np.corrcoef(reading, felt)[0, 1]), at_vehicle
    dt = float(np.median(np.diff(trace["time_s"])))
    lags = np.arange(0, int(round(3.0 / dt)))  # the air reaches the vehicle after the anemometer: 0-3 s
    cross = [float(np.corrcoef(reading[: reading.size - k], felt[k:])[0, 1]) for k in lags]
    lag_s = float(lags[int(np.argmax(cross))] * dt)
    assert abs(lag_s - outcomes[name].truth.wind["transport_delay_s"]) <= 0.15, (lag_s, trace["transport_delay_s"])
    section = outcomes[name].report.split('id="wind-timing"', 1)[1].split("<h2", 1)[0]
    assert "<svg" in section and f"r = {at_vehicle:.2f}" in section


@pytest.mark.slow
@pytest.mark.parametrize("name", WINDY)
def test_the_wind_terms_come_within_15_percent(outcomes: dict[str, _Outcome], name: str) -> None:
    """Measured: X_w_lon +1.1 to -5.4 %, Z_w_lon -1.3 to -11.0 % (X_u estimated again with them: -0.2 to -7.1 %)."""
    parameters, truth = outcomes[name].model["parameters"], outcomes[name].truth.parameters
    for term in ("X_w_lon", "Z_w_lon", "X_u"):
        assert parameters[term]["status"] == "estimated", (term, parameters[term])
        assert abs(parameters[term]["value"] / truth[term] - 1) <= 0.15, (term, parameters[term], truth[term])
    assert parameters["X_u"]["stage"] == "wind"
    for term, p in parameters.items():  # Z_w came out "estimated" at CR 100-111 % on two of these before
        unmeasured = p["status"] == "estimated" and p["cr_percent"] > 20 and p["insensitivity_percent"] > 10
        assert not (p["stage"] == "wind" and unmeasured), (term, p)


@pytest.mark.slow
@pytest.mark.parametrize("name", WINDY)
def test_the_wind_term_cuts_the_doublets_ax_and_az_error_by_20_percent(
    outcomes: dict[str, _Outcome], name: str
) -> None:
    """Measured: ax -71, -57, -87, -75 %; az -46, -84, -37, -48 % on ap-ahead, px4-behind, px4-slight, ap-none.

    The model is driven with the wind its G_w was fitted on, low-passed at 2 Hz
    (:func:`sysid.fit.wind_offset.smoothed_flights`): driven with the anemometer's raw reading, the
    ArduPilot cases' az cut was 19.8 and 16.1 %, the sensor's noise passed through Z_w_lon to az at 2-10 Hz.
    """
    correction = outcomes[name].validation["wind_correction"]
    for output in ("ax", "az"):
        assert correction[output]["reduction_percent"] >= 20.0, (output, correction[output])


@pytest.mark.slow
def test_the_fitted_wind_term_cuts_az_as_much_as_the_true_one(outcomes: dict[str, _Outcome]) -> None:
    """The fitted model's az cut against that of the same model with the wind step's true values, on the same
    doublets and wind (measured 46.4 / 47.4, 83.9 / 83.6, 36.8 / 36.0, 47.5 / 46.4 %): within 3 points of it or
    better, on every case.

    Step 1's values stay as fitted: with every true value, px4-slight's az cut is 53.4 %, the gap step 1's Z_thr
    (-8.3 % at CR 7.5 %, the truth inside 2 CR; the true Z_thr alone gives 54.8 %), not the wind term's.
    """
    for name, outcome in outcomes.items():
        fitted = outcome.validation["wind_correction"]["az"]["reduction_percent"]
        true = outcome.true_wind_validation["wind_correction"]["az"]["reduction_percent"]
        assert fitted >= true - 3.0, (name, fitted, true)


@pytest.mark.slow
def test_in_the_winds_band_the_wind_term_cuts_every_cases_ax_and_az_error_by_20_percent(
    outcomes: dict[str, _Outcome],
) -> None:
    """The errors low-passed as the wind step low-passes the anemometer's wind (2 Hz): what G_w can correct.

    Measured, fitted model: ax 82.4, 68.7, 91.3, 80.4 %; az 37.2, 84.1, 35.4, 45.2 % on ap-ahead, px4-behind,
    px4-slight, ap-none."""
    for name, outcome in outcomes.items():
        correction = outcome.validation["wind_correction"]
        for output in ("ax", "az"):
            assert correction[output]["band_hz"] == 2.0, correction[output]
            assert correction[output]["reduction_in_band_percent"] >= 20.0, (name, output, correction[output])


def _inside_2_cr(outcome: _Outcome, term: str) -> bool:
    parameter, truth = outcome.model["parameters"][term], outcome.truth.parameters[term]
    return bool(abs(parameter["value"] / truth - 1) * 100 <= 2 * parameter["cr_percent"])


@pytest.mark.slow
def test_x_w_lons_truth_is_inside_2_cr(outcomes: dict[str, _Outcome]) -> None:
    """Measured +1.1 / -5.5 / -4.7 / -0.1 % at CR 5.4 / 5.6 / 6.3 / 5.0 % (X_u's uncertainty carried in)."""
    assert all(_inside_2_cr(outcome, "X_w_lon") for outcome in outcomes.values())


def test_body_w_from_the_pitch_input_is_fitted_where_the_wind_carries_it(outcomes: dict[str, _Outcome]) -> None:
    """In 5-6 m/s the trim airspeed U0 carries body w's answer to the pitch input at first order: the trim-path
    rule (:mod:`sysid.fit.trim_paths`, set by analysis, its data check our fleet's still air) leaves out no
    response of these logs, and w/delta_lon is fitted wherever it passed gating."""
    for name, outcome in outcomes.items():
        assert not [n for n in outcome.model["notes"] if "only through the trim" in n], name
    fitted = [
        n
        for n, o in outcomes.items()
        if any((r["output"], r["input"]) == ("w", "delta_lon") for r in o.model["responses"])
    ]
    assert "heldout-wind-clock-px4-behind" in fitted, fitted


@pytest.mark.slow
def test_z_w_lons_truth_is_inside_2_cr(outcomes: dict[str, _Outcome]) -> None:
    """Measured -3.0 / -1.4 / -11.0 / -1.9 % at CR 3.3 / 3.2 / 8.4 / 3.2 %. On px4-slight the error is step 1's
    Z_thr (-8.3 %; the thrust loop answers the gusts, so Z_thr's error moves Z_w_lon): Tischler's bound gave it
    CR 3.0 % and Z_w_lon 3.4 %; with the residual's sandwich bound and the fit range's spread in step 1's bounds
    (:func:`sysid.fit.engine.fit_frequency_responses`) 7.5 % and 8.4 %."""
    assert all(_inside_2_cr(outcome, "Z_w_lon") for outcome in outcomes.values())


@pytest.mark.slow
@pytest.mark.parametrize("name", WINDY)
def test_the_coarse_prior_models_the_estimators_lag(independent_corpus, name: str) -> None:  # type: ignore[no-untyped-def]
    """``--estimate-wind-offset`` against the autopilot's wind estimate (smoothed over 2-4 s): within 0.3 s of
    the truth (the tuning cases: 0.00 and 0.11 s off; without the lag modelled it read -1.42 where the truth is 0,
    0.41 where it is +1.7), and the smoothing found (measured: +0.08, +0.04, -0.12, 0.00 s off; 3.0, 2.0, 4.0,
    2.5 s exactly)."""
    files = independent_corpus.files(name)
    done = CliRunner().invoke(
        cli,
        [
            "ingest",
            str(files.log),
            "--wind",
            str(files.anemometer_csv),
            "--wind-distance",
            "4.6",
            "--estimate-wind-offset",
            "--json",
            "-",
            "-q",
        ],
    )
    assert done.exit_code == 0, done.output
    alignment = json.loads(done.stdout)["wind_alignment"]
    truth = files.truth.wind
    assert truth is not None and alignment["clock_offset_source"] == "estimated", alignment
    assert abs(alignment["clock_offset_s"] - truth["clock_offset_s"]) <= 0.3, (alignment, truth)
    assert abs(alignment["residual_lag_modelled_s"] - truth["estimate_time_constant_s"]) <= 0.5, (alignment, truth)


@pytest.mark.slow
def test_the_true_offset_given_raises_no_warning(independent_corpus, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """On the held-out case whose logger keeps UTC, and on one whose clock runs 2.6 s ahead, given as such."""
    for name in ("heldout-wind-clock-ap-none", "heldout-wind-clock-ap-ahead"):
        files = independent_corpus.files(name)
        assert files.truth.wind is not None
        given = f"{files.truth.wind['clock_offset_s']:.2f}"
        folder = tmp_path / name
        folder.mkdir()
        doc, stderr = _fit(files, folder, "--wind-offset", given)
        assert "clock offset given" not in stderr and "not identified" not in stderr, stderr
        clock = doc["wind"]["clock_offset"]
        assert clock["measured"] and abs(clock["clock_offset_s"] - float(given)) <= 0.2, clock


@pytest.mark.slow
def test_calm_air_claims_no_wind_term(independent_corpus, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """A breath of wind (0.8 m/s, turbulence 0.05 m/s) on the calm airframe: the clock cannot be timed, no G_w.

    Before the gate, X_w_lon came out -0.29 ± 0.02 here: X_u's share of the anemometer's noise, which reaches
    the residual through u (the tuning case ``tune-wind-calm`` showed it first)."""
    files = independent_corpus.files("heldout-wind-calm")
    doc, stderr = _fit(files, tmp_path)
    assert "the anemometer's wind cannot be timed against the flight" in stderr, stderr
    for term in ("X_w_lon", "Z_w_lon"):
        assert doc["parameters"][term]["status"] == "unidentified", doc["parameters"][term]
    assert any("anemometer clock offset not measured" in note for note in doc["notes"]), doc["notes"]
    assert doc["wind"] is None or doc["wind"].get("trace") is None  # no G_w, nothing read as wind
