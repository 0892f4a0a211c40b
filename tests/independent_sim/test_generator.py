"""Tests of the independent corpus generator: plant, integrator, closed loop, logs, wind, catalogue."""

from __future__ import annotations

import math
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from pyulog import ULog
from scipy.integrate import solve_ivp
from scipy.signal import bilinear, csd, lfilter, lfilter_zi, welch

import flightlogs.signals
from flightlogs.conditioning.lag import transport_delay
from flightlogs.readers import read_anemometer_csv, read_log, read_messages
from independent_sim import (
    HELDOUT_CASES,
    TUNING_CASES,
    Case,
    Chirp,
    Doublet,
    FlightPlan,
    Maneuver,
    PilotedSweep,
    WindModel,
    hover_plant,
    linear_plant,
    simulate,
    write_case,
)
from independent_sim._common import motor_commands
from independent_sim._zoh import delayed_input_map, expm
from independent_sim.control import ardupilot_gains, closed_loop, px4_gains
from independent_sim.fixtures import independent_corpus_fixture  # noqa: F401 (registers the fixture)
from independent_sim.plant import PLANT_INPUTS, STATES, G

REPO = Path(__file__).resolve().parents[2]
#: Canonical signals (DESIGN.md) both writers must carry.
CANONICAL = (
    "p q r phi theta psi ax ay az delta_lat delta_lon delta_yaw delta_thr vn ve vd height_agl battery_v".split()
    + [f"motor_{k}" for k in range(1, 9)]
)


def _short_case(fmt: str, **changes: object) -> Case:
    case = Case(
        name=f"short-{fmt}",
        fmt=fmt,  # type: ignore[arg-type]
        plan=FlightPlan(duration_s=60.0, log_start_us=52_345_000),
        maneuvers=(
            Maneuver(axis="lon", design=Chirp(duration_s=30.0), start_s=10.0, amplitude=0.06),
            Maneuver(axis="lat", design=Doublet(width_s=1.0), start_s=44.0, amplitude=0.06),
        ),
        heading_deg=200.0,
        seed=11,
    )
    return replace(case, **changes)  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def px4_files(tmp_path_factory: pytest.TempPathFactory):
    return write_case(_short_case("ulog"), tmp_path_factory.mktemp("px4"))


@pytest.fixture(scope="module")
def ap_files(tmp_path_factory: pytest.TempPathFactory):
    return write_case(_short_case("dataflash"), tmp_path_factory.mktemp("ap"))


def _wind_case() -> Case:
    return Case(
        name="short-wind",
        fmt="dataflash",
        plan=FlightPlan(duration_s=45.0),
        maneuvers=(Maneuver(axis="lon", design=Doublet(), start_s=15.0, amplitude=0.06),),
        condition="strong",
        wind=WindModel(mean_speed_m_s=5.4, from_deg=250.0),
        seed=12,
    )


@pytest.fixture(scope="module")
def wind_files(tmp_path_factory: pytest.TempPathFactory):
    return write_case(_wind_case(), tmp_path_factory.mktemp("wind"))


# ----------------------------------------------------------------------------- plant


def test_calm_longitudinal_eigenvalues_are_the_si_values_of_table_3_3() -> None:
    # tables.md: with g = 9.81 the calm eq. 3.11 gives 0.878 ± 1.694i and -2.073 (not Table 3.7's ft/s² values)
    values = linear_plant(hover_plant("calm")).eigenvalues(("u", "q", "theta"))
    np.testing.assert_allclose(np.sort_complex(values), [-2.073, 0.878 - 1.694j, 0.878 + 1.694j], atol=1e-3)


@pytest.mark.parametrize("condition", ["calm", "light", "strong"])
def test_open_loop_eigenvalues_are_the_analytic_roots(condition: str) -> None:
    # eq. 3.11: s³ - X_u s² + g M_u = 0; eq. 3.10: s³ - Y_v s² - g L_v = 0 (u, q, θ and v, p, φ blocks at trim)
    plant = hover_plant(condition)  # type: ignore[arg-type]
    trimmed = replace(plant, trim=replace(plant.trim, theta0=0.0, U0=0.0, W0=0.0))
    linear = linear_plant(trimmed)
    lon = np.roots([1.0, -plant.X_u, 0.0, G * plant.M_u])
    lat = np.roots([1.0, -plant.Y_v, 0.0, -G * plant.L_v])
    np.testing.assert_allclose(
        np.sort_complex(linear.eigenvalues(("u", "q", "theta"))), np.sort_complex(lon), atol=1e-9
    )
    np.testing.assert_allclose(np.sort_complex(linear.eigenvalues(("v", "p", "phi"))), np.sort_complex(lat), atol=1e-9)


def test_truth_uses_the_parameter_names_of_the_hover_structures() -> None:
    for structure, condition in (("hover", "calm"), ("hover-wind", "strong")):
        toml = tomllib.loads((REPO / "sysid" / "model" / "builtin" / f"{structure}.toml").read_text())
        names = set(hover_plant(condition).parameters(structure))  # type: ignore[arg-type]
        assert names == set(toml["parameters"]), structure


def test_control_derivatives_are_table_3_3_per_unit_of_the_logged_mixer() -> None:
    calm, strong = hover_plant("calm"), hover_plant("strong")
    assert (calm.X_lon, calm.M_lon, calm.Y_lat, calm.L_lat, calm.N_yaw, calm.Z_thr) == pytest.approx(
        (-9.85, 52.51, 11.85, 62.26, 7.44, -87.12), abs=1e-9
    )
    assert (calm.N_r, calm.Z_w, calm.T_a, calm.tau_lat, calm.tau_lon) == (0.0, 0.0, 0.0458, 0.0194, 0.0201)
    assert (strong.N_r, strong.X_w_lon, strong.Z_w_lon, strong.tau_w_lon, strong.tau_w_thr) == (
        -0.2543,
        -0.3560,
        1.323,
        0.0132,
        0.0203,
    )
    assert math.degrees(strong.trim.theta0) == pytest.approx(-4.36)


# ----------------------------------------------------------------------------- integrator


def test_matrix_exponential_matches_scipy() -> None:
    from scipy.linalg import expm as scipy_expm

    rng = np.random.default_rng(3)
    for scale in (0.01, 1.0, 40.0):
        matrix = scale * rng.standard_normal((12, 12))
        reference = scipy_expm(matrix)
        assert np.abs(expm(matrix) - reference).max() <= 1e-12 * np.abs(reference).max()


def test_held_delayed_input_matches_numerical_integration() -> None:
    # x' = A x + b u(t - tau), u held over T: the exact maps against RK45 between the input's breakpoints
    linear = linear_plant(hover_plant("strong"))
    A, b = linear.A, linear.B[:, PLANT_INPUTS.index("delta_lon")]
    period, tau, n_sub = 0.004, 0.0193, 4
    maps = delayed_input_map(A, b, tau, period, n_sub)
    assert maps.n_periods == 4 and maps.remainder_s == pytest.approx(0.0033)
    u = np.random.default_rng(5).uniform(-0.1, 0.1, 40)
    held = lambda t: u[int(math.floor(t / period + 1e-12))] if t >= 0 else 0.0
    x, exact = np.zeros(len(STATES)), [np.zeros(len(STATES))]
    for k in range(30):
        cur = u[k - 4] if k >= 4 else 0.0
        prev = u[k - 5] if k >= 5 else 0.0
        exact += [
            maps.before[m] * prev + maps.after[m] * cur + expm(A * (m + 1) * period / n_sub) @ x for m in range(n_sub)
        ]
        x = exact[-1]
    times = np.arange(len(exact)) * period / n_sub
    breaks = sorted({*np.arange(0, 31) * period + maps.remainder_s, *times})
    state, numeric = np.zeros(len(STATES)), {0.0: np.zeros(len(STATES))}
    for start, end in zip(breaks[:-1], breaks[1:]):
        if end > times[-1] + 1e-12:
            break
        value = held(0.5 * (start + end) - tau)
        sol = solve_ivp(lambda t, y, u=value: A @ y + b * u, (start, end), state, rtol=1e-11, atol=1e-13)
        state = sol.y[:, -1]
        numeric[round(end, 9)] = state
    reference = np.array([numeric[round(t, 9)] for t in times])
    np.testing.assert_allclose(np.array(exact), reference, atol=1e-9)


# ----------------------------------------------------------------------------- closed loop


@pytest.mark.parametrize("condition", ["calm", "strong"])
@pytest.mark.parametrize("profile", [px4_gains, ardupilot_gains])
def test_closed_loop_is_stable_and_well_damped(condition: str, profile) -> None:
    plant = hover_plant(condition)  # type: ignore[arg-type]
    gains = profile(plant)
    loop = closed_loop(plant, gains)
    z = loop.eigenvalues()
    assert np.abs(z).max() < 1.0
    s = np.log(z[np.abs(z) > 1e-9].astype(complex)) * gains.rate_hz
    assert s.real.max() < -0.05  # the slowest mode (the position integrators) settles within a minute
    flight_modes = s[np.abs(s) < 60.0]  # below the delay and filter modes
    assert flight_modes.size >= 12
    assert (-flight_modes.real / np.abs(flight_modes)).min() > 0.4


@pytest.mark.parametrize("fmt", ["ulog", "dataflash"])
def test_feedback_cancels_the_low_frequency_part_of_the_sweep(fmt: str) -> None:
    flight = simulate(_short_case(fmt))
    sweep = flight.maneuvers[0]
    index = np.flatnonzero((flight.time_s >= sweep.start_s) & (flight.time_s < sweep.end_s))[:: flight.sub_steps]
    rate = flight.gains.rate_hz
    logged = flight.truth["delta_lon"][index] - flight.plant.trim.delta_lon
    injected = flight.truth["exc_mixer_lon"][index]
    f, p_logged = welch(logged, fs=rate, nperseg=int(15 * rate))
    _, p_injected = welch(injected, fs=rate, nperseg=int(15 * rate))

    def ratio(low: float, high: float) -> float:
        band = (f >= low) & (f < high)
        return float(np.sqrt(p_logged[band].sum() / p_injected[band].sum()))

    assert ratio(0.1, 0.5) < 0.3  # the rate loop cancels most of the slow part of the sweep ...
    assert ratio(1.5, 8.0) > 0.8  # ... and passes the fast part
    slow = index[: int(8 * rate)]  # 0.1-0.25 Hz: the vehicle still pitches with the sweep
    assert np.std(flight.truth["theta"][slow]) > 0.005


def test_logged_response_matches_the_truth_model(px4_files) -> None:
    # H1 estimate of q/delta_lon and ax/delta_lon over the sweep against eq. 3.11 built from the truth JSON.
    # Tolerance: 3 standard deviations of the estimate's random error (Bendat & Piersol,
    # sigma = sqrt((1 - coh) / (2 n coh)) in rad and in relative magnitude), plus 1 % and 0.5°.
    truth, log = px4_files.truth, read_log(px4_files.log)
    k = truth.parameters
    sweep = next(m for m in truth.maneuvers if m.kind == "sweep")
    rate, segment_s = 250.0, 10.0
    grid = np.arange(sweep.start_s, sweep.end_s, 1 / rate)
    x = np.interp(grid, log["delta_lon"].time_s, log["delta_lon"].values)
    f, s_xx = welch(x, fs=rate, nperseg=int(segment_s * rate))
    segments = 2 * (grid[-1] - grid[0]) / segment_s - 1  # 50 % overlap
    s = 2j * np.pi * f
    lag = np.exp(-s * k["tau_lon"]) / (k["T_a"] * s + 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        q_model = (
            lag
            * s
            * (k["M_lon"] * s - k["M_lon"] * k["X_u"] + k["M_u"] * k["X_lon"])
            / (s**3 - k["X_u"] * s**2 + G * k["M_u"])
        )
        ax_model = k["X_lon"] * lag + k["X_u"] * (k["X_lon"] * lag - G * q_model / s) / (s - k["X_u"])
    band = (f >= 0.8) & (f <= 5.0)  # a 1 ms error in tau_lon fails this
    for name, model in (("q", q_model), ("ax", ax_model)):
        y = np.interp(grid, log[name].time_s, log[name].values)
        _, s_xy = csd(x, y, fs=rate, nperseg=int(segment_s * rate))
        _, s_yy = welch(y, fs=rate, nperseg=int(segment_s * rate))
        coherence = np.abs(s_xy[band]) ** 2 / (s_xx[band] * s_yy[band])
        assert coherence.min() > 0.9, name
        sigma = np.sqrt((1 - coherence) / (2 * segments * coherence))
        error = s_xy[band] / s_xx[band] / model[band]
        assert np.all(np.abs(np.abs(error) - 1) < 3 * sigma + 0.01), name
        assert np.all(np.abs(np.angle(error)) < 3 * sigma + np.radians(0.5)), name


# ----------------------------------------------------------------------------- logs


def _generator_values(flight, name: str, index: np.ndarray) -> np.ndarray:
    from independent_sim._common import battery

    measured = {"height_agl": "height"}.get(name, name)
    if name.startswith("motor_"):
        return motor_commands(flight, index)[:, int(name[6:]) - 1]
    if name == "battery_v":
        return battery(flight, index)[0]
    if name.startswith("delta_"):
        return flight.truth[name][index]
    return flight.measured[measured][index]


@pytest.mark.parametrize("fixture", ["px4_files", "ap_files"])
def test_log_reads_back_as_the_generator_wrote_it(fixture: str, request: pytest.FixtureRequest) -> None:
    files = request.getfixturevalue(fixture)
    case = _short_case(files.truth.fmt)
    flight = simulate(case)
    log = read_log(files.log)
    assert set(CANONICAL) <= set(log.signals)
    assert not log.warnings
    assert log.utc_offset_s == pytest.approx(files.truth.utc_offset_s, abs=1e-6)
    assert log.time_range_s[0] == pytest.approx(case.plan.log_start_us / 1e6, abs=0.01)
    step = flight.step_us / 1e6
    # resolution of what the log keeps: float32, ATT's 0.01°, whole PWM µs
    tolerance = {"phi": 1e-4, "theta": 1e-4, "psi": 1e-4} if files.truth.fmt == "dataflash" else {}
    for name in CANONICAL:
        signal = log[name]
        index = np.rint((signal.time_s - flight.time_s[0]) / step).astype(int)
        np.testing.assert_allclose(flight.time_s[index], signal.time_s, atol=1e-9, err_msg=name)
        expected = _generator_values(flight, name, index)
        if name.startswith("motor_") and files.truth.fmt == "dataflash":
            expected = np.round(1100 + 800 * expected)
            expected[~flight.armed[index]] = 1000
        difference = signal.values - expected
        if name == "psi":
            difference = np.angle(np.exp(1j * difference))
        atol = tolerance.get(name, 2e-6 * max(1.0, float(np.abs(expected).max())))
        assert np.abs(difference).max() <= atol, name
        times, values = files.expected[name]
        np.testing.assert_array_equal(signal.time_s, times, err_msg=name)


@pytest.mark.parametrize("fixture", ["px4_files", "ap_files"])
def test_references_read_back(fixture: str, request: pytest.FixtureRequest) -> None:
    # the setpoints and sticks the autopilots log: what a detector may use for piloted or injected maneuvers
    files = request.getfixturevalue(fixture)
    log = read_log(files.log)
    for name in flightlogs.signals.REFERENCE_SIGNALS:  # every reference the readers know, written by both
        times, values = files.expected[name]
        np.testing.assert_array_equal(log[name].time_s, times, err_msg=name)
        difference = log[name].values - values
        if name == "psi_ref":
            difference = np.angle(np.exp(1j * difference))
        assert np.abs(difference).max() < 1e-5, name


def test_piloted_sweep_shows_in_the_sticks_not_in_the_mixer_excitation() -> None:
    flight = simulate(
        _short_case(
            "ulog",
            maneuvers=(
                Maneuver(
                    axis="lon", design=PilotedSweep(duration_s=25.0), start_s=10.0, amplitude=0.1, injection="attitude"
                ),
                Maneuver(
                    axis="yaw", design=PilotedSweep(duration_s=10.0), start_s=36.0, amplitude=0.3, injection="rate"
                ),
            ),
        )
    )
    pitch, yaw = flight.maneuvers
    inside = (flight.time_s >= pitch.start_s) & (flight.time_s < pitch.end_s)
    nominal = 0.1 / math.radians(35.0)  # 0.1 rad of a 35° full stick; the pilot's amplitude wanders by ±25 % (1 sigma)
    assert 0.5 * nominal < np.abs(flight.truth["stick_lon"][inside]).max() < 2.0 * nominal
    back_is_nose_up = np.corrcoef(flight.truth["stick_lon"][inside], flight.truth["theta_sp"][inside])[0, 1]
    assert back_is_nose_up > 0.8  # the position loop's own attitude demands account for the rest
    inside = (flight.time_s >= yaw.start_s) & (flight.time_s < yaw.end_s)
    assert np.corrcoef(flight.truth["stick_yaw"][inside], flight.truth["r_sp"][inside])[0, 1] > 0.8
    assert not any(np.any(flight.truth[f"exc_mixer_{axis}"]) for axis in ("lat", "lon", "yaw", "thr"))
    assert np.std(flight.truth["delta_lon"][(flight.time_s >= pitch.start_s) & (flight.time_s < pitch.end_s)]) > 0.005


def test_rates_of_the_log_are_realistic_and_mutually_different(px4_files, ap_files) -> None:
    px4, ap = read_log(px4_files.log), read_log(ap_files.log)
    assert px4["q"].rate_hz == pytest.approx(250, rel=1e-3) and px4["delta_lon"].rate_hz == pytest.approx(250, rel=1e-3)
    assert px4["theta"].rate_hz == pytest.approx(125, rel=1e-3) and px4["vn"].rate_hz == pytest.approx(50, rel=1e-3)
    assert px4["ax"].rate_hz == pytest.approx(200, rel=1e-3) and px4["motor_1"].rate_hz == pytest.approx(100, rel=1e-3)
    assert ap["q"].rate_hz == pytest.approx(400, rel=1e-3) and ap["theta"].rate_hz == pytest.approx(100, rel=1e-3)
    assert ap["vn"].rate_hz == pytest.approx(50, rel=1e-3) and ap["height_agl"].rate_hz == pytest.approx(25, rel=1e-3)


def test_accelerometer_from_sensor_combined_only(tmp_path: Path) -> None:
    case = _short_case("ulog", px4_accel_topic="sensor_combined", plan=FlightPlan(duration_s=30.0), maneuvers=())
    files = write_case(case, tmp_path)
    log = read_log(files.log)
    assert log["az"].source.startswith("sensor_combined") and log["az"].rate_hz == pytest.approx(200, rel=1e-3)
    assert "vehicle_acceleration" not in {d.name for d in ULog(str(files.log)).data_list}


def test_no_excitation_is_logged(px4_files, ap_files) -> None:
    topics = {d.name for d in ULog(str(px4_files.log)).data_list}
    assert not {t for t in topics if any(w in t for w in ("sysid", "excitation", "chirp", "identification"))}
    assert "manual_control_setpoint" in topics and "vehicle_rates_setpoint" in topics
    messages = read_messages(ap_files.log)
    assert not {"SIDD", "SIDS"} & set(messages.tables)
    for files in (px4_files, ap_files):
        log = read_log(files.log)
        assert "excitation" not in log.signals and log.system_id_runs == ()


def test_maneuver_bounds_are_on_the_log_clock() -> None:
    case = _short_case(
        "dataflash",
        maneuvers=(
            Maneuver(axis="lon", design=Chirp(duration_s=20.0), start_s=10.0, amplitude=0.06),
            Maneuver(
                axis="lat", design=PilotedSweep(duration_s=15.0), start_s=32.0, amplitude=0.1, injection="attitude"
            ),
        ),
    )
    flight = simulate(case)
    takeoff = flight.time_s[np.argmax(flight.airborne)]
    sweep, piloted = flight.maneuvers
    assert (sweep.start_s, sweep.end_s) == pytest.approx((takeoff + 10.0, takeoff + 30.0))
    active = flight.time_s[flight.truth["exc_mixer_lon"] != 0.0]
    assert active[0] - sweep.start_s < 0.003 and sweep.end_s - active[-1] < 0.003
    stick = flight.time_s[flight.truth["stick_lat"] != 0.0]
    assert (stick[0], stick[-1]) == pytest.approx((piloted.start_s, piloted.end_s), abs=0.003)
    assert piloted.injection == "attitude" and not np.any(flight.truth["exc_mixer_lat"])


def test_flight_is_deterministic_per_seed() -> None:
    first, again = simulate(_short_case("dataflash")), simulate(_short_case("dataflash"))
    other = simulate(_short_case("dataflash", seed=12))
    for name in ("q", "delta_lon", "vn"):
        np.testing.assert_array_equal(
            first.measured.get(name, first.truth.get(name)), again.measured.get(name, again.truth.get(name))
        )
    assert not np.array_equal(first.measured["q"], other.measured["q"])


# ----------------------------------------------------------------------------- wind


def test_anemometer_csv_reads_back_upstream_of_the_vehicle(wind_files) -> None:
    wind = read_anemometer_csv(wind_files.anemometer_csv)
    truth = wind_files.truth.wind
    assert wind.rate_hz == pytest.approx(20.0, rel=1e-6) and not wind.warnings
    log = read_log(wind_files.log)
    start, end = log.time_range_s
    assert (
        wind.utc_s[0] < start + log.utc_offset_s - truth["transport_delay_s"] < end + log.utc_offset_s < wind.utc_s[-1]
    )
    assert wind.speed_m_s.mean() == pytest.approx(5.4, abs=0.1)
    assert np.degrees(np.angle(np.exp(1j * wind.direction_from_rad).mean())) % 360 == pytest.approx(250.0, abs=2.0)
    assert truth["transport_delay_s"] == 4.6 / 5.4 and truth["distance_m"] == 4.6
    delay = transport_delay(np.column_stack([wind.wind_n, wind.wind_e]), distance_m=4.6)  # the workbench's rule
    assert delay.delay_s == pytest.approx(truth["transport_delay_s"], rel=0.02)
    assert delay.frozen_turbulence_holds


def test_vehicle_feels_the_anemometer_wind_one_transport_delay_later(wind_files) -> None:
    flight = simulate(_wind_case())
    wind = read_anemometer_csv(wind_files.anemometer_csv)
    hover = flight.airborne & (flight.truth["height"] > 4.0)
    time_s = flight.time_s[hover]
    at_vehicle = flight.truth["wind_n"][hover]

    def measured(delay_s: float) -> np.ndarray:
        return np.interp(time_s + flight.utc_offset_s - delay_s, wind.utc_s, wind.wind_n)

    delay = wind_files.truth.wind["transport_delay_s"]
    assert np.corrcoef(at_vehicle, measured(delay))[0, 1] > 0.9
    assert np.std(at_vehicle - measured(delay)) < 0.3
    for wrong in (0.0, 2 * delay):  # Taylor's frozen turbulence: the anemometer leads by distance / mean speed
        assert np.corrcoef(at_vehicle, measured(wrong))[0, 1] < np.corrcoef(at_vehicle, measured(delay))[0, 1] - 0.02


def test_wind_truth_is_hover_wind(wind_files) -> None:
    truth = wind_files.truth
    assert truth.structure == "hover-wind"
    assert truth.parameters["X_w_lon"] == -0.3560 and truth.parameters["Z_w_lon"] == 1.323
    assert truth.hover_parameters.keys() <= truth.parameters.keys()
    assert truth.trim["theta0"] == pytest.approx(math.radians(-4.36))


# ------------------------------------------------------- wind: the anemometer's clock, the autopilot's estimate


def _clock_case(fmt: str, offset_s: float, tau_s: float | None = 2.0, duration_s: float = 40.0) -> Case:
    """A short flight in wind, the anemometer's logger `offset_s` ahead of UTC, the estimate lagging `tau_s`."""
    wind = WindModel(
        mean_speed_m_s=5.4, from_deg=250.0, sigma_m_s=0.75, clock_offset_s=offset_s, estimate_time_constant_s=tau_s
    )
    return Case(
        name=f"short-clock-{fmt}",
        fmt=fmt,  # type: ignore[arg-type]
        plan=FlightPlan(duration_s=duration_s, log_start_us=47_500_000),
        maneuvers=(Maneuver(axis="lon", design=Doublet(), start_s=12.0, amplitude=0.06),),
        condition="strong",
        wind=wind,
        seed=14,
    )


@pytest.mark.parametrize("offset_s", [1.7, -2.3])
def test_anemometer_stamps_are_true_utc_plus_the_logger_clock_offset(offset_s: float, tmp_path: Path) -> None:
    """Placed at stamp - offset the CSV's wind is the true air at the anemometer within the sensor's bound;
    taken at its stamp it is the air of another moment, clearly off."""
    case = _clock_case("dataflash", offset_s, duration_s=30.0)
    files = write_case(case, tmp_path)
    flight = simulate(case)
    model, field_ = case.wind, flight.wind
    assert model is not None and field_ is not None and files.anemometer_csv is not None
    measured = read_anemometer_csv(files.anemometer_csv)
    assert files.truth.wind is not None and files.truth.wind["clock_offset_s"] == offset_s
    logged = np.column_stack([measured.wind_n, measured.wind_e])

    def true_at(utc_s: np.ndarray) -> np.ndarray:
        log_s = utc_s - flight.utc_offset_s
        return np.column_stack([np.interp(log_s, field_.time_s, field_.wind_ne[:, k]) for k in range(2)])

    right = np.hypot(*(logged - true_at(measured.utc_s - offset_s)).T)
    wrong = np.hypot(*(logged - true_at(measured.utc_s)).T)
    # uniform speed error ±0.3 m/s, direction ±2° of up to (speed + 0.3) m/s; 0.001 m/s, 0.01° of rounding
    bound = model.speed_noise_m_s + (measured.speed_m_s + 0.3) * math.radians(model.direction_noise_deg) + 0.002
    assert np.all(right <= bound)
    assert np.mean(wrong > bound) > 0.1 and np.sqrt(np.mean(wrong**2)) > 1.5 * np.sqrt(np.mean(right**2))
    # the record covers, in true time, the log plus the transport delay and 5 s (less one or two samples) each side
    log = read_log(files.log)
    start, end = np.array(log.time_range_s) + log.utc_offset_s
    assert measured.utc_s[0] - offset_s <= start - model.transport_delay_s - 5.0
    assert measured.utc_s[-1] - offset_s >= end + 5.0 - 2.0 / model.anemometer_rate_hz


def _first_order_lag(time_s: np.ndarray, values: np.ndarray, tau_s: float) -> np.ndarray:
    """1 / (tau s + 1) by the bilinear transform, at rest at the first value."""
    b, a = bilinear([1.0], [tau_s, 1.0], fs=1.0 / (time_s[1] - time_s[0]))
    return lfilter(b, a, values, zi=lfilter_zi(b, a) * values[0])[0]


@pytest.mark.parametrize("fmt", ["ulog", "dataflash"])
def test_autopilot_wind_estimate_is_the_true_wind_lagged(fmt: str, tmp_path: Path) -> None:
    """est_wind_n/e read back by the workbench: the true wind at the vehicle through 1 / (tau s + 1), plus noise
    of 0.05 m/s, and late by a good part of tau. The cross-correlation of a first-order lag with Dryden
    turbulence of time scale L / V peaks at ln(2 / (1 + r)) / (1 - r) tau, r = tau V / L (0.61 tau here);
    over 40 s of flight the peak falls at 0.4-0.75 tau (seeds 40-69: 29 of 30 at 0.5 tau or more)."""
    tau = 2.0
    files = write_case(_clock_case(fmt, 0.0, tau), tmp_path)
    flight = simulate(_clock_case(fmt, 0.0, tau))
    log = read_log(files.log)
    assert not log.warnings
    assert files.truth.wind is not None and files.truth.wind["estimate_time_constant_s"] == tau
    north, east = log["est_wind_n"], log["est_wind_e"]
    assert north.rate_hz == pytest.approx(10.0 if fmt == "ulog" else 25.0, rel=1e-3)
    np.testing.assert_array_equal(north.time_s, files.expected["est_wind_n"][0])
    np.testing.assert_allclose(east.values, files.expected["est_wind_e"][1], atol=1e-6)
    index = np.rint((north.time_s - flight.time_s[0]) * 1e6 / flight.step_us).astype(int)
    true = np.column_stack([flight.truth["wind_n"], flight.truth["wind_e"]])
    lagged = np.column_stack([_first_order_lag(flight.time_s, true[:, k], tau) for k in range(2)])[index]
    estimate = np.column_stack([north.values, east.values])
    assert np.sqrt(np.mean((estimate - lagged) ** 2)) < 0.15
    assert np.sqrt(np.mean((estimate - true[index]) ** 2)) > 0.15  # the lag shows (0.5 m/s RMS here)
    airborne = flight.airborne[index]
    x, y, rate = true[index][airborne], estimate[airborne], north.rate_hz

    def correlation(k: int) -> float:  # Pearson, both components, estimate k samples after the truth
        a, b = x[: x.shape[0] - k], y[k:]
        a, b = a - a.mean(axis=0), b - b.mean(axis=0)
        return float(np.sum(a * b) / np.sqrt(np.sum(a * a) * np.sum(b * b)))

    lags = np.arange(int(4 * tau * rate) + 1)
    peak = lags[np.argmax([correlation(int(k)) for k in lags])] / rate
    assert 0.5 * tau <= peak < 1.5 * tau


@pytest.mark.parametrize("fmt", ["ulog", "dataflash"])
def test_wind_model_without_a_clock_offset_or_estimate_writes_the_same_bytes(fmt: str, tmp_path: Path) -> None:
    """clock_offset_s=0.0 and estimate_time_constant_s=None are the defaults: the log and CSV do not change."""
    plain = _wind_case()
    assert plain.wind is not None
    explicit = replace(plain, wind=replace(plain.wind, clock_offset_s=0.0, estimate_time_constant_s=None))
    (tmp_path / "plain").mkdir()
    (tmp_path / "explicit").mkdir()
    first = write_case(plain, tmp_path / "plain", fmt)  # type: ignore[arg-type]
    second = write_case(explicit, tmp_path / "explicit", fmt)  # type: ignore[arg-type]
    assert first.anemometer_csv is not None and second.anemometer_csv is not None
    assert first.log.read_bytes() == second.log.read_bytes()
    assert first.anemometer_csv.read_bytes() == second.anemometer_csv.read_bytes()
    assert "est_wind_n" not in read_log(first.log).signals
    assert first.truth.wind is not None
    assert (first.truth.wind["clock_offset_s"], first.truth.wind["estimate_time_constant_s"]) == (0.0, None)


def test_wind_model_rejects_a_wild_clock_or_a_time_constant_not_positive() -> None:
    for bad in ({"clock_offset_s": 30.5}, {"clock_offset_s": -31.0}, {"clock_offset_s": math.nan}):
        with pytest.raises(ValueError, match="clock_offset_s"):
            WindModel(**bad)
    for tau in (0.0, -1.0, math.inf):
        with pytest.raises(ValueError, match="estimate_time_constant_s"):
            WindModel(estimate_time_constant_s=tau)
    assert WindModel(clock_offset_s=-30.0, estimate_time_constant_s=0.5).clock_offset_s == -30.0


def test_clock_cases_of_the_catalogue() -> None:
    """Windy with the CSV, two lon sweeps, a thr sweep, four doublets; seeds of their own; the calm one calm."""
    existing = {c.seed for c in TUNING_CASES + HELDOUT_CASES if "wind-c" not in c.name}
    tuning = {c.name: c for c in TUNING_CASES if c.name.startswith("tune-wind-clock-")}
    heldout = {c.name: c for c in HELDOUT_CASES if c.name.startswith(("heldout-wind-clock-", "heldout-wind-calm"))}
    offsets = [sorted(c.wind.clock_offset_s for c in cases.values() if c.wind) for cases in (tuning, heldout)]
    assert offsets == [[-0.9, 1.7], [-2.3, 0.0, 0.4, 1.2, 2.6]]
    cases = [*tuning.values(), *heldout.values()]
    assert {c.fmt for c in tuning.values()} == {c.fmt for c in heldout.values()} == {"ulog", "dataflash"}
    seeds = [c.seed for c in cases]
    assert len(set(seeds)) == len(seeds) and all(300 <= s < 400 for s in seeds) and not set(seeds) & existing
    for case in cases:
        model = case.wind
        assert model is not None and model.estimate_time_constant_s is not None
        assert 2.0 <= model.estimate_time_constant_s <= 4.0
        sweeps = [m.axis for m in case.maneuvers if m.design.kind == "sweep"]
        doublets = [m.axis for m in case.maneuvers if m.design.kind == "doublet"]
        assert sweeps.count("lon") >= 2 and "thr" in sweeps, case.name
        assert doublets.count("lon") >= 2 and doublets.count("thr") >= 2, case.name
        if case.name == "heldout-wind-calm":
            assert (model.mean_speed_m_s, model.sigma_m_s, model.clock_offset_s) == (0.8, 0.05, 1.2)
            assert case.condition == "calm" and not hover_plant(case.condition).has_wind_terms
        else:
            assert 4.0 <= model.mean_speed_m_s <= 6.0 and 0.6 <= model.sigma_m_s <= 0.9, case.name
            assert case.condition == "strong" and hover_plant(case.condition).has_wind_terms


# ----------------------------------------------------------------------------- catalogue


def test_catalogue_splits_tuning_from_heldout_and_covers_the_variants() -> None:
    assert not {c.name for c in TUNING_CASES} & {c.name for c in HELDOUT_CASES}
    for cases in (TUNING_CASES, HELDOUT_CASES):
        assert {c.fmt for c in cases} == {"ulog", "dataflash"}
        assert any(not c.maneuvers for c in cases)  # a hover with no maneuver
        assert any(c.maneuvers and len(c.excited_axes) < 4 and c.wind is None for c in cases)  # an axis never excited
        assert any(c.wind is not None for c in cases)
        kinds = {(m.design.kind, m.injection) for c in cases for m in c.maneuvers}
        assert {("sweep", "mixer"), ("doublet", "mixer"), ("3211", "mixer"), ("multisine", "mixer")} <= kinds
        assert any(injection != "mixer" for _, injection in kinds)  # a piloted sweep
        amplitudes = [m.amplitude for c in cases for m in c.maneuvers if m.injection == "mixer"]
        assert all(0.05 <= abs(a) <= 0.08 for a in amplitudes)
    designs = {
        type(m.design).__name__ + getattr(m.design, "law", "") + getattr(m.design, "direction", "")
        for c in TUNING_CASES + HELDOUT_CASES
        for m in c.maneuvers
    }
    assert {"Chirplogup", "Chirplogdown", "Chirplinearup"} <= designs


def test_case_rejects_overlapping_maneuvers() -> None:
    with pytest.raises(ValueError, match="overlap"):
        _short_case(
            "ulog",
            maneuvers=(
                Maneuver(axis="lon", design=Chirp(duration_s=20.0), start_s=10.0, amplitude=0.06),
                Maneuver(axis="lon", design=Doublet(), start_s=25.0, amplitude=0.06),
            ),
        )


def test_corpus_fixture_writes_each_case_once(independent_corpus) -> None:
    files = independent_corpus.files("heldout-ap-hover")
    assert independent_corpus.files("heldout-ap-hover") is files
    assert files.truth.maneuvers == () and files.truth.unexcited_axes == ("lat", "lon", "yaw", "thr")
    assert files.segments_csv.read_text().splitlines() == ["start_s,end_s,axis,kind,f_min_hz,f_max_hz"]


# ------------------------------------------------------------------ physics outside the plant (discrepancy pairs)


@pytest.fixture(scope="module", name="physics_flights")
def physics_flights_fixture():  # type: ignore[no-untyped-def]
    """The pair plan flown plain, with a payload picked up at 120 s, with a strong ground cushion, in wind."""
    from independent_sim.effects import GroundCushion, PayloadPickUp
    from independent_sim.pairs import physics_pair_case

    wind = WindModel(mean_speed_m_s=5.4, sigma_m_s=0.0, from_deg=30.0)
    return {
        "plain": simulate(physics_pair_case("plain", 7)),
        "payload": simulate(physics_pair_case("payload", 7, effects=(PayloadPickUp(at_s=120.0, ratio=0.06),))),
        "cushion": simulate(physics_pair_case("cushion", 7, effects=(GroundCushion(gain=0.25),))),
        "wind": simulate(physics_pair_case("wind", 7, wind=wind)),
    }


def _mean_over(flight, name: str, start_s: float, end_s: float) -> float:  # type: ignore[no-untyped-def]
    """Mean of a truth signal from `start_s` to `end_s` after take-off."""
    t = flight.time_s - flight.time_s[flight.airborne][0]
    return float(np.mean(flight.truth[name][(t >= start_s) & (t < end_s)]))


def test_a_payload_raises_the_hover_thrust_by_its_weight(physics_flights) -> None:  # type: ignore[no-untyped-def]
    """Mass 1.06 m from 120 s: the loop needs g 0.06 / -Z_thr more thrust command (the linear plant's slope)."""
    flight, plain = physics_flights["payload"], physics_flights["plain"]
    before = _mean_over(flight, "delta_thr", 110.0, 119.0) - _mean_over(plain, "delta_thr", 110.0, 119.0)
    after = _mean_over(flight, "delta_thr", 125.0, 140.0) - _mean_over(plain, "delta_thr", 125.0, 140.0)
    assert abs(before) < 1e-4
    assert after == pytest.approx(G * 0.06 / -flight.plant.Z_thr, rel=0.02)


def test_the_low_hover_goes_down_to_its_height_and_the_cushion_lifts_there(physics_flights) -> None:  # type: ignore[no-untyped-def]
    """20 s at 0.35 m: the cushion 0.25 exp(-(h + 0.12) / 0.15) of thrust at the height flown is taken off the command."""
    from independent_sim.pairs import LOW_HOVER_M

    flight, plain = physics_flights["cushion"], physics_flights["plain"]
    height = _mean_over(flight, "height", 198.0, 210.0)
    assert height == pytest.approx(LOW_HOVER_M, abs=0.05)  # the height loop's own error (plain flight: +0.023 m)
    saved = _mean_over(plain, "delta_thr", 198.0, 210.0) - _mean_over(flight, "delta_thr", 198.0, 210.0)
    cushion = 0.25 * math.exp(-(height + 0.12) / 0.15)
    assert saved == pytest.approx(G * cushion / -flight.plant.Z_thr, rel=0.05)
    assert abs(_mean_over(plain, "delta_thr", 60.0, 100.0) - _mean_over(flight, "delta_thr", 60.0, 100.0)) < 1e-4


def test_the_calm_airframe_holds_its_place_in_a_steady_wind(physics_flights) -> None:  # type: ignore[no-untyped-def]
    """Nose into 5.4 m/s: no ground speed, the accelerometer reads the drag, the air flows level past it."""
    flight = physics_flights["wind"]
    plant = flight.plant
    for name in ("vn", "ve", "vd"):
        assert abs(_mean_over(flight, name, 60.0, 100.0)) < 0.05, name
    assert _mean_over(flight, "ax", 60.0, 100.0) == pytest.approx(G * math.sin(plant.trim.theta0), rel=0.02)
    assert _mean_over(flight, "u", 60.0, 100.0) == pytest.approx(5.4 * math.cos(plant.trim.theta0), rel=0.02)
    assert abs(_mean_over(flight, "w", 60.0, 100.0) - 5.4 * math.sin(plant.trim.theta0)) < 0.05
