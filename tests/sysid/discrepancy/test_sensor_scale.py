"""The catalogue's ``sensor_scale``: a gyro's scale error, measured against the attitude's kinematics.

Three kinds of evidence: an analytic flight whose rates are the attitude's kinematics times a known
scale (the measurement recovers it); ``independent_sim`` pairs, whose gyro errors act at measurement
only (written without reading the term); a real PX4 flight whose two halves share one gyro (no claim).

Tuning and assertions are apart: the band, the 3 σ rule and the 2 % floor were set on SIM seeds 3000
and 3200 (REAL 3101 on, 3301 on) and on the real flight below; the pairs here fly seeds 8600 on, read
for the first time by this test.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from independent_sim.corpus import write_case
from independent_sim.effects_more import GyroScale, MotorWear
from independent_sim.pairs import open_pair_case

from flightlogs.frames import euler_rates_to_body
from sysid.discrepancy import DiscrepancyResult, discover
from sysid.discrepancy.catalogue import EFFECTS
from sysid.discrepancy.catalogue.sensor_scale import gyro_scale_errors
from sysid.discrepancy.series import FlightSeries

from builders import discrepancy_series

pytestmark = pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning")

SIM_SEED, REAL_SEED = 8600, 8601  # held out: the term was tuned on 3000 / 3101 on and 3200 / 3301 on
GYROS = {  # case -> the REAL vehicle's gyro errors (p, q, r)
    "gyro_default": GyroScale(),  # p +4 %, q -3 %, r +5 %
    "gyro_other": GyroScale(p_error=-0.05, q_error=0.06, r_error=0.0),
}
NULLS = {"none": (), "worn_thrust": (MotorWear(thrust_fraction=0.30),)}


def _analytic(scale: tuple[float, float, float], seed: int, noise: float = 0.002) -> FlightSeries:
    """120 s at 50 Hz of a sweeping attitude, the rates its kinematics times ``scale``, plus white `noise` (rad/s)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 120.0, 0.02)
    phi = 0.2 * np.sin(2 * np.pi * (0.3 + 0.01 * t) * t)
    theta = 0.15 * np.sin(2 * np.pi * (0.5 + 0.008 * t) * t + 1.0)
    psi = 0.3 * np.sin(2 * np.pi * 0.4 * t) + 0.01 * t
    rates = euler_rates_to_body(phi, theta, *(np.gradient(a, t) for a in (phi, theta, psi)))
    signals = {"phi": phi, "theta": theta, "psi": psi}
    for k, name in enumerate(("p", "q", "r")):
        signals[name] = scale[k] * rates[:, k] + noise * rng.standard_normal(t.size)
    return FlightSeries(name="analytic", time_s=t, piece=np.zeros(t.size, int), signals=signals, rate_hz=50.0)


def test_the_measured_scale_is_the_one_flown_on_analytic_kinematics() -> None:
    """Rates 4 % high, 3 % low and right: the errors relative to a right gyro, within a few tenths of a percent."""
    errors = {p.name: p for p in gyro_scale_errors(_analytic((1.0, 1.0, 1.0), 1), _analytic((1.04, 0.97, 1.0), 2))}
    assert errors["gyro_p_scale_error"].value == pytest.approx(0.04, abs=0.003)
    assert errors["gyro_q_scale_error"].value == pytest.approx(-0.03, abs=0.003)
    assert errors["gyro_r_scale_error"].value == pytest.approx(0.0, abs=0.003)
    for p in errors.values():  # each within 3 of its own standard deviations of the truth
        truth = {"gyro_p_scale_error": 0.04, "gyro_q_scale_error": -0.03, "gyro_r_scale_error": 0.0}[p.name]
        assert abs(p.value - truth) < 3 * p.uncertainty + 1e-4, p


def test_an_axis_without_motion_is_not_measured() -> None:
    """No yaw at all (rate and heading still): r is left out, not reported as a scale error of 0 or infinity."""
    still = _analytic((1.0, 1.0, 1.0), 4, noise=0.0)
    still = replace(still, signals={**still.signals, "psi": np.zeros(still.n), "r": np.zeros(still.n)})
    moving = _analytic((1.04, 1.0, 1.0), 5)
    names = [p.name for p in gyro_scale_errors(moving, still)]
    assert names == ["gyro_p_scale_error", "gyro_q_scale_error"]


def test_a_flight_without_its_attitude_is_not_measured() -> None:
    flight = _analytic((1.0, 1.0, 1.0), 3)
    assert gyro_scale_errors(flight, flight.without(["psi"])) == ()


def test_sensor_scale_is_in_the_catalogue() -> None:
    assert "sensor_scale" in EFFECTS


@pytest.fixture(scope="module", name="results")
def results_fixture(tmp_path_factory: pytest.TempPathFactory) -> dict[str, DiscrepancyResult]:
    folder = tmp_path_factory.mktemp("sensor-scale-pairs")
    sim = discrepancy_series(write_case(open_pair_case("sim", SIM_SEED), folder).log)
    cases = {**{name: (gyro,) for name, gyro in GYROS.items()}, **NULLS}
    return {
        name: discover(
            [sim], [discrepancy_series(write_case(open_pair_case(name, REAL_SEED + k, effects=e), folder).log)]
        )
        for k, (name, e) in enumerate(cases.items())
    }


@pytest.mark.parametrize("case", GYROS)
def test_a_gyro_scale_error_is_named_alone_and_measured(
    results: dict[str, DiscrepancyResult], case: str, record_property: Callable[[str, object], None]
) -> None:
    """The verdict is ``sensor_scale`` and nothing else; every axis it claims holds the truth within 2 σ."""
    result = results[case]
    record_property(
        "findings", repr([(f.effect, f.outputs, f.improvement_percent, f.parameters) for f in result.findings])
    )
    assert [f.effect for f in result.findings] == ["sensor_scale"], result.summary
    finding = result.findings[0]
    assert finding.improvement_percent > 0.0
    truth = {f"gyro_{axis}_scale_error": scale - 1.0 for axis, scale in zip("pqr", GYROS[case].scales.values())}
    claimed = [p for p in finding.parameters if f"{p.name.split('_')[1]}_dot" in finding.outputs]
    assert claimed, finding
    for p in claimed:
        assert abs(p.value - truth[p.name]) < 2.0 * p.uncertainty, (p, truth[p.name])


@pytest.mark.parametrize("case", NULLS)
def test_no_gyro_error_is_claimed_where_none_was_flown(results: dict[str, DiscrepancyResult], case: str) -> None:
    assert "sensor_scale" not in [f.effect for f in results[case].findings], results[case].summary


def test_a_real_flights_two_halves_share_one_gyro(real_data: Path) -> None:
    """One PX4 gyro read against its own attitude in the first and second half: no scale error is claimed.

    A regression check, not held-out evidence: this flight set the 2 % floor (its halves read 0.9 % apart
    on q at 3.4 σ); the only other real logs here lack the mixer inputs or 10 s of flight.
    """
    from sysid.discrepancy.catalogue.sensor_scale import TERM

    flight = discrepancy_series(real_data / "px4-ulog-rs/quadrotor_local.ulg")
    rows = np.arange(flight.n)
    halves = flight.subset(rows[: flight.n // 2]), flight.subset(rows[flight.n // 2 :])
    assert len(gyro_scale_errors(*halves)) == 3
    assert TERM.calibrate is not None and TERM.calibrate(*halves) is None
