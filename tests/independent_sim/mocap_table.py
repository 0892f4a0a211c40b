"""A flown case as a motion-capture rig exports it: a 50 Hz CSV of what the rig and the vehicle's own IMU give.

The rig tracks height (1 mm of noise) and attitude (0.03°); the vehicle's own velocity estimate, gyro rates
and each rotor's speed (ESC telemetry) are merged in at the rig's rate, sampled as a logger samples. Nothing
the rig does not record is written: no accelerometer, no mixer input. (Velocities cleaner than the
simulation's sensors make the search read the simulation's attenuated drag as a small parasitic drag:
0.6 % on seed 32 with the rig's own 5 mm/s velocities; errors in variables, not the table.) Rotor speed is ``FULL_RPM sqrt(command)``
(thrust grows with its square), with the octocopter's mixer (gains 0.5 roll and pitch, 0.3 yaw).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from independent_sim._common import motor_commands
from independent_sim.flight import Flight

__all__ = ["FULL_RPM", "MOCAP_MAP", "write_mocap_table"]

#: Rotor speed at full command, rpm.
FULL_RPM = 9000.0
_STEP_S = 0.02  # the rig's rate: 50 Hz

#: The column map (TOML) of :func:`write_mocap_table`'s tables.
MOCAP_MAP = (
    "[columns]\ntime = 'time_ms:ms'\nheight_agl = 'height_mm:mm'\n"
    + "".join(f"v{a} = 'v{a}'\n" for a in "ned")
    + "".join(f"{a} = '{a}_deg:deg'\n" for a in ("phi", "theta", "psi"))
    + "".join(f"{r} = '{r}_dps:deg/s'\n" for r in "pqr")
    + "".join(f"motor_{k} = 'rpm{k}:rpm'\n" for k in range(1, 9))
    + f"\n[rotors]\nframe = 'octo_x'\nfull_scale = {FULL_RPM:g}\ngains = [0.5, 0.5, 0.3]\n"
)


def write_mocap_table(flight: Flight, path: Path, seed: int) -> Path:
    """Write `flight` as a motion-capture CSV at 50 Hz (time in ms from the first row).

    Parameters
    ----------
    flight : Flight
        The flown case.
    path : Path
        Destination ``.csv``.
    seed : int
        Seed of the rig's own noise.

    Returns
    -------
    Path
        `path`.
    """
    rng = np.random.default_rng(seed)
    every = int(round(_STEP_S / (flight.step_us * 1e-6)))
    i = np.arange(0, flight.time_s.size, every)
    truth = flight.truth

    def tracked(name: str, std: float) -> np.ndarray:
        return np.asarray(truth[name][i] + rng.normal(0.0, std, i.size))

    columns = {
        "time_ms": (flight.time_s[i] - flight.time_s[0]) * 1e3,
        "height_mm": 1e3 * tracked("height", 0.001),
        **{f"v{a}": np.asarray(flight.measured[f"v{a}"][i]) for a in "ned"},
        **{f"{a}_deg": np.degrees(tracked(a, 0.0005)) for a in ("phi", "theta", "psi")},
        **{f"{r}_dps": np.degrees(flight.measured[r][i]) for r in "pqr"},
    }
    command = motor_commands(flight, i)
    columns.update({f"rpm{k + 1}": FULL_RPM * np.sqrt(command[:, k]) for k in range(command.shape[1])})
    names = list(columns)
    rows = np.column_stack([columns[n] for n in names])
    path.write_text(",".join(names) + "\n" + "".join(",".join(f"{v:.9g}" for v in row) + "\n" for row in rows))
    return path
