"""Gating (eq. 3.8), HDF5 round trip, maneuver records and pairs, and the errors users meet."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import h5py
import numpy as np
import pandas as pd
import pytest

from flightlogs.conditioning.condition import ConditionedFlight
from flightlogs.errors import DataError, LogFormatError, MissingSignalError
from flightlogs.maneuvers.segments import Segment
from flightlogs.record import Record
from sysid.freqresp import (
    DEFAULT_PAIRS,
    FrequencyResponse,
    Gating,
    ResponseOptions,
    default_pairs,
    fit_range,
    flight_responses,
    frequency_responses,
    gate_responses,
    maneuver_records,
    parse_pairs,
    read_responses,
    write_responses,
)
from sysid.freqresp import io as freqresp_io

OMEGA = np.geomspace(1.0, 100.0, 81)  # 40 points per decade


def _response(
    coherence: np.ndarray, *, output: str = "q", input_: str = "delta_lon", **extra: object
) -> FrequencyResponse:
    n = OMEGA.size
    rng = np.random.default_rng(0)
    values: dict[str, Any] = {
        "input": input_,
        "output": output,
        "omega": OMEGA.copy(),
        "response": rng.normal(size=n) + 1j * rng.normal(size=n),
        "coherence": np.asarray(coherence, dtype=float),
        "random_error": np.full(n, 0.05),
        "input_autospectrum": np.full(n, 2.0),
        "output_autospectrum": np.full(n, 3.0),
        "cross_spectrum": np.full(n, 1.0 + 0.5j),
        "windows_s": (2.5, 17.0),
    }
    values.update(extra)
    return FrequencyResponse(**values)


def _band(lo: float, hi: float, inside: float = 0.9, outside: float = 0.2) -> np.ndarray:
    return np.where((OMEGA >= lo) & (OMEGA <= hi), inside, outside)


def test_kept_responses_get_the_widest_range_above_the_threshold() -> None:
    coherence = np.maximum(_band(2.0, 40.0), _band(60.0, 90.0))
    result = gate_responses([_response(coherence)])
    (kept,) = result.kept
    assert result.dropped == ()
    assert kept.fit_range == pytest.approx((OMEGA[OMEGA >= 2.0][0], OMEGA[OMEGA <= 40.0][-1]))
    original = _response(coherence)
    for field in dataclasses.fields(FrequencyResponse):
        if field.name != "fit_range":
            assert np.array_equal(getattr(kept, field.name), getattr(original, field.name))


def test_a_dip_narrower_than_the_bridge_does_not_split_the_range() -> None:
    coherence = _band(2.0, 40.0)
    coherence[np.argmin(np.abs(OMEGA - 10.0))] = 0.3  # one point, 0.025 decade
    assert fit_range(OMEGA, coherence, 0.5) == pytest.approx((OMEGA[OMEGA >= 2.0][0], OMEGA[OMEGA <= 40.0][-1]))
    wide = _band(2.0, 40.0) * np.where((OMEGA > 8.0) & (OMEGA < 12.0), 0.1, 1.0)  # 0.18 decade: splits
    lo, hi = fit_range(OMEGA, wide, 0.5) or (0.0, 0.0)
    assert lo == pytest.approx(OMEGA[OMEGA >= 2.0][0]) and hi < 8.0  # 0.6 decade beats the 0.52 above the dip


@pytest.mark.parametrize(("hi", "kept"), [(1.9, False), (2.1, True)])
def test_the_range_must_span_three_tenths_of_a_decade(hi: float, kept: bool) -> None:
    """log10(2.1) = 0.32 passes, log10(1.9) = 0.28 fails (dissertation eq. 3.8)."""
    result = gate_responses([_response(_band(1.0, hi))])
    assert (len(result.kept) == 1) is kept
    if not kept:
        (dropped,) = result.dropped
        assert (dropped.input, dropped.output, dropped.pair) == ("delta_lon", "q", "q/delta_lon")
        assert "0.28 decade" in dropped.reason and "the 0.3 decade required" in dropped.reason


def test_stricter_coherence_option_drops_a_marginal_response() -> None:
    marginal = _response(_band(2.0, 40.0, inside=0.55))
    assert len(gate_responses([marginal]).kept) == 1
    strict = gate_responses([marginal], Gating(min_coherence=0.6))
    assert strict.kept == ()
    assert strict.dropped[0].reason == "q/delta_lon: coherence never reaches 0.6 (at most 0.55)."


def test_order_is_kept_and_every_response_is_accounted_for() -> None:
    responses = [_response(_band(1.0, 50.0), output=name) for name in ("q", "ax")]
    responses.insert(1, _response(np.full(OMEGA.size, 0.1), output="theta"))
    result = gate_responses(responses)
    assert [r.output for r in result.kept] == ["q", "ax"] and [d.output for d in result.dropped] == ["theta"]


@pytest.mark.parametrize("kwargs", [{"min_coherence": 1.0}, {"min_coherence": 0.0}, {"min_decades": 0.0}])
def test_gate_thresholds_are_checked(kwargs: dict[str, float]) -> None:
    with pytest.raises(ValueError):
        Gating(**kwargs)


def test_responses_round_trip_through_hdf5(tmp_path: Path) -> None:
    gated = dataclasses.replace(
        _response(_band(1.0, 50.0), input_unit="%", output_unit="rad/s", reference="excitation", whole_record=True),
        fit_range=(1.0, 50.0),
    )
    conditioned = _response(_band(1.0, 50.0), output="ax", conditioned_on=("wind_lon",), windows_s=(4.0,))
    target = tmp_path / "fr.h5"
    write_responses(target, [gated, conditioned])
    back = read_responses(target)
    for original, read in zip((gated, conditioned), back):
        for field in dataclasses.fields(FrequencyResponse):
            a, b = getattr(original, field.name), getattr(read, field.name)
            assert np.array_equal(a, b) if isinstance(a, np.ndarray) else a == b, field.name
    with h5py.File(target) as h5:
        assert h5.attrs["schema_version"] == freqresp_io.RESPONSES_SCHEMA_VERSION
        group = h5["responses"]["000"]
        assert group["omega"].attrs["unit"] == b"rad/s"
        assert group["response"].attrs["unit"] == b"(rad/s)/(%)"
        assert group["input_autospectrum"].attrs["unit"] == b"(%)^2/(rad/s)"
        assert group.attrs["reference"] == b"excitation" and "reference" not in h5["responses"]["001"].attrs


def test_a_file_without_the_newer_attributes_reads_as_no_reference(tmp_path: Path) -> None:
    target = tmp_path / "old.h5"
    write_responses(target, [_response(_band(1.0, 50.0), reference="excitation", whole_record=True)])
    with h5py.File(target, "a") as h5:
        for name in ("reference", "whole_record"):
            del h5["responses"]["000"].attrs[name]
    (back,) = read_responses(target)
    assert back.reference is None and back.whole_record is False


def test_a_failed_write_leaves_the_old_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    target = tmp_path / "fr.h5"
    write_responses(target, [_response(_band(1.0, 50.0))])

    def broken(group: h5py.Group, response: FrequencyResponse) -> None:
        raise OSError("disk full")

    monkeypatch.setattr(freqresp_io, "_write_one", broken)
    with pytest.raises(OSError):
        write_responses(target, [_response(_band(1.0, 50.0), output="ax")])
    assert [r.output for r in read_responses(target)] == ["q"]
    assert list(tmp_path.iterdir()) == [target]


def test_reading_a_foreign_or_newer_file_is_a_format_error(tmp_path: Path) -> None:
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as h5:
        h5.attrs["schema"] = "something else"
    with pytest.raises(LogFormatError, match="no flight-sysid frequency responses"):
        read_responses(other)
    newer = tmp_path / "newer.h5"
    write_responses(newer, [])
    with h5py.File(newer, "a") as h5:
        h5.attrs["schema_version"] = 99
    with pytest.raises(LogFormatError, match="newer"):
        read_responses(newer)
    text = tmp_path / "fr.h5.txt"
    text.write_text("not hdf5")
    with pytest.raises(LogFormatError, match="not an HDF5 file"):
        read_responses(text)


# --- records, pairs, flights -------------------------------------------------------------------------------

RATE_HZ = 100.0


def _flight(*, gap: tuple[float, float] | None = None, seed: int = 0, excitation: str = "none") -> ConditionedFlight:
    """100 s at 100 Hz: a lon sweep 10-50 s (q = 2 delta_lon + noise), a lat sweep 60-90 s, a lon doublet 52-54 s.

    Outside the lon sweep (and its 1 s margins) delta_lon is a twentieth as large, a closed loop's feedback:
    flight without a lon maneuver is the floor :func:`flight_responses` removes (``quiet_records``).

    `excitation`: "none" (as PX4), "sweeps" (logged during the sweeps only, as ArduPilot's SIDD: the lon one
    is delta_lon there, the mixer input being the excitation itself), "lat" (during the lat sweep only).
    """
    rng = np.random.default_rng(seed)
    t = np.arange(int(100 * RATE_HZ)) / RATE_HZ
    delta = rng.normal(size=t.size) * np.where((t >= 9.0) & (t <= 51.0), 1.0, 0.05)
    columns = {
        "delta_lon": delta,
        "q": 2.0 * delta + 0.1 * rng.normal(size=t.size),
        "ax": rng.normal(size=t.size),
        "delta_lat": rng.normal(size=t.size),
        "p": rng.normal(size=t.size),
    }
    if excitation != "none":
        lon, lat = (t >= 10.0) & (t <= 50.0), (t >= 60.0) & (t <= 90.0)
        columns["excitation"] = np.where(lon, delta, 0.0) * (excitation == "sweeps") + np.where(
            lat, columns["delta_lat"], 0.0
        )
    table = pd.DataFrame(columns, index=t)
    units = {name: "-" for name in columns}
    whole = Record.from_table(table, units=units, trim={}, source=Path("f.bin"), label="piece 1 of 1")
    records = (whole,) if gap is None else (whole.between(0.0, gap[0]), whole.between(gap[1], 99.99))
    segments = (
        Segment(axis="lon", kind="sweep", start_s=10.0, end_s=50.0, source="detected"),
        Segment(axis="lon", kind="doublet", start_s=52.0, end_s=54.0, source="detected"),
        Segment(axis="lat", kind="sweep", start_s=60.0, end_s=90.0, source="detected"),
        Segment(axis=None, kind="hover", start_s=91.0, end_s=99.0, source="detected"),
    )
    return ConditionedFlight(source=Path("f.bin"), records=records, segments=segments, rate_hz=RATE_HZ)


def test_maneuver_records_keep_a_margin_that_stops_at_the_next_maneuver() -> None:
    (piece,) = maneuver_records([_flight()], "lon")
    assert piece.start_s == pytest.approx(9.0) and piece.end_s == pytest.approx(51.0)  # the doublet starts at 52 s
    assert "lon sweep 10.00-50.00" in piece.label
    (doublet,) = maneuver_records([_flight()], "lon", kind="doublet", margin_s=3.0)
    assert doublet.start_s == pytest.approx(50.0) and doublet.end_s == pytest.approx(57.0)


def test_a_maneuver_cut_by_a_gap_gives_two_pieces_and_flights_add_up() -> None:
    pieces = maneuver_records([_flight(gap=(30.0, 31.0)), _flight(seed=1)], "lon", margin_s=0.0)
    assert [(round(p.start_s, 2), round(p.end_s, 2)) for p in pieces] == [(10.0, 30.0), (31.0, 50.0), (10.0, 50.0)]
    assert maneuver_records([_flight()], "yaw") == []
    with pytest.raises(DataError, match="not a mixer axis"):
        maneuver_records([_flight()], "pitch")


def test_default_pairs_follow_the_axes_with_sweeps_and_the_signals_logged() -> None:
    assert default_pairs([_flight()]) == (("p", "delta_lat"), ("q", "delta_lon"), ("ax", "delta_lon"))
    assert DEFAULT_PAIRS["lon"][:2] == ("q", "ax") and DEFAULT_PAIRS["thr"] == ("az", "w")


def test_flight_responses_compute_the_pairs_on_their_axis() -> None:
    found = flight_responses(
        [_flight()], [("q", "delta_lon"), ("p", "delta_lat")], options=ResponseOptions(omega_min=2.0, n_freq=40)
    )
    q, p = found.responses
    assert (q.pair, p.pair) == ("q/delta_lon", "p/delta_lat") and dict(found.pieces) == {"lon": 1, "lat": 1}
    good = q.coherence > 0.9
    assert good.mean() > 0.9 and np.allclose(q.response[good], 2.0, rtol=0.05)


@pytest.mark.parametrize(
    ("pairs", "error", "fragment"),
    [
        ([("q", "wind_lon")], DataError, "cannot tell which maneuvers"),
        ([("r", "delta_yaw")], DataError, "no sweep on axis yaw in f.bin"),
        ([("az", "delta_lon")], MissingSignalError, "has no signal az"),
    ],
)
def test_flight_responses_errors_name_the_problem(
    pairs: list[tuple[str, str]], error: type[Exception], fragment: str
) -> None:
    with pytest.raises(error, match=fragment):
        flight_responses([_flight()], pairs)


def test_a_flight_without_sweeps_has_no_default_pairs() -> None:
    quiet = dataclasses.replace(_flight(), segments=())
    with pytest.raises(DataError, match="no sweep on any axis in f.bin"):
        flight_responses([quiet])


def test_the_logged_excitation_is_the_reference_where_every_piece_carries_it() -> None:
    options = ResponseOptions(omega_min=2.0, n_freq=40)
    found = flight_responses([_flight(excitation="sweeps")], [("q", "delta_lon"), ("p", "delta_lat")], options=options)
    q, p = found.responses
    assert (q.reference, p.reference) == ("excitation", "excitation")
    assert found.notes == tuple(
        f"{axis}: the logged excitation (SIDD) is the reference of the delta_{axis} responses, H = G_ry / G_rx."
        for axis in ("lon", "lat")
    )
    good = q.coherence > 0.9
    assert good.mean() > 0.9 and np.allclose(q.response[good], 2.0, rtol=0.05)
    off = flight_responses([_flight(excitation="sweeps")], [("q", "delta_lon")], options=options, use_excitation=False)
    assert off.responses[0].reference is None and "reference not used, as asked" in off.notes[0]


def test_without_a_logged_excitation_the_mixer_input_is_used_and_said_so() -> None:
    """PX4 logs no excitation; an axis whose pieces do not all carry it falls back too."""
    options = ResponseOptions(omega_min=2.0, n_freq=40)
    px4 = flight_responses([_flight()], [("q", "delta_lon")], options=options)
    assert px4.responses[0].reference is None
    assert px4.notes == (
        "lon: none of the sweep pieces carry a logged excitation (only ArduPilot's System ID mode logs one, SIDD): responses "
        "computed from the mixer input delta_lon, which in closed loop also carries the feedback "
        "of noise and turbulence.",
    )
    mixed = flight_responses([_flight(excitation="sweeps"), _flight(seed=1)], [("q", "delta_lon")], options=options)
    assert mixed.responses[0].reference is None and "only 1 of 2 of the sweep pieces" in mixed.notes[0]
    lat_only = flight_responses([_flight(excitation="lat")], [("q", "delta_lon"), ("p", "delta_lat")], options=options)
    assert [r.reference for r in lat_only.responses] == [None, "excitation"]
    wind_only = flight_responses([_flight(excitation="sweeps")], [("q", "ax")], axis="lon", options=options)
    assert wind_only.responses[0].reference is None and "no mixer input delta_lon" in wind_only.notes[0]


def test_a_reference_asked_for_is_used_on_every_axis_or_is_an_error() -> None:
    options = ResponseOptions(omega_min=2.0, n_freq=40, reference="excitation")
    found = flight_responses([_flight(excitation="sweeps")], [("q", "delta_lon")], options=options)
    assert found.responses[0].reference == "excitation" and "(as asked)" in found.notes[0]
    with pytest.raises(MissingSignalError, match="has no signal excitation"):
        flight_responses([_flight()], [("q", "delta_lon")], options=options)
    with pytest.raises(DataError, match="reference excitation does not vary in any record"):
        flight_responses([_flight(excitation="lat")], [("q", "delta_lon")], options=options)


def test_two_inputs_on_one_axis_are_conditioned_on_each_other() -> None:
    found = flight_responses(
        [_flight()], [("q", "delta_lon"), ("q", "ax")], axis="lon", options=ResponseOptions(omega_min=2.0, n_freq=20)
    )
    to_delta, to_ax = found.responses
    assert (to_delta.conditioned_on, to_ax.conditioned_on) == (("ax",), ("delta_lon",))
    assert np.all(np.abs(np.log(to_delta.response / 2.0)) < 3.5 * to_delta.random_error)
    assert np.all(np.abs(to_ax.response) < 0.25) and np.median(to_ax.coherence) < 0.1


def test_parse_pairs() -> None:
    assert parse_pairs("q/delta_lon,ax/delta_lon,q/delta_lon") == (("q", "delta_lon"), ("ax", "delta_lon"))
    for bad in ("q", "q/", "/delta_lon", "q/delta/lon", "q/delta_lon,,ax/delta_lon"):
        with pytest.raises(ValueError, match="OUTPUT/INPUT"):
            parse_pairs(bad)


# --- options and frequency_responses errors ----------------------------------------------------------------


@pytest.mark.parametrize(
    "kwargs",
    [
        {"omega_min": 0.0},
        {"omega_min": 10.0, "omega_max": 5.0},
        {"n_freq": 1},
        {"n_freq": 2.5},
        {"window_lengths_s": ()},
        {"window_lengths_s": (2.0, -1.0)},
        {"overlap": 0.95},
        {"overlap": -0.1},
        {"taper": "no-such-window"},
        {"min_cycles": 0.0},
        {"spacing": "octave"},
        {"reference": ""},
    ],
)
def test_options_are_checked(kwargs: dict[str, object]) -> None:
    with pytest.raises(ValueError):
        ResponseOptions(**kwargs)  # type: ignore[arg-type]


def test_window_lengths_are_sorted_and_unique() -> None:
    assert ResponseOptions(window_lengths_s=(8.0, 2.0, 8.0)).window_lengths_s == (2.0, 8.0)


def _simple(columns: dict[str, np.ndarray], rate_hz: float = RATE_HZ) -> Record:
    t = np.arange(next(iter(columns.values())).size) / rate_hz
    return Record.from_table(
        pd.DataFrame(columns, index=t),
        units={name: "-" for name in columns},
        trim={},
        source=Path("x.ulg"),
        label="r",
    )


@pytest.mark.parametrize(
    ("records", "inputs", "outputs", "error", "fragment"),
    [
        ([], ["x"], ["y"], DataError, "no records"),
        ("two rates", ["x"], ["y"], DataError, "not all at one rate"),
        ("nan", ["x"], ["y"], DataError, "NaN or infinite values in y"),
        ("constant", ["x"], ["y"], DataError, "input x does not vary"),
        ("short", ["x"], ["y"], DataError, "longer than every record"),
        ("ok", ["x"], ["z"], MissingSignalError, "has no signal z"),
        ("ok", ["x"], ["x"], DataError, "named twice"),
        ("ok", [], ["y"], DataError, "at least one input"),
        ("ok", ["x"], ["y"], DataError, "reference y is also an input or output"),
    ],
)
def test_bad_inputs_raise_one_sentence(
    records: object, inputs: list[str], outputs: list[str], error: type[Exception], fragment: str
) -> None:
    rng = np.random.default_rng(0)
    x, y = rng.normal(size=3000), rng.normal(size=3000)
    cases = {
        "two rates": [_simple({"x": x, "y": y}), _simple({"x": x, "y": y}, rate_hz=50.0)],
        "nan": [_simple({"x": x, "y": np.where(np.arange(3000) == 5, np.nan, y)})],
        "constant": [_simple({"x": np.zeros(3000), "y": y})],
        "ok": [_simple({"x": x, "y": y})],
    }
    chosen = cases.get(records, records) if isinstance(records, str) else records
    options = ResponseOptions(window_lengths_s=(40.0,)) if records == "short" else ResponseOptions()
    if fragment.startswith("reference"):
        options = ResponseOptions(reference="y")
    if records == "short":
        chosen = cases["ok"]
    with pytest.raises(error, match=fragment):
        frequency_responses(chosen, inputs, outputs, options)  # type: ignore[arg-type]


def test_a_grid_above_the_nyquist_frequency_is_refused() -> None:
    record = _simple({"x": np.random.default_rng(0).normal(size=2000), "y": np.ones(2000)}, rate_hz=20.0)
    with pytest.raises(DataError, match="above the Nyquist frequency 62.8 rad/s of the 20 Hz records"):
        frequency_responses([record], ["x"], ["y"])


def test_the_phase_branch_is_fixed_where_the_response_is_coherent() -> None:
    """A 20 ms delay, with noise at the incoherent low end that turns the phase a whole turn there.

    Unwrapped from the first grid point the whole curve sat 360 deg low (kd0aij's q/q_ref read -371 deg at
    4 rad/s where the loop tracks with -11 deg); anchored at the first point of coherence 0.6, the delay's
    -omega tau is exact on the coherent part.
    """
    delay = np.exp(-1j * OMEGA * 0.02)
    noisy = OMEGA < 1.5
    steps = np.cumsum(noisy) * -2 * np.pi / noisy.sum()  # noise: steps of under half a turn, a turn in all
    response = _response(np.where(noisy, 0.2, 0.95), response=delay * np.exp(1j * np.where(noisy, steps, 0.0)))
    coherent = ~noisy
    assert np.degrees(np.unwrap(np.angle(response.response)))[coherent][0] < -300.0  # the naive unwrap: a turn low
    assert response.phase_deg[coherent] == pytest.approx(-np.degrees(OMEGA[coherent] * 0.02), abs=1e-9)


def test_a_lone_point_past_a_bridged_dip_at_the_top_does_not_extend_the_range() -> None:
    """The shape met on a fleet log's yaw sweep: good to the sweep's top, a dip of two points, one point at 0.51
    (its gain a hundred times the response's): the range ends below the dip. Coherence that comes back for more
    points than the dip held is bridged, and at the bottom, where a sweep dwells, a short stretch is kept."""
    coherence = _band(2.0, 40.0)
    inside = np.flatnonzero(coherence > 0.5)
    top = inside[-1]
    coherence[top + 1 : top + 4] = [0.36, 0.13, 0.51]
    assert np.log10(OMEGA[top + 3] / OMEGA[top + 1]) <= 0.05 + 1e-9  # a dip the bridge spans
    assert fit_range(OMEGA, coherence, 0.5) == pytest.approx((OMEGA[inside[0]], OMEGA[top]))
    coherence[top + 4 : top + 6] = 0.8
    assert fit_range(OMEGA, coherence, 0.5) == pytest.approx((OMEGA[inside[0]], OMEGA[top + 5]))
    bottom = inside[0]
    coherence[bottom - 3 : bottom] = [0.51, 0.13, 0.36]
    assert fit_range(OMEGA, coherence, 0.5) == pytest.approx((OMEGA[bottom - 3], OMEGA[top + 5]))
