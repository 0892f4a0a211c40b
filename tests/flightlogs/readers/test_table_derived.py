"""What a motion-capture table lacks, derived (issue 32): mixer inputs from rotor speeds, specific forces.

The mixer inverse is checked against mixers written elsewhere: the simulator's PX4 airframe (its
``Airframe.mix``) and the independent generator's octocopter (``MOTOR_MIX``, gains 0.5 and 0.3).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from flightlogs.conditioning.condition import ConditioningOptions, condition_flight
from flightlogs.errors import DataError, DataQualityWarning
from flightlogs.readers import ReadOptions, parse_table_map, read_log
from flightlogs.readers._table_derived import FRAMES, RotorLayout
from flightlogs.store.dataset import read_dataset, write_dataset

T = np.round(np.arange(0.0, 20.0, 0.02), 6)
RNG = np.random.default_rng(3)
#: Mixer inputs (lat, lon, yaw, thr), slow enough that no motor leaves 0..1.
INPUTS = np.column_stack(
    [
        0.05 * np.sin(2 * np.pi * 0.3 * T),
        0.04 * np.cos(2 * np.pi * 0.5 * T),
        0.03 * np.sin(2 * np.pi * 0.2 * T + 1.0),
        0.5 + 0.05 * np.sin(2 * np.pi * 0.1 * T),
    ]
)


def _table(folder: Path, columns: dict[str, np.ndarray], rotors: str | None) -> tuple[Path, Path]:
    csv = folder / "rig.csv"
    names = list(columns)
    rows = np.column_stack([columns[n] for n in names])
    csv.write_text(",".join(names) + "\n" + "".join(",".join(f"{v:.12g}" for v in row) + "\n" for row in rows))
    mapping = folder / "rig.toml"
    entries = "".join(f"{n} = '{n}'\n" for n in names if n != "time" and not n.startswith("rpm"))
    motors = "".join(f"motor_{n[3:]} = '{n}:rpm'\n" for n in names if n.startswith("rpm"))
    layout = "" if rotors is None else f"\n[rotors]\n{rotors}"
    mapping.write_text(f"[columns]\ntime = 'time:s'\n{entries}{motors}{layout}")
    return csv, mapping


def _read(csv: Path, mapping: Path) -> object:
    return read_log(csv, reading=ReadOptions(table_map=parse_table_map(str(mapping))))


def _rpm(commands: np.ndarray, full: float) -> dict[str, np.ndarray]:
    return {f"rpm{k + 1}": full * np.sqrt(commands[:, k]) for k in range(commands.shape[1])}


def test_rotor_speeds_give_back_the_px4_airframe_s_mixer_inputs(tmp_path: Path) -> None:
    from simulator.output.px4 import AIRFRAMES

    commands = AIRFRAMES["quad"].mix(INPUTS[:, 3], INPUTS[:, :3])
    csv, mapping = _table(tmp_path, {"time": T, **_rpm(commands, 25_000.0)}, "frame = 'quad_x'\nfull_scale = 25000\n")
    log = _read(csv, mapping)
    for k, name in enumerate(("delta_lat", "delta_lon", "delta_yaw", "delta_thr")):
        np.testing.assert_allclose(log[name].values, INPUTS[:, k], atol=1e-9)
        assert log[name].derived and log[name].unit == "normalised"
    assert not log["motor_1"].derived


def test_the_independent_generator_s_octocopter_mixer_is_the_octo_x_layout_with_its_gains() -> None:
    from independent_sim._mixer import MOTOR_MIX

    angles, spins = FRAMES["octo_x"]
    layout = RotorLayout(angles, spins, 9000.0, (0.5, 0.5, 0.3))
    np.testing.assert_allclose(layout.mixer, MOTOR_MIX, atol=1e-12)


def test_a_hexacopter_given_by_angles_and_spins_round_trips(tmp_path: Path) -> None:
    """A layout no frame names: six rotors, gains 0.8 / 0.7 / 0.4, rotor speeds in rad/s."""
    angles = [0.0, 60.0, 120.0, 180.0, 240.0, 300.0]
    spins = [1, -1, 1, -1, 1, -1]
    layout = RotorLayout(tuple(angles), tuple(spins), 900.0, (0.8, 0.7, 0.4))
    commands = INPUTS @ layout.mixer.T
    columns = {"time": T, **{f"rpm{k + 1}": 900.0 * np.sqrt(commands[:, k]) for k in range(6)}}
    csv, mapping = _table(
        tmp_path, columns, f"angles_deg = {angles}\nspins = {spins}\nfull_scale = 900\ngains = [0.8, 0.7, 0.4]\n"
    )
    mapping.write_text(mapping.read_text().replace(":rpm'", ":rad/s'"))
    log = _read(csv, mapping)
    derived = np.column_stack([log[n].values for n in ("delta_lat", "delta_lon", "delta_yaw", "delta_thr")])
    np.testing.assert_allclose(derived, INPUTS, atol=1e-9)


def test_specific_forces_come_from_the_velocities_and_survive_a_dataset(tmp_path: Path) -> None:
    """A climb accelerating 0.5 m/s² north, level: ax = 0.5, az = -g; flagged derived in the log, the
    conditioned flight and the dataset that stores them; a mapped ax is never replaced."""
    columns = {
        "time": T,
        "vn": 0.5 * T,
        "ve": np.zeros(T.size),
        "vd": np.full(T.size, -1.0),
        "phi": np.zeros(T.size),
        "theta": np.zeros(T.size),
        "psi": np.zeros(T.size),
        "p": 0.001 * RNG.standard_normal(T.size),
    }
    csv, mapping = _table(tmp_path, columns, None)
    log = _read(csv, mapping)
    np.testing.assert_allclose(log["ax"].values, 0.5, atol=1e-9)
    np.testing.assert_allclose(log["az"].values, -9.80665, atol=1e-9)
    assert log["ax"].derived and "derived" in log["ax"].source and not log["vn"].derived
    with pytest.warns(DataQualityWarning, match="no wind given"):
        flight = condition_flight(log, None, ConditioningOptions(segments=()))
    assert flight.derived == ("ax", "ay", "az")
    write_dataset(tmp_path / "rig.h5", [log], conditioned=[flight])
    stored = read_dataset(tmp_path / "rig.h5")
    assert stored.logs[0]["ax"].derived and not stored.logs[0]["vn"].derived
    assert stored.conditioned[0].derived == ("ax", "ay", "az")
    mapping.write_text(mapping.read_text().replace("[columns]\n", "[columns]\nax = 'p'\n"))
    assert not _read(csv, mapping)["ax"].derived


@pytest.mark.parametrize(
    ("rotors", "message"),
    [
        ("frame = 'quad_x'\n", "the motors are rotor speeds; give [rotors] full_scale"),
        (
            "frame = 'octo_x'\nfull_scale = 1\n",
            "[rotors] lays out 8 rotors but the table maps motor_1, motor_2, motor_3, motor_4",
        ),
        ("frame = 'tri'\n", "[rotors] frame 'tri' is not one of quad_x, octo_x"),
        (
            "angles_deg = [0, 90, 180, 270]\nspins = [1, 0, 1, -1]\n",
            "[rotors] spins [1, 0, 1, -1] must each be +1 or -1",
        ),
        ("frame = 'quad_x'\nspeed = 3\n", "[rotors] has speed; it takes frame or angles_deg and spins"),
        ("frame = 'quad_x'\nfull_scale = -5\n", "[rotors] full_scale -5.0 must be a positive rotor speed"),
    ],
)
def test_a_bad_rotor_layout_is_one_sentence(tmp_path: Path, rotors: str, message: str) -> None:
    commands = INPUTS @ RotorLayout(*FRAMES["quad_x"]).mixer.T
    csv, mapping = _table(tmp_path, {"time": T, **_rpm(commands, 100.0)}, rotors)
    with pytest.raises(DataError) as caught:
        _read(csv, mapping)
    assert message in str(caught.value) and "\n" not in str(caught.value)
