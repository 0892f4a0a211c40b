"""Which axes an identification identified: the reason given for each one that was not, and the exit message."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from flightlogs.conditioning.condition import ConditionedFlight
from flightlogs.maneuvers.segments import Segment
from flightlogs.record import Record
from simulator.vehicle.identified import CALM_HOVER
from sysid.fit import synthetic_responses
from sysid.fit.axes import (
    AxisStatus,
    diagnose_axis,
    merge_axes,
    partial_warning,
    structure_axes,
    unidentified_message,
)
from sysid.freqresp import Gating, gate_responses
from sysid.model import load_structure, structure_model


def _flight(name: str, *segments: tuple[str, str]) -> ConditionedFlight:
    found = tuple(
        Segment(axis=axis, kind=kind, start_s=10.0 * k, end_s=10.0 * k + 5.0, source="detected")  # type: ignore[arg-type]
        for k, (axis, kind) in enumerate(segments)
    )
    return ConditionedFlight(source=Path(name), records=(), segments=found, rate_hz=100.0)


def _record() -> Record:
    table = pd.DataFrame({"delta_lon": np.zeros(20), "q": np.zeros(20)}, index=np.arange(20) * 0.01)
    return Record.from_table(table, units={"delta_lon": "%", "q": "rad/s"}, trim={}, source=Path("a.bin"))


FLIGHTS = [_flight("a.bin", ("lat", "sweep"), ("lon", "doublet")), _flight("b.bin"), _flight("c.bin")]
GATING = {"gating": Gating()}


def test_an_axis_with_no_maneuver_says_so_and_what_was_found() -> None:
    lon = diagnose_axis("delta_lon", kind="sweep", flights=FLIGHTS, records=(), responses=(), dropped=(), **GATING)
    assert lon.status == "unidentified"
    assert lon.reason == (
        "no sweep found in 3 logs; the delta_lon input never passed the sweep test (a doublet of this axis was found)"
    )
    assert lon.remedy == "give the maneuvers with `segments`"
    yaw = diagnose_axis("delta_yaw", kind="sweep", flights=FLIGHTS, records=(), responses=(), dropped=(), **GATING)
    assert yaw.reason == "no sweep found in 3 logs; the delta_yaw input never passed the sweep test"
    given = [
        _flight("a.bin"),
        ConditionedFlight(
            source=Path("b.bin"),
            records=(),
            segments=(Segment(axis="lat", kind="sweep", start_s=1.0, end_s=30.0, source="user"),),
            rate_hz=100.0,
        ),
    ]
    assert (
        "the maneuvers given name no lon sweep"
        in diagnose_axis(
            "delta_lon", kind="sweep", flights=given, records=(), responses=(), dropped=(), **GATING
        ).reason
    )


def test_an_axis_whose_responses_all_fail_gating_says_which_and_why() -> None:
    truth, _ = structure_model(load_structure("hover"), dict(CALM_HOVER))
    noisy = synthetic_responses(truth, ["q/delta_lon", "ax/delta_lon"], coherence=0.3)
    gated = gate_responses(noisy, Gating(min_coherence=0.5, min_decades=0.3))
    lon = diagnose_axis(
        "delta_lon",
        kind="sweep",
        flights=FLIGHTS,
        records=[_record()],
        responses=noisy,
        dropped=gated.dropped,
        **GATING,
    )
    assert lon.reason == (
        "1 sweep in 3 logs, but no response passed the coherence gating (γ² ≥ 0.5 over ≥ 0.3 decade): "
        "q/delta_lon: coherence never reaches 0.5 (at most 0.30). ax/delta_lon: coherence never reaches 0.5 (at most 0.30)"
    )
    assert "lower `min_coherence`" in lon.remedy
    fine = synthetic_responses(truth, ["q/delta_lon"])
    ok = diagnose_axis(
        "delta_lon", kind="sweep", flights=FLIGHTS, records=[_record()], responses=fine, dropped=(), **GATING
    )
    assert ok.identified and ok.reason == ""


def test_every_control_input_of_the_structure_gets_a_status_and_the_message_one_sentence_each() -> None:
    truth, _ = structure_model(load_structure("hover"), dict(CALM_HOVER))
    lat = synthetic_responses(truth, ["p/delta_lat"])
    axes = structure_axes(
        load_structure("hover"), FLIGHTS, {"lat": [_record()]}, lat, gate_responses(lat), kind="sweep", **GATING
    )
    assert [(a.axis, a.status) for a in axes] == [
        ("lat", "identified"),
        ("lon", "unidentified"),
        ("yaw", "unidentified"),
        ("thr", "unidentified"),
    ]
    lines = unidentified_message(axes, model="hover").splitlines()
    assert lines[0] == "model hover: 3 of its 4 axes cannot be identified."
    assert lines[1] == (
        "lon: no sweep found in 3 logs; the delta_lon input never passed the sweep test (a doublet of this axis was "
        "found); give the maneuvers with `segments`, or `partial` to write a model of the other axes."
    )
    assert partial_warning(axes, model="hover").startswith("model hover is partial: it covers lat only;")


def test_the_fit_may_leave_an_axis_with_responses_unidentified() -> None:
    found = (AxisStatus(axis="lon", input="delta_lon", status="identified"),)
    fitted = (
        AxisStatus(
            axis="lon", input="delta_lon", status="unidentified", reason="X_lon is informed by no fitted response"
        ),
    )
    (merged,) = merge_axes(found, fitted)
    assert (
        merged.reason == "X_lon is informed by no fitted response" and merged.remedy == "fit responses that inform them"
    )
    before = (AxisStatus(axis="lon", input="delta_lon", status="unidentified", reason="no sweep found in 1 log"),)
    assert merge_axes(before, fitted) == before  # the earlier, more precise reason


def test_an_unidentified_axis_needs_a_reason() -> None:
    with pytest.raises(ValueError, match="needs a reason"):
        AxisStatus(axis="lon", input="delta_lon", status="unidentified")
