"""An ambiguous finding says so once: the rivals with their held-out scores, and each separating flight once.

A 4 ms delay on another generator's pair is named a 10 ms lag with the delay as an alternative (10 % each);
its sentence used to name the higher-frequency sweeps twice, in the two terms' own words.
"""

from __future__ import annotations

from sysid.discrepancy.catalogue import term_of
from sysid.discrepancy.describe import describe_finding
from sysid.discrepancy.result import Alternative, Finding, FittedParameter, Regime


def _lag(*alternatives: Alternative) -> Finding:
    return Finding(
        effect="actuator_lag",
        outputs=("p_dot", "q_dot"),
        band_rad_s=(2.0, 30.0),
        regime=Regime(variable="time", unit="s", low=0.0, high=240.0),
        explained_variance=0.10,
        parameters=(FittedParameter(name="time_constant_s", value=0.010, uncertainty=0.0007, unit="s"),),
        rmse_before={"p_dot": 0.20, "q_dot": 0.20},
        rmse_after={"p_dot": 0.19, "q_dot": 0.19},
        improvement_percent=5.0,
        evidence="",
        alternatives=alternatives,
    )


def test_a_delay_against_a_lag_names_the_faster_sweeps_once() -> None:
    sentence = describe_finding(
        _lag(Alternative(effect="time_delay", explained_variance=0.09)), term_of("actuator_lag")
    )
    assert "Ambiguous: time_delay (9 %) explains the same held-out residual about as well as actuator_lag (10 %)." in (
        sentence
    )
    assert sentence.count("sweeps to higher frequency") == 1, sentence
    assert sentence.endswith("would tell them apart.")


def test_each_rival_adds_its_own_flight() -> None:
    sentence = describe_finding(
        _lag(
            Alternative(effect="time_delay", explained_variance=0.09),
            Alternative(effect="mass_change", explained_variance=0.08),
        ),
        term_of("actuator_lag"),
    )
    assert sentence.count("sweeps to higher frequency") == 1
    assert term_of("mass_change").separated_by in sentence


def test_an_unambiguous_finding_names_no_flight() -> None:
    assert "tell them apart" not in describe_finding(_lag(), term_of("actuator_lag"))
