"""Every terminal table states the units of its numbers (issue 33): rad/s and s in the terminal, the unit of each row.

Each table is printed from what the library gives (a model built from Table 3.3's structure, a verification
of two doublets, a transfer structure), so a column the library adds without a unit, or a unit the printer
drops, fails here. The commands' own runs check the same lines on real output (``test_demo``, ``test_tf_fit``).
"""

from __future__ import annotations

import pytest

from sysid.fit import fit_summary
from sysid.model.transfer import parse_transfer_function
from sysid_cli._tables import print_fit, print_validation

from builders import sample_verification, small_model


def _lines(capsys: pytest.CaptureFixture[str]) -> list[str]:
    return capsys.readouterr().out.splitlines()


def test_the_fit_table_gives_each_parameter_its_unit_and_the_modes_theirs(capsys: pytest.CaptureFixture[str]) -> None:
    model = small_model()
    print_fit(fit_summary(model), model.guidelines)
    lines = _lines(capsys)
    header = next(line for line in lines if line.split()[:2] == ["parameter", "value"])
    assert header.split()[-1] == "unit"
    rows = {line.split()[0]: line for line in lines if line.startswith("  ") and line.split()[0] in model.values}
    assert set(rows) == {p.name for p in model.parameters}
    for p in model.parameters:
        assert p.unit and rows[p.name].rstrip().endswith(p.unit), (p.name, p.unit, rows[p.name])
    modes = next(line for line in lines if line.split()[:1] == ["mode"])
    assert "eigenvalue 1/s" in modes and "omega_n rad/s" in modes and "t2 / t1/2 s" in modes


def test_the_verification_table_gives_each_output_its_unit(capsys: pytest.CaptureFixture[str]) -> None:
    verification = sample_verification()
    summary = {"model": "model.json", "logs": []} | verification.digest()
    print_validation(summary | {"notes": [], "report": None, "output": None})
    lines = _lines(capsys)
    header = next(line for line in lines if line.split()[:1] == ["output"])
    assert header.split()[:4] == ["output", "unit", "RMS", "error"]
    for output in verification.summary:
        (row,) = [line for line in lines if line.split()[:1] == [output.name]]
        assert row.split()[1] == output.unit, (output.name, output.unit, row)


@pytest.mark.parametrize(
    ("text", "units"),
    [
        (  # the generator's roll response: a monic fourth-order denominator
            "p/delta_lat = b2*s^2/(s^4 + a3*s^3 + a2*s^2 + a1*s + a0)",
            {"b2": "rad/s per 1, s^-2", "a3": "s^-1", "a2": "s^-2", "a1": "s^-3", "a0": "s^-4"},
        ),
        (  # the fixed term in the numerator: the denominator carries input per output
            "q/delta_lon = 1/(a1*s + a0)",
            {"a1": "1 per rad/s, s^1", "a0": "1 per rad/s"},
        ),
    ],
)
def test_a_transfer_functions_coefficients_have_units_from_the_power_of_s(text: str, units: dict[str, str]) -> None:
    """Dimensional analysis by hand: a_k s^k ~ s^n gives a_k in s^(k-n); b_k s^k / s^n ~ output per input."""
    assert parse_transfer_function(text).parameter_units("rad/s", "") == units
