"""Responses from one closed-loop sweep with no excitation logged (issue 14's independent corpus).

The airframe is the pitch axis of the chapter 3 octocopter in calm hover (Table
3.3 x 100 per unit of mixer input, actuator lag T_a, no delay): its phugoid is
unstable (0.88 +/- 1.69j rad/s), so a window's output keeps answering input
from before the window however long it is. A state feedback on q, theta and u
stabilises it; the sweep is injected at the mixer and only the mixer input
``delta_lon = e - K x`` and ``q`` are recorded, one 38 s record, as in an
ordinary PX4 log. The truth is the airframe's ``q / delta_lon``, analytic.

* Noise-free, the record's whole-length transforms obey ``Q = P D`` exactly;
  the windows alone (the composite before the single-record member) are off
  by up to 18 deg at 1-2 rad/s with coherence 0.95-1.
* With an unmeasured moment disturbance fed back by the loop, ``G_xy / G_xx``
  tends to ``P (1 - f)``, f the feedback's share of the input power, while
  the coherence hardly drops; flight without the excitation gives that
  floor, and removing it takes the bias away.
* A second input that is uncorrelated noise leaves the response on the
  airframe (conditioning costs an average, not accuracy, now that the
  whole-record member no longer needs more records than inputs); one that
  never varies is an error, never a silent singular matrix.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import signal as sps

from flightlogs.conditioning.condition import ConditionedFlight
from flightlogs.errors import DataError
from flightlogs.maneuvers.segments import Segment
from flightlogs.record import Record
from simulator.autopilot.excitation import Maneuver, sweep
from sysid.freqresp import ResponseOptions, coupled_inputs, frequency_responses, maneuver_band, quiet_records

G = 9.81
X_U, M_U, X_LON, M_LON, T_A = -0.3172, 0.769, -9.85, 52.51, 0.0458  # Table 3.3 (calm) x 100, per unit
A = np.array([[X_U, 0.0, -G, X_LON], [M_U, 0.0, 0.0, M_LON], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, -1.0 / T_A]])
B = np.array([[0.0], [0.0], [0.0], [1.0 / T_A]])
GAIN = np.array([[-0.03, 0.15, 0.6, 0.0]])  # delta = e - GAIN x: closed-loop poles -10.6, -5.2 +/- 4.9j, -1.15
FINE_HZ, RATE_HZ = 1000.0, 100.0
SWEEP = Maneuver(axis="lon", kind="sweep", start_s=1.0, amplitude=0.06, duration_s=36.0, f_start_hz=0.1, f_stop_hz=10.0)
OPTIONS = ResponseOptions(omega_min=0.8, omega_max=60.0)


def _airframe(omega: np.ndarray) -> np.ndarray:
    """``q / delta_lon`` of the open-loop airframe, analytic."""
    rows = [np.linalg.solve(1j * w * np.eye(4) - A, B)[1, 0] for w in omega]
    return np.array(rows)


def _disturbance(sigma: float, seed: int, seconds: float) -> np.ndarray:
    """Moment disturbance, rad/s^2: white noise through a first-order lag at 2 rad/s, on the fine grid."""
    white = np.random.default_rng(seed).normal(size=int(seconds * FINE_HZ)) * sigma * np.sqrt(FINE_HZ)
    b, a = sps.butter(1, 2.0 / (2 * np.pi), fs=FINE_HZ)
    return np.asarray(sps.lfilter(b, a, white))


def _fly(excitation: bool, disturbance: np.ndarray) -> Record:
    """38 s of closed loop, recorded at 100 Hz: ``delta_lon`` and ``q``."""
    t = np.arange(disturbance.size) / FINE_HZ
    e = sweep(t, SWEEP)[0] if excitation else np.zeros_like(t)
    closed = sps.StateSpace(
        A - B @ GAIN,
        np.hstack([B, [[0.0], [1.0], [0.0], [0.0]]]),
        np.vstack([[[0.0, 1.0, 0.0, 0.0]], -GAIN]),
        [[0.0, 0.0], [1.0, 0.0]],
    )
    _, y, _ = sps.lsim(closed, np.column_stack([e, disturbance]), t)
    step = int(FINE_HZ / RATE_HZ)
    table = pd.DataFrame({"delta_lon": y[::step, 1], "q": y[::step, 0]}, index=t[::step])
    return Record.from_table(table, units={"delta_lon": "-", "q": "rad/s"}, trim={}, source=Path("closed-loop"))


def _errors(response: np.ndarray, omega: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    ratio = response / _airframe(omega)
    return 20 * np.log10(np.abs(ratio)), np.degrees(np.angle(ratio))


def test_one_noise_free_closed_loop_sweep_gives_the_unstable_airframe_exactly() -> None:
    """0.1 dB / 0.5 deg wherever the coherence passes 0.5, 0.8-60 rad/s (before: windows only, 0.8 dB / 18 deg).

    Source: the analytic airframe. Tolerance: what is left is the local model of the member's noise
    (a parabola over +/-3 bins) and rounding; a windowed composite misses by 0.8 dB and 18 deg at 1-2 rad/s.
    """
    (response,) = frequency_responses([_fly(True, np.zeros(38_000))], ["delta_lon"], ["q"], OPTIONS)
    used = response.coherence >= 0.5
    magnitude_db, phase_deg = _errors(response.response, response.omega)
    assert response.whole_record and used.all() and response.omega[0] < 1.0
    assert np.max(np.abs(magnitude_db[used])) < 0.1
    assert np.max(np.abs(phase_deg[used])) < 0.5


def test_a_single_window_length_is_biased_there() -> None:
    """The same record through windows alone: the bias the member removes (documents the failure it fixes)."""
    options = ResponseOptions(omega_min=0.8, omega_max=60.0, whole_record=False)
    (response,) = frequency_responses([_fly(True, np.zeros(38_000))], ["delta_lon"], ["q"], options)
    low = (response.omega < 2.5) & (response.coherence >= 0.9)
    _, phase_deg = _errors(response.response, response.omega)
    assert low.any() and np.max(np.abs(phase_deg[low])) > 5.0


def _mean_low_bias_db(quiet: bool, seeds: range) -> float:
    """Mean log-magnitude error below 6 rad/s where the coherence passes 0.5, over `seeds`, dB."""
    biases = []
    for seed in seeds:
        record = _fly(True, _disturbance(0.3, 1000 * seed, 38.0))
        floor = [_fly(False, _disturbance(0.3, 1000 * seed + k + 1, 38.0)) for k in range(5)] if quiet else []
        (response,) = frequency_responses([record], ["delta_lon"], ["q"], OPTIONS, quiet=floor)
        used = (response.coherence >= 0.5) & (response.omega < 6.0)
        biases.append(float(np.mean(_errors(response.response, response.omega)[0][used])))
    return float(np.mean(biases))


def test_the_feedback_floor_removes_most_of_the_closed_loop_bias() -> None:
    """Moment disturbance (0.3 rad/s^2 white through a 2 rad/s lag) fed back by the loop, 6 flights.

    From the mixer input alone the magnitude below 6 rad/s is 2.5 dB low on average (``P (1 - f)``, from
    -1.3 to -3.6 dB flight to flight); with five 38 s stretches of the same loop flown without the sweep as
    floor, -0.9 dB (-0.1 to -2.1). What is left is the feedback's random part in the one record, and the
    gate's selection of the frequencies where it happened to be large (they pass ``G_xx >= 4 F_xx`` more
    easily): both are of the order of the floor's share, which the gate bounds. Tolerance: the mean
    within 1.2 dB and at most half the direct estimate's.
    """
    direct = _mean_low_bias_db(False, range(6))
    floored = _mean_low_bias_db(True, range(6))
    assert direct < -2.0
    assert abs(floored) < 1.2 and abs(floored) < 0.5 * abs(direct)


def test_feedback_dominated_frequencies_are_not_fitted() -> None:
    """Where the input's power is under `min_excitation_ratio` times its floor, the coherence is zero."""
    record = _fly(True, _disturbance(0.3, 7, 38.0))
    floor = [_fly(False, _disturbance(0.3, 8 + k, 38.0)) for k in range(3)]
    (plain,) = frequency_responses([record], ["delta_lon"], ["q"], OPTIONS)
    (strict,) = frequency_responses(
        [record], ["delta_lon"], ["q"], ResponseOptions(omega_min=0.8, omega_max=60.0, min_excitation_ratio=100.0)
    )
    (floored,) = frequency_responses(
        [record],
        ["delta_lon"],
        ["q"],
        ResponseOptions(omega_min=0.8, omega_max=60.0, min_excitation_ratio=100.0),
        quiet=floor,
    )
    np.testing.assert_array_equal(strict.coherence, plain.coherence)  # no quiet records: no floor, no gate
    cut = (floored.coherence == 0) & (plain.coherence >= 0.5)
    assert cut.any() and np.all(floored.omega[cut] < 10.0)
    assert np.all(floored.coherence[floored.omega > 15.0] == plain.coherence[plain.omega > 15.0])
    with pytest.raises(ValueError, match="min_excitation_ratio"):
        ResponseOptions(min_excitation_ratio=1.0)


@pytest.mark.parametrize(("n_records", "max_db", "max_deg"), [(1, 0.6, 4.5), (2, 0.5, 3.0)])
def test_an_uncorrelated_noise_input_leaves_the_response_on_the_airframe(
    n_records: int, max_db: float, max_deg: float
) -> None:
    """A second input of pure noise (a wind record the output ignores): the airframe, 0.8-60 rad/s.

    Before, a second input left as many records as inputs or fewer without the whole-record member:
    from one or two sweeps the response fell back on the windows, 0.8 dB / 13 deg off at 1-2 rad/s.
    Now their neighbouring bins give it (``sysid.freqresp._local``). Tolerance: from one record the
    local model spans +/-5 bins (7 coefficients), wide against the unstable pair at 1.9 rad/s;
    from two, +/-3 bins as for one input.
    """
    base = _fly(True, np.zeros(38_000))
    rng = np.random.default_rng(4)
    units = {**base.units, "wind_lon": "m/s"}
    records = [
        Record.from_table(
            base.table.assign(wind_lon=rng.normal(size=base.time_s.size)),
            units=units,
            trim={},
            source=base.source,
        )
        for _ in range(n_records)
    ]
    response = frequency_responses(records, ["delta_lon", "wind_lon"], ["q"], OPTIONS)[0]
    used = response.coherence >= 0.5
    magnitude_db, phase_deg = _errors(response.response, response.omega)
    assert response.whole_record and response.conditioned_on == ("wind_lon",) and used.all()
    assert np.max(np.abs(magnitude_db)) < max_db and np.max(np.abs(phase_deg)) < max_deg


def test_a_second_input_that_never_varies_is_an_error() -> None:
    """Not a silent singular spectral matrix: the message names the input."""
    record = _fly(True, np.zeros(38_000))
    silent = Record.from_table(
        record.table.assign(wind_lon=0.0),
        units={**record.units, "wind_lon": "m/s"},
        trim={},
        source=record.source,
    )
    with pytest.raises(DataError, match="input wind_lon does not vary"):
        frequency_responses([silent], ["delta_lon", "wind_lon"], ["q"], OPTIONS)


def _flight(segments: list[Segment]) -> ConditionedFlight:
    t = np.arange(0.0, 200.0, 0.01)
    table = pd.DataFrame({"delta_lon": np.sin(t), "q": np.cos(t)}, index=t)
    record = Record.from_table(table, units={"delta_lon": "-", "q": "rad/s"}, trim={}, source=Path("f.ulg"))
    return ConditionedFlight(source=Path("f.ulg"), records=(record,), segments=tuple(segments), rate_hz=100.0)


def test_quiet_records_are_the_other_maneuvers_and_hover_away_from_the_axis() -> None:
    """Other axes' maneuvers (with their 1 s margin) and hover, less 2 s before / 5 s after this axis's."""
    flight = _flight(
        [
            Segment(axis=None, kind="hover", start_s=10.0, end_s=20.0, source="detected"),
            Segment(axis="lon", kind="sweep", start_s=20.0, end_s=56.0, source="user", f_min_hz=0.1, f_max_hz=8.0),
            Segment(axis="lat", kind="sweep", start_s=58.0, end_s=94.0, source="user", f_min_hz=0.2, f_max_hz=10.0),
            Segment(axis="lon", kind="doublet", start_s=120.0, end_s=122.0, source="user"),
        ]
    )
    spans = [(round(r.start_s, 2), round(r.end_s, 2)) for r in quiet_records([flight], "lon")]
    assert spans == [(10.0, 18.0), (61.0, 95.0)]  # hover up to 2 s before the sweep; lat from 5 s after it
    lat = [(round(r.start_s, 2), round(r.end_s, 2)) for r in quiet_records([flight], "lat")]
    assert lat == [(10.0, 56.0), (119.0, 123.0)]  # hover + lon sweep merged; the lon doublet with its margins
    assert maneuver_band([flight], "lon") == pytest.approx((2 * np.pi * 0.1, 2 * np.pi * 8.0))
    assert maneuver_band([flight], "lon", kind="doublet") is None  # a doublet has no band
    assert maneuver_band([flight], "yaw") is None


def test_coupled_inputs_are_those_that_move_with_the_maneuver() -> None:
    """In wind a lon sweep moves the thrust through the altitude loop: correlated, so conditioned on; a thrust
    input that is feedback of its own noise only is not (the calm case), nor one that never varies."""
    record = _fly(True, _disturbance(0.03, 5, 38.0))
    rng = np.random.default_rng(6)
    delta = record["delta_lon"]
    b, a = sps.butter(1, 3.0, fs=RATE_HZ)
    table = record.table.assign(
        delta_thr=sps.lfilter(b, a, delta) + 0.2 * np.std(delta) * rng.normal(size=delta.size),
        delta_lat=rng.normal(size=delta.size),
        delta_yaw=0.0,
    )
    units = {**record.units, "delta_thr": "-", "delta_lat": "-", "delta_yaw": "-"}
    flown = Record.from_table(table, units=units, trim={}, source=record.source)
    found = coupled_inputs([flown], "delta_lon", ["delta_lat", "delta_yaw", "delta_thr"], OPTIONS)
    assert found == ("delta_thr",)
    # the candidates are judged together (one transform of the control per window length), each as if alone
    alone = [
        name
        for name in ("delta_lat", "delta_yaw", "delta_thr")
        if coupled_inputs([flown], "delta_lon", [name], OPTIONS)
    ]
    assert tuple(alone) == found
    both = flown.table.assign(delta_lat=flown["delta_thr"] + 0.1 * np.std(delta) * rng.normal(size=delta.size))
    twice = Record.from_table(both, units=units, trim={}, source=record.source)
    assert coupled_inputs([twice], "delta_lon", ["delta_thr", "delta_yaw", "delta_lat"], OPTIONS) == (
        "delta_thr",
        "delta_lat",
    )  # in the order given
