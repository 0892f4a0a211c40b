"""Maneuver detection on logs our simulator did not write (issue 14): the independent corpus and real logs.

The detector's thresholds were set on the corpus's TUNING cases only; every
assertion here is on its HELD-OUT cases (``tests/independent_sim``: closed
loop, excitation 5-8 % of the mixer range injected after the rate loop and
never logged, PX4 and ArduPilot), and on real logs recorded by others.

Measured on the held-out calm cases (bounds minus truth, s):
sweeps found 15/15 on the right axis, starts +0.1 to +1.3 s (the 3 s
fade-in of a 0.1 Hz chirp stays under the noise for about a second), ends
-0.6 to +0.9 (+1.015 on heldout-ap-sweeps' falling thr sweep before the
vertical speed, which integrates the acceleration and rings on after the
last 0.1 Hz half-wave, stopped setting the end; no tuning case moved); doublets and 3211s 22/22 within 0.05 s (the start is the
first step of the logged input: before that rule the thrust doublets
started 2.2-2.5 s early and the altitude loop's recovery after one was a
fourth "doublet"); one Schroeder multisine (0.1-6 Hz, lon) read as a sweep
starting 5.4 s late.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from independent_sim.catalogue import case_named
from independent_sim.fixtures import independent_corpus_fixture  # noqa: F401 (registers the fixture)

from flightlogs.conditioning.condition import condition_flight
from flightlogs.maneuvers import Segment
from flightlogs.readers import read_log

pytestmark = [
    pytest.mark.slow,
    pytest.mark.filterwarnings("ignore:no wind given:flightlogs.errors.DataQualityWarning"),  # u v w unused here
]

CALM_HELDOUT = [
    "heldout-px4-sweeps",
    "heldout-px4-piloted",
    "heldout-px4-multisine",
    "heldout-px4-no-lat",
    "heldout-ap-sweeps",
    "heldout-ap-doublets",
]
BOUND_S = 0.5  # issue 14: "bounds within 0.5 s"


def _found(segments: tuple[Segment, ...], axis: str, start_s: float, end_s: float) -> list[Segment]:
    return [s for s in segments if s.axis == axis and s.start_s < end_s and start_s < s.end_s]


@pytest.fixture(scope="module", name="detections")
def detections_fixture(independent_corpus):  # type: ignore[no-untyped-def]
    out = {}
    for name in CALM_HELDOUT:
        files = independent_corpus.files(name)
        segments = tuple(s for s in condition_flight(read_log(files.log)).segments if s.kind != "hover")
        out[name] = (files.truth, segments)
    return out


@pytest.mark.parametrize("name", CALM_HELDOUT)
def test_every_held_out_maneuver_is_found_once_on_its_axis(name: str, detections) -> None:  # type: ignore[no-untyped-def]
    truth, segments = detections[name]
    for maneuver in truth.maneuvers:
        assert len(_found(segments, maneuver.axis, maneuver.start_s, maneuver.end_s)) == 1, (maneuver, segments)


@pytest.mark.parametrize("name", CALM_HELDOUT)
def test_steps_have_exact_bounds_and_kinds(name: str, detections) -> None:  # type: ignore[no-untyped-def]
    """Doublets and 3211s: the joint feedback fit and the logged input's first step give both ends within 0.05 s."""
    truth, segments = detections[name]
    steps = [m for m in truth.maneuvers if m.kind in ("doublet", "3211")]
    for maneuver in steps:
        (found,) = _found(segments, maneuver.axis, maneuver.start_s, maneuver.end_s)
        assert found.kind == maneuver.kind, (maneuver, found)
        assert abs(found.start_s - maneuver.start_s) <= BOUND_S and abs(found.end_s - maneuver.end_s) <= BOUND_S


@pytest.mark.parametrize("name", CALM_HELDOUT)
def test_sweeps_are_sweeps_and_name_the_traces_that_carried_them(name: str, detections) -> None:  # type: ignore[no-untyped-def]
    truth, segments = detections[name]
    for maneuver in (m for m in truth.maneuvers if m.kind == "sweep"):
        (found,) = _found(segments, maneuver.axis, maneuver.start_s, maneuver.end_s)
        assert found.kind == "sweep" and found.source == "detected"
        assert "ridge in" in found.detail and found.f_max_hz is not None and found.f_max_hz > 3 * found.f_min_hz


def _rise_s(independent_corpus, name: str, index: int) -> float:  # type: ignore[no-untyped-def]
    """When the `index`-th maneuver's excitation first rises above the log's noise floor, s on the log clock.

    The floor is the standard deviation of the logged mixer input of its axis over the quiet hover before the
    first maneuver (the controller's answer to sensor noise and gusts); the excitation is the design rendered
    again (it is never logged).
    """
    files, case = independent_corpus.files(name), case_named(name)
    truth, design = files.truth.maneuvers[index], case.maneuvers[index]
    shift = truth.start_s - design.start_s  # the plan's clock to the log's
    signal = read_log(files.log)[f"delta_{truth.axis}"]
    first = min(m.start_s for m in files.truth.maneuvers)
    quiet = (signal.time_s > first - 8.0) & (signal.time_s < first - 1.0)
    floor = float(np.std(signal.values[quiet]))
    t = np.arange(design.start_s, design.start_s + design.design.duration_s, 0.001)
    values = design.design.render(t, design.start_s, design.amplitude, np.random.default_rng(0)).values
    return float(t[np.argmax(np.abs(values) >= floor)] + shift)


@pytest.mark.parametrize("name", ["heldout-px4-sweeps", "heldout-ap-sweeps"])
def test_a_sweep_starts_where_its_excitation_rises_above_the_noise_floor(
    name: str,
    detections,  # type: ignore[no-untyped-def]
    independent_corpus,  # type: ignore[no-untyped-def]
) -> None:
    """Issue 32's rule: the start within 1.5 s (or a tenth of the sweep, the larger) of where the excitation
    rises above the log's noise floor, the end within 1 s (issue 14's 0.5 s asked more of a fade-in than the
    data hold: its first second is under the noise)."""
    truth, segments = detections[name]
    for index, maneuver in enumerate(truth.maneuvers):
        if maneuver.kind != "sweep":
            continue
        (found,) = _found(segments, maneuver.axis, maneuver.start_s, maneuver.end_s)
        rise = _rise_s(independent_corpus, name, index)
        assert maneuver.start_s <= rise < maneuver.start_s + 3.0, (maneuver, rise)
        assert abs(found.start_s - rise) <= max(1.5, 0.1 * (maneuver.end_s - maneuver.start_s)), (maneuver, rise, found)
        assert abs(found.end_s - maneuver.end_s) <= 1.0, (maneuver, found)


def test_a_hover_with_repositions_has_no_maneuver(independent_corpus) -> None:  # type: ignore[no-untyped-def]
    files = independent_corpus.files("heldout-ap-hover")
    assert [s for s in condition_flight(read_log(files.log)).segments if s.kind != "hover"] == []


@pytest.mark.parametrize(
    "relative",
    [
        "dronekit-la-testdata/log171.bin",  # was a 242 s "yaw multisine"
        "pyulog/sample.ulg",  # never armed; was a "multisine"
        "px4-ulog-rs/quadrotor_local.ulg",  # its landing was a "thr doublet" that validate scored
        "ardupilot-log-diagnosis/sample.bin",  # was lat and yaw "multisines"
        # a mission flight: a "yaw doublet" at 469 s, the yaw controller's chatter in a climb, r flat; r was left
        # out of detection for one gap in the record (now bridged) and a step must turn the vehicle
        "px4-ulog-rs/corrupt_unregistered_msg_id.ulg",
    ],
)
@pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning")  # dropouts and gaps of real logs, not tested here
def test_real_logs_without_excitation_get_no_maneuver(relative: str, real_data: Path) -> None:
    """No designed maneuver; a pilot's stick work without a frequency trend is at most ``broadband`` (issue 32: a
    kind of its own, fitted only when asked and never judged a model): log171's last 40 s, where its pilot works
    the pitch stick through a landing and a second take-off (stick_lon 0.29 rms at 238-246 s), is one."""
    path = real_data / relative
    found = [(s.kind, s.axis) for s in condition_flight(read_log(path)).segments if s.kind != "hover"]
    assert found == ([("broadband", "lon")] if relative.endswith("log171.bin") else [])


KD0AIJ = "kd0aij-impulse-response/log1.ulg"
#: The pilot's roll and pitch stick oscillations, 2-5 Hz bursts from 6 s to 42 s of flight (data/README.md), on
#: the log clock (its first sample at 20.4 s).
KD0AIJ_BURSTS_S = (26.4, 62.4)


@pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning")  # its logging dropouts, tested in the readers
def test_pilot_stick_oscillations_of_a_real_log_are_found_on_both_axes_from_the_setpoints(real_data: Path) -> None:
    """kd0aij: no mixer input, no stick logged; the pilot shakes roll and pitch at once, without a frequency trend.

    Both axes are found (the stronger no longer hides the other: neither is the other's reaction), each from
    its own attitude and rate setpoints, and each covers the documented bursts (before: one "lon" sweep only).
    """
    segments = [s for s in condition_flight(read_log(real_data / KD0AIJ)).segments if s.kind != "hover"]
    assert sorted(s.axis for s in segments) == ["lat", "lon"]
    first, last = KD0AIJ_BURSTS_S
    for segment in segments:
        assert segment.kind == "broadband" and segment.detail.startswith("piloted, without a frequency trend")
        assert f"{'phi' if segment.axis == 'lat' else 'theta'}_ref" in segment.detail
        assert segment.start_s <= first and segment.end_s >= last - 1.0, segment
        assert segment.start_s >= first - 5.0, segment  # not the whole log: it starts at 20.4 s
