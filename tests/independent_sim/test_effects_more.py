"""Tests of the newer physics (catalogue entries with our own laws, physics outside the catalogue) and the nuisances.

Short flights (70 s: lat and lon chirps at once, a 20 m reposition out and back, a 4 m climb and descent) flown with and
without each effect on one seed. A law is checked where its consequence is plain (the hover thrust of worn
rotors, a scaled gyro), and every effect's accelerations against the flown state; an outside effect must leave
a residual against the simulated plant's own model (eq. 3.5 with the truth's parameters) on its primary
outputs well above the unmeasured disturbances (0.03 m/s², rad/s²) and none elsewhere.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from pyulog import ULog
from scipy.signal import welch

from flightlogs.readers import read_log
from independent_sim import (
    AccelScale,
    AirframeDrag,
    Case,
    Chirp,
    ClimbInflow,
    FlightPlan,
    GyroScale,
    Maneuver,
    MixerCrossCoupling,
    MotorWear,
    NoiseModel,
    Nuisances,
    Reposition,
    SpeedPitchMoment,
    SwingingPayload,
    ThrustCeiling,
    TranslationalLift,
    open_pair_case,
    simulate,
)
from independent_sim._mixer import MOTOR_MIX
from independent_sim.effects_outside import OUTPUTS
from independent_sim.plant import G
from independent_sim.scenario import HeightChange

_PLAN = FlightPlan(
    duration_s=70.0,
    repositions=(Reposition(start_s=32.0, north_m=20.0), Reposition(start_s=42.0, north_m=-20.0)),
    height_changes=(
        HeightChange(start_s=50.0, down_m=-4.0, duration_s=3.0),
        HeightChange(start_s=56.0, down_m=4.0, duration_s=3.0),
    ),
)
_LAT = tuple(
    Maneuver(axis=axis, design=Chirp(duration_s=18.0, f_min_hz=0.2, f_max_hz=6.0), start_s=13.0, amplitude=amplitude)  # type: ignore[arg-type]
    for axis, amplitude in (("lat", 0.07), ("lon", 0.06))
)
_SEED = 5
_OUTSIDE = (SwingingPayload(), MixerCrossCoupling(), SpeedPitchMoment())
_INSIDE = (
    MotorWear(thrust_fraction=0.3, roll_fraction=0.2),
    AirframeDrag(),
    ClimbInflow(),
    TranslationalLift(),
    ThrustCeiling(),
)


def _case(effects: tuple = (), *, seed: int = _SEED, nuisances: Nuisances | None = None, **changes: object) -> Case:
    return Case(
        name=f"short-{seed}",
        fmt="ulog",
        plan=changes.pop("plan", _PLAN),  # type: ignore[arg-type]
        maneuvers=changes.pop("maneuvers", _LAT),  # type: ignore[arg-type]
        seed=seed,
        effects=effects,
        nuisances=nuisances,
        **changes,  # type: ignore[arg-type]
    )


@pytest.fixture(scope="module", name="flights")
def flights_fixture():  # type: ignore[no-untyped-def]
    """The short plan flown plain and with each effect, one seed (the effects' own constants: their defaults)."""
    out = {"plain": simulate(_case())}
    for effect in _INSIDE + _OUTSIDE:
        out[type(effect).__name__] = simulate(_case((effect,)))
    return out


def _after(flight) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Time after take-off on the fine grid, s."""
    return flight.time_s - flight.time_s[flight.airborne][0]


def _window(flight, start_s: float, end_s: float) -> np.ndarray:  # type: ignore[no-untyped-def]
    t = _after(flight)
    return (t >= start_s) & (t < end_s)


def _rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(values**2)))


def _residuals(flight) -> dict[str, np.ndarray]:  # type: ignore[no-untyped-def]
    """Each output less what the simulated plant (eq. 3.5, calm, the truth's own parameters) makes of its state."""
    k, t = flight.plant, flight.truth

    def rate(name: str) -> np.ndarray:
        return np.gradient(t[name], flight.time_s)

    return {
        "ax": t["ax"] - (k.X_u * t["u"] + k.X_lon * t["actuator_lon"]),
        "ay": t["ay"] - (k.Y_v * t["v"] + k.Y_lat * t["actuator_lat"]),
        "az": t["az"] - (-G + k.Z_thr * (t["actuator_thr"] - k.trim.delta_thr)),
        "p_dot": rate("p") - (k.L_v * t["v"] + k.L_lat * t["actuator_lat"]),
        "q_dot": rate("q") - (k.M_u * t["u"] + k.M_lon * t["actuator_lon"]),
        "r_dot": rate("r") - k.N_r * t["r"],
    }


# ----------------------------------------------------------------------------- catalogue entries, our laws


def test_worn_rotors_need_the_thrust_their_law_says(flights) -> None:  # type: ignore[no-untyped-def]
    """(1 - f)(g - Z_thr d) = g: the hover thrust input rises by g f / ((1 - f) |Z_thr|), within 2 % (got 0.1 %)."""
    wear, plain = flights["MotorWear"], flights["plain"]
    hover = _window(plain, 8.0, 12.5)
    rise = np.mean(wear.truth["delta_thr"][hover]) - np.mean(plain.truth["delta_thr"][hover])
    assert rise == pytest.approx(G * 0.3 / (0.7 * -wear.plant.Z_thr), rel=0.02)
    chirp = _window(plain, 14.0, 30.0)[::4]  # control instants: the roll moment per unit input is 0.8 of SIM's
    roll, lagged = wear.truth["effect_p"][::4][chirp], wear.truth["actuator_lat"][::4][chirp]
    np.testing.assert_allclose(roll, -0.2 * wear.plant.L_lat * lagged, atol=1e-9)


def test_the_catalogue_laws_act_as_written_on_the_flown_state(flights) -> None:  # type: ignore[no-untyped-def]
    """Each law's acceleration at every control step, from the truth at that step (air-relative velocity, inputs)."""
    step = slice(None, None, 4)  # control instants (the fine grid is 1 kHz, the loop 250 Hz)
    drag = flights["AirframeDrag"].truth
    speed = np.sqrt(drag["u"] ** 2 + drag["v"] ** 2 + drag["w"] ** 2)[step]
    np.testing.assert_allclose(drag["effect_u"][step], -0.03 * speed * drag["u"][step], atol=1e-9)
    np.testing.assert_allclose(drag["effect_v"][step], -0.03 * speed * drag["v"][step], atol=1e-9)
    assert np.abs(drag["effect_u"]).max() > 0.5  # over 5 m/s in the reposition
    for name, ratio in (
        ("ClimbInflow", lambda u, v, w: ClimbInflow().ratio(-w)),
        ("TranslationalLift", lambda u, v, w: TranslationalLift().ratio(math.hypot(u, v))),
    ):
        flight = flights[name]
        t = {k: v[step][flight.airborne[step]] for k, v in flight.truth.items()}
        thrust = G - flight.plant.Z_thr * (t["actuator_thr"] - flight.plant.trim.delta_thr)
        law = np.array([ratio(u, v, w) for u, v, w in zip(t["u"], t["v"], t["w"])]) - 1.0
        np.testing.assert_allclose(t["effect_w"], -law * thrust, atol=1e-9)
        assert np.abs(t["effect_w"]).max() > 0.5, name  # the climb at 1.7 m/s, the reposition at 6 m/s


def test_climb_inflow_and_translational_lift_change_the_thrust_the_loop_needs(flights) -> None:  # type: ignore[no-untyped-def]
    """Climbing (1.7 m/s) needs more thrust input with inflow; fast (6 m/s) less with translational lift."""
    plain = flights["plain"]
    climb = _window(plain, 51.0, 52.5)
    fast = _window(plain, 34.5, 36.5)
    extra = flights["ClimbInflow"].truth["delta_thr"] - plain.truth["delta_thr"]
    saved = plain.truth["delta_thr"] - flights["TranslationalLift"].truth["delta_thr"]
    loss = 1.0 - ClimbInflow().ratio(1.5)  # thrust lost at 1.5 m/s, 8 %
    assert np.mean(extra[climb]) > 0.5 * G * loss / -plain.plant.Z_thr
    gain = TranslationalLift().ratio(5.0) - 1.0
    assert np.mean(saved[fast]) > 0.5 * G * gain / -plain.plant.Z_thr


def test_the_thrust_ceiling_takes_what_the_motors_over_it_would_add(flights) -> None:  # type: ignore[no-untyped-def]
    """Motors over 0.48 (the sweep's peaks, the reposition) lose their excess: less thrust and moment, none below."""
    flight = flights["ThrustCeiling"]
    t = flight.truth
    inputs = np.column_stack([t["actuator_lat"], t["actuator_lon"], t["actuator_thr"]])
    motors = np.column_stack([inputs[:, :2], np.zeros(len(inputs)), inputs[:, 2]]) @ MOTOR_MIX.T
    over = motors.max(axis=1) > 0.48 + 0.01  # (the yaw input is small)
    under = motors.max(axis=1) < 0.48 - 0.01
    assert over[flight.airborne].mean() > 0.05  # the flight reaches the ceiling
    assert np.all(t["effect_w"][over] > 0.0)  # thrust lost: w (down) accelerates
    assert np.all(t["effect_w"][under] == 0.0) and np.all(t["effect_q"][under] == 0.0)
    assert np.abs(t["effect_q"]).max() > 1.0


def test_scale_errors_scale_the_logged_gyro_and_accelerometer() -> None:
    """Logged = (1 + e) true, exactly (no noise); the vehicle flies as without them."""
    scales = (GyroScale(p_error=0.04, q_error=-0.03, r_error=0.05), AccelScale())
    quiet = NoiseModel.quiet()
    plan = FlightPlan(duration_s=30.0)
    sweep = (
        Maneuver(axis="lat", design=Chirp(duration_s=9.5, f_min_hz=0.3, f_max_hz=5.0), start_s=10.0, amplitude=0.07),
    )
    flight = simulate(_case(scales, noise=quiet, plan=plan, maneuvers=sweep))
    plain = simulate(_case((), noise=quiet, plan=plan, maneuvers=sweep))
    for name, factor in (("p", 1.04), ("q", 0.97), ("r", 1.05), ("ax", 1.03), ("ay", 0.96), ("az", 1.03)):
        np.testing.assert_allclose(flight.measured[name], factor * flight.truth[name], rtol=1e-12, atol=1e-12)
        np.testing.assert_array_equal(flight.truth[name], plain.truth[name])
    assert np.abs(flight.truth["p"]).max() > 0.1


# ----------------------------------------------------------------------------- physics outside the catalogue


@pytest.mark.parametrize("effect", _OUTSIDE, ids=lambda e: type(e).__name__)
def test_outside_effects_leave_a_residual_on_their_primary_outputs_only(flights, effect) -> None:  # type: ignore[no-untyped-def]
    """Against the simulated plant's own model: RMS over 3× the plain flight's (the disturbances) on a primary output.

    The plain flight's residuals are the unmeasured disturbances alone (0.03 m/s², rad/s² each); an output the
    effect does not act on keeps them.
    """
    assert set(effect.primary_outputs) <= set(OUTPUTS) and effect.primary_outputs
    plain, flight = _residuals(flights["plain"]), _residuals(flights[type(effect).__name__])
    span = _window(flights["plain"], 12.0, 60.0)  # the chirp, the repositions, the climb
    for name in OUTPUTS:
        floor, found = _rms(plain[name][span]), _rms(flight[name][span])
        if name in effect.primary_outputs:
            assert found > 3.0 * floor, (name, found, floor)
        elif name in ("az", "r_dot"):
            assert found == pytest.approx(floor, rel=0.05), name


def test_a_swinging_payload_swings_at_its_pendulum_frequency(flights) -> None:  # type: ignore[no-untyped-def]
    """The lateral force of the swing peaks near sqrt(g / ((1 - r) l)) / 2π = 0.53 Hz (within the loop's shift)."""
    flight = flights["SwingingPayload"]
    load = SwingingPayload()
    span = _window(flight, 12.0, 60.0)
    f, power = welch(flight.truth["effect_v"][span], fs=1000.0, nperseg=20_000)
    peak = f[np.argmax(power)]
    assert peak == pytest.approx(math.sqrt(G / ((1 - load.mass_ratio) * load.length_m)) / (2 * math.pi), rel=0.25)


def test_mixer_cross_coupling_puts_a_share_of_the_roll_input_on_pitch(flights) -> None:  # type: ignore[no-untyped-def]
    t, k = flights["MixerCrossCoupling"].truth, flights["plain"].plant
    np.testing.assert_allclose(t["effect_q"][::4], 0.15 * k.M_lon * t["actuator_lat"][::4], atol=1e-9)


# ----------------------------------------------------------------------------- nuisances

_SHAKY = Nuisances(dropouts=(2, 2), dropout_s=(0.2, 0.2))


@pytest.fixture(scope="module", name="shaky")
def shaky_fixture(tmp_path_factory: pytest.TempPathFactory):  # type: ignore[no-untyped-def]
    """A 40 s hover with a lon chirp, quiet sensors but the nuisances, flown and written as a ULog."""
    from independent_sim.px4_log import write_px4

    sweep = (
        Maneuver(axis="lon", design=Chirp(duration_s=20.0, f_min_hz=0.3, f_max_hz=5.0), start_s=10.0, amplitude=0.06),
    )
    case = _case(nuisances=_SHAKY, noise=NoiseModel.quiet(), plan=FlightPlan(duration_s=40.0), maneuvers=sweep)
    flight = simulate(case)
    path = tmp_path_factory.mktemp("shaky") / "shaky.ulg"
    write_px4(flight, path)
    return flight, path


def test_dropouts_leave_every_topic_without_samples_for_their_length(shaky) -> None:  # type: ignore[no-untyped-def]
    """Read back with pyulog: no topic has a sample inside a gap; a topic at 10 Hz or more skips over its whole length."""
    flight, path = shaky
    assert len(flight.dropouts_s) == 2
    takeoff, touchdown = flight.time_s[flight.airborne][[0, -1]]
    for start, end in flight.dropouts_s:
        assert end - start == pytest.approx(0.2) and takeoff + 10.0 <= start < end <= touchdown - 10.0
    for data in ULog(str(path)).data_list:
        stamps = data.data["timestamp"] / 1e6
        for start, end in flight.dropouts_s:
            assert not np.any((stamps >= start) & (stamps < end)), data.name
            if len(stamps) / (stamps[-1] - stamps[0]) >= 9.0:
                before, after = stamps[stamps < start][-1], stamps[stamps >= end][0]
                assert after - before >= end - start, data.name


def test_vibration_aliases_into_the_logged_accelerations(shaky) -> None:  # type: ignore[no-untyped-def]
    """The 140 Hz blade-passing line, sampled at 200 Hz, is a 60 Hz line in the log (its harmonic, 280 Hz: 80 Hz)."""
    flight, path = shaky
    log = read_log(path)
    signal = log["az"]
    hover = (signal.time_s > flight.time_s[flight.airborne][0] + 12.0) & (signal.time_s < flight.dropouts_s[0][0])
    f, power = welch(signal.values[hover] - np.mean(signal.values[hover]), fs=200.0, nperseg=1024)
    line = f[np.argmax(power)]
    assert line == pytest.approx(200.0 - 140.0, abs=2.0)
    harmonic = power[(f > 75.0) & (f < 85.0)].max()
    assert harmonic > 100 * np.median(power) and harmonic < power.max()
    amplitude = np.sqrt(2 * power[(f > 55.0) & (f < 65.0)].sum() * (f[1] - f[0]))
    assert amplitude == pytest.approx(_SHAKY.vibration_m_s2[2], rel=0.1)  # at hover thrust


def test_gyro_biases_drift_as_a_random_walk(shaky) -> None:  # type: ignore[no-untyped-def]
    """Quiet sensors: the logged gyro less the truth is the walk, steps of sigma sqrt(dt / 240 s) (within 2 %)."""
    flight, _ = shaky
    dt = flight.step_us / 1e6
    for name in ("p", "q", "r"):
        drift = flight.measured[name] - flight.truth[name]
        assert np.std(np.diff(drift)) == pytest.approx(_SHAKY.gyro_drift_rad_s * math.sqrt(dt / 240.0), rel=0.02)
        assert abs(drift[0]) < 1e-9 and np.abs(drift).max() < 0.02


def test_the_open_pair_plan_reaches_the_speeds_and_climb_rates_its_physics_need() -> None:
    """Over 5 m/s in the repositions, ±1.5 m/s in the climb and descent, 0.35 m in the low hover; nuisances on."""
    flight = simulate(open_pair_case("open", 3))
    t = _after(flight)
    speed = np.hypot(flight.truth["u"], flight.truth["v"])
    assert speed[(t > 146.0) & (t < 175.0)].max() > 5.0
    climb = -flight.truth["vd"][(t > 174.0) & (t < 190.0)]
    assert climb.max() > 1.5 and climb.min() < -1.5
    assert np.mean(flight.truth["height"][(t > 202.0) & (t < 214.0)]) == pytest.approx(0.35, abs=0.05)
    assert 1 <= len(flight.dropouts_s) <= 3
