"""Builders the tests share: known closed-loop flights, a small identified model, a small verification.

Importable from any test as ``import builders`` (``tests`` is on pytest's ``pythonpath``).

- The roll axis of a hovering multirotor under a cascaded hold (position P, velocity PI,
  angle P, rate PI), with the injected excitation known exactly, and the inputs flown in it.
- The hover structure at Table 3.3's values with chosen costs and accuracies (for reports).
- A small simulated verification of a pitch-like model on two noisy doublets (for reports).
- A read whose project warnings are checked against the result's ``warnings`` (for real logs).
"""

from __future__ import annotations

import dataclasses
import math
import re
import warnings
from collections.abc import Callable, Mapping
from datetime import UTC, datetime
from importlib import resources
from pathlib import Path
from typing import TypeVar

import numpy as np
import pandas as pd

from flightlogs.conditioning.condition import ConditioningOptions, condition_flight
from flightlogs.errors import SysidWarning
from flightlogs.flightlog import FlightLog
from flightlogs.readers import read_log
from flightlogs.record import Record
from simulator.vehicle.identified import CALM_HOVER
from sysid.discrepancy import DiscrepancyResult, FlightSeries, discover, flight_series
from sysid.fit import CostSummary, IdentifiedModel, ParameterEstimate, Provenance, ReductionStep, synthetic_responses
from sysid.model import parse_structure
from sysid.model.discrete import discretize, simulate
from sysid.model.statespace import DelayedStateSpace
from sysid.verify import Verification, verify

# ------------------------------------------------------------------ a closed-loop roll hold

RATE_HZ = 100.0


DT = 1.0 / RATE_HZ


AMPLITUDE = 0.15  # mixer units (0-1 scale), as the chapter 3 campaign's 15 % doublets


def closed_loop_roll_hold(excitation: np.ndarray, seed: int, gust: float) -> dict[str, np.ndarray]:
    """Mixer input ``u`` and the logged ``p phi ve`` of the roll axis with `excitation` summed at the mixer.

    Plant: actuator lag 0.05 s, roll acceleration 60 rad/s² per unit input,
    ``ve' = g phi``; turbulence as slowly varying torque and acceleration.
    Gains: rate loop crossover 10 rad/s with its integrator at a fifth of it,
    angle 4 /s, velocity 1 /s (integral 0.2), position 0.4 /s.
    """
    rng = np.random.default_rng(seed)
    effectiveness, lag_s, substeps = 60.0, 0.05, 4
    kp, ki, k_angle, k_vel, ki_vel, k_pos = 10 / effectiveness, 20 / effectiveness, 4.0, 1.0, 0.2, 0.4
    actuator = p = phi = ve = pe = rate_integral = velocity_integral = torque = accel = 0.0
    log = {name: np.zeros(excitation.size) for name in ("u", "p", "phi", "ve")}
    h = DT / substeps
    for k, e in enumerate(excitation):
        noise = rng.standard_normal(3) * (0.005, 0.001, 0.02)  # rate, angle and velocity estimates
        p_m, phi_m, ve_m = p + noise[0], phi + noise[1], ve + noise[2]
        v_set = -k_pos * pe
        velocity_integral += ki_vel * (v_set - ve_m) * DT
        phi_set = (k_vel * (v_set - ve_m) + velocity_integral) / 9.81
        rate_error = k_angle * (phi_set - phi_m) - p_m
        rate_integral += ki * rate_error * DT
        u = kp * rate_error + rate_integral + e
        log["u"][k], log["p"][k], log["phi"][k], log["ve"][k] = u, p_m, phi_m, ve_m
        torque = 0.995 * torque + gust * 0.3 * rng.standard_normal()
        accel = 0.995 * accel + gust * 0.05 * rng.standard_normal()
        for _ in range(substeps):
            actuator += h * (u - actuator) / lag_s
            p += h * (effectiveness * actuator + torque)
            phi += h * p
            ve += h * (9.81 * phi + accel)
            pe += h * ve
    return log


def doublet_input(t: np.ndarray, start_s: float, pulse_s: float) -> np.ndarray:
    first = (t >= start_s) & (t < start_s + pulse_s)
    second = (t >= start_s + pulse_s) & (t < start_s + 2 * pulse_s)
    return AMPLITUDE * (first.astype(float) - second)


def sweep_input(t: np.ndarray, start_s: float, length_s: float) -> np.ndarray:
    tau = np.clip(t - start_s, 0.0, length_s)
    phase = 2 * np.pi * (0.3 * tau + (4.0 - 0.3) * tau**2 / (2 * length_s))  # 0.3 to 4 Hz, linear
    return np.where((t >= start_s) & (t < start_s + length_s), 0.5 * AMPLITUDE * np.sin(phase), 0.0)


def input_3211(t: np.ndarray, start_s: float, unit_s: float) -> np.ndarray:
    edges = start_s + unit_s * np.cumsum([0, 3, 2, 1, 1])
    return AMPLITUDE * sum(sign * ((t >= a) & (t < b)) for sign, a, b in zip([1, -1, 1, -1], edges[:-1], edges[1:]))


def multisine_input(t: np.ndarray, start_s: float, length_s: float) -> np.ndarray:
    tones = [0.4, 0.9, 1.3, 2.1, 2.9, 3.7]
    phases = np.random.default_rng(9).uniform(0, 2 * np.pi, len(tones))
    inside = (t >= start_s) & (t < start_s + length_s)
    return 0.3 * AMPLITUDE * inside * sum(np.sin(2 * np.pi * f * t + ph) for f, ph in zip(tones, phases))


# ------------------------------------------------------------------ a small identified model (reports)

STAMP = "2024-05-01 12:00 UTC"


PAIRS = ("q/delta_lon", "u/delta_lon", "p/delta_lat", "az/delta_thr")


DROPPED = ("N_r", "Z_w", "tau_thr")


NORMALISED_UNIT = "normalised (-1..1)"


def small_model(
    *,
    average: float = 40.0,
    costs: Mapping[str, float] | None = None,
    accuracy: Mapping[str, tuple[float, float]] | None = None,
    files: tuple[str, ...] = ("flight.bin",),
    notes: tuple[str, ...] = (),
    responses: bool = True,
) -> IdentifiedModel:
    """The hover structure at Table 3.3's values (per normalised input) with chosen costs and accuracies."""
    text = (resources.files("sysid.model") / "builtin" / "hover.toml").read_text()
    structure = parse_structure(text, source="hover")
    values = dict(CALM_HOVER) | {"N_r": 0.0, "Z_w": 0.0, "tau_thr": 0.0}
    for name in ("X_lon", "M_lon", "Y_lat", "L_lat", "N_yaw", "Z_thr"):
        values[name] *= 100.0  # the mixer input is logged normalised to -1..1
    accuracy = dict(accuracy or {})
    parameters = []
    for p in structure.parameters:
        estimated = p.name not in DROPPED
        cr, ins = accuracy.get(p.name, (5.0, 2.0)) if estimated else (math.nan, math.nan)
        unit = re.sub(r"\{delta_\w+\}", NORMALISED_UNIT, p.unit)
        parameters.append(
            ParameterEstimate(
                name=p.name,
                value=values[p.name],
                cr_percent=cr,
                insensitivity_percent=ins,
                status="estimated" if estimated else "dropped",
                unit=unit,
            )
        )
    names = tuple(p.name for p in parameters if p.status == "estimated")
    correlation = np.eye(len(names))
    correlation[0, 1] = correlation[1, 0] = -0.95  # X_u, M_u: the one pair beyond |r| = 0.9
    correlation[2, 3] = correlation[3, 2] = 0.5
    constants = {"g": 9.81, "U0": 0.0, "V0": 0.0, "W0": 0.0, "phi0": 0.0, "theta0": 0.0}
    model = IdentifiedModel(
        structure_name="hover",
        structure_text=text,
        parameters=tuple(parameters),
        correlation_names=names,
        correlation=correlation,
        cost=CostSummary(average=average),
        constants=constants,
    )
    fitted = (
        synthetic_responses(model.linear_model(), PAIRS, noise_db=0.5, noise_deg=3.0, fit_range=(1.0, 40.0), seed=3)
        if responses
        else ()
    )
    costs = dict(costs) if costs is not None else {pair: average for pair in PAIRS}
    reduction = (
        ReductionStep(
            step=1,
            parameter="N_r",
            action="dropped",
            value=0.0,
            estimate=-0.02,
            cr_percent=80.0,
            insensitivity_percent=45.0,
            reason="I% = 45 > 10",
            cost_average=average,
            cost_average_after=average,
        ),
    )
    provenance = Provenance(
        files=files,
        sha256={f: "ab" * 32 for f in files},
        options={"min_coherence": 0.5, "fit": {"starts": 1}},
        versions={"flight-sysid": "0.1.0"},
        created_utc="2024-05-01T12:00:00+00:00",
    )
    return dataclasses.replace(
        model,
        cost=CostSummary(average=average, responses=costs),
        responses=fitted,
        reduction=reduction,
        provenance=provenance,
        notes=notes,
        input_units={"delta_lon": NORMALISED_UNIT},
    )


# ------------------------------------------------------------------ a small verification (reports)


def sample_verification(*, seed: int = 0) -> Verification:
    """A small verification to render: a pitch-like model with and without a wind term on two noisy doublets.

    A weakly coupled roll rate ``p`` (driven by the pitch rate and its own input) is an off-axis output of the
    ``delta_lon`` doublets, shown for information.
    """
    a = np.array([[-1.5, -6.0, 1.2, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -20.0, 0.0], [0.3, 0.0, 0.0, -3.0]])
    b = np.array([[0.0, 0.0, 0.3], [0.0, 0.0, 0.0], [20.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    c = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [-0.4, 0.0, 0.3, 0.0], [0.0, 0.0, 0.0, 1.0]])
    d = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.5], [0.0, 0.0, 0.0]])
    with_wind = DelayedStateSpace(
        a=a,
        b=b,
        c=c,
        d=d,
        states=("q", "theta", "d_lon", "p"),
        inputs=("delta_lon", "delta_lat", "wind_lon"),
        outputs=("q", "theta", "ax", "p"),
        input_delays_s=np.array([0.02, 0.02, 0.015]),
    )
    without = DelayedStateSpace(
        a=a,
        b=b[:, :2],
        c=c,
        d=d[:, :2],
        states=with_wind.states,
        inputs=with_wind.inputs[:2],
        outputs=with_wind.outputs,
        input_delays_s=with_wind.input_delays_s[:2],
    )
    rng = np.random.default_rng(seed)
    t = np.arange(400) * 0.01
    records = []
    for k in range(2):
        doublet = np.where((t >= 0.5) & (t < 1.5), 0.4, 0.0) - np.where((t >= 1.5) & (t < 2.5), 0.4, 0.0)
        wind = np.cumsum(rng.normal(scale=0.02, size=t.size))
        inputs = np.column_stack([doublet, 0.05 * np.sin(2.0 * t), wind - wind.mean()])
        y = simulate(discretize(with_wind, 0.01), inputs, np.zeros(4))
        y += rng.normal(scale=[0.005, 0.001, 0.03, 0.005], size=y.shape)
        table = pd.DataFrame(
            {
                "delta_lon": inputs[:, 0],
                "delta_lat": inputs[:, 1],
                "wind_lon": inputs[:, 2],
                "q": y[:, 0],
                "theta": y[:, 1],
                "ax": y[:, 2],
                "p": y[:, 3],
            },
            index=pd.Index(20.0 * k + 5.0 + t, name="time_s"),
        )
        units = {
            "delta_lon": "%",
            "delta_lat": "%",
            "wind_lon": "m/s",
            "q": "rad/s",
            "theta": "rad",
            "ax": "m/s^2",
            "p": "rad/s",
        }
        records.append(
            Record.from_table(
                table,
                units=units,
                trim={},
                source=Path("doublets.ulg"),
                label=f"doublets.ulg lon doublet {k + 1}",
            )
        )
    return verify(
        without,
        records,
        wind_model=with_wind,
        excited=["delta_lon", "delta_lon"],
        axes={"delta_lon": ("q", "theta", "ax")},
    )


# ------------------------------------------------------------------ warnings kept in results

_T = TypeVar("_T")


def read_warned(read: Callable[..., _T], *args: object, **kwargs: object) -> _T:
    """``read(*args, **kwargs)``, checking that the project warnings it raises are its result's ``warnings``.

    For tests on real logs, whose warnings (dropouts, samples flagged
    invalid, GNSS without a fix) are not what they test: each warning must
    still be raised to the caller and kept in the result, in order. Any
    other warning stays an error, as the test configuration makes it.
    """
    with warnings.catch_warnings(record=True) as raised:
        warnings.simplefilter("always", SysidWarning)
        result = read(*args, **kwargs)
    assert tuple(str(w.message) for w in raised) == tuple(result.warnings)  # type: ignore[attr-defined]
    return result


# ------------------------------------------------------------------ models with unidentified axes


def with_unidentified(
    model: IdentifiedModel, names: set[str], reasons: Mapping[str, str] | None = None
) -> IdentifiedModel:
    """`model` with the parameters `names` unidentified (no value, no accuracy), as ``sysid fit --partial`` leaves them.

    `reasons` gives the recorded reason of each unidentified axis (``{"lon": "no sweep found in 3 logs"}``);
    without it the model records no axes, as an older file, and they are derived from the parameters.
    """
    nothing = {"status": "unidentified", "value": math.nan, "cr_percent": math.nan, "insensitivity_percent": math.nan}
    parameters = tuple(dataclasses.replace(p, **nothing) if p.name in names else p for p in model.parameters)
    changed = dataclasses.replace(model, parameters=parameters, axes=())
    if reasons is None:
        return changed
    axes = tuple(
        dataclasses.replace(a, status="unidentified", reason=reasons[a.axis]) if a.axis in reasons else a
        for a in changed.axis_status
    )
    return dataclasses.replace(changed, axes=axes)


def discrepancy_series(path: Path) -> FlightSeries:
    """A log's flown samples as the discrepancy search reads them (no maneuver detection: it needs none)."""
    flight = condition_flight(read_log(path), options=ConditioningOptions(segments=()))
    return flight_series(path.name, flight.records)


def discover_independent_pairs(
    folder: Path, sim_seed: int, real_seed: int, changes: Mapping[str, tuple[tuple[str, float], ...]]
) -> dict[str, DiscrepancyResult]:
    """The search on ``independent_sim`` pairs: one SIM flight, a REAL one per entry of `changes` (its plant changes).

    REAL flight k has noise seed ``real_seed + k``; every log is a PX4 ULog written into `folder`.
    """
    from independent_sim.corpus import write_case
    from independent_sim.pairs import pair_case

    sim = discrepancy_series(write_case(pair_case("sim", sim_seed, ()), folder).log)
    return {
        name: discover(
            [sim], [discrepancy_series(write_case(pair_case(f"real-{k}", real_seed + k, plant), folder).log)]
        )
        for k, (name, plant) in enumerate(changes.items())
    }


def synthetic_series(n: int = 3000, seed: int = 0, *, drag: float = 0.0, lowest_m: float = 2.0) -> FlightSeries:
    """A synthetic flight at 50 Hz: smooth random commands and states, outputs linear in them plus white noise.

    ``ax = -(0.3 + drag) u + 2 δ_lon``, ``ay`` likewise in ``v`` and ``δ_lat``, ``az = -9.81 - 20 (δ_thr - 0.45)``,
    each angular acceleration 50 times its command; noise 0.05 m/s² and 0.1 rad/s². `drag` (1/s) is a
    rotor drag that a flight built with 0 lacks; the height stays above `lowest_m`.
    """
    from sysid.discrepancy.series import COMMANDS

    rng = np.random.default_rng(seed)

    def smooth(scale: float) -> np.ndarray:
        return scale * np.convolve(rng.normal(size=n + 49), np.ones(50) / 50.0, mode="valid")

    signals = {c: smooth(0.05) for c in COMMANDS}
    signals["delta_thr"] = signals["delta_thr"] + 0.45
    for name, scale in (("u", 3.0), ("v", 3.0), ("w", 0.5), ("p", 0.2), ("q", 0.2), ("r", 0.2), ("vd", 0.5)):
        signals[name] = smooth(scale)
    signals["height_agl"] = lowest_m + np.abs(smooth(5.0))
    signals["battery_v"] = 25.0 - np.linspace(0.0, 1.0, n) + smooth(0.05)
    signals["t_flight"] = np.arange(n) / 50.0
    signals["ax"] = -(0.3 + drag) * signals["u"] + 2.0 * signals["delta_lon"] + rng.normal(0, 0.05, n)
    signals["ay"] = -(0.3 + drag) * signals["v"] + 2.0 * signals["delta_lat"] + rng.normal(0, 0.05, n)
    signals["az"] = -9.81 - 20.0 * (signals["delta_thr"] - 0.45) + rng.normal(0, 0.05, n)
    for axis, command in (("p_dot", "delta_lat"), ("q_dot", "delta_lon"), ("r_dot", "delta_yaw")):
        signals[axis] = 50.0 * signals[command] + rng.normal(0, 0.1, n)
    return FlightSeries(
        name=f"synthetic-{seed}", time_s=np.arange(n) / 50.0, piece=np.zeros(n, int), signals=signals, rate_hz=50.0
    )


#: The column map of :func:`roll_table`'s tables.
ROLL_TABLE_MAP = "time=time_ms:ms,delta_lat=mixer_roll,p=roll_rate_dps:deg/s"


def simulated_roll_log(folder: Path) -> Path:
    """Our simulator's 34 s roll sweep (calm hover, seed 2) as a PX4 log; the sweep is 28-62 s on the log clock."""
    from simulator.autopilot.excitation import Maneuver
    from simulator.flights.linear import simulate_hover
    from simulator.output.px4 import write_px4_log

    flight = simulate_hover(
        50.0,
        (Maneuver(axis="lat", kind="sweep", start_s=8.0, amplitude=8.0, duration_s=34.0),),
        parameters=CALM_HOVER,
        seed=2,
    )
    return write_px4_log(flight, folder / "roll.ulg", utc_start=datetime(2024, 5, 1, 10, tzinfo=UTC))


def roll_table(log: FlightLog, folder: Path) -> tuple[Path, Path]:
    """A log's roll mixer input and roll rate on the rate's time base, as a flight-test export would hold them:
    ``roll.csv`` (time in ms, rate in deg/s) and ``roll.parquet``, read with :data:`ROLL_TABLE_MAP`."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    t = log["p"].time_s
    delta = np.interp(t, log["delta_lat"].time_s, log["delta_lat"].values)
    p_deg_s = np.degrees(log["p"].values)
    csv = folder / "roll.csv"
    csv.write_text(
        "time_ms,mixer_roll,roll_rate_dps\n"
        + "".join(f"{a * 1e3:.4f},{b:.9g},{c:.9g}\n" for a, b, c in zip(t, delta, p_deg_s))
    )
    parquet = folder / "roll.parquet"
    pq.write_table(pa.table({"time_ms": t * 1e3, "mixer_roll": delta, "roll_rate_dps": p_deg_s}), parquet)
    return csv, parquet
