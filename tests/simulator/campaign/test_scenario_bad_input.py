"""Scenario files missing a field, with an unknown one or a value of the wrong type: a plain sentence, no internals."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from flightlogs.errors import DataError
from simulator.campaign.scenario import read_scenario

_BODY = '\n[[condition]]\nname = "c"\nmean_speed_m_s = 1\n[[maneuver]]\naxis = "lon"\nkind = "sweep"\nduration_s = 3\n'


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('name = "x"\n', "[scenario] needs a vehicle"),
        ("", "[scenario] needs a vehicle"),
        (
            '[scenario]\nvehicle = "crazyflie"\ncolour = "red"' + _BODY,
            "[scenario] has no field 'colour' (fields: name,",
        ),
        ('[scenario]\nvehicle = "crazyflie"\n[[condition]]\nmean_speed_m_s = 1\n', "[condition] needs a name"),
        ('[scenario]\nvehicle = "crazyflie"\n[[maneuver]]\nduration_s = 3\n', "[maneuver] needs an axis and a kind"),
        (
            '[scenario]\nvehicle = "crazyflie"\ntrials = "many"' + _BODY,
            "[scenario] trials is 'many', not a whole number",
        ),
        ("[scenario]\nvehicle = 3" + _BODY, "[scenario] vehicle is 3, not text"),
        ('[scenario]\nvehicle = "crazyflie"\nutc_start = "noon"' + _BODY, "utc_start 'noon' is not an ISO 8601"),
        ('[scenario]\nvehicle = "crazyflie"\n' + _BODY + "seed = 2\n", "[maneuver] has no field 'seed'"),
        (
            'vehicle = "crazyflie"\n[scenario]\nname = "x"\nvehicle = "crazyflie"' + _BODY,
            "vehicle is outside any table",
        ),
        ('condition = 3\n[scenario]\nvehicle = "crazyflie"\n', "condition must be an array of tables"),
    ],
)
def test_a_bad_scenario_names_the_file_table_and_field(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "partial.toml"
    path.write_text(text)
    with pytest.raises(DataError) as info:
        read_scenario(path)
    assert str(info.value).startswith(f"{path}: "), info.value
    assert message in str(info.value)
    assert not re.search(
        r"__init__|positional argument|keyword argument|TypeError|not supported between", str(info.value)
    )


def test_a_complete_scenario_still_reads(tmp_path: Path) -> None:
    path = tmp_path / "ok.toml"
    path.write_text('[scenario]\nvehicle = "crazyflie"\ntrials = 2\n[effects]\nground_effect = true' + _BODY)
    scenario = read_scenario(path)
    assert (scenario.name, scenario.vehicle, scenario.n_trials, scenario.effects) == (
        "ok",
        "crazyflie",
        2,
        {"ground_effect": True},
    )
