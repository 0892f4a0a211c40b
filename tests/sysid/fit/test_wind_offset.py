"""The wind a model's G_w is driven with: the anemometer's, low-passed as the wind step regresses on it."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import replace

import numpy as np
import pytest

from flightlogs.conditioning.condition import ConditionedFlight, ConditioningOptions, condition_flight
from flightlogs.frames import air_velocity_body, wind_to_body_axes
from flightlogs.readers.anemometer import read_anemometer_csv
from flightlogs.readers.dispatch import read_log
from simulator.campaign.demo_flight import write_demo_flight
from sysid.fit.result import WindClockOffset
from sysid.fit.wind import wind_cost
from sysid.fit.wind_offset import SMOOTHING_HZ, CostOf, _fine_costs, smoothed, smoothed_flights
from sysid.model import load_structure


@pytest.fixture(scope="module")
def flight(tmp_path_factory: pytest.TempPathFactory) -> ConditionedFlight:
    files = write_demo_flight(tmp_path_factory.mktemp("demo"), clock_offset_s=1.5)
    options = ConditioningOptions(wind_distance_m=4.6, wind_offset_s=1.5)
    return condition_flight(read_log(files.log), read_anemometer_csv(files.wind_csv), options)


def _noisy(flight: ConditionedFlight, seed: int) -> ConditionedFlight:
    """The flight with 0.3 m/s of white noise on the anemometer's north and east wind (u v w left as they were:
    only the smoothing's own change of them is compared)."""
    rng = np.random.default_rng(seed)
    records = []
    for record in flight.records:
        noise = {n: record[n] + 0.3 * rng.standard_normal(record.time_s.size) for n in ("wind_n", "wind_e")}
        records.append(replace(record, columns=dict(record.columns) | noise))
    return replace(flight, records=tuple(records))


def _above_cut_off(x: np.ndarray, rate_hz: float) -> float:
    """Share of `x`'s power above twice the smoothing's cut-off."""
    power = np.abs(np.fft.rfft(x - x.mean())) ** 2
    f = np.fft.rfftfreq(x.size, 1.0 / rate_hz)
    return float(power[f > 2 * SMOOTHING_HZ].sum() / power.sum())


def test_the_wind_is_low_passed_and_u_v_w_follow_it(flight: ConditionedFlight) -> None:
    noisy = _noisy(flight, seed=3)
    (smooth,) = smoothed_flights([noisy])
    assert smooth.wind == noisy.wind  # the clock offset and the alignment as they were
    assert len(smooth.records) == len(noisy.records)
    for before, after in zip(noisy.records, smooth.records):
        wind = np.column_stack([before["wind_n"], before["wind_e"]])
        change = np.column_stack([after["wind_n"], after["wind_e"]]) - wind
        np.testing.assert_allclose(change, smoothed(wind, before.rate_hz) - wind, atol=1e-12)
        assert _above_cut_off(after["wind_n"], after.rate_hz) < 0.01 < _above_cut_off(before["wind_n"], before.rate_hz)
        angles = [before.absolute(n) for n in ("phi", "theta", "psi")]
        uvw = air_velocity_body(np.zeros((change.shape[0], 3)), change, *angles)  # eq. 3.1: the ground speed kept
        for k, name in enumerate("uvw"):
            np.testing.assert_allclose(after[name] - before[name], uvw[:, k], atol=1e-12)
        body = wind_to_body_axes(change, angles[2])
        for k, name in enumerate(("wind_lon", "wind_lat")):
            np.testing.assert_allclose(after[name] - before[name], body[:, k], atol=1e-12)


def test_a_record_cut_or_thinned_moves_its_wind_as_one_made_for_it(flight: ConditionedFlight) -> None:
    """The scan cuts its records to the rows every move reaches and thins them for the coarse pass: the
    rotations of the record are taken for those rows, the same to the last bit as worked out for them anew."""
    from sysid.fit.wind_offset import _movable, _Moved

    (moved, *_) = _movable(flight.records, [flight], smooth=True)
    n = moved.record.time_s.size
    for made in (moved.cut(n // 5, n - n // 4), moved.every(20.0), moved.cut(n // 5, n - n // 4).every(20.0)):
        anew = _Moved.of(made.record, made.piece_time_s, made.piece_wind_ne)
        assert made.record.time_s.size < n
        for shift in (-1.3, 0.0, 0.47):
            ours, theirs = made.columns(shift), anew.columns(shift)
            assert ours.keys() == theirs.keys()
            for name in ours:
                np.testing.assert_array_equal(ours[name], theirs[name])


def test_a_record_moved_by_many_shifts_at_once_moves_as_by_each(flight: ConditionedFlight) -> None:
    """The scan moves a record's wind by all its trial shifts at once: each row is that shift's move, bitwise."""
    from sysid.fit.wind_offset import _movable

    (moved, *_) = _movable(flight.records, [flight], smooth=True)
    shifts = np.array([-4.9, -1.37, -0.01, 0.0, 0.013, 2.5])
    at_once = moved.columns(shifts)
    for k, shift in enumerate(shifts):
        alone = moved.columns(float(shift))
        assert at_once.keys() == alone.keys()
        for name in alone:
            assert at_once[name].shape == (shifts.size, moved.record.time_s.size)
            np.testing.assert_array_equal(at_once[name][k], alone[name])


@pytest.mark.parametrize("thinned", [False, True])
def test_the_costs_of_many_moves_are_those_of_each_move(flight: ConditionedFlight, thinned: bool) -> None:
    """The scan's costs of all its trials at once (:meth:`WindCost.costs`) are the cost of each trial alone, on
    the scan's cut (and, for the coarse pass, thinned) records: whole-sample and fractional moves, the wind
    read from its own record where a move does not give it, and records that move no velocity."""
    from sysid.fit.wind_offset import _movable

    structure = load_structure("hover-wind")
    movable = [m.cut(600, m.record.time_s.size - 600) for m in _movable(flight.records, [flight], smooth=True)]
    movable = [m.every(20.0) for m in movable] if thinned else movable
    records = [m.record for m in movable]
    trim = {
        n: float(np.mean([r.trim[n] for r in records if n in r.trim])) for n in {n for r in records for n in r.trim}
    }
    cost = wind_cost(structure, structure.values(), structure.constants_from_trim(trim), records)
    assert cost is not None
    shifts = np.array([-5.0, -1.5, -1.49, -0.255, 0.0, 0.03, 3.7])
    each = np.array([cost([m.columns(float(s)) for m in movable])[0] for s in shifts])
    np.testing.assert_allclose(cost.costs(m.columns(shifts) for m in movable), each, rtol=1e-10)
    assert np.ptp(each) > 0.01 * np.max(each)  # the moves change the cost: the rows are told apart
    for dropped in (("wind_lon",), ("u", "v", "w"), ("w",)):  # read from the record as it is
        partial = [{n: v for n, v in m.columns(shifts).items() if n not in dropped} for m in movable]
        alone = [cost([{n: v[k] for n, v in p.items()} for p in partial])[0] for k in range(shifts.size)]
        np.testing.assert_allclose(cost.costs(partial), alone, rtol=1e-10)


def test_rows_are_interpolated_as_numpy_interpolates_each() -> None:
    from sysid.fit.wind import _interpolated_rows

    rng = np.random.default_rng(5)
    xp = np.cumsum(rng.uniform(0.005, 0.015, 300))
    fp = rng.standard_normal((4, xp.size))
    x = np.concatenate([xp - 0.0123, xp[::7], [xp[0] - 1.0, xp[-1] + 1.0, xp[0], xp[-1]]])
    expected = np.array([np.interp(x, xp, row) for row in fp])
    np.testing.assert_allclose(_interpolated_rows(x, xp, fp), expected, rtol=0, atol=1e-14)
    np.testing.assert_allclose(_interpolated_rows(x, xp, fp[0]), expected[0], rtol=0, atol=1e-14)


def test_a_flight_without_wind_is_kept_as_it_is(flight: ConditionedFlight) -> None:
    calm = replace(flight, wind=None)
    assert smoothed_flights([calm])[0] is calm


class _Trial:
    """Stands for a record moved by the scan: the move it was asked for is what the cost reads."""

    def columns(self, shift_s: float | np.ndarray) -> dict[str, float | np.ndarray]:
        return {"shift_s": shift_s}


class _CostOf:
    """A residual least at `true_shift_s`, with a ripple of 0.3 s (the wind low-passed at 2 Hz) on a parabola."""

    def __init__(self, true_shift_s: float) -> None:
        self.true_shift_s = true_shift_s

    def __call__(self, moved: Sequence[Mapping[str, float]]) -> tuple[float, float, np.ndarray]:
        s = moved[0]["shift_s"] - self.true_shift_s
        return 1.0 + 4.0 * s**2 + 0.05 * (1.0 - np.cos(2 * np.pi * s / 0.3)), 2.0, np.zeros(1)

    def costs(self, moved: Iterable[Mapping[str, np.ndarray]]) -> np.ndarray:
        shifts = next(iter(moved))["shift_s"]
        return np.array([self([{"shift_s": float(s)}])[0] for s in shifts])


def _cost_of(true_shift_s: float) -> CostOf:
    return _CostOf(true_shift_s)


@pytest.mark.parametrize("true_shift_s", [0.0, 0.013, -0.047, 0.08, -0.099, 0.14, -0.2])
def test_the_fine_pass_finds_the_least_cost_of_the_whole_fine_grid(true_shift_s: float) -> None:
    """The coarse pass leaves the minimum within a coarse step of the centre (0.1 s); beyond it (-0.2 s) the
    fine pass walks to its ±0.15 s edge. Every cost it computes is the full grid's at that move."""
    centre, cost_of, trials = 0.0, _cost_of(true_shift_s), [_Trial()]
    grid = np.round(centre + np.arange(-0.15, 0.15 + 1e-9, 0.01), 10)
    whole = {float(s): cost_of([{"shift_s": float(s)}])[0] for s in grid}
    found = _fine_costs(centre, cost_of, trials)  # type: ignore[arg-type]
    assert min(found, key=found.__getitem__) == min(whole, key=whole.__getitem__)
    assert all(found[s] == whole[s] for s in found)
    best = min(whole, key=whole.__getitem__)
    assert all(round(best + k * 0.01, 10) in found for k in range(-3, 4) if abs(best + k * 0.01) <= 0.15 + 1e-9)
    if abs(true_shift_s) <= 0.05:
        assert len(found) <= 13  # not the 31 of the whole grid


def test_the_contrast_is_the_same_however_many_fine_trials_were_made() -> None:
    """The residual's median over the scan is that of its evenly spaced trials, not pulled down by the fine ones."""
    coarse = np.round(np.arange(-5.0, 5.0 + 1e-9, 0.1), 10)
    cost_of = _cost_of(1.234)
    cost = np.array([cost_of([{"shift_s": float(s)}])[0] for s in coarse])
    scan = WindClockOffset(
        shift_s=coarse,
        cost=cost,
        cost_without_wind=2.0,
        best_shift_s=1.2,
        sigma_s=0.01,
        used_clock_offset_s=0.0,
        transport_delay_s=0.5,
        measured=True,
        reason="",
        samples=1000,
    )
    fine = np.round(1.2 + np.arange(-0.15, 0.151, 0.01), 10)
    shifts = np.union1d(coarse, fine)
    denser = replace(scan, shift_s=shifts, cost=np.array([cost_of([{"shift_s": float(s)}])[0] for s in shifts]))
    assert float(np.median(denser.cost)) < float(np.median(cost))  # what the plain median would have read
    assert denser.contrast == pytest.approx(scan.contrast, abs=1e-12)
    assert scan.contrast == pytest.approx(1.0 - scan.cost_at(1.2) / float(np.median(cost)), abs=1e-12)
