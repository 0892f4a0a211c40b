"""Identification on logs our simulator did not write (issue 14): the held-out calm sweep logs of the independent corpus.

``tests/independent_sim`` flies the Table 3.3 octocopter in closed loop
(PX4-like cascade; PX4 at 250 Hz, ArduPilot at 400 Hz), injects sweeps of
5-8 % of the mixer range after the rate loop and logs nothing about them.
The maneuvers are given (the true ``--segments`` file the generator
writes: detection is tested elsewhere), so what is tested here is the
front end from the records to the responses, and the fit. The front end was
tuned on the corpus's TUNING cases only; every assertion is on HELD-OUT logs.

Measured here (truth: the case's ``hover_parameters``; before -> after the
fixes of this test's commit; errors in % or ms):

* ``heldout-px4-sweeps``: N_yaw +26.3 -> -4.8, tau_yaw +11.4 -> -0.5 ms (the
  yaw sweep stops at 5 Hz; above it the mixer input is only the autopilot's
  feedback of gyro noise, coherent with r through the controller's inverse:
  +12-16 dB at 38-70 rad/s with gamma^2 0.75-0.92); T_a -10.0 -> -3.8,
  M_lon -6.6 -> -3.1, X_lon -5.1 -> -3.2, L_lat -3.8 -> -1.6, Y_lat -5.6 -> -3.4;
  N_r -1.8 -> dropped (truth 0; the feedback of the moment disturbance biases
  ``G_xy / G_xx`` towards ``P (1 - f)``: -16 dB at 1 rad/s).
* ``heldout-ap-sweeps``: N_yaw +26.9 -> -0.9, tau_yaw +4.0 -> -0.4 ms,
  T_a -8.0 -> -3.2, L_lat -4.3 -> -3.8.

The speed derivatives X_u, M_u, Y_v and L_v are not within 5 % (heldout-px4:
-22, +87, +14, -17 %; heldout-ap: -5, -14, -30, +20 %): they shape the
responses below about 3 rad/s only, where these closed-loop logs carry
little excitation (the linear sweeps pass 0.15-0.5 Hz in 1.5 s, under their
fade-in) and the feedback of the disturbances is as large as it. With the
true excitation, never logged, given as the reference (instrumental
variables, free of the feedback's bias) they are still -16, +49, +11, -11 %
on heldout-px4-sweeps, and on four other seeds of a tuning case from -12 to
+37 %: the limit is the data's, not the front end's. They are checked in
:func:`test_speed_derivatives_are_inside_their_own_accuracy` against what
the data can give.
"""

from __future__ import annotations

import json
import math

import pytest
from independent_sim.fixtures import independent_corpus_fixture  # noqa: F401 (registers the fixture)

from flightlogs.conditioning.condition import ConditioningOptions
from flightlogs.readers.segments_file import read_segments_file
from sysid.fit import IdentifyOptions, identify_logs
from sysid.fit.result import IdentifiedModel

pytestmark = [  # about 25 s in all (four logs generated, ingested and fitted once)
    pytest.mark.filterwarnings("ignore:no wind given:flightlogs.errors.DataQualityWarning"),  # calm: no anemometer
]

HELDOUT_SWEEPS = ["heldout-px4-sweeps", "heldout-ap-sweeps"]
#: Table 3.3 parameters whose responses the sweeps excite well (everything but the speed derivatives).
WELL_EXCITED = ("X_lon", "M_lon", "Y_lat", "L_lat", "N_yaw", "Z_thr", "T_a")
DELAYS = ("tau_lat", "tau_lon", "tau_yaw")
SPEED_DERIVATIVES = ("X_u", "M_u", "Y_v", "L_v")
RELATIVE = 0.05  # issue 14: within 5 % of truth
DELAY_S = 0.002  # issue 14: within 2 ms of truth
CR_MULTIPLE = 2.0  # issue 14: truth inside 2 Cramér-Rao bounds


_FITTED: dict[str, tuple[IdentifiedModel, dict[str, float]]] = {}


def _fit(corpus, name: str, *, partial: bool = False) -> tuple[IdentifiedModel, dict[str, float]]:  # type: ignore[no-untyped-def]
    """The `hover` fit of a held-out case with its true segments, and the truth (fitted once per session)."""
    key = f"{name} partial" if partial else name
    if key not in _FITTED:
        files = corpus.files(name)
        conditioning = ConditioningOptions(segments=read_segments_file(files.segments_csv))
        options = IdentifyOptions(partial=partial)
        model = identify_logs([files.log], "hover", conditioning=conditioning, options=options)
        truth = json.loads(files.truth_json.read_text())["hover_parameters"]
        _FITTED[key] = (model, truth)
    return _FITTED[key]


def _estimate(model: IdentifiedModel, name: str) -> tuple[float, float]:
    (p,) = [p for p in model.parameters if p.name == name]
    assert p.status == "estimated", f"{name} is {p.status}"
    return p.value, abs(p.cr_percent / 100.0 * p.value)


@pytest.mark.parametrize("case", HELDOUT_SWEEPS)
def test_well_excited_parameters_within_5_percent_and_2_cr(independent_corpus, case: str) -> None:  # type: ignore[no-untyped-def]
    """Control derivatives and T_a: within 5 % of truth, truth inside 2 CR (issue 14's criteria as they stand).

    Measured: at most 4.8 % (N_yaw, heldout-px4-sweeps) and 1.9 CR (idem).
    """
    model, truth = _fit(independent_corpus, case)
    for name in WELL_EXCITED:
        value, cr = _estimate(model, name)
        assert abs(value / truth[name] - 1.0) <= RELATIVE, f"{case} {name} = {value:.4g}, truth {truth[name]:.4g}"
        assert abs(value - truth[name]) <= CR_MULTIPLE * cr, f"{case} {name}: truth outside 2 CR ({cr:.3g})"


@pytest.mark.parametrize("case", HELDOUT_SWEEPS)
def test_delays_within_2_ms_and_2_cr(independent_corpus, case: str) -> None:  # type: ignore[no-untyped-def]
    """tau_lat, tau_lon, tau_yaw within 2 ms, truth inside 2 CR. Measured: at most 0.5 ms."""
    model, truth = _fit(independent_corpus, case)
    for name in DELAYS:
        value, cr = _estimate(model, name)
        assert abs(value - truth[name]) <= DELAY_S, (
            f"{case} {name} = {value * 1e3:.2f} ms, truth {truth[name] * 1e3} ms"
        )
        assert abs(value - truth[name]) <= CR_MULTIPLE * cr, f"{case} {name}: truth outside 2 CR ({cr * 1e3:.2f} ms)"


@pytest.mark.parametrize("case", HELDOUT_SWEEPS)
def test_unexcited_terms_of_the_truth_are_not_invented(independent_corpus, case: str) -> None:  # type: ignore[no-untyped-def]
    """N_r and Z_w are zero in calm air: both dropped (before: N_r = -1.8 on heldout-px4-sweeps)."""
    model, _ = _fit(independent_corpus, case)
    for name in ("N_r", "Z_w"):
        (p,) = [p for p in model.parameters if p.name == name]
        assert p.status == "dropped" or abs(p.value) < 0.3, f"{case} {name} = {p.value:.3g}"


@pytest.mark.parametrize("case", HELDOUT_SWEEPS)
def test_speed_derivatives_are_inside_their_own_accuracy(independent_corpus, case: str) -> None:  # type: ignore[no-untyped-def]
    """X_u, M_u, Y_v, L_v: the right sign and within a factor of two of truth (not yet issue 14's 5 %).

    Tolerance: what the data allow. With the true excitation as reference the same fit scatters by
    -12 to +49 % over these logs and four other seeds (module notes), so a factor of two is the bound
    that a correct front end keeps and a broken one does not (before: X_u -336 % on heldout-px4-sweeps,
    Y_v -76 % on heldout-ap-sweeps).
    """
    model, truth = _fit(independent_corpus, case)
    for name in SPEED_DERIVATIVES:
        value, _ = _estimate(model, name)
        ratio = value / truth[name]
        assert 0.5 <= ratio <= 2.0 and math.isfinite(ratio), f"{case} {name} = {value:.4g}, truth {truth[name]:.4g}"


def test_a_long_low_sweep_without_position_hold_gives_the_speed_derivatives_within_10_percent(  # type: ignore[no-untyped-def]
    independent_corpus,
) -> None:
    """Issue 32: flown in attitude hold, pitch and roll attitude sweeps from 0.15 rad/s (two periods there) to
    2 Hz, 240 s each; the fit range follows the sweeps' band down to 0.15 rad/s. X_u, M_u, Y_v, L_v within
    10 % of truth, truth inside 2 CR, every CR under 20 %.

    Tuning case (tune-px4-long-low, seed 131): +1.8, +0.0, +1.2, -0.3 % at CR 3.4-3.5 % (with the grid held
    at 0.5 rad/s: +2.6, +1.1, +6.2, +0.7 %; another seed's Y_v -11 % at CR 9 %). Held out (seed 210): +2.0,
    +2.0, +0.4, +0.5 % at CR 3.4-4.4 %.
    """
    model, truth = _fit(independent_corpus, "heldout-px4-long-low")
    for name in SPEED_DERIVATIVES:
        value, cr = _estimate(model, name)
        assert abs(value / truth[name] - 1.0) <= 0.10, f"{name} = {value:.4g}, truth {truth[name]:.4g}"
        assert abs(value - truth[name]) <= CR_MULTIPLE * cr and cr <= 0.2 * abs(value), f"{name}: CR {cr:.3g}"


#: Held-out cases for the speed derivatives' calibration (issue 32, item 4): three flown in closed loop with
#: position hold (the piloted one has no lateral sweep: fitted with ``partial``), one long, low sweep without it.
CALIBRATION_CASES = (*HELDOUT_SWEEPS, "heldout-px4-piloted", "heldout-px4-long-low")


@pytest.mark.filterwarnings("ignore:model hover is partial:flightlogs.errors.FitWarning")  # px4-piloted: no lat
def test_the_speed_derivatives_truth_is_inside_2_cr_on_90_percent_of_the_held_out_cases(  # type: ignore[no-untyped-def]
    independent_corpus,
) -> None:
    """Issue 32 item 4's criterion for X_u, M_u, Y_v, L_v: calibration, not a fixed percentage.

    With Tischler's bound alone 8 of 14 (M_u -13.8 % at CR 4.0 % on ap-sweeps, -13.3 % at 3.6 % on px4-piloted,
    +87 % at 22 % on px4-sweeps; L_v -16.8 % at 4.1 % and Y_v +13.6 % at 5.5 % on px4-sweeps; X_u -8.8 % at 4.4 %
    on px4-piloted). With the residual's sandwich bound and the fit range's spread
    (:func:`sysid.fit.engine.fit_frequency_responses`), set on the tuning cases (9 of 14 there before, 11 after),
    measured 14 of 14: those six at CR 9.8, 7.7, 32, 11.5, 8.9 and 6.3 %. Unidentified ones (Y_v and L_v without
    a lateral sweep) are not counted; the estimated and the dropped are (a dropped one at its drop value, with no
    bound).
    """
    outside, counted = [], 0
    for case in CALIBRATION_CASES:
        model, truth = _fit(independent_corpus, case, partial=case == "heldout-px4-piloted")
        for p in model.parameters:
            if p.name not in SPEED_DERIVATIVES or p.status == "unidentified":
                continue
            counted += 1
            cr = abs(p.cr_percent / 100.0 * p.value) if p.status == "estimated" else 0.0
            if not abs(p.value - truth[p.name]) <= CR_MULTIPLE * cr:
                outside.append(
                    f"{case} {p.name} {100 * (p.value / truth[p.name] - 1):+.1f} % at CR {p.cr_percent:.1f} %"
                )
    assert counted >= 12
    assert len(outside) <= 0.1 * counted, f"{counted - len(outside)} of {counted} inside 2 CR; outside: {outside}"
