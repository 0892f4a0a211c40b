"""Sweeps and multisines by their time-frequency ridge (``detect_segments(..., responses=...)``), on signals
with known truth built here: a chirp whose low-frequency part the feedback has cancelled from the input, a
Schroeder multisine, and noise alone."""

from __future__ import annotations

import numpy as np
import pytest

from flightlogs.maneuvers import DetectionOptions, detect_segments

DT = 0.01
T = np.arange(0.0, 120.0, DT)
NO_HOVER = DetectionOptions(min_hover_s=1e9)  # the maneuvers alone


def _chirp(start_s: float, duration_s: float, f0: float, f1: float) -> np.ndarray:
    """Logarithmic chirp from f0 to f1 Hz with 1 s raised-cosine fades, zero outside."""
    tau = T - start_s
    inside = (tau >= 0) & (tau <= duration_s)
    k = np.log(f1 / f0) / duration_s
    phase = 2 * np.pi * f0 * np.expm1(k * np.clip(tau, 0, duration_s)) / k
    fade = np.clip(np.minimum(tau, duration_s - tau), 0, 1.0)
    return np.where(inside, np.sin(phase) * 0.5 * (1 - np.cos(np.pi * fade)), 0.0)


def _high_passed(x: np.ndarray, corner_hz: float) -> np.ndarray:
    """What a loop with crossover `corner_hz` leaves of an input excitation: its low frequencies cancelled."""
    spectrum = np.fft.rfft(x)
    f = np.fft.rfftfreq(x.size, DT)
    return np.fft.irfft(spectrum * (1j * f / corner_hz) / (1 + 1j * f / corner_hz), x.size)


@pytest.mark.parametrize(("f0", "f1", "direction"), [(0.1, 8.0, "up"), (8.0, 0.1, "down")])
def test_a_chirp_is_found_from_input_and_response_together(f0: float, f1: float, direction: str) -> None:
    """The input alone keeps only the chirp's fast part and the response its slow part; together, one sweep."""
    rng = np.random.default_rng(3)
    chirp = _chirp(30.0, 40.0, f0, f1)
    delta = 0.06 * _high_passed(chirp, 1.0) + rng.normal(0, 0.003, T.size)
    theta = 0.05 * (chirp - _high_passed(chirp, 1.0)) + rng.normal(0, 0.002, T.size)
    (found,) = detect_segments(T, {}, responses={"lon": {"delta_lon": delta, "theta": theta}}, options=NO_HOVER)
    assert (found.axis, found.kind) == ("lon", "sweep")
    assert found.detail.startswith(f"{direction} ridge in")
    assert 28.0 <= found.start_s <= 31.5 and 68.5 <= found.end_s <= 72.0  # truth 30-70 s with 1 s fades
    assert found.f_min_hz is not None and found.f_max_hz is not None
    assert found.f_min_hz <= 0.5 and found.f_max_hz >= 6.0  # the ridge's range where it stands out of the noise


def test_a_schroeder_multisine_is_a_multisine() -> None:
    """Schroeder phases sweep the band once a period: a saw-tooth ridge, not one sweep."""
    rng = np.random.default_rng(4)
    harmonics = np.arange(2, 61)  # 0.2-6 Hz over a 10 s period
    k = np.arange(1, harmonics.size + 1)
    phases = -np.pi * k * (k - 1) / harmonics.size  # Schroeder (1970)
    signal = np.cos(2 * np.pi * np.outer(T, harmonics) / 10.0 + phases).sum(axis=1)
    signal *= (T >= 40.0) & (T < 70.0)
    x = 0.06 * signal / np.abs(signal).max() + rng.normal(0, 0.002, T.size)
    (found,) = detect_segments(T, {}, responses={"thr": {"delta_thr": x}}, options=NO_HOVER)
    assert (found.axis, found.kind) == ("thr", "multisine")
    assert 39.0 <= found.start_s <= 41.0 and 69.0 <= found.end_s <= 71.0


def test_noise_alone_is_no_maneuver() -> None:
    rng = np.random.default_rng(5)
    traces = {"lat": {"delta_lat": rng.normal(0, 0.003, T.size), "p": rng.normal(0, 0.01, T.size)}}
    assert detect_segments(T, {}, responses=traces, options=NO_HOVER) == ()


def _band_noise(rng: np.random.Generator, lo_hz: float, hi_hz: float) -> np.ndarray:
    """White noise band-passed to [lo_hz, hi_hz] (a pilot shaking the stick at will), unit RMS."""
    spectrum = np.fft.rfft(rng.standard_normal(T.size))
    f = np.fft.rfftfreq(T.size, DT)
    x = np.fft.irfft(spectrum * ((f >= lo_hz) & (f <= hi_hz)), T.size)
    return x / x.std()


def test_a_pilot_shaking_two_sticks_at_once_is_found_on_both_axes() -> None:
    """Roll and pitch setpoints driven together by a pilot at 0.7-5 Hz, no trend, held exactly at zero before.

    A held setpoint has no noise floor (kd0aij's before take-off): the floor is then bounded by the trace's
    own level, not by the rounding. Neither axis is the other's reaction: both are found, as piloted.
    """
    rng = np.random.default_rng(5)
    flown = (T >= 30.0) & (T < 80.0)
    responses = {}
    for axis, rate in (("lat", "p"), ("lon", "q")):
        command = np.where(flown, 0.3 * _band_noise(rng, 0.7, 5.0), 0.0)
        responses[axis] = {f"{rate}_ref": command, rate: command + rng.normal(0, 0.01, T.size)}
    found = detect_segments(T, {}, responses=responses, options=NO_HOVER)
    assert sorted(s.axis for s in found) == ["lat", "lon"]
    for segment in found:
        assert segment.kind == "broadband" and segment.detail.startswith("piloted, without a frequency trend")
        assert 28.5 <= segment.start_s <= 31.0 and 79.0 <= segment.end_s <= 81.5


def test_broadband_motion_that_no_command_carries_is_no_maneuver() -> None:
    """The same shaking in the rate alone, with the pilot's stick logged and centred: turbulence, not a pilot."""
    rng = np.random.default_rng(6)
    flown = (T >= 30.0) & (T < 80.0)
    p = np.where(flown, 0.3 * _band_noise(rng, 0.7, 5.0), 0.0) + rng.normal(0, 0.01, T.size)
    stick = rng.normal(0, 1e-3, T.size)
    found = detect_segments(T, {}, responses={"lat": {"stick_lat": stick, "p": p}}, options=NO_HOVER)
    assert found == ()
