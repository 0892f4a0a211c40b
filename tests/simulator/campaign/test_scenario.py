"""Scenario files: the built-ins parse to the campaigns they describe; bad files say why."""

from __future__ import annotations

from pathlib import Path

import pytest

from flightlogs.errors import DataError
from simulator.campaign.scenario import builtin_scenarios, load_builtin, read_scenario


def test_the_chapter3_campaign_is_120_trials() -> None:
    scenario = load_builtin("chapter3-campaign")
    assert scenario.n_trials == 4 * 2 * 3 * 5 == 120
    assert [c.mean_speed_m_s for c in scenario.conditions] == [0.9, 2.7, 5.4]  # tables.md: calm, light, strong
    assert {(m.axis, m.kind) for m in scenario.maneuvers} == {
        (axis, kind) for axis in ("lat", "lon", "yaw", "thr") for kind in ("sweep", "doublet")
    }
    sweeps = [m for m in scenario.maneuvers if m.kind == "sweep"]
    assert all((m.f_start_hz, m.f_stop_hz, m.duration_s) == (0.1, 10.0, 34.0) for m in sweeps)
    assert scenario.anemometer is not None and scenario.anemometer.distance_m == 4.6


def test_every_builtin_parses() -> None:
    names = builtin_scenarios()
    assert {"chapter3-campaign", "chapter2-ground-effect", "sitl-nominal"} <= set(names)
    for name in names:
        assert load_builtin(name).description


def test_the_ground_effect_steps_start_out_of_ground_effect() -> None:
    (steps,) = load_builtin("chapter2-ground-effect").maneuvers
    rotor_radius_m = 0.0225  # Crazyflie 2.0, 45 mm propellers
    assert steps.heights_m[0] / rotor_radius_m == pytest.approx(10.0, rel=0.05)
    assert list(steps.heights_m) == sorted(steps.heights_m, reverse=True)


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("[scenario\nvehicle = 1", "not valid TOML"),
        (
            '[scenario]\nvehicle = "hexa"\n[[condition]]\nname="c"\nmean_speed_m_s=1\n[[maneuver]]\naxis="lon"\nkind="sweep"\nduration_s=3',
            "unknown vehicle 'hexa'",
        ),
        ('[scenario]\nvehicle = "octo-s1000"\n[[condition]]\nname="c"\nmean_speed_m_s=1\ncolour="red"', "[condition] "),
        (
            '[scenario]\nvehicle = "octo-s1000"\n[[condition]]\nname="c"\nmean_speed_m_s=1\n[[maneuver]]\naxis="up"\nkind="sweep"\nduration_s=3',
            "unknown axis 'up'",
        ),
        ('[scenario]\nvehicle = "octo-s1000"', "needs trials"),
    ],
)
def test_bad_scenarios_name_the_file_and_table(tmp_path: Path, text: str, fragment: str) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(DataError) as info:
        read_scenario(path)
    assert str(path) in str(info.value) and fragment in str(info.value)


def test_an_unknown_builtin_lists_the_known_ones() -> None:
    with pytest.raises(DataError, match="chapter3-campaign"):
        load_builtin("nope")
