"""Multi-input conditioning, the multi-window composite and its whole-record member.

Conditioning: two correlated inputs drive one output through known discrete
filters, so the truth is exact (``freqz`` at ``omega dt``). The conditioned
(MISO) responses recover each filter; the single-input ones absorb the other
input's correlated part, ``H1 + H2 G_12 / G_11``, and are visibly biased.

The windows' composite (CIFER's) is compared with its single windows with
the whole-record member switched off; the member's own rules (its noise
between records or, from one record, between bins; significance against
that noise) are tested at the end.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import signal as sps

from flightlogs.record import Record
from simulator.autopilot.excitation import Maneuver, sweep
from sysid.freqresp import ResponseOptions, frequency_responses
from sysid.model.statespace import DelayedStateSpace

RATE_HZ = 100.0
K_SIGMA = 4.5  # random-error multiple, family-wise (see tests/sysid/freqresp/test_estimate.py)
DT = 1.0 / RATE_HZ
# H1: first-order lag (0.1 s) and H2: lightly damped second order at 10 rad/s delayed 3 samples, both discretised
H1 = sps.cont2discrete(([10.0], [1.0, 10.0]), DT, method="bilinear")[:2]
H2_NUM, H2_DEN = sps.cont2discrete(([200.0], [1.0, 6.0, 100.0]), DT, method="bilinear")[:2]
H2 = (np.concatenate([[0.0, 0.0, 0.0], np.ravel(H2_NUM)]), H2_DEN)


def _truth(filt: tuple[np.ndarray, np.ndarray], omega: np.ndarray) -> np.ndarray:
    return sps.freqz(np.ravel(filt[0]), filt[1], worN=omega * DT)[1]


def _record(columns: dict[str, np.ndarray]) -> Record:
    time_s = np.arange(next(iter(columns.values())).size) * DT
    return Record.from_table(
        pd.DataFrame(columns, index=time_s),
        units={name: "-" for name in columns},
        trim={},
        source=Path("simulated"),
    )


def _correlated_records(n_records: int = 4, seconds: float = 60.0, seed: int = 0) -> list[Record]:
    """x2 = 0.9 x (low-passed x1) + independent noise: coherence of the two inputs about 0.8 below 5 rad/s."""
    rng = np.random.default_rng(seed)
    shaping = sps.butter(2, 12.0, fs=RATE_HZ, output="sos")
    mixing = sps.butter(1, 1.0, fs=RATE_HZ, output="sos")
    records = []
    for _ in range(n_records):
        n = int(seconds * RATE_HZ)
        x1 = sps.sosfilt(shaping, rng.normal(size=n))
        x2 = 0.9 * sps.sosfilt(mixing, x1) / np.std(sps.sosfilt(mixing, x1)) * np.std(x1)
        x2 += 0.5 * sps.sosfilt(shaping, rng.normal(size=n))
        y = sps.lfilter(np.ravel(H1[0]), H1[1], x1) + sps.lfilter(*H2, x2)
        y += 0.02 * np.std(y) * rng.normal(size=n)
        records.append(_record({"x1": x1, "x2": x2, "y": y}))
    return records


def test_conditioned_responses_recover_each_path_and_single_input_ones_do_not() -> None:
    records = _correlated_records()
    options = ResponseOptions(omega_min=1.0, omega_max=60.0, n_freq=80)
    to_x1, to_x2 = frequency_responses(records, ["x1", "x2"], ["y"], options)
    assert (to_x1.pair, to_x1.conditioned_on, to_x2.conditioned_on) == ("y/x1", ("x2",), ("x1",))
    (naive,) = frequency_responses(records, ["x1"], ["y"], options)
    for response, filt in ((to_x1, H1), (to_x2, H2)):
        truth = _truth(filt, response.omega)
        good = response.coherence > 0.8  # partial coherence
        assert np.log10(response.omega[good].max() / response.omega[good].min()) > 1.3
        ratio = response.response[good] / truth[good]
        eps = response.random_error[good]
        assert np.all(np.abs(20 * np.log10(np.abs(ratio))) < np.maximum(0.5, 20 * np.log10(np.e) * K_SIGMA * eps))
        assert np.all(np.abs(np.degrees(np.angle(ratio))) < np.maximum(3.0, np.degrees(K_SIGMA * eps)))
    # the unconditioned x1 response carries x2's path: several dB off where x2 follows x1
    error_db = np.abs(20 * np.log10(np.abs(naive.response / _truth(H1, naive.omega))))
    assert np.median(error_db[naive.omega < 10.0]) > 3.0
    # conditioning spectra are consistent: response = cross / input, coherence = |cross|^2 / (input output)
    np.testing.assert_allclose(to_x1.response, to_x1.cross_spectrum / to_x1.input_autospectrum, rtol=1e-9)
    np.testing.assert_allclose(
        to_x1.coherence,
        np.abs(to_x1.cross_spectrum) ** 2 / (to_x1.input_autospectrum * to_x1.output_autospectrum),
        rtol=1e-9,
    )


def test_an_input_that_copies_another_has_no_partial_coherence() -> None:
    rng = np.random.default_rng(1)
    x = rng.normal(size=6000)
    records = [_record({"a": x, "b": 2.0 * x, "y": sps.lfilter([0.3], [1.0, -0.6], x)})]
    to_a, to_b = frequency_responses(records, ["a", "b"], ["y"], ResponseOptions(omega_min=2.0, n_freq=30))
    assert np.all(to_a.coherence < 1e-6) and np.all(to_b.coherence < 1e-6)
    assert np.all(np.isfinite(to_a.response)) and np.all(np.isinf(to_a.random_error))


def _lag_sweeps(noise: float, seed: int) -> tuple[list[Record], DelayedStateSpace]:
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
    rng = np.random.default_rng(seed)
    maneuver = Maneuver(
        axis="lon", kind="sweep", start_s=2.0, amplitude=1.0, duration_s=34.0, f_start_hz=0.1, f_stop_hz=12.0
    )
    fine = np.arange(int(38.0 * RATE_HZ * 10)) / (RATE_HZ * 10)
    _, y, _ = sps.lsim(sps.StateSpace(model.a, model.b, model.c, model.d), sweep(fine - 0.05, maneuver)[0], fine)
    x, y = sweep(fine, maneuver)[0][::10], np.ravel(y)[::10]
    return [_record({"x": x, "y": y + noise * np.std(y) * rng.normal(size=y.size)}) for _ in range(5)], model


@pytest.mark.parametrize("noise", [0.03, 0.3])
def test_composite_beats_every_single_window_over_the_full_range(noise: float) -> None:
    """RMS of |ln(H_est / H)| (magnitude and phase together) over the composite's whole grid.

    Each single window is run alone over the same grid (its low-frequency limit lifted), as an analysis
    with one window length would be: short windows are biased at low frequency, long ones noisy at high.
    The composite, with its whole-record member (which takes the grid down to 3 periods of the record),
    beats every one of them, and beats the windows' composite where both are defined.
    """
    records, model = _lag_sweeps(noise, seed=4)
    (composite,) = frequency_responses(records, ["x"], ["y"])
    truth = model.frequency_response(composite.omega)[:, 0, 0]
    composite_error = float(np.sqrt(np.mean(np.abs(np.log(composite.response / truth)) ** 2)))
    assert len(composite.windows_s) == 5 and composite.whole_record
    (windows,) = frequency_responses(records, ["x"], ["y"], ResponseOptions(whole_record=False))
    shared = np.isin(composite.omega, windows.omega)
    assert windows.omega[0] > composite.omega[0] and shared.sum() == windows.omega.size
    windows_error = float(np.sqrt(np.mean(np.abs(np.log(windows.response / truth[shared])) ** 2)))
    assert float(np.sqrt(np.mean(np.abs(np.log(composite.response / truth)[shared]) ** 2))) <= windows_error
    for window_s in composite.windows_s:
        cycles = composite.omega[0] * window_s / (2 * np.pi) * (1 - 1e-9)
        (single,) = frequency_responses(
            records, ["x"], ["y"], ResponseOptions(window_lengths_s=(window_s,), min_cycles=cycles, whole_record=False)
        )
        np.testing.assert_allclose(single.omega, composite.omega)
        single_error = float(np.sqrt(np.mean(np.abs(np.log(single.response / truth)) ** 2)))
        assert composite_error < single_error, f"{window_s:.1f} s window: {single_error:.4f} <= {composite_error:.4f}"


def test_composite_random_error_lies_between_its_windows() -> None:
    """Between the best and the worst window's at every frequency, and well below the longest window's at high
    frequency, where the short windows add hundreds of averages. Never far below the best: the windows reuse
    the same data, so the composite is credited the weighted mean of their averages, not their sum."""
    records, _ = _lag_sweeps(0.1, seed=5)
    (composite,) = frequency_responses(records, ["x"], ["y"], ResponseOptions(whole_record=False))
    singles = [
        frequency_responses(records, ["x"], ["y"], ResponseOptions(window_lengths_s=(t,), whole_record=False))[0]
        for t in composite.windows_s
    ]
    best = np.full(composite.omega.size, np.inf)
    worst = np.zeros(composite.omega.size)
    for single in singles:
        shared = np.isin(composite.omega, single.omega)
        best[shared] = np.minimum(best[shared], single.random_error)
        worst[shared] = np.maximum(worst[shared], single.random_error)
    assert np.all(composite.random_error > 0.7 * best)
    assert np.all(composite.random_error <= worst)
    high = composite.omega > 20.0
    assert np.median(composite.random_error[high] / singles[-1].random_error[high]) < 0.5


def test_the_whole_record_member_from_one_record_measures_its_noise_between_bins() -> None:
    """More records than inputs: the noise between records. One record: between its neighbouring bins
    (``sysid.freqresp._local``); either way the grid reaches down to 3 periods of the 38 s records,
    below the longest window's 3 periods."""
    records, model = _lag_sweeps(0.1, seed=6)
    (one,) = frequency_responses(records[:1], ["x"], ["y"])
    (two,) = frequency_responses(records[:2], ["x"], ["y"])
    assert one.whole_record and two.whole_record
    longest_window = max(two.windows_s)
    for response in (one, two):
        assert response.omega[0] < 2 * np.pi * 3 / longest_window
        assert response.omega[0] >= 2 * np.pi * 3 / 38.0 * (1 - 1e-9)
    truth = model.frequency_response(one.omega)[:, 0, 0]
    low = one.omega < 2 * np.pi * 3 / longest_window  # only the member reaches here
    assert np.all(one.coherence[low] > 0.5)
    assert np.sqrt(np.mean(np.abs(np.log(one.response[low] / truth[low])) ** 2)) < 0.1


@pytest.mark.parametrize("n_records", [1, 2, 3])
def test_noise_only_records_never_look_coherent(n_records: int) -> None:
    """An output unrelated to the sweep: from 1, 2 or 3 records the member's own coherence is 0.5 or more at
    a few per cent of the frequencies by chance; its significance test (1e-4) keeps it out, so the response
    is the windows' composite where the windows reach and has no coherence below."""
    records, _ = _lag_sweeps(0.1, seed=7)
    rng = np.random.default_rng(8)
    unrelated = [_record({"x": r["x"], "y": rng.normal(size=r["x"].size)}) for r in records[:n_records]]
    (response,) = frequency_responses(unrelated, ["x"], ["y"])
    (windows,) = frequency_responses(unrelated, ["x"], ["y"], ResponseOptions(whole_record=False))
    assert not response.whole_record and response.omega[0] < windows.omega[0]
    shared = np.isin(response.omega, windows.omega)
    np.testing.assert_allclose(response.coherence[shared], windows.coherence, rtol=1e-12)
    np.testing.assert_allclose(response.response[shared], windows.response, rtol=1e-12)
    assert np.all(response.coherence[~shared] == 0.0)
