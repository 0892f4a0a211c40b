"""A residual located but not modelled claims no held-out improvement, in words, in the JSON and in the report."""

from __future__ import annotations

from dataclasses import replace

import pytest

from reports.discrepancy_report import render_discrepancy_report
from sysid.discrepancy import DiscrepancyResult
from sysid.discrepancy.catalogue import Term
from sysid.discrepancy.describe import describe_finding
from sysid.discrepancy.result import Finding, FittedParameter, Regime


def _finding(parameters: tuple[FittedParameter, ...], improvement: float) -> Finding:
    return Finding(
        effect="unexplained",
        outputs=("az",),
        band_rad_s=(0.5, 4.0),
        regime=Regime(variable="time", unit="s", low=10.0, high=200.0),
        explained_variance=0.0 if not parameters else 0.4,
        parameters=parameters,
        rmse_before={"az": 0.20},
        rmse_after={"az": 0.20 * (1.0 - improvement / 100.0)},
        improvement_percent=improvement,
        evidence="",
    )


TERM = Term(
    effect="unexplained",
    summary="a residual",
    outputs=("az",),
    regime=None,
    make=lambda _context: None,
    what=lambda _finding: "Something acts on az",
)


@pytest.mark.parametrize(
    ("parameters", "improvement", "claim"),
    [
        ((), 0.0, "it is located, not modelled: no held-out improvement is claimed"),
        (
            (FittedParameter(name="az per w", value=-0.04, uncertainty=0.003, unit="1/s"),),
            37.0,
            "modelling it cuts the az residual by 37 % on held-out data",
        ),
    ],
    ids=["located", "modelled"],
)
def test_the_sentence_claims_a_cut_only_for_a_model(
    parameters: tuple[FittedParameter, ...], improvement: float, claim: str
) -> None:
    finding = _finding(parameters, improvement)
    assert finding.modelled is bool(parameters)
    sentence = describe_finding(finding, TERM)
    assert sentence == f"Something acts on az; {claim}."


def test_a_located_finding_says_so_in_the_json_and_the_report() -> None:
    located = _finding((), 0.0)
    result = DiscrepancyResult(
        verdict="unexplained",
        findings=(located,),
        summary="x",
        screened=(),
        noise_floor={"az": 0.05},
        sim=("sim",),
        real=("real",),
    )
    (entry,) = result.to_dict()["findings"]
    assert entry["modelled"] is False and entry["parameters"] == {}
    html = render_discrepancy_report(result)
    assert "located, not modelled" in html
    assert "of the weighted held-out residual of its outputs" not in html  # the modelled finding's wording
    parameter = FittedParameter(name="az per w", value=-0.04, uncertainty=0.003, unit="1/s")
    modelled = render_discrepancy_report(replace(result, findings=(_finding((parameter,), 37.0),)))
    assert "of the weighted held-out residual of its outputs" in modelled and "located, not modelled" not in modelled
