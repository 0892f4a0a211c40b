"""Closed-loop batch simulation: bounded hover in strong wind, Taylor delay, payload, battery, determinism."""

from __future__ import annotations

from datetime import UTC, datetime

import numpy as np
import pytest

from simulator.autopilot.control import HeightSteps, Injection, Legs
from simulator.autopilot.excitation import Maneuver
from simulator.campaign.fly import scenario_trials
from simulator.campaign.scenario import load_builtin
from simulator.flights.linear import SimulatedFlight
from simulator.flights.nonlinear import NonlinearFlight, Trial, simulate_flights
from simulator.output.ardupilot import write_ardupilot_log
from simulator.vehicle.presets import CRAZYFLIE, OCTO_S1000
from simulator.world.environment import Anemometer, Environment, GroundEffect, PayloadChange, SensorNoise
from simulator.world.wind_field import Gust, Wind

G = 9.81
STRONG = Wind.dissertation("strong", direction_from_deg=250.0)


@pytest.fixture(scope="module")
def long_flights() -> list[NonlinearFlight]:
    """One 60 s batch: sweeps on every axis in strong wind; a calm hover dropping 0.7 kg; an anemometer abeam."""
    sweeps = tuple(
        Maneuver(axis=axis, kind="sweep", start_s=4.0, amplitude=pct, duration_s=52.0)
        for axis, pct in (("lat", 8.0), ("lon", 8.0), ("yaw", 10.0), ("thr", 4.0))
    )
    strong = Trial(duration_s=60.0, maneuvers=sweeps, environment=Environment(wind=STRONG), seed=5, label="strong")
    calm = Trial(
        duration_s=60.0,
        environment=Environment(
            wind=Wind(mean_speed_m_s=0.9, direction_from_deg=20.0),
            payload=PayloadChange(30.0, -0.7),
            thrust_sag=True,
            sensors=SensorNoise.off(),
        ),
        seed=6,
        label="calm",
    )
    abeam = Trial(
        duration_s=60.0, environment=Environment(wind=STRONG, anemometer=Anemometer(15.0, bearing_deg=340.0)), seed=7
    )
    return simulate_flights([strong, calm, abeam])


def test_closed_loop_hover_stays_within_bounds_in_strong_wind_with_sweeps(long_flights) -> None:
    flight = long_flights[0]
    truth = flight.truth
    theta_trim = np.median(truth["theta"][:300])
    assert theta_trim < np.radians(-2)  # nose down into the wind
    assert np.max(np.abs(truth["phi"])) < np.radians(25)
    assert np.max(np.abs(truth["theta"] - theta_trim)) < np.radians(25)
    assert np.max(np.hypot(truth["pn"], truth["pe"])) < 3.0
    assert np.max(np.abs(truth["height_agl"] - 4.6)) < 1.5  # the 4 % thrust sweep moves it about 0.9 m at 0.1 Hz
    heading = np.radians(250.0)
    assert np.max(np.abs(np.angle(np.exp(1j * (truth["psi"] - heading))))) < np.radians(20)
    motors = np.column_stack([truth[f"motor_{k}"] for k in range(1, 9)])
    assert np.mean((motors <= 5.0 + 1e-9) | (motors >= 100.0 - 1e-9)) < 0.01  # hardly ever saturated


def test_flight_has_the_canonical_signals_and_the_truth(long_flights) -> None:
    flight = long_flights[0]
    assert isinstance(flight, SimulatedFlight)
    expected = {
        "p",
        "q",
        "r",
        "phi",
        "theta",
        "psi",
        "u",
        "v",
        "w",
        "ax",
        "ay",
        "az",
        "vn",
        "ve",
        "vd",
        "height_agl",
        "delta_lat",
        "delta_lon",
        "delta_yaw",
        "delta_thr",
        "battery_v",
    }
    assert expected | {f"motor_{k}" for k in range(1, 9)} <= set(flight.signals)
    assert flight.time_s.size == 6000 and flight.time_s[1] == pytest.approx(0.01)
    assert flight.parameters["X_u"] == pytest.approx(-0.3172, rel=1e-6)
    assert flight.parameters["wind_speed_m_s"] == 5.4
    # eq. 3.1: mean body airspeed along the nose is the wind speed (nose into the wind)
    assert np.mean(flight.truth["u"]) == pytest.approx(5.4, rel=0.15)
    noise = flight.signals["q"] - flight.truth["q"]
    assert np.std(noise) == pytest.approx(0.005, rel=0.1)


def test_anemometer_series_leads_the_vehicle_series_by_distance_over_speed(long_flights) -> None:
    flight = long_flights[0]
    delay = flight.transport_delay_s
    assert delay == pytest.approx(4.6 / 5.4)
    towards = STRONG.towards
    vehicle = flight.wind_at_vehicle @ towards
    sensor = flight.wind_at_anemometer @ towards
    vehicle, sensor = vehicle - vehicle.mean(), sensor - sensor.mean()
    lags = np.arange(0, 200)
    corr = [np.dot(sensor[: sensor.size - lag], vehicle[lag:]) for lag in lags]
    lag_s = lags[int(np.argmax(corr))] * 0.01
    assert abs(lag_s - delay) <= 0.01 + 1e-9  # within one sample at 100 Hz
    assert np.max(corr) / np.sqrt(np.dot(sensor, sensor) * np.dot(vehicle, vehicle)) > 0.98


def test_an_anemometer_abeam_of_the_wind_sees_decorrelated_gusts_without_delay(long_flights) -> None:
    flight = long_flights[2]
    assert flight.transport_delay_s == pytest.approx(0.0, abs=1e-12)
    vehicle = flight.wind_at_vehicle @ STRONG.towards
    sensor = flight.wind_at_anemometer @ STRONG.towards
    corr = np.corrcoef(vehicle, sensor)[0, 1]
    assert 0.2 < corr < 0.95  # exp(-15 m / 33.9 m) = 0.64 expected, from a 60 s record
    assert np.std(sensor) == pytest.approx(np.std(vehicle), rel=0.5)


def test_payload_drop_lowers_the_thrust_input_by_the_weight_change(long_flights) -> None:
    truth = long_flights[1].truth
    time = long_flights[1].time_s
    before = np.mean(truth["delta_thr"][(time > 25) & (time < 30)])
    after = np.mean(truth["delta_thr"][(time > 50) & (time < 60)])
    expected = -0.7 * G / (0.8712 * 7.0)  # Z_thr = -0.8712 m/s^2 per % for 7 kg
    assert after - before == pytest.approx(expected, rel=0.1)
    assert truth["mass_kg"][0] == 7.0 and truth["mass_kg"][-1] == pytest.approx(6.3)
    volts = truth["battery_v"]
    assert volts[-1] < volts[0] - 0.01  # the pack sags as it discharges
    assert np.mean(truth["az"][time > 50]) == pytest.approx(-G, abs=0.02)


def test_a_batch_gives_the_same_flights_as_each_trial_alone() -> None:
    trials = [
        Trial(
            duration_s=3.0,
            maneuvers=(Maneuver(axis="lon", kind="doublet", start_s=0.5, amplitude=10.0, duration_s=1.0),),
            environment=Environment(wind=STRONG),
            seed=1,
        ),
        Trial(
            duration_s=3.0,
            injections=(
                Injection(axis="lat", kind="3211", start_s=0.5, amplitude=6.0, duration_s=1.4),
                Injection(axis="thr", kind="multisine", start_s=0.2, amplitude=3.0, duration_s=2.5),
            ),
            environment=Environment(
                wind=Wind(
                    mean_speed_m_s=2.7,
                    direction_from_deg=300.0,
                    turbulence=None,
                    gusts=(Gust(arrival_s=1.0, duration_s=1.0, amplitude_m_s=2.0),),
                ),
                cg_offset_m=(0.01, 0, 0),
            ),
            seed=2,
        ),
        Trial(duration_s=3.0, environment=Environment(wind=Wind.dissertation("light")), seed=3, heading_deg=45.0),
    ]
    batch = simulate_flights(trials)
    for trial, together in zip(trials, batch):
        alone = simulate_flights([trial])[0]
        for name in together.signals:
            assert np.array_equal(alone.signals[name], together.signals[name]), name
        assert np.array_equal(alone.wind_at_anemometer, together.wind_at_anemometer)
    again = simulate_flights(trials[:1])[0]
    assert np.array_equal(again.signals["ax"], batch[0].signals["ax"])  # seeded: reproducible


def test_crazyflie_ground_effect_steps_show_eq_2_5_in_flight() -> None:
    """Chapter 2's descent: in a steady hover F/F0 = weight / sum(k_f PWM) (eq. 2.6) follows eq. 2.5."""
    steps = HeightSteps.ground_effect_descent(CRAZYFLIE.rotor_radius_m, ratios=(6.0, 2.0), hold_s=8.0)
    environment = Environment(ground_effect=GroundEffect(model="fitted_4rotor"), sensors=SensorNoise.off())
    flight = simulate_flights([Trial(duration_s=16.0, environment=environment, height_steps=steps)], CRAZYFLIE)[0]
    time, truth = flight.time_s, flight.truth
    pwm = np.column_stack([truth[f"motor_{k}"] for k in range(1, 5)]) / 100 * 65535
    ratio = CRAZYFLIE.mass_kg * G / np.sum(2.083e-6 * pwm, axis=1)
    assert np.mean(ratio[(time > 5) & (time < 8)]) == pytest.approx(1.0, abs=1e-3)  # Z/R = 6: out of it
    settled = (time > 10) & (np.abs(truth["vd"]) < 0.01)
    model = -0.0373 * truth["height_agl"][settled] / CRAZYFLIE.rotor_radius_m + 1.1651
    np.testing.assert_allclose(ratio[settled], model, atol=3e-3)
    assert np.max(ratio) > 1.04
    # and, as chapter 2 found, the PID height loop creeps down against the growing thrust: not settled in 8 s
    assert truth["height_agl"][-1] > 2.5 * CRAZYFLIE.rotor_radius_m


def test_the_log_writer_accepts_a_nonlinear_flight(tmp_path) -> None:
    sweep = Maneuver(
        axis="lat", kind="sweep", start_s=0.2, amplitude=5.0, duration_s=1.5, fade_in_s=0.5, fade_out_s=0.2
    )
    flight = simulate_flights([Trial(duration_s=2.0, maneuvers=(sweep,))])[0]
    path = write_ardupilot_log(flight, tmp_path / "flight.bin", utc_start=datetime(2024, 5, 1, tzinfo=UTC))
    assert path.stat().st_size > 10_000


def test_campaign_has_120_trials_and_euler_agrees_with_rk4() -> None:
    campaign = scenario_trials(load_builtin("chapter3-campaign"))
    assert len(campaign) == 120
    assert sorted({t.duration_s for t in campaign}) == [8.0, 40.0]  # 2 s doublet or 34 s sweep + 3 s trim each side
    assert len({t.seed for t in campaign}) == 120
    doublet = Maneuver(axis="lon", kind="doublet", start_s=1.0, amplitude=10.0, duration_s=2.0)
    trial = Trial(duration_s=4.0, maneuvers=(doublet,), environment=Environment(sensors=SensorNoise.off()))
    rk4, euler = simulate_flights([trial], method="rk4")[0], simulate_flights([trial], method="euler")[0]
    assert np.max(np.abs(rk4.signals["q"] - euler.signals["q"])) < 0.02 * np.max(np.abs(rk4.signals["q"]))
    assert OCTO_S1000.n_rotors == 8


def test_legs_are_flown_at_the_speed_limit_and_end_on_their_point() -> None:
    """A 20 m leg north at 2 s and back at 14 s: the position loop saturates at its 3 m/s and settles on each point."""
    legs = Legs(times_s=(0.0, 2.0, 14.0), north_m=(0.0, 20.0, 0.0), east_m=(0.0, 0.0, 0.0))
    trial = Trial(duration_s=26.0, legs=legs, heading_deg=0.0, environment=Environment(sensors=SensorNoise.off()))
    flight = simulate_flights([trial])[0]
    time, truth = flight.time_s, flight.truth
    assert np.max(truth["vn"]) == pytest.approx(3.0, abs=0.3)
    assert np.min(truth["vn"]) == pytest.approx(-3.0, abs=0.3)
    assert np.interp(13.5, time, truth["pn"]) == pytest.approx(20.0, abs=0.5)
    assert abs(truth["pn"][-1]) < 0.5 and np.max(np.abs(truth["pe"])) < 0.2
