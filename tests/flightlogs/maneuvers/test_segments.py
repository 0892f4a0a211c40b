"""Maneuver segmentation: detection on synthetic closed-loop flights, System ID runs, user files."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.signal import butter, lfilter

from flightlogs.errors import DataError
from flightlogs.flightlog import SystemIdRun
from flightlogs.maneuvers.segments import (
    SID_AXES,
    DetectionOptions,
    Segment,
    SegmentDetector,
    detect_segments,
    segments_from_sid,
)
from flightlogs.readers.segments_file import read_segments_file

RATE_HZ = 100.0
AMPLITUDE = {"lat": 0.1, "lon": 0.1, "yaw": 0.08, "thr": 0.05}  # mixer units, 0-1 scale
#: (axis, kind, start_s, end_s) of the excitation, and the hover between.
PLAN = [
    ("lon", "sweep", 10.0, 44.0),
    ("lat", "doublet", 54.0, 56.0),
    ("yaw", "sweep", 64.0, 98.0),
    ("thr", "doublet", 108.0, 110.0),
]
HOVER = [(0.0, 10.0), (44.0, 54.0), (56.0, 64.0), (98.0, 108.0), (110.0, 125.0)]
BOUNDARY_TOL_S = 0.3


def _log_sweep(
    t: np.ndarray, f0: float = 0.1, f1: float = 10.0, length_s: float = 34.0, fade_in_s: float = 2.0
) -> np.ndarray:
    """0.1-10 Hz logarithmic sweep from trim (zero phase) with a linear fade-in."""
    tau = np.clip(t, 0.0, length_s)
    k = np.log(f1 / f0)
    phase = 2 * np.pi * f0 * length_s / k * (np.exp(k * tau / length_s) - 1)
    fade = np.minimum(tau / fade_in_s, 1.0)
    return np.where((t >= 0) & (t <= length_s), fade * np.sin(phase), 0.0)


def _doublet(t: np.ndarray, pulse_s: float = 1.0) -> np.ndarray:
    return ((t >= 0) & (t < pulse_s)).astype(float) - ((t >= pulse_s) & (t < 2 * pulse_s)).astype(float)


def _lowpass(x: np.ndarray, cutoff_hz: float, order: int = 1) -> np.ndarray:
    b, a = butter(order, cutoff_hz / (RATE_HZ / 2))
    return lfilter(b, a, x)


def _flight(seed: int, plan=PLAN, *, duration_s: float = 125.0, noise: float = 1.0) -> tuple:
    """Mixer inputs of a closed-loop hover flight with the maneuvers of `plan` injected.

    Each input is the excitation of its own axis, minus the controller's
    reaction to it (30 %, 3 Hz), plus cross-talk from the maneuvers on the
    other axes (12 %, 2 Hz, random sign), white (0.45 × `noise` %) and
    1 Hz-coloured (0.3 × `noise` %) noise, slow pilot inputs (periods 50 s
    and 90 s) and the hover trim.
    """
    rng = np.random.default_rng(seed)
    t = np.arange(int(duration_s * RATE_HZ)) / RATE_HZ
    excitation = {axis: np.zeros_like(t) for axis in AMPLITUDE}
    for axis, kind, start, _ in plan:
        shape = _log_sweep(t - start) if kind == "sweep" else _doublet(t - start)
        excitation[axis] += AMPLITUDE[axis] * shape
    inputs = {}
    for axis, own in excitation.items():
        x = own - 0.3 * _lowpass(own, 3.0)
        for other, theirs in excitation.items():
            if other != axis:
                x += 0.12 * rng.choice([-1.0, 1.0]) * _lowpass(theirs, 2.0, order=2)
        x += 0.0045 * noise * rng.standard_normal(t.size)
        x += 0.003 * noise * _lowpass(rng.standard_normal(t.size), 1.0) * np.sqrt(RATE_HZ / np.pi)
        x += 0.008 * np.sin(2 * np.pi * t / 90 + rng.uniform(0, 6.3)) + 0.005 * np.sin(
            2 * np.pi * t / 50 + rng.uniform(0, 6.3)
        )
        inputs[axis] = x + (0.45 if axis == "thr" else 0.0)
    return t, inputs


# ------------------------------------------------------------------ detection


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_every_maneuver_is_found_once_with_its_axis_kind_and_bounds(seed: int) -> None:
    t, inputs = _flight(seed, noise=0.1)
    found = detect_segments(t, inputs)
    maneuvers = [s for s in found if s.kind != "hover"]
    assert [(s.axis, s.kind) for s in maneuvers] == [(axis, kind) for axis, kind, _, _ in PLAN]
    for segment, (_, _, start, end) in zip(maneuvers, PLAN):
        assert segment.source == "detected"
        assert abs(segment.start_s - start) <= BOUNDARY_TOL_S, (segment, start)
        assert abs(segment.end_s - end) <= BOUNDARY_TOL_S, (segment, end)
        if segment.kind == "sweep":
            assert 0.1 <= segment.f_min_hz <= 0.2  # the first half-wave, centred near 0.13 Hz
            assert 9.0 <= segment.f_max_hz <= 11.0


@pytest.mark.parametrize("seed", [0, 1])
def test_hover_is_found_between_maneuvers_and_never_overlaps_them(seed: int) -> None:
    t, inputs = _flight(seed, noise=0.1)
    hovers = [s for s in detect_segments(t, inputs) if s.kind == "hover"]
    assert all(s.axis is None for s in hovers)
    for lo, hi in HOVER:
        inside = [s for s in hovers if s.start_s >= lo - 0.05 and s.end_s <= hi + 0.05]
        assert len(inside) == 1 and inside[0].duration_s >= 0.6 * (hi - lo), (lo, hi, hovers)
    for s in hovers:
        assert not any(s.start_s < end and s.end_s > start for _, _, start, end in PLAN)


@pytest.mark.parametrize(("seed", "noise"), [(3, 1.0), (4, 0.1), (5, 3.0)])
def test_a_record_of_noise_and_drift_holds_no_maneuver(seed: int, noise: float) -> None:
    t, inputs = _flight(seed, plan=[], duration_s=200.0, noise=noise)
    found = detect_segments(t, inputs)
    assert all(s.kind == "hover" for s in found)
    assert sum(s.duration_s for s in found) > 0.95 * 200.0


def test_a_3211_and_a_multisine_are_told_apart() -> None:
    rng = np.random.default_rng(7)
    t = np.arange(9000) / RATE_HZ
    unit = 0.5
    edges = np.cumsum([20.0, 3 * unit, 2 * unit, unit, unit])
    s3211 = sum(sign * ((t >= a) & (t < b)) for sign, a, b in zip([1, -1, 1, -1], edges[:-1], edges[1:]))
    tones = [0.3, 0.7, 1.1, 1.9, 2.6, 3.7, 4.3, 5.9]
    multisine = sum(np.sin(2 * np.pi * f * t + rng.uniform(0, 6.3)) for f in tones) / 3 * ((t >= 50) & (t < 70))
    inputs = {
        "lat": 0.1 * s3211 + 0.0005 * rng.standard_normal(t.size),
        "lon": 0.1 * multisine + 0.0005 * rng.standard_normal(t.size),
        "yaw": 0.0005 * rng.standard_normal(t.size),
    }
    maneuvers = [s for s in detect_segments(t, inputs) if s.kind != "hover"]
    assert [(s.axis, s.kind) for s in maneuvers] == [("lat", "3211"), ("lon", "multisine")]
    assert abs(maneuvers[0].start_s - 20.0) <= 0.3 and abs(maneuvers[0].end_s - 23.5) <= 0.3
    assert abs(maneuvers[1].start_s - 50.0) <= 0.3 and abs(maneuvers[1].end_s - 70.0) <= 0.3


def test_a_clean_doublet_on_a_slight_drift_is_bounded_at_its_steps() -> None:
    """Almost free of noise (as the excitation recovered from a closed loop), a bump of 0.4 % of the
    doublet just before it stands out of the noise yet is not the doublet: its bounds are its steps."""
    rng = np.random.default_rng(11)
    t = np.arange(1200) / RATE_HZ
    drift = 4e-4 * np.exp(-(((t - 4.8) / 0.3) ** 2))
    inputs = {"lat": 0.1 * _doublet(t - 5.0) + drift + 1e-5 * rng.standard_normal(t.size)}
    (found,) = [s for s in detect_segments(t, inputs) if s.kind != "hover"]
    assert (found.axis, found.kind) == ("lat", "doublet")
    assert abs(found.start_s - 5.0) <= 1 / RATE_HZ + 1e-9 and abs(found.end_s - 7.0) <= 1 / RATE_HZ + 1e-9


@pytest.mark.parametrize(
    ("inputs", "time_s", "fragment"),
    [
        ({"pitch": np.zeros(100)}, np.arange(100) / 100, "unknown axis 'pitch'"),
        ({"lon": np.zeros(99)}, np.arange(100) / 100, "has shape"),
        ({"lon": np.r_[np.zeros(99), np.nan]}, np.arange(100) / 100, "non-finite"),
        ({"lon": np.zeros(100)}, np.r_[np.arange(50), np.arange(51, 101)] / 100, "uniformly sampled"),
        ({}, np.arange(100) / 100, "no mixer input"),
    ],
)
def test_bad_detection_input_is_a_data_error(inputs, time_s, fragment) -> None:
    with pytest.raises(DataError, match=fragment):
        detect_segments(time_s, inputs)


# ------------------------------------------------------------------ System ID runs


def _run(start_s: float, axis: int, *settings: float) -> SystemIdRun:
    """A System ID run with SIDS `settings` (Mag, FSt, FSp, TFin, TC, TR, TFout) and no SIDD (end unknown)."""
    names = ("magnitude", "f_start_hz", "f_stop_hz", "fade_in_s", "const_s", "record_s", "fade_out_s")
    return SystemIdRun(
        start_s=start_s, end_s=float("nan"), axis=axis, axis_name="test", **dict(zip(names, settings, strict=True))
    )


def test_sids_rows_give_exact_sweep_segments() -> None:
    rows = [_run(100.0, 11, 0.1, 0.1, 10.0, 2.0, 20.0, 34.0, 1.0), _run(200.5, 13, 0.05, 0.5, 8.0, 1.0, 4.0, 30.0, 2.0)]
    lon, thr = segments_from_sid(rows)
    assert (lon.axis, lon.kind, lon.source, lon.start_s, lon.end_s) == ("lon", "sweep", "sids", 101.0, 135.0)
    assert (lon.f_min_hz, lon.f_max_hz) == (0.1, 10.0)
    assert (thr.axis, thr.start_s, thr.end_s) == ("thr", 201.5, 231.5)
    assert "Mixer Thrust" in thr.detail
    mode = segments_from_sid(rows, extent="mode")
    assert (mode[0].start_s, mode[0].end_s) == (100.0, 100.0 + 1.0 + 2.0 + 20.0 + 34.0 + 1.0)


def test_a_run_ends_with_its_sidd_samples_and_a_run_without_any_is_dropped() -> None:
    rows = {  # as a DataFlash reader hands them over: columns by field name, TimeUS in µs
        "TimeUS": [10_000_000, 60_000_000, 90_000_000],
        "Ax": [1, 8, 12],
        "Mag": [5.0, 20.0, 0.1],
        "FSt": [0.5, 0.5, 1.0],
        "FSp": [20.0, 20.0, 1.0],
        "TFin": [5.0, 5.0, 0.0],
        "TC": [4.0, 4.0, 2.0],
        "TR": [30.0, 30.0, 10.0],
        "TFout": [2.0, 2.0, 0.0],
    }
    sidd = np.r_[np.arange(10.0, 52.0, 0.0025), np.arange(60.0, 75.0, 0.0025)]  # run 2 aborted at 75 s
    first, second = segments_from_sid(rows, sidd_time_s=sidd)
    assert (first.axis, first.start_s, first.end_s) == ("lat", 11.0, 41.0)
    assert (second.axis, second.start_s) == ("lon", 61.0) and second.end_s == pytest.approx(75.0, abs=0.003)


@pytest.mark.parametrize(
    ("sid_axis", "axis"),
    [(1, "lat"), (2, "lon"), (3, "yaw"), (4, "lat"), (9, "yaw"), (10, "lat"), (13, "thr"), (17, "lon"), (18, "lat")],
)
def test_sid_axis_values_map_to_mixer_axes(sid_axis: int, axis: str) -> None:
    assert SID_AXES[sid_axis][0] == axis
    assert segments_from_sid([_run(0.0, sid_axis, 1.0, 1.0, 5.0, 1.0, 2.0, 10.0, 1.0)])[0].axis == axis


def test_an_unknown_sid_axis_is_a_data_error() -> None:
    with pytest.raises(DataError, match="SID_AXIS=26 is not a known axis"):
        segments_from_sid([_run(3.0, 26, 1.0, 1.0, 5.0, 1.0, 2.0, 10.0, 1.0)])
    with pytest.raises(DataError, match="lack the field"):
        segments_from_sid({"TimeUS": [0], "Ax": [1]})


# ------------------------------------------------------------------ segment files


def test_a_toml_file_is_read(tmp_path: Path) -> None:
    path = tmp_path / "segments.toml"
    path.write_text(
        '[[segment]]\nstart_s = 50.0\nend_s = 55.0\naxis = "lat"\nkind = "doublet"\n\n'
        '[[segment]]\nstart_s = 12.5\nend_s = 46.5\naxis = "lon"\nkind = "sweep"\nf_min_hz = 0.1\nf_max_hz = 10\n\n'
        '[[segment]]\nstart_s = 0\nend_s = 10\nkind = "hover"\n'
    )
    hover, sweep, doublet = read_segments_file(path)
    assert (sweep.axis, sweep.kind, sweep.source, sweep.start_s, sweep.end_s) == ("lon", "sweep", "user", 12.5, 46.5)
    assert (sweep.f_min_hz, sweep.f_max_hz) == (0.1, 10.0)
    assert (doublet.axis, doublet.kind) == ("lat", "doublet")
    assert (hover.axis, hover.kind) == (None, "hover")


@pytest.mark.parametrize(
    "text",
    [
        "start_s,end_s,axis,kind\n12.5,46.5,lon,sweep\n# a comment\n50,55,LAT,doublet\n0,10,,hover\n",
        "12.5,46.5,lon\n50,55,lat,doublet\n0,10,,hover\n",
    ],
    ids=["with-header", "without-header"],
)
def test_a_csv_file_is_read(tmp_path: Path, text: str) -> None:
    path = tmp_path / "segments.csv"
    path.write_text(text)
    hover, sweep, doublet = read_segments_file(path)
    assert (sweep.axis, sweep.kind, sweep.start_s, sweep.end_s) == ("lon", "sweep", 12.5, 46.5)
    assert (doublet.axis, doublet.kind) == ("lat", "doublet")
    assert (hover.axis, hover.kind) == (None, "hover")


@pytest.mark.parametrize(
    ("name", "text", "fragment"),
    [
        ("s.csv", "start_s,end_s,axis\n12,46,lon\n50,45,lat\n", r"s\.csv:3: end_s=45 is not after start_s=50"),
        ("s.csv", "start_s,end_s,axis\n12,46,pitch\n", r"s\.csv:2: unknown axis 'pitch'"),
        ("s.csv", "12,46,lon\n\n20,x,lon\n", r"s\.csv:3: end_s='x' is not a number"),
        ("s.csv", "start_s,end_s,roll\n1,2,3\n", r"s\.csv:1: unknown column 'roll'"),
        ("s.csv", "12,46,lon,wiggle\n", r"s\.csv:1: unknown kind 'wiggle'"),
        ("s.csv", "start_s,end_s,axis,kind\n0,10,lat,hover\n", r"s\.csv:2: a hover segment has no axis"),
        ("s.csv", "# nothing here\n", r"s\.csv: no segment found"),
        (
            "s.toml",
            '[[segment]]\nstart_s = 1\nend_s = 2\naxis = "lon"\n\n[[segment]]\nstart_s = 5\naxis = "lat"\n',
            r"s\.toml:6: end_s is missing",
        ),
        ("s.toml", '[[segment]]\nstart_s = 1\nend_s = 2\naxis = "lon"\nwidth = 3\n', r"s\.toml:1: unknown key 'width'"),
        ("s.toml", "[[segment]\nstart_s = 1\n", r"s\.toml: not valid TOML"),
        ("s.toml", "[maneuver]\nstart_s = 1\n", r"s\.toml: unknown top-level key 'maneuver'"),
        ("s.txt", "12,46,lon\n", r"s\.txt: a segments file is \.toml or \.csv"),
    ],
)
def test_a_bad_segments_file_names_the_file_and_line(tmp_path: Path, name: str, text: str, fragment: str) -> None:
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(DataError, match=fragment):
        read_segments_file(path)


def test_a_missing_segments_file_is_a_data_error(tmp_path: Path) -> None:
    with pytest.raises(DataError, match="cannot be read"):
        read_segments_file(tmp_path / "absent.toml")


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"axis": "lon", "kind": "hover"}, "a hover segment has no axis"),
        ({"axis": None, "kind": "sweep"}, "unknown axis None for a sweep"),
        ({"axis": "lon", "kind": "sweep", "f_min_hz": 5.0, "f_max_hz": 1.0}, "below f_min_hz"),
        ({"axis": "lon", "kind": "sweep", "f_min_hz": -1.0}, "positive frequency"),
        ({"axis": "lon", "kind": "sweep", "source": "guess"}, "unknown source"),
    ],
)
def test_an_inconsistent_segment_is_rejected(kwargs: dict, fragment: str) -> None:
    base = {"start_s": 1.0, "end_s": 2.0, "source": "user"} | kwargs
    with pytest.raises(DataError, match=fragment):
        Segment(**base)


def test_runs_from_the_dataflash_reader_are_accepted() -> None:
    run = SystemIdRun(
        start_s=50.0,
        end_s=80.0,
        axis=10,
        axis_name="mixer roll",
        magnitude=0.1,
        f_start_hz=0.5,
        f_stop_hz=20.0,
        fade_in_s=2.0,
        const_s=4.0,
        record_s=40.0,
        fade_out_s=1.0,
    )
    (segment,) = segments_from_sid([run])
    assert (segment.axis, segment.start_s, segment.end_s) == ("lat", 51.0, 80.0)  # ended early at the last SIDD
    no_sidd = SystemIdRun(
        start_s=50.0,
        end_s=float("nan"),
        axis=10,
        axis_name="mixer roll",
        magnitude=0.1,
        f_start_hz=0.5,
        f_stop_hz=20.0,
        fade_in_s=2.0,
        const_s=4.0,
        record_s=40.0,
        fade_out_s=1.0,
    )
    assert segments_from_sid([no_sidd])[0].end_s == 91.0


@pytest.mark.parametrize(("follows", "expected"), [(True, ["doublet"]), (False, [])])
def test_a_doublet_counts_only_when_the_rate_answers_it(follows: bool, expected: list[str]) -> None:
    """The same mixer doublet, with a pitch rate that integrates it (the airframe) or stays at its noise.

    The second is what a mission log showed: the yaw controller's chatter in a climb passed the doublet test
    in delta_yaw while r did not move.
    """
    rng = np.random.default_rng(12)
    t = np.arange(2000) / RATE_HZ
    delta = 0.1 * _doublet(t - 8.0) + 1e-3 * rng.standard_normal(t.size)
    answer = np.cumsum(delta) / RATE_HZ * 30.0 if follows else 0.0  # q = M_lon ∫ delta, M_lon = 30 rad/s² per unit
    q = answer + 0.01 * rng.standard_normal(t.size)
    found = detect_segments(t, {"lon": delta}, responses={"lon": {"delta_lon": delta, "q": q}})
    assert [s.kind for s in found if s.kind != "hover"] == expected


def test_a_detector_run_twice_gives_what_detect_segments_gives_each_time() -> None:
    """The sweeps found once from the responses serve both sets of inputs (a doublet, then none)."""
    rng = np.random.default_rng(13)
    t = np.arange(12000) / RATE_HZ
    sweep = np.where((t > 20.0) & (t < 60.0), np.sin(2 * np.pi * (0.2 + 0.05 * (t - 20.0)) * (t - 20.0)), 0.0)
    delta_lat = 0.05 * sweep + 1e-3 * rng.standard_normal(t.size)
    p = np.cumsum(delta_lat) / RATE_HZ * 30.0 + 0.01 * rng.standard_normal(t.size)
    delta_lon = 0.1 * _doublet(t - 80.0) + 1e-3 * rng.standard_normal(t.size)
    q = np.cumsum(delta_lon) / RATE_HZ * 30.0 + 0.01 * rng.standard_normal(t.size)
    responses = {"lat": {"delta_lat": delta_lat, "p": p}, "lon": {"delta_lon": delta_lon, "q": q}}
    detector = SegmentDetector(t, responses=responses)
    quiet_lon = 1e-3 * rng.standard_normal(t.size)
    for inputs in ({"lat": delta_lat, "lon": delta_lon}, {"lat": delta_lat, "lon": quiet_lon}):
        assert detector.detect(inputs) == detect_segments(t, inputs, responses=responses)
    kinds = [[(s.axis, s.kind) for s in detector.detect(i) if s.kind != "hover"] for i in ({"lon": delta_lon}, {})]
    assert kinds == [[("lat", "sweep"), ("lon", "doublet")], [("lat", "sweep")]]


@pytest.mark.parametrize(
    "bad", [{"threshold": 0.0}, {"min_hover_s": -1.0}, {"trend_window_s": float("nan")}, {"hover_margin_s": -0.1}]
)
def test_detection_options_are_checked(bad: dict[str, float]) -> None:
    with pytest.raises(ValueError, match=next(iter(bad))):
        DetectionOptions(**bad)


def test_a_longer_least_hover_finds_less_hover() -> None:
    """The options reach the detection: hover shorter than ``min_hover_s`` is not hover."""
    t = np.arange(0.0, 60.0, 0.01)
    quiet = {"lon": np.random.default_rng(3).normal(0.0, 1e-3, t.size)}
    assert [s.kind for s in detect_segments(t, quiet)] == ["hover"]
    assert detect_segments(t, quiet, options=DetectionOptions(min_hover_s=61.0)) == ()
