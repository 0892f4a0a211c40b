"""Frequency responses against analytic systems: a lag with delay, a pure delay, an unstable pair, Table 3.3.

Tolerance: the issue's 0.5 dB and 3° wherever gamma^2 > 0.8, or 4.5 times the
estimate's own random error where that is larger. The random error is
theory (Bendat & Piersol): ``sqrt(1 - g^2) / (|g| sqrt(2 n_d))`` is 0.5 /
sqrt(2 n_d) at g^2 = 0.8, about 1.8° for the n_d ~ 130 averages of the
shortest window, so at the 0.8 edge a 3° bound alone would be a 1.7-sigma
test; 4.5 sigma keeps the chance of a false alarm over the ~300 points of a
test under 0.3 % (Bonferroni), and test_random_error_estimate_matches_the_scatter
checks that the reported error is that standard deviation. The systems are simulated exactly (input evaluated analytically at 10x
the log rate, first-order-hold integration, then sampled at 100 Hz), so what
remains is the estimator's error. No band is excused.

Closed loop, the mixer input is notched at the unstable pair's frequency
and the pair's impulse response never decays, so every window's estimate is
biased there (it smooths the spectra over its main lobe, and the output in a
window answers input from before it); so is the sweep's 0.1 Hz fade-in tone
at the lowest frequencies. Measured with windows only: 0.64 dB / 6.4° on
theta, 11° on q, 0.58 dB on u, below 2.6 rad/s, in every seed: CIFER's
windows hide it behind the random error their lowered coherence reports. The
records' whole-length transforms (:mod:`sysid.freqresp._whole`) hold
``Y = H X`` exactly and remove it: the bias tests below check 0.5 dB / 3°
with no random-error allowance where those transforms measure to a fraction
of a degree, and that windows alone fail them.

The feedback of a disturbance (turbulence) biases the mixer-input estimate
towards ``-1 / K`` even where gamma^2 > 0.8; the injected excitation as
reference (``H = G_ry / G_rx``) does not.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal as sps

from flightlogs.record import Record
from simulator.autopilot.excitation import Maneuver, excitation_signal, sweep
from simulator.flights.linear import simulate_hover
from simulator.vehicle.identified import CALM_HOVER
from sysid.freqresp import ResponseOptions, frequency_response_sets, frequency_responses
from sysid.freqresp._spectra import effective_averages
from sysid.model.statespace import DelayedStateSpace

RATE_HZ = 100.0
G = 9.81
MAX_DB, MAX_DEG = 0.5, 3.0
K_SIGMA = 4.5  # random-error multiple, family-wise over a test's points (see the module docstring)
PAD_S = 2.0  # trim before and after each sweep, as flown


def _sweep(amplitude: float = 1.0, f_stop_hz: float = 12.0) -> Maneuver:
    return Maneuver(
        axis="lon",
        kind="sweep",
        start_s=PAD_S,
        amplitude=amplitude,
        duration_s=34.0,
        f_start_hz=0.1,
        f_stop_hz=f_stop_hz,
    )


def _record(columns: dict[str, np.ndarray], time_s: np.ndarray) -> Record:
    return Record.from_table(
        pd.DataFrame(columns, index=time_s),
        units={name: "-" for name in columns},
        trim={},
        source=Path("simulated"),
    )


def _open_loop_records(
    model: DelayedStateSpace, *, noise: float, seed: int, n_records: int = 5, oversample: int = 10
) -> list[Record]:
    """Sweeps through `model` (one input, one output), output noise `noise` x its RMS."""
    rng = np.random.default_rng(seed)
    maneuver = _sweep()
    fine = np.arange(int((34.0 + 2 * PAD_S) * RATE_HZ * oversample)) / (RATE_HZ * oversample)
    delayed = sweep(fine - model.input_delays_s[0], maneuver)[0]
    _, y, _ = sps.lsim(sps.StateSpace(model.a, model.b, model.c, model.d), delayed, fine)
    x, y = sweep(fine, maneuver)[0][::oversample], np.ravel(y)[::oversample]
    return [
        _record({"x": x, "y": y + noise * np.std(y) * rng.normal(size=y.size)}, fine[::oversample])
        for _ in range(n_records)
    ]


def _errors(estimate: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    ratio = estimate / truth
    return np.abs(20 * np.log10(np.abs(ratio))), np.abs(np.degrees(np.angle(ratio)))


def _assert_within_tolerance(
    response,
    truth: np.ndarray,
    *,
    min_decades: float,  # type: ignore[no-untyped-def]
    k_sigma: float = K_SIGMA,
    below_rad_s: float = np.inf,
) -> None:
    """0.5 dB / 3° (or `k_sigma` eps_r) wherever gamma^2 > 0.8 (below `below_rad_s`)."""
    good = response.coherence > 0.8
    assert np.log10(response.omega[good].max() / response.omega[good].min()) >= min_decades
    good &= response.omega <= below_rad_s
    db, deg = _errors(response.response[good], truth[good])
    eps = response.random_error[good]
    omega = response.omega[good]
    allowed_db = np.maximum(MAX_DB, 20 * np.log10(np.e) * k_sigma * eps)
    allowed_deg = np.maximum(MAX_DEG, np.degrees(k_sigma * eps))
    worst = np.argmax(db / allowed_db)
    assert db[worst] < allowed_db[worst], f"{response.pair}: {db[worst]:.2f} dB at {omega[worst]:.2f} rad/s"
    worst = np.argmax(deg / allowed_deg)
    assert deg[worst] < allowed_deg[worst], f"{response.pair}: {deg[worst]:.2f} deg at {omega[worst]:.2f} rad/s"


def _fails_tolerance(response, truth: np.ndarray, **kwargs: float) -> bool:  # type: ignore[no-untyped-def]
    try:
        _assert_within_tolerance(response, truth, **kwargs)
    except AssertionError:
        return True
    return False


def test_first_order_lag_with_delay() -> None:
    lag_s, delay_s = 0.2, 0.05
    model = DelayedStateSpace(
        a=np.array([[-1 / lag_s]]),
        b=np.array([[1 / lag_s]]),
        c=np.eye(1),
        d=np.zeros((1, 1)),
        states=("x1",),
        inputs=("x",),
        outputs=("y",),
        input_delays_s=np.array([delay_s]),
    )
    for seed, noise in ((1, 0.03), (2, 0.1)):
        (response,) = frequency_responses(_open_loop_records(model, noise=noise, seed=seed), ["x"], ["y"])
        truth = model.frequency_response(response.omega)[:, 0, 0]
        _assert_within_tolerance(response, truth, min_decades=1.5)
        assert response.omega[0] < 1.2 and response.omega[-1] == pytest.approx(70.0)


def test_random_error_estimate_matches_the_scatter() -> None:
    """With heavy noise the errors are random: ln(H_est/H), real (log magnitude) and imaginary (phase, rad)
    parts, scatters with the standard deviation eps_r the estimate reports (Bendat & Piersol)."""
    model = DelayedStateSpace(
        a=np.array([[-5.0]]),
        b=np.array([[5.0]]),
        c=np.eye(1),
        d=np.zeros((1, 1)),
        states=("x1",),
        inputs=("x",),
        outputs=("y",),
        input_delays_s=np.array([0.05]),
    )
    z = []
    for seed in range(3):
        (response,) = frequency_responses(_open_loop_records(model, noise=1.0, seed=seed), ["x"], ["y"])
        log_ratio = np.log(response.response / model.frequency_response(response.omega)[:, 0, 0])
        used = response.coherence > 0.5
        z.extend(np.concatenate([log_ratio.real[used], log_ratio.imag[used]]) / np.tile(response.random_error[used], 2))
    rms = float(np.sqrt(np.mean(np.square(z))))
    assert 0.8 < rms < 1.25, rms


def _delayed_sweep_records(delay_s: float, seed: int, n_records: int = 3) -> list[Record]:
    rng = np.random.default_rng(seed)
    maneuver = _sweep()
    time_s = np.arange(int((34.0 + 2 * PAD_S) * RATE_HZ)) / RATE_HZ
    x = sweep(time_s, maneuver)[0]
    y = sweep(time_s - delay_s, maneuver)[0]  # exact, fractional-sample delay
    return [_record({"x": x, "y": y + 0.05 * rng.normal(size=y.size)}, time_s) for _ in range(n_records)]


@settings(max_examples=12, deadline=None)
@given(delay_s=st.floats(0.0, 0.08), seed=st.integers(0, 2**16))
def test_pure_delay_from_the_phase_slope(delay_s: float, seed: int) -> None:
    """Phase = -omega tau: the weighted least-squares slope where gamma^2 > 0.8 gives tau within 1 ms."""
    (response,) = frequency_responses(_delayed_sweep_records(delay_s, seed), ["x"], ["y"])
    good = response.coherence > 0.8
    omega, phase = response.omega[good], np.unwrap(np.angle(response.response[good]))
    weight = 1.0 / response.random_error[good] ** 2
    estimate = -float(np.sum(weight * omega * phase) / np.sum(weight * omega**2))
    assert abs(estimate - delay_s) < 1e-3
    assert np.all(np.abs(np.abs(response.response[good]) - 1.0) < 0.06)  # |e^{-j w tau}| = 1


@settings(max_examples=10, deadline=None)
@given(scale=st.floats(1e-3, 1e3), seed=st.integers(0, 2**16))
def test_scaling_the_input_scales_the_response_inversely(scale: float, seed: int) -> None:
    rng = np.random.default_rng(seed)
    time_s = np.arange(2000) / RATE_HZ
    x = rng.normal(size=time_s.size)
    y = sps.lfilter([0.2], [1.0, -0.8], x) + 0.3 * rng.normal(size=time_s.size)
    options = ResponseOptions(window_lengths_s=(2.0, 5.0), omega_min=3.0, n_freq=40)
    (base,) = frequency_responses([_record({"x": x, "y": y}, time_s)], ["x"], ["y"], options)
    (scaled,) = frequency_responses([_record({"x": scale * x, "y": y}, time_s)], ["x"], ["y"], options)
    np.testing.assert_allclose(scaled.response, base.response / scale, rtol=1e-9)
    np.testing.assert_allclose(scaled.coherence, base.coherence, atol=1e-9)
    np.testing.assert_allclose(scaled.random_error, base.random_error, rtol=1e-6)


def _closed_loop_unstable(
    noise: float, seed: int, n_records: int = 5, oversample: int = 10, disturbance: float = 0.0
) -> list[Record]:
    """Plant b / (s^2 - 1.756 s + 3.641) (poles 0.878 +- 1.694j, the calm pitch pair) with a 20 ms input
    delay, stabilised by u = r - kp y - kd y'; the sweep r enters at the mixer input u, which is logged, and
    r itself as ``excitation`` (as ArduPilot logs SIDD).

    `disturbance`: RMS of a torque d at the plant input, white noise low-passed at 3 rad/s (turbulence), fed
    back by the loop: u = S (r + d) - d and y = P S (r + d) with S = 1 / (1 + K P).

    Exact ZOH discretisation at 1 kHz; closed loop solved as a rational filter (lfilter), so there is no
    divergence and no integration error: the plant sees u held over each 1 ms step (half a step of delay).
    """
    b, kp, kd = 2.0, 6.18, 3.28
    a = np.array([[0.0, 1.0], [-3.641, 1.756]])
    dt = 1.0 / (RATE_HZ * oversample)
    ad, bd, *_ = sps.cont2discrete((a, np.array([[0.0], [b]]), np.eye(2), np.zeros((2, 1))), dt)
    num_y, den = sps.ss2tf(ad, bd, np.array([[1.0, 0.0]]), np.zeros((1, 1)))
    num_rate, _ = sps.ss2tf(ad, bd, np.array([[0.0, 1.0]]), np.zeros((1, 1)))
    lag = int(round(0.02 / dt))
    delayed_y = np.concatenate([np.zeros(lag), num_y[0]])
    feedback = np.concatenate([np.zeros(lag), kp * num_y[0] + kd * num_rate[0]])
    closed = np.concatenate([den, np.zeros(lag)]) + feedback  # den + N z^-d, polynomials in z^-1
    rng = np.random.default_rng(seed)
    fine = np.arange(int((34.0 + 2 * PAD_S) * RATE_HZ * oversample)) * dt
    r = sweep(fine, _sweep(amplitude=2.0))[0]
    low_pass = sps.butter(1, 3.0 * dt / np.pi, output="sos")
    records = []
    for _ in range(n_records):
        d = np.zeros(fine.size)
        if disturbance > 0:
            d = sps.sosfilt(low_pass, rng.normal(size=fine.size))
            d *= disturbance / np.std(d)
        u = sps.lfilter(np.concatenate([den, np.zeros(lag)]), closed, r + d)[::oversample] - d[::oversample]
        y = sps.lfilter(delayed_y, closed, r + d)[::oversample]
        records.append(
            _record(
                {"u": u, "y": y + noise * np.std(y) * rng.normal(size=y.size), "excitation": r[::oversample]},
                fine[::oversample],
            )
        )
    return records


def _unstable_plant_truth(omega: np.ndarray) -> np.ndarray:
    plant = DelayedStateSpace(
        a=np.array([[0.0, 1.0], [-3.641, 1.756]]),
        b=np.array([[0.0], [2.0]]),
        c=np.array([[1.0, 0.0]]),
        d=np.zeros((1, 1)),
        states=("y", "y_dot"),
        inputs=("u",),
        outputs=("y",),
        input_delays_s=np.array([0.02 + 0.0005]),
    )  # + half a 1 ms hold
    return plant.frequency_response(omega)[:, 0, 0]


@pytest.mark.parametrize("reference", [None, "excitation"])
def test_unstable_pair_identified_in_closed_loop_from_the_mixer_input(reference: str | None) -> None:
    records = _closed_loop_unstable(noise=0.05, seed=3)
    assert np.max(np.abs(records[0]["y"])) < 10.0  # flown stabilised
    (response,) = frequency_responses(records, ["u"], ["y"], ResponseOptions(reference=reference))
    assert response.whole_record and response.reference == reference
    _assert_within_tolerance(response, _unstable_plant_truth(response.omega), min_decades=1.0)
    good = response.coherence > 0.8
    assert response.omega[good].min() < 0.7  # the pair (1.91 rad/s) and the fade-in tone (0.63 rad/s) are measured


def test_the_windows_bias_at_the_unstable_pair_is_gone() -> None:
    """Below 2.6 rad/s (the pair plus two bins of the longest window): 0.5 dB / 3° with no random-error
    allowance. The windows alone are 0.5-0.7 dB off there (and claim a random error that hides it)."""
    records = _closed_loop_unstable(noise=0.05, seed=3)
    (response,) = frequency_responses(records, ["u"], ["y"])
    truth = _unstable_plant_truth(response.omega)
    _assert_within_tolerance(response, truth, min_decades=1.0, k_sigma=0.0, below_rad_s=2.6)
    (windows,) = frequency_responses(records, ["u"], ["y"], ResponseOptions(whole_record=False))
    assert not windows.whole_record
    assert _fails_tolerance(
        windows, _unstable_plant_truth(windows.omega), min_decades=1.0, k_sigma=0.0, below_rad_s=2.6
    )


@pytest.mark.parametrize("seed", [0, 1])
def test_a_fed_back_disturbance_biases_the_mixer_input_estimate_but_not_the_reference_one(seed: int) -> None:
    """Turbulence at the plant input, fed back by the loop: where it dominates, x = -K y + ... and G_xy / G_xx
    tends to -1 / K with a coherence still above 0.8 (2-5 dB off, measured). G_ry / G_rx with the injected
    excitation r, uncorrelated with the disturbance, stays within the tolerance."""
    records = _closed_loop_unstable(noise=0.05, seed=seed, disturbance=0.5)
    (mixer,) = frequency_responses(records, ["u"], ["y"])
    assert _fails_tolerance(mixer, _unstable_plant_truth(mixer.omega), min_decades=0.5)
    (referenced,) = frequency_responses(records, ["u"], ["y"], ResponseOptions(reference="excitation"))
    _assert_within_tolerance(referenced, _unstable_plant_truth(referenced.omega), min_decades=0.5)


def test_reference_random_error_matches_the_scatter() -> None:
    """As test_random_error_estimate_matches_the_scatter, for the reference estimate in closed loop with a
    fed-back disturbance: its coherence, ``1 / (1 + G_nn [G_zx^-1 G_zz G_zx^-H] / |H|^2)`` (the one its error
    covariance gives), makes the error scatter with unit RMS. Measured on four closed-loop cases (disturbance
    0.1 and 0.3, sensor noise fed back at 0.3 and 1 x RMS): RMS 0.89-1.14. The min of gamma^2_rx and
    gamma^2_ry gave 1.39 with fed-back noise (it ignores the x channel's error); their product, close to this
    one while both errors are small, gave 4 and 32 points out of tolerance in two of the cases."""
    z = []
    for seed in range(3):
        records = _closed_loop_unstable(noise=0.05, seed=seed, disturbance=0.3)
        (response,) = frequency_responses(records, ["u"], ["y"], ResponseOptions(reference="excitation"))
        log_ratio = np.log(response.response / _unstable_plant_truth(response.omega))
        used = response.coherence > 0.5
        z.extend(np.concatenate([log_ratio.real[used], log_ratio.imag[used]]) / np.tile(response.random_error[used], 2))
    rms = float(np.sqrt(np.mean(np.square(z))))
    assert 0.8 < rms < 1.3, rms


def _bare_airframe_lon(p: dict[str, float], delay_s: float) -> DelayedStateSpace:
    """Eq. 3.11 with the actuator lag of eq. 3.2; outputs q, ax = u' + g theta (eq. 3.7), theta, u."""
    a = np.array(
        [
            [p["X_u"], 0.0, -G, p["X_lon"]],
            [p["M_u"], 0.0, 0.0, p["M_lon"]],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, -1.0 / p["T_a"]],
        ]
    )
    b = np.array([[0.0], [0.0], [0.0], [1.0 / p["T_a"]]])
    c = np.array([[0.0, 1.0, 0.0, 0.0], a[0] + np.array([0.0, 0.0, G, 0.0]), [0.0, 0.0, 1.0, 0.0], [1.0, 0, 0, 0]])
    return DelayedStateSpace(
        a=a,
        b=b,
        c=c,
        d=np.zeros((4, 1)),
        states=("u", "q", "theta", "d_lon"),
        inputs=("delta_lon",),
        outputs=("q", "ax", "theta", "u"),
        input_delays_s=np.array([delay_s]),
    )


@pytest.fixture(scope="module")
def octocopter_sweeps() -> list[Record]:
    """Three 34 s pitch sweeps (0.1-10 Hz, 8 %) of the Table 3.3 calm model flown by the LQR hover controller,
    with the injected sweep logged as ``excitation`` (normalised, as SIDD)."""
    starts = (4.0, 44.0, 84.0)
    maneuvers = tuple(Maneuver(axis="lon", kind="sweep", start_s=s, amplitude=8.0, duration_s=34.0) for s in starts)
    flight = simulate_hover(124.0, maneuvers, parameters=CALM_HOVER, seed=5)
    time_s = flight.time_s
    table = pd.DataFrame({name: flight.signals[name] for name in ("delta_lon", "q", "ax", "theta", "u")}, index=time_s)
    table["excitation"] = excitation_signal(time_s, maneuvers, "lon") / 100.0
    record = Record.from_table(table, units={c: "-" for c in table.columns}, trim={}, source=Path("octocopter"))
    return [record.between(s - 1.0, s + 36.0) for s in starts]


def _octocopter_truth(omega: np.ndarray) -> np.ndarray:
    """Shape (n_freq, 4): q, ax, theta, u per delta_lon, as the simulator's log carries them.

    The simulator delays the command by whole 2 ms integration steps (tau = 10 x 2 ms) and holds its
    500 Hz command over each step, ``exp(-j w h/2) sinc(w h/2)`` with h = 2 ms, which the airframe sees;
    its log carries the command averaged over the five steps centred on each log instant, a zero-phase
    boxcar ``(1 + 2 cos w h + 2 cos 2 w h) / 5`` (-0.13 dB at 70 rad/s), which divides the response.
    """
    step = 0.002
    tau = round(CALM_HOVER["tau_lon"] / step) * step
    hold = np.exp(-0.5j * omega * step) * np.sinc(omega * step / (2 * np.pi))
    boxcar = (1 + 2 * np.cos(omega * step) + 2 * np.cos(2 * omega * step)) / 5
    return _bare_airframe_lon(dict(CALM_HOVER), tau).frequency_response(omega)[:, :, 0] * (hold / boxcar)[:, None]


@pytest.mark.parametrize("reference", [None, "excitation"])
def test_octocopter_of_table_3_3(octocopter_sweeps: list[Record], reference: str | None) -> None:
    """q, ax, theta, u per delta_lon against eqs. 3.7, 3.11 with T_a and tau_lon (closed loop, sensor noise),
    from the mixer input or with the excitation as reference, over the whole grid (0.5-70 rad/s).

    At 70 rad/s, 1 Hz above the sweep's top, only the skirt of its 1 s fade-out is left: the outputs with
    sensor noise lose their coherence there (u, noise-free in the simulator, keeps it, and is right)."""
    responses = frequency_responses(
        octocopter_sweeps, ["delta_lon"], ["q", "ax", "theta", "u"], ResponseOptions(reference=reference)
    )
    truth = _octocopter_truth(responses[0].omega)
    spans = {"q": 1.5, "ax": 1.0, "theta": 1.5, "u": 0.5}
    for k, response in enumerate(responses):
        assert response.pair == f"{('q', 'ax', 'theta', 'u')[k]}/delta_lon" and response.whole_record
        _assert_within_tolerance(response, truth[:, k], min_decades=spans[response.output])
        assert response.omega[response.coherence > 0.8].min() < 0.6  # down to the fade-in tone
        if response.output != "u":
            assert response.coherence[-1] < 0.5 and response.omega[-1] == pytest.approx(70.0)


def test_the_windows_bias_below_the_pitch_pair_is_gone(octocopter_sweeps: list[Record]) -> None:
    """Below 2.6 rad/s the whole records measure q, theta and u to a fraction of a degree: 0.5 dB / 3° with no
    random-error allowance. The windows alone are 11° (q), 0.64 dB and 6.4° (theta), 0.58 dB (u) off there,
    in every seed tried. (ax, whose random error there is 4°, is held to the general rule above.)"""
    outputs = ["q", "theta", "u"]
    responses = frequency_responses(octocopter_sweeps, ["delta_lon"], outputs)
    windows = frequency_responses(octocopter_sweeps, ["delta_lon"], outputs, ResponseOptions(whole_record=False))
    for response, window in zip(responses, windows):
        k = ("q", "ax", "theta", "u").index(response.output)
        _assert_within_tolerance(
            response, _octocopter_truth(response.omega)[:, k], min_decades=0.5, k_sigma=0.0, below_rad_s=2.6
        )
        assert _fails_tolerance(
            window, _octocopter_truth(window.omega)[:, k], min_decades=0.5, k_sigma=0.0, below_rad_s=2.6
        )


def test_chirp_z_on_an_even_grid_equals_the_matrix_transform() -> None:
    rng = np.random.default_rng(0)
    time_s = np.arange(3000) / RATE_HZ
    x = rng.normal(size=time_s.size)
    records = [_record({"x": x, "y": np.roll(x, 2) + 0.1 * rng.normal(size=x.size)}, time_s)]
    linear = ResponseOptions(omega_min=2.0, omega_max=60.0, n_freq=57, window_lengths_s=(3.0, 6.0), spacing="linear")
    (czt,) = frequency_responses(records, ["x"], ["y"], linear)
    assert czt.omega[1] - czt.omega[0] == pytest.approx(58.0 / 56)
    from sysid.freqresp import _spectra

    data = [np.vstack([records[0]["x"], records[0]["y"]])]
    for n in (300, 600):
        by_czt = _spectra.window_spectra(
            data, 0.01, n, czt.omega, overlap=0.8, taper="hann", min_cycles=2, spacing="linear"
        )
        by_matrix = _spectra.window_spectra(data, 0.01, n, czt.omega, overlap=0.8, taper="hann", min_cycles=2)
        assert by_czt is not None and by_matrix is not None
        np.testing.assert_allclose(by_czt.spectra, by_matrix.spectra, rtol=1e-8, atol=1e-12)


def _two_input_records(seed: int, n_records: int) -> tuple[list[Record], Record]:
    """Records of a reference r, inputs x1 (r plus noise) and x2, outputs driven by both or one; and a quiet one."""
    rng = np.random.default_rng(seed)
    time_s = np.arange(2500) / RATE_HZ

    def flown(excited: float) -> Record:
        r = excited * rng.normal(size=time_s.size)
        x1, x2 = r + 0.3 * rng.normal(size=r.size), rng.normal(size=r.size)
        noise = 0.1 * rng.normal(size=(3, r.size))
        columns = {"r": r, "x1": x1, "x2": x2, "y1": np.roll(x1, 3) - 0.5 * x2 + noise[0]}
        return _record(columns | {"y2": 2.0 * x1 + noise[1], "y3": np.roll(x1, 7) + noise[2]}, time_s)

    return [flown(1.0) for _ in range(n_records)], flown(0.0)


@pytest.mark.parametrize(("reference", "n_records"), [(None, 3), ("r", 2)])  # one grid; two (a member for B alone)
def test_sets_of_responses_of_the_same_records_are_each_set_computed_alone(
    reference: str | None, n_records: int
) -> None:
    """Channels shared by several sets are transformed once: each set's responses are still its own, to rounding."""
    records, quiet = _two_input_records(3, n_records)
    options = ResponseOptions(omega_min=1.0, omega_max=40.0, n_freq=60, reference=reference)
    sets = [(["x1", "x2"], ["y1", "y3"], []), (["x1"], ["y2", "y3"], [] if reference else [quiet])]
    together = frequency_response_sets(records, sets, options)
    assert len(together) == len(sets)
    for (inputs, outputs, quiet_records), found in zip(sets, together):
        alone = frequency_responses(records, inputs, outputs, options, quiet=quiet_records)
        assert [(r.input, r.output, r.conditioned_on) for r in found] == [
            (r.input, r.output, r.conditioned_on) for r in alone
        ]
        for a, b in zip(found, alone):
            np.testing.assert_array_equal(a.omega, b.omega)
            assert a.windows_s == b.windows_s and a.whole_record == b.whole_record
            for name in ("response", "coherence", "random_error", "input_autospectrum", "cross_spectrum"):
                np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=1e-10, atol=1e-14)
    if reference:  # the member needs more records than inputs with a reference: the sets' grids differ
        assert together[0][0].omega[0] > together[1][0].omega[0]


@pytest.mark.parametrize("keep_bytes", [None, 0])  # within the budget; nothing kept
def test_channel_windows_give_each_request_the_spectra_of_its_channels_alone(keep_bytes, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """Transforms kept from one request serve the next, on another grid reaching the same frequencies too: each
    request's spectra are those of its channels transformed on their own; the coupling search sharing them
    finds what it finds alone."""
    from sysid.freqresp import ChannelWindows, _spectra, coupled_inputs
    from sysid.freqresp import estimate as estimate_module

    if keep_bytes is not None:
        monkeypatch.setattr(estimate_module, "_KEEP_BYTES", keep_bytes)
    records, _ = _two_input_records(4, 3)
    options = ResponseOptions(omega_min=1.0, omega_max=40.0, n_freq=60)
    windows = ChannelWindows(records, options)
    long_grid, short_grid = options.grid(), options.grid()[10:]  # the same frequencies from 1.5 rad/s up
    assert coupled_inputs(records, "x1", ["x2", "r"], options, windows=windows) == coupled_inputs(
        records, "x1", ["x2", "r"], options
    )
    transformed: list[int] = []  # channels transformed by each request
    made = estimate_module.window_transforms
    monkeypatch.setattr(
        estimate_module,
        "window_transforms",
        lambda data, *a, **k: transformed.append(data[0].shape[0]) or made(data, *a, **k),
    )
    for channels, grid, keep, new in [
        (("x1", "y1"), long_grid, ("x1",), 2),
        (("y2", "x1", "x2"), short_grid, ("x2",), 2),  # x1 kept, on the other grid: the same frequencies
        (("x2", "y3", "x1"), long_grid, (), 1),
    ]:
        for n_window in (300, 600):
            transformed.clear()
            found = windows.spectra(channels, n_window, grid, keep=keep)
            assert transformed == [len(channels) if keep_bytes == 0 else new]
            data = [np.vstack([r[c] for c in channels]) for r in records]
            alone = _spectra.window_spectra(
                data, 0.01, n_window, grid, overlap=0.8, taper="hann", min_cycles=options.min_cycles
            )
            assert found is not None and alone is not None
            assert (found.n_windows, found.n_effective, found.omega_low) == (
                alone.n_windows,
                alone.n_effective,
                alone.omega_low,
            )
            np.testing.assert_allclose(found.spectra, alone.spectra, rtol=1e-12, atol=1e-15)
    kept = {c for _, by_channel in windows._kept.values() for c in by_channel}
    assert kept == (set() if keep_bytes == 0 else {"x1", "x2"})


def test_the_kernels_kept_are_those_computed_and_stay_within_their_budget(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """A transform from a kept kernel equals one from a fresh kernel, bit for bit; past the budget the oldest go."""
    from sysid.freqresp import _spectra

    rng = np.random.default_rng(3)
    flat, taper = rng.normal(size=(12, 400)), np.hanning(400)
    grids = [np.geomspace(1.0, 60.0, n) for n in (20, 30, 40)]
    monkeypatch.setattr(_spectra, "_KERNELS", {})
    monkeypatch.setattr(_spectra, "_KERNEL_BYTES", 2 * 2 * 40 * 400 * 8)  # room for two of the largest
    fresh = [_spectra._matrix_dft(flat, 0.01, taper, omega) for omega in grids]
    assert len(_spectra._KERNELS) == 2  # the 20-point grid's went to make room for the 40-point one
    assert sum(k.nbytes for k, _ in _spectra._KERNELS.values()) <= _spectra._KERNEL_BYTES
    kernels = dict(_spectra._KERNELS)
    again = [_spectra._matrix_dft(flat, 0.01, taper, omega) for omega in grids[1:]]  # from the kernels kept
    assert _spectra._KERNELS == kernels
    for a, b in zip(fresh[1:], again):
        np.testing.assert_array_equal(a, b)
    assert all(not k.flags.writeable and not total.flags.writeable for k, total in _spectra._KERNELS.values())


def test_the_kernels_are_kept_safely_from_several_threads(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """Eight threads transforming on twelve grids, the budget forcing evictions all along, threads switched every
    microsecond: no error, and each transform what it is alone. Without the lock, 5 of 20 such rounds raised
    "dictionary changed size during iteration"; here 20 rounds."""
    import sys
    from concurrent.futures import ThreadPoolExecutor

    from sysid.freqresp import _spectra

    rng = np.random.default_rng(4)
    flat, taper = rng.normal(size=(6, 300)), np.hanning(300)
    grids = [np.geomspace(1.0, 60.0, n) for n in range(20, 32)]
    monkeypatch.setattr(_spectra, "_KERNEL_BYTES", 3 * 2 * 31 * 300 * 8)
    alone = [_spectra._matrix_dft(flat, 0.01, taper, omega) for omega in grids]
    interval = sys.getswitchinterval()
    try:
        sys.setswitchinterval(1e-6)
        for _ in range(20):
            monkeypatch.setattr(_spectra, "_KERNELS", {})
            with ThreadPoolExecutor(8) as pool:
                together = list(pool.map(lambda k: _spectra._matrix_dft(flat, 0.01, taper, grids[k % 12]), range(96)))
            for k, transform in enumerate(together):
                np.testing.assert_array_equal(transform, alone[k % 12])
    finally:
        sys.setswitchinterval(interval)
    assert sum(k.nbytes for k, _ in _spectra._KERNELS.values()) <= _spectra._KERNEL_BYTES


def test_autospectrum_scaling_of_white_noise() -> None:
    """One-sided density per rad/s: white noise of variance s^2 at step dt has G = s^2 dt / pi."""
    rng = np.random.default_rng(7)
    time_s = np.arange(40_000) / RATE_HZ
    sigma = 0.7
    records = [_record({"x": sigma * rng.normal(size=time_s.size), "y": rng.normal(size=time_s.size)}, time_s)]
    (response,) = frequency_responses(
        records, ["x"], ["y"], ResponseOptions(window_lengths_s=(4.0,), omega_min=5.0, omega_max=300.0, n_freq=200)
    )
    expected = sigma**2 * 0.01 / np.pi
    assert np.mean(response.input_autospectrum) == pytest.approx(expected, rel=0.02)
    # a 4 s window at 80 % overlap over 400 s: about 460 effective averages -> coherence of independent noise ~ 1/n_d
    assert np.mean(response.coherence) < 0.01


def test_effective_number_of_averages_follows_welch() -> None:
    """Hann at 50 %: rho(N/2) = 1/6, so K windows count as K / (1 + 2 (1 - 1/K) / 36)."""
    taper = sps.get_window("hann", 400)
    assert effective_averages(10, 200, taper) == pytest.approx(10 / (1 + 2 * 0.9 / 36), rel=1e-3)
    assert effective_averages(10, 400, taper) == pytest.approx(10.0)
    assert effective_averages(1, 80, taper) == 1.0
