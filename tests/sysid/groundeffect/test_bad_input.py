"""Ground-effect bad input: damaged model files, an F0 far off, too few points, a log that does not read."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from flightlogs.errors import DataError, FitError, LogFormatError, ModelError
from sysid.groundeffect import (
    FitConfig,
    GroundEffectDataConfig,
    HoverStep,
    HoverSteps,
    ThrustRatioData,
    evaluate_model,
    fit_ground_effect,
    load_thrust_ratio,
    read_ground_effect_model,
    rig_thrust_ratio,
    write_ground_effect_model,
)

_INTERNALS = re.compile(r"KeyError|ValueError|TypeError|\bNone\b")
R = 0.0225


@pytest.fixture(scope="module")
def exponential_doc(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    x = np.linspace(1.2, 9.0, 20)
    y = evaluate_model("exponential", [0.26, 0.68], x) * (1 + 0.002 * np.sin(5 * x))
    fit = fit_ground_effect(
        ThrustRatioData(height_ratio=x, thrust_ratio=y, rotor_radius_m=R), FitConfig(models=("exponential",))
    )
    path = write_ground_effect_model(fit, tmp_path_factory.mktemp("ge") / "ge.json")
    return dict(json.loads(path.read_text()))


def _refused(tmp_path: Path, doc: dict[str, Any], *needles: str) -> None:
    path = tmp_path / "ge.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(ModelError) as caught:
        read_ground_effect_model(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: ") and not _INTERNALS.search(message), message
    for needle in needles:
        assert needle in message, message


def test_a_damaged_ground_effect_model_names_the_parameter(exponential_doc: dict[str, Any], tmp_path: Path) -> None:
    assert read_ground_effect_model(_save(tmp_path, exponential_doc)).model == "exponential"
    params = exponential_doc["params"]
    _refused(tmp_path, exponential_doc | {"params": {"b": params["b"]}}, "the exponential model needs parameter a")
    _refused(
        tmp_path,
        exponential_doc | {"params": params | {"a": "abc"}},
        "parameter a of the exponential model is 'abc', not a finite number",
    )
    _refused(tmp_path, exponential_doc | {"params": params | {"a": float("nan")}}, "parameter a", "nan")
    _refused(tmp_path, exponential_doc | {"params": params | {"rho": 1.0}}, "rho is not a parameter")
    _refused(tmp_path, {k: v for k, v in exponential_doc.items() if k != "rotor_radius_m"}, "rotor radius")
    _refused(tmp_path, exponential_doc | {"model": "foo"}, "unknown ground-effect model 'foo'")


def _save(tmp_path: Path, doc: dict[str, Any]) -> Path:
    path = tmp_path / "ok.json"
    path.write_text(json.dumps(doc))
    return path


def test_an_f0_that_puts_the_readings_far_from_one_is_refused() -> None:
    height = np.linspace(0.027, 0.27, 30)
    thrust = 0.40 * evaluate_model("corrected", [3.0], height / R)
    assert abs(np.median(rig_thrust_ratio(height, thrust, rotor_radius_m=R, f0_n=0.40).thrust_ratio) - 1) < 0.05
    for f0 in (1000.0, 0.1, 0.9):  # F/F0 medians 4e-4, 4.0, 0.45: a wrong unit or a wrong F0
        with pytest.raises(DataError, match=r"rig\.csv: with F0 = .* N \(given\) the median F/F0"):
            rig_thrust_ratio(height, thrust, rotor_radius_m=R, f0_n=f0, source="rig.csv")
    rig_thrust_ratio(height, thrust, rotor_radius_m=R, f0_n=0.75, source="rig.csv")  # median 0.54: kept


def test_too_few_points_says_what_was_found() -> None:
    x, y = np.array([1.5, 3.0]), np.array([1.05, 1.01])
    with pytest.raises(FitError, match=r"^rig\.csv: 2 points were given; at least 3 are needed to fit$"):
        fit_ground_effect(ThrustRatioData(height_ratio=x, thrust_ratio=y, rotor_radius_m=R, source="rig.csv"))
    steps = HoverSteps(
        time_s=np.array([0.0, 1.0]),
        height_m=np.array([0.03, 0.07]),
        steps=tuple(
            HoverStep(
                start_s=10.0 * k,
                end_s=10.0 * k + 10,
                steady_start_s=10.0 * k + 5,
                height_m=h,
                height_std_m=0.001,
                climb_rate_m_s=0.0,
                f0_n=0.4,
                thrust_ratio=r,
                samples=50,
            )
            for k, (h, r) in enumerate(zip(x * R, y))
        ),
    )
    with pytest.raises(FitError, match=r"^f\.ulg: 2 hover steps near the ground were found; at least 3 are needed"):
        fit_ground_effect(
            ThrustRatioData(height_ratio=x, thrust_ratio=y, rotor_radius_m=R, source="f.ulg", steps=steps)
        )
    with pytest.raises(FitError, match=r"^f\.ulg: 1 hover step near the ground was found;"):
        fit_ground_effect(
            ThrustRatioData(height_ratio=x[:1], thrust_ratio=y[:1], rotor_radius_m=R, source="f.ulg", steps=steps)
        )


@pytest.mark.parametrize("suffix", [".ulg", ".bin", ".tlog"])
def test_a_log_named_file_is_judged_by_the_log_reader_not_as_a_csv(tmp_path: Path, suffix: str) -> None:
    path = tmp_path / f"text{suffix}"
    path.write_text("hello there, this is text\n1,2\n")
    with pytest.raises(LogFormatError, match=rf"text\{suffix}: not a PX4 ULog, ArduPilot DataFlash or MAVLink"):
        load_thrust_ratio(path, GroundEffectDataConfig(rotor_radius_m=R))
