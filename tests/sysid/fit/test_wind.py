"""The wind step (eq. 3.14) on simulated strong-wind flights with the Table 3.5 terms."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from flightlogs.errors import FitError
from flightlogs.record import Record
from simulator.autopilot.excitation import Maneuver
from simulator.flights.linear import WindField, simulate_hover
from simulator.vehicle.identified import CALM_HOVER, STRONG_WIND_TERMS
from sysid.fit import fit_wind
from sysid.model import load_structure

CONTROLS = ("X_lon", "M_lon", "Y_lat", "L_lat", "N_yaw", "Z_thr")
UNITS = {
    "u": "m/s",
    "w": "m/s",
    "q": "rad/s",
    "theta": "rad",
    "ax": "m/s^2",
    "az": "m/s^2",
    "wind_lon": "m/s",
    "delta_lat": "%",
    "delta_lon": "%",
    "delta_yaw": "%",
    "delta_thr": "%",
}


def _record(axis: str, seed: int) -> Record:
    """A sweep flown in strong wind, as conditioning leaves it: air-relative u from the noisy velocity."""
    sweep = Maneuver(axis=axis, kind="sweep", start_s=3.0, amplitude=8.0 if axis == "lon" else 4.0, duration_s=34.0)  # type: ignore[arg-type]
    flight = simulate_hover(
        40.0,
        (sweep,),
        wind=WindField(mean_speed_m_s=5.4, direction_from_deg=0.0, turbulence_ratio=0.2),
        wind_terms=STRONG_WIND_TERMS,
        seed=seed,
    )
    s, wind = flight.signals, flight.wind_at_vehicle
    table = pd.DataFrame(
        {
            "u": s["vn"] - wind[:, 0],
            "w": s["vd"],
            "q": s["q"],
            "theta": s["theta"],
            "ax": s["ax"],
            "az": s["az"],
            "wind_lon": wind[:, 0],
        }
        | {f"delta_{a}": s[f"delta_{a}"] for a in ("lat", "lon", "yaw", "thr")},
        index=flight.time_s,
    )
    trim = table.mean()
    return Record(
        table=table - trim, units=UNITS, trim=trim.to_dict(), source=Path(f"{axis}.bin"), label=f"{axis} sweep"
    )


@pytest.fixture(scope="module")
def records() -> list[Record]:
    return [_record("lon", 3), _record("thr", 4)]


def test_wind_terms_come_back_from_the_residual(records: list[Record]) -> None:
    structure = load_structure("hover-wind")
    values = structure.values(dict(CALM_HOVER) | {"N_r": 0.0, "Z_w": 0.0})  # step 1 exact: per %, as logged here
    result = fit_wind(structure, values, structure.default_constants(), records)
    for name in ("X_w_lon", "Z_w_lon"):
        assert result.status[name] == "estimated"
        k = result.accuracy.names.index(name)
        error = abs(result.values[name] - STRONG_WIND_TERMS[name])
        assert error <= max(3 * result.accuracy.cramer_rao[k], 0.02 * abs(STRONG_WIND_TERMS[name])), name
    assert all(after < 0.5 * before for before, after in zip(result.fit.rms_before, result.fit.rms_after))
    # a_x is left with its sensor noise (0.03 m/s^2); a_z also with the error of rebuilding the lagged throttle
    # from its 100 Hz log of a 500 Hz simulation (about 1 ms at up to 10 Hz, times Z_thr)
    assert 0.03 <= result.fit.rms_after[0] < 0.06
    for name in ("tau_w_lon", "tau_w_thr"):
        assert 0.0 <= result.values[name] <= 0.5


def test_unresolved_wind_delays_are_dropped_to_zero(records: list[Record]) -> None:
    """The gusts roll off above 0.3 Hz: a 13 ms delay barely moves them, so its I% fails and it becomes 0."""
    structure = load_structure("hover-wind")
    values = structure.values(dict(CALM_HOVER) | {"N_r": 0.0, "Z_w": 0.0})
    result = fit_wind(structure, values, structure.default_constants(), records)
    assert {step.parameter for step in result.reduction} == {"tau_w_lon", "tau_w_thr"}
    assert all(step.action == "dropped" and result.values[step.parameter] == 0.0 for step in result.reduction)
    assert np.all(result.accuracy.insensitivity_percent <= 10)


def test_records_without_wind_are_refused(records: list[Record]) -> None:
    structure = load_structure("hover-wind")
    bare = [
        Record(table=r.table.drop(columns="wind_lon"), units=r.units, trim=r.trim, source=r.source) for r in records
    ]
    with pytest.raises(FitError, match="wind_lon"):
        fit_wind(structure, structure.values(), structure.default_constants(), bare)
    with pytest.raises(FitError, match="no wind parameters"):
        fit_wind(load_structure("hover"), structure.values(), structure.default_constants(), records)
