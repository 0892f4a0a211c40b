"""Physics outside the plant, on another generator's logs (issue 15): ground, battery, payload, CG and wind.

``independent_sim`` (no code shared with ``simulator`` or ``sysid``) flies the Table 3.3 octocopter as a
linear plant under a PX4-like cascade. Its REAL vehicles here carry physics written for this test
(:mod:`independent_sim.effects`) with laws our simulator does not use and the search's terms do not
assume: an exponential ground cushion (not the chapter 2 laws, not the search's inverse square), thrust
and control moments that fade as the pack's voltage (logged, 10 Hz) to a power, a payload picked up at
an instant, a CG off the thrust axis, and a steady wind with turbulence that the calm airframe meets
only through its own speed derivatives, measured by an anemometer 4.6 m upstream. The mission: lon,
lat and yaw sweeps, a 15 m reposition out and back and 20 s at 0.35 m; 240 s, PX4 ULog.

Tuning and assertions are apart. The effects' strengths and this module's tolerances were set on SIM
seed 501 against REAL seeds 601 on (exploration); every assertion runs on SIM seed 1101 and REAL seeds
1201 on, flown only here. The exploration found these defects, each fixed in the search:

* the SIM model extrapolated the square of a thrust held within 0.2 % into a roll and pitch moment
  when REAL needed more thrust (a sagging battery then came with a CG offset);
* the anemometer's fast fluctuations, noise for the drag, shrank the wind's coefficients (at 2.7 m/s
  its moment came out 30 % short, and the constant rest was named a CG offset);
* two terms on az read their thrust from different predictions, and the joint fit used the difference
  of the two near-copies (the battery exponent beside a ground effect read 2.78 for 2);
* the mass step's size was printed as the change of thrust per thrust, not of the mass.

The benchmark (``benchmarks/bench_discrepancy_independent.py``) runs the eight effects at three
strengths on other seeds. It found three more, each fixed: the ground effect at half and a quarter of
this strength was missed, its 20 s near the ground under the 5 % of the whole flight's residual a term
had to remove (the first term is now judged where it acts), or its contribution, mostly at take-off
and landing, under the 2 s a term had to span (a term may now recur instead); and the speed damping's
null score came out 0.28 on one simulated flight (25 s blocks: the half that held the reposition out
made the model extrapolate along it; now 4 s blocks and both halves).
"""

from __future__ import annotations

import json
import math

import pytest
from click.testing import CliRunner
from independent_sim.corpus import write_case
from independent_sim.effects import BatteryFade, GroundCushion, OffsetCentre, PayloadPickUp
from independent_sim.pairs import PLANT, physics_pair_case
from independent_sim.wind import WindModel

from sysid.discrepancy import DiscrepancyResult, discover
from sysid_cli.main import cli

from builders import discrepancy_series

pytestmark = [
    pytest.mark.long,  # 100 s on 2 cores: run by .ci/run with -m long, out of the README's ten-minute suite
    pytest.mark.timeout(900),
    pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning"),
]

SIM_SEED, REAL_SEED = 1101, 1201  # held out: the exploration flew 501 and 601 on
STRONG_CUSHION, WEAK_CUSHION = GroundCushion(gain=0.25), GroundCushion(gain=0.12)
CG, HALF_CG = OffsetCentre(roll_rad_m=0.02, pitch_rad_m=-0.05), OffsetCentre(roll_rad_m=0.01, pitch_rad_m=-0.025)
PICK_UP, SMALL_PICK_UP = PayloadPickUp(at_s=120.0, ratio=0.06), PayloadPickUp(at_s=95.0, ratio=0.03)

#: Pair name -> (the effects concealed, the REAL vehicle's effects).
PAIRS: dict[str, tuple[tuple[str, ...], tuple[object, ...]]] = {
    "none": ((), ()),
    "ground_effect": (("ground_effect",), (STRONG_CUSHION,)),
    "ground_effect_weak": (("ground_effect",), (WEAK_CUSHION,)),
    "battery_sag": (("battery_sag",), (BatteryFade(exponent=2.0),)),
    "battery_sag_weak": (("battery_sag",), (BatteryFade(exponent=1.0),)),
    "mass_change": (("mass_change",), (PICK_UP,)),
    "mass_change_weak": (("mass_change",), (SMALL_PICK_UP,)),
    "cg_offset": (("cg_offset",), (CG,)),
    "cg_offset_weak": (("cg_offset",), (HALF_CG,)),
    "ground_effect+battery_sag": (("battery_sag", "ground_effect"), (STRONG_CUSHION, BatteryFade(exponent=2.0))),
    "mass_change+cg_offset": (("cg_offset", "mass_change"), (PICK_UP, CG)),
}
#: Wind pairs (through ``sysid discrepancy --wind``): mean speed, m/s (the chapter 3 strong and light days).
WINDS = {"wind": 5.4, "wind_weak": 2.7}

#: Named beside the concealed effect, and right too: this generator's battery fades the roll and pitch moment per
#: command with the voltage (7 % under the simulation's at the pack's mean voltage), a control effectiveness of its
#: own since the catalogue has one (issue 30).
_ALSO_RIGHT = {
    name: {"control_effectiveness"} for name in ("battery_sag", "battery_sag_weak", "ground_effect+battery_sag")
}

Found = tuple[DiscrepancyResult, float]  # the result, and the REAL log's first flown sample on the log clock (s)


@pytest.fixture(scope="module", name="results")
def results_fixture(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Found]:
    folder = tmp_path_factory.mktemp("independent-physics-pairs")
    sim = discrepancy_series(write_case(physics_pair_case("sim", SIM_SEED), folder).log)
    out = {}
    for k, (name, (_, effects)) in enumerate(PAIRS.items()):
        case = physics_pair_case(f"real-{k}", REAL_SEED + k, effects=effects)  # type: ignore[arg-type]
        files = write_case(case, folder)
        real = discrepancy_series(files.log)
        out[name] = (discover([sim], [real]), float(real.time_s[0]) - files.truth.takeoff_s)
    return out


@pytest.fixture(scope="module", name="wind_results")
def wind_results_fixture(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[str, object]]:
    """``sysid discrepancy SIM REAL --wind CSV --wind-distance 4.6 -o gap.json``, as a user runs it."""
    folder = tmp_path_factory.mktemp("independent-wind-pairs")
    sim = write_case(physics_pair_case("sim", SIM_SEED), folder).log
    out = {}
    for k, (name, speed) in enumerate(WINDS.items()):
        wind = WindModel(mean_speed_m_s=speed, sigma_m_s=0.11 * speed, from_deg=30.0)  # the SIM heading
        files = write_case(physics_pair_case(f"windy-{k}", REAL_SEED + 50 + k, wind=wind), folder)
        assert files.anemometer_csv is not None
        gap = folder / f"{name}.json"
        wind_options = ["--wind", str(files.anemometer_csv), "--wind-distance", "4.6"]
        result = CliRunner().invoke(cli, ["discrepancy", str(sim), str(files.log), *wind_options, "-o", str(gap), "-q"])
        assert result.exit_code == 0, result.output
        out[name] = json.loads(gap.read_text())
    return out


def _value(result: DiscrepancyResult, effect: str, name: str) -> float:
    (finding,) = [f for f in result.findings if f.effect == effect]
    (p,) = [p for p in finding.parameters if p.name == name]
    return p.value


_REGRESSED = {  # issue 30, open: a later term must now cut its outputs' RMS by 10 %; the cushion's 20 s beside the battery
    "ground_effect+battery_sag": pytest.mark.xfail(
        reason="issue 30: the verdict is control_effectiveness (the moments fade with the battery), not a concealed effect",
        strict=False,
    )
}


@pytest.mark.parametrize("name", [pytest.param(n, marks=_REGRESSED.get(n, ())) for n in PAIRS])
def test_the_physics_left_out_is_named_and_nothing_else(results: dict[str, Found], name: str) -> None:
    """Every single effect at both strengths is named alone, both effects of a double, nothing on the null."""
    result, _ = results[name]
    concealed = PAIRS[name][0]
    found = {f.effect for f in result.findings}
    assert set(concealed) <= found and found - set(concealed) <= _ALSO_RIGHT.get(name, set()), result.summary
    assert result.verdict in (concealed or ("none",))
    for finding in result.findings:
        assert finding.improvement_percent > 0.0, finding
    if len(concealed) == 1:
        assert max(result.unexplained.values()) < 2.0, result.unexplained  # the finding accounts for the gap


@pytest.mark.parametrize(("name", "exponent"), [("battery_sag", 2.0), ("battery_sag_weak", 1.0)])
def test_the_battery_exponent_is_the_one_flown(results: dict[str, Found], name: str, exponent: float) -> None:
    """Thrust ∝ V^n: n within 10 % (exploration: 2.11 for 2 and 1.02 for 1, against our simulator's 2.2 for 2)."""
    assert _value(results[name][0], "battery_sag", "exponent") == pytest.approx(exponent, rel=0.10)


@pytest.mark.parametrize(("name", "pick_up"), [("mass_change", PICK_UP), ("mass_change_weak", SMALL_PICK_UP)])
def test_the_payload_is_weighed_and_timed(results: dict[str, Found], name: str, pick_up: PayloadPickUp) -> None:
    """The mass change within 5 % of the payload's share, its time within 0.5 s on the log clock.

    The search's flight clock starts at the first flown sample (thrust over 85 % of the hover's): the
    payload's time is compared on the log clock. Exploration: 5.92 % for 6 %, 2.96 % for 3 %.
    """
    result, first_flown_s = results[name]
    assert _value(result, "mass_change", "mass_change_fraction") == pytest.approx(pick_up.ratio, rel=0.05)
    assert abs(_value(result, "mass_change", "time_s") + first_flown_s - pick_up.at_s) <= 0.5


@pytest.mark.parametrize(("name", "centre"), [("cg_offset", CG), ("cg_offset_weak", HALF_CG)])
def test_the_cg_moments_are_the_ones_flown(results: dict[str, Found], name: str, centre: OffsetCentre) -> None:
    """Roll and pitch acceleration per specific thrust within 10 % (exploration: 2 % roll, 3.4-4.8 % pitch)."""
    result = results[name][0]
    assert _value(result, "cg_offset", "roll_moment_per_thrust") == pytest.approx(centre.roll_rad_m, rel=0.10)
    assert _value(result, "cg_offset", "pitch_moment_per_thrust") == pytest.approx(centre.pitch_rad_m, rel=0.10)


@pytest.mark.parametrize(("name", "cushion"), [("ground_effect", STRONG_CUSHION), ("ground_effect_weak", WEAK_CUSHION)])
def test_the_ground_effect_ends_where_the_cushion_falls_to_one_percent(
    results: dict[str, Found], name: str, cushion: GroundCushion
) -> None:
    """The search's end of the effect (its shape falls to 1 % of thrust) within 0.1 m of the flown law's.

    The law ``1 + a exp(-z / L)`` falls to 1 % at ``z = L ln(100 a)``, rotor plane ``rotor_above_m`` over the
    logged height: 0.36 m (a = 0.25) and 0.25 m (a = 0.12). Exploration: 0.355 and 0.202 m.
    """
    truth = cushion.decay_m * math.log(100.0 * cushion.gain) - cushion.rotor_above_m
    assert abs(_value(results[name][0], "ground_effect", "ends_at_height") - truth) <= 0.1


def test_the_battery_exponent_of_the_double(results: dict[str, Found]) -> None:
    """With the ground cushion at once, the exponent is still the one flown (within 10 %)."""
    exponent = _value(results["ground_effect+battery_sag"][0], "battery_sag", "exponent")
    assert exponent == pytest.approx(2.0, rel=0.10)


@pytest.mark.parametrize("name", list(WINDS))
def test_the_wind_is_named_alone_with_the_airframes_drag(wind_results: dict[str, dict[str, object]], name: str) -> None:
    """The calm airframe in a steady wind: ``wind`` alone, its drag per thrust and wind the airframe's -X_u / g.

    Within 5 % (exploration: 0.4 % at 5.4 m/s and 1.2 % at 2.7 m/s), cutting the held-out residual by half.
    """
    doc = wind_results[name]
    findings = doc["findings"]
    assert isinstance(findings, list)
    assert doc["verdict"] == "wind" and [f["effect"] for f in findings] == ["wind"], doc["summary"]
    drag = findings[0]["parameters"]["drag_x"]["value"]
    assert drag == pytest.approx(-PLANT.X_u / 9.81, rel=0.05)
    assert findings[0]["improvement_percent"] >= 50.0
