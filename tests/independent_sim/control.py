"""A PX4-like cascade autopilot closed around the plant, as one discrete LTI system.

Every element is linear near hover (saturation is never reached at 5-8 % of
the mixer range), so the autopilot, the plant, the actuator lag and the
delays are assembled into one system sampled at the control rate::

    X[k+1] = A X[k] + B W[k],    Y[k] = C X[k] + D W[k]

``X`` holds the plant states (sampled exactly, :mod:`._zoh`), shift
registers of the last mixer commands (the delays), the filtered gyro and the
integrators. ``W`` holds everything from outside: sensor noise, the
excitation at each injection point, position setpoints, wind and
disturbances. ``Y`` holds what the autopilot logs: the mixer inputs
(controller output plus excitation), the rate, attitude and velocity
setpoints.

The cascade (PX4's ``mc_pos_control`` → ``mc_att_control`` →
``mc_rate_control``, and ArduPilot's equivalents)::

    velocity setpoint   v_sp = K_pos (x_sp - x)                     (NED)
    acceleration        a_sp = K_vel (v_sp - v) + integral K_vel_i (v_sp - v)
    attitude setpoint   theta_sp = -a_fwd / g,  phi_sp = a_right / g (heading frame)
    rate setpoint       omega_sp = K_att (att_sp - att)
    torque              tau = K_p e + integral K_i e - K_d d(gyro_f)/dt,  e = omega_sp - gyro_f
    thrust              delta_thr = -k_thr a_sp,d

where ``gyro_f`` is the gyro through a first-order low-pass filter.

The mixer command is held over each control period; a hold is a delay of
half a period, so the plant receives each held sample ``tau - T/2`` after it
(:func:`closed_loop`): the logged samples then lead the response by exactly
the model's ``tau`` (Table 3.3), for PX4 (T = 4 ms) and ArduPilot (2.5 ms) alike.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from independent_sim._zoh import DelayedInputMap, delayed_input_map, propagator
from independent_sim.plant import PLANT_INPUTS, STATES, G, HoverPlant, LinearPlant, linear_plant

__all__ = [
    "NOISE_INPUTS",
    "EXCITATION_INPUTS",
    "SETPOINT_INPUTS",
    "MIXER",
    "CascadeGains",
    "ClosedLoop",
    "px4_gains",
    "ardupilot_gains",
    "closed_loop",
]

#: Measurement errors the controller sees (gyro rad/s, attitude rad, velocity m/s, position m).
NOISE_INPUTS: tuple[str, ...] = ("n_p", "n_q", "n_r", "n_phi", "n_theta", "n_psi", "n_vn", "n_ve", "n_vd")
NOISE_INPUTS += ("n_xn", "n_ye", "n_zd")
#: Excitation by injection point: mixer (normalised), rate setpoint (rad/s),
#: attitude setpoint (rad), climb-rate setpoint (m/s, up).
EXCITATION_INPUTS: tuple[str, ...] = (
    "exc_mixer_lat",
    "exc_mixer_lon",
    "exc_mixer_yaw",
    "exc_mixer_thr",
    "exc_rate_lat",
    "exc_rate_lon",
    "exc_rate_yaw",
    "exc_attitude_lat",
    "exc_attitude_lon",
    "exc_climb_thr",
)
#: NED position setpoint perturbation, m.
SETPOINT_INPUTS: tuple[str, ...] = ("sp_xn", "sp_ye", "sp_zd")
#: The mixer inputs, in :data:`~independent_sim.plant.PLANT_INPUTS` order.
MIXER: tuple[str, ...] = ("delta_lat", "delta_lon", "delta_yaw", "delta_thr")
_EXTERNAL = tuple(name for name in PLANT_INPUTS if name not in MIXER)


@dataclass(frozen=True, slots=True, kw_only=True)
class CascadeGains:
    """Gains and rate of the cascade (PX4 parameter meanings, our values).

    Parameters
    ----------
    rate_hz : float
        Control (and mixer logging) rate, Hz.
    pos_xy_p, pos_z_p : float
        Position gains, (m/s)/m (``MPC_XY_P``, ``MPC_Z_P``).
    vel_xy_p, vel_z_p : float
        Velocity gains, (m/s²)/(m/s) (``MPC_XY_VEL_P_ACC``, ``MPC_Z_VEL_P_ACC``).
    vel_xy_i, vel_z_i : float
        Velocity integral gains, (m/s²)/m.
    att_roll_p, att_pitch_p, att_yaw_p : float
        Attitude gains, (rad/s)/rad (``MC_ROLL_P``...).
    rate_roll_p, rate_pitch_p, rate_yaw_p : float
        Rate gains, normalised torque per rad/s (``MC_ROLLRATE_P``...).
    rate_roll_i, rate_pitch_i, rate_yaw_i : float
        Rate integral gains, normalised torque per rad.
    rate_roll_d, rate_pitch_d : float
        Rate derivative gains on the filtered gyro, normalised torque per rad/s².
    gyro_cutoff_hz : float
        First-order gyro low-pass cut-off, Hz (``IMU_GYRO_CUTOFF``).
    thrust_per_accel : float
        Normalised thrust per m/s² of upward acceleration setpoint (the
        hover-thrust scaling; ``1/|Z_thr|`` when tuned to the plant).
    """

    rate_hz: float = 250.0
    pos_xy_p: float = 0.95
    pos_z_p: float = 1.0
    vel_xy_p: float = 1.8
    vel_xy_i: float = 0.4
    vel_z_p: float = 4.0
    vel_z_i: float = 2.0
    att_roll_p: float = 5.0
    att_pitch_p: float = 5.0
    att_yaw_p: float = 2.5
    rate_roll_p: float = 0.20
    rate_roll_i: float = 0.20
    rate_roll_d: float = 0.004
    rate_pitch_p: float = 0.22
    rate_pitch_i: float = 0.22
    rate_pitch_d: float = 0.0045
    rate_yaw_p: float = 1.2
    rate_yaw_i: float = 0.6
    gyro_cutoff_hz: float = 40.0
    thrust_per_accel: float = 1.0 / 87.12

    def __post_init__(self) -> None:
        for name in self.__dataclass_fields__:
            if getattr(self, name) < 0.0:
                raise ValueError(f"{name}={getattr(self, name)} must be ≥ 0")
        if not 50.0 <= self.rate_hz <= 2000.0:
            raise ValueError(f"{self.rate_hz=} Hz must be within [50, 2000]")
        if not 0.0 < self.gyro_cutoff_hz < self.rate_hz / 2:
            raise ValueError(f"{self.gyro_cutoff_hz=} Hz must be within (0, rate_hz / 2)")

    @property
    def period_s(self) -> float:
        """Control period, s."""
        return 1.0 / self.rate_hz


def px4_gains(plant: HoverPlant) -> CascadeGains:
    """The PX4 profile: 250 Hz rate loop, PX4-like default outer gains.

    Parameters
    ----------
    plant : HoverPlant
        The airframe (sets the thrust scaling).

    Returns
    -------
    CascadeGains
    """
    return CascadeGains(rate_hz=250.0, thrust_per_accel=1.0 / abs(plant.Z_thr))


def ardupilot_gains(plant: HoverPlant) -> CascadeGains:
    """The ArduPilot profile: 400 Hz loop, its own (softer outer, stiffer rate) gains.

    Parameters
    ----------
    plant : HoverPlant
        The airframe (sets the thrust scaling).

    Returns
    -------
    CascadeGains
    """
    return CascadeGains(
        rate_hz=400.0,
        pos_xy_p=1.0,
        pos_z_p=1.0,
        vel_xy_p=2.0,
        vel_xy_i=1.0,
        vel_z_p=5.0,
        vel_z_i=1.0,
        att_roll_p=4.5,
        att_pitch_p=4.5,
        att_yaw_p=2.0,
        rate_roll_p=0.18,
        rate_roll_i=0.18,
        rate_roll_d=0.0036,
        rate_pitch_p=0.20,
        rate_pitch_i=0.20,
        rate_pitch_d=0.004,
        rate_yaw_p=1.0,
        rate_yaw_i=0.1,
        gyro_cutoff_hz=20.0,
        thrust_per_accel=1.0 / abs(plant.Z_thr),
    )


@dataclass(frozen=True, slots=True)
class ClosedLoop:
    """The closed loop as one discrete LTI system at the control rate.

    Parameters
    ----------
    A, B, C, D : ndarray
        ``X[k+1] = A X[k] + B W[k]``, ``Y[k] = C X[k] + D W[k]``.
    states, inputs, outputs : tuple of str
        Names of the entries of X, W and Y.
    plant : LinearPlant
        The continuous plant.
    maps : tuple of DelayedInputMap
        Exact sub-step maps of each plant input (order of ``PLANT_INPUTS``).
    n_sub : int
        Sub-steps per control period of the fine time grid.
    period_s : float
        Control period, s.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    plant: LinearPlant
    maps: tuple[DelayedInputMap, ...] = field(repr=False)
    n_sub: int
    period_s: float

    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of ``A`` (discrete, inside the unit circle when stable)."""
        return np.linalg.eigvals(self.A)


class _Rows:
    """Linear expressions over ``[X; W]`` as row vectors, named by state or input."""

    def __init__(self, states: tuple[str, ...], inputs: tuple[str, ...]) -> None:
        self.states, self.inputs = states, inputs
        self._x = {name: k for k, name in enumerate(states)}
        self._w = {name: len(states) + k for k, name in enumerate(inputs)}
        self.size = len(states) + len(inputs)

    def x(self, name: str) -> np.ndarray:
        row = np.zeros(self.size)
        row[self._x[name]] = 1.0
        return row

    def w(self, name: str) -> np.ndarray:
        row = np.zeros(self.size)
        row[self._w[name]] = 1.0
        return row

    def states_block(self, names: tuple[str, ...]) -> np.ndarray:
        return np.array([self.x(name) for name in names])


def _state_names(maps: tuple[DelayedInputMap, ...]) -> tuple[str, ...]:
    buffers = tuple(f"buf_{name}_{j}" for name, m in zip(MIXER, maps) for j in range(m.n_periods + 1))
    control = ("gf_p", "gf_q", "gf_r", "i_p", "i_q", "i_r", "i_vn", "i_ve", "i_vd")
    return STATES + buffers + control


def closed_loop(plant: HoverPlant, gains: CascadeGains, *, n_sub: int = 1) -> ClosedLoop:
    """Assemble the discrete closed loop of `plant` under the cascade `gains`.

    Parameters
    ----------
    plant : HoverPlant
        The airframe and its trim.
    gains : CascadeGains
        Controller gains and rate.
    n_sub : int
        Sub-steps per control period of the fine output grid (≥ 1).

    Returns
    -------
    ClosedLoop
        Inputs ``W``: :data:`NOISE_INPUTS`, :data:`EXCITATION_INPUTS`,
        :data:`SETPOINT_INPUTS`, then ``name@prev`` and ``name@cur`` for each
        external plant input (the held samples ``u[k-n-1]`` and ``u[k-n]``).
        Outputs ``Y``: the mixer inputs (perturbation from trim, excitation
        included), ``p_sp q_sp r_sp`` (rad/s), ``phi_sp theta_sp`` (rad) and
        ``vn_sp ve_sp vd_sp`` (m/s).

    Examples
    --------
    >>> from independent_sim.plant import hover_plant
    >>> loop = closed_loop(hover_plant(), px4_gains(hover_plant()))
    >>> bool(np.abs(loop.eigenvalues()).max() < 1.0)
    True
    """
    linear = linear_plant(plant)
    T = gains.period_s
    maps = _input_maps(linear, T, n_sub)
    states = _state_names(maps)
    inputs = NOISE_INPUTS + EXCITATION_INPUTS + SETPOINT_INPUTS
    inputs += tuple(f"{name}@{when}" for name in _EXTERNAL for when in ("prev", "cur"))
    rows = _Rows(states, inputs)
    outputs, mixer = _controller(rows, linear, plant, gains)
    following: dict[str, np.ndarray] = {}
    _plant_update(rows, linear, maps, mixer, T, following)
    _buffer_update(rows, maps, mixer, following)
    for name in states:
        if name not in following:
            following[name] = outputs.pop(f"next:{name}")
    A_full = np.array([following[name] for name in states])
    Y_full = np.array(list(outputs.values()))
    n = len(states)
    return ClosedLoop(
        A=A_full[:, :n],
        B=A_full[:, n:],
        C=Y_full[:, :n],
        D=Y_full[:, n:],
        states=states,
        inputs=inputs,
        outputs=tuple(outputs),
        plant=linear,
        maps=maps,
        n_sub=n_sub,
        period_s=T,
    )


def _input_maps(linear: LinearPlant, period_s: float, n_sub: int) -> tuple[DelayedInputMap, ...]:
    """Exact sub-step maps of every plant input, with the hold's half period taken off the delays."""
    return tuple(
        delayed_input_map(linear.A, linear.B[:, j], _held_delay(name, linear.delays[j], period_s), period_s, n_sub)
        for j, name in enumerate(PLANT_INPUTS)
    )


def _held_delay(name: str, delay_s: float, period_s: float) -> float:
    """Delay applied to the held samples so that the logged (or smooth) signal leads by `delay_s`.

    A zero-order hold over a period T is a pure delay of T/2 (times a sinc
    magnitude, 0.9997 at 10 Hz and 250 Hz): the mixer samples the log
    carries, and the smooth wind the anemometer measures, reach the plant
    held for T after their instant. Delaying the held signal by ``tau - T/2``
    makes the logged samples lead the response by exactly the model's
    ``tau``, the value a correct identification returns. Disturbances and
    the kinematic wind are not delayed.
    """
    if name not in (*MIXER, "wind_lon_x", "wind_lon_z") or (name.startswith("wind") and delay_s == 0.0):
        return delay_s  # (a calm plant has no wind term and no wind delay)
    if delay_s < period_s / 2:
        raise ValueError(f"{name}: delay {delay_s} s is shorter than half the control period ({period_s / 2} s)")
    return delay_s - period_s / 2


def _plant_update(
    rows: _Rows,
    linear: LinearPlant,
    maps: tuple[DelayedInputMap, ...],
    mixer: dict[str, np.ndarray],
    T: float,
    following: dict[str, np.ndarray],
) -> None:
    """Rows of the plant states at the next period (exact hold, fractional delays)."""
    phi, _ = propagator(linear.A, linear.B[:, :1], T)
    block = phi @ rows.states_block(STATES)
    for j, name in enumerate(PLANT_INPUTS):
        m = maps[j]
        if name in MIXER:
            prev = rows.x(f"buf_{name}_{m.n_periods}")
            cur = rows.x(f"buf_{name}_{m.n_periods - 1}") if m.n_periods else mixer[name]
        else:
            prev, cur = rows.w(f"{name}@prev"), rows.w(f"{name}@cur")
        block += np.outer(m.before[-1], prev) + np.outer(m.after[-1], cur)
    for k, name in enumerate(STATES):
        following[name] = block[k]


def _buffer_update(
    rows: _Rows, maps: tuple[DelayedInputMap, ...], mixer: dict[str, np.ndarray], following: dict[str, np.ndarray]
) -> None:
    """Shift registers: ``buf_j[k+1] = buf_{j-1}[k]``, ``buf_0[k+1] = delta[k]``."""
    for name, m in zip(MIXER, maps):
        following[f"buf_{name}_0"] = mixer[name]
        for j in range(1, m.n_periods + 1):
            following[f"buf_{name}_{j}"] = rows.x(f"buf_{name}_{j - 1}")


def _controller(
    rows: _Rows, linear: LinearPlant, plant: HoverPlant, gains: CascadeGains
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """The cascade as rows: logged outputs, next controller states (``next:`` keys), mixer commands."""
    T, x, w = gains.period_s, rows.x, rows.w
    out: dict[str, np.ndarray] = {}
    # measured NED velocity: rotated air velocity and attitude terms, plus the wind now, plus noise
    position_rows = linear.A[[STATES.index(s) for s in ("x_n", "y_e", "z_d")]]
    velocity = position_rows @ rows.states_block(STATES)
    velocity[0] += w("wind_n@cur") + w("n_vn")
    velocity[1] += w("wind_e@cur") + w("n_ve")
    velocity[2] += w("n_vd")
    position = [x(s) + w(n) for s, n in (("x_n", "n_xn"), ("y_e", "n_ye"), ("z_d", "n_zd"))]
    # position P and velocity PI (NED)
    v_sp = [
        gains.pos_xy_p * (w("sp_xn") - position[0]),
        gains.pos_xy_p * (w("sp_ye") - position[1]),
        gains.pos_z_p * (w("sp_zd") - position[2]) - w("exc_climb_thr"),
    ]
    accel = []
    for k, axis in enumerate(("vn", "ve", "vd")):
        kp, ki = (gains.vel_z_p, gains.vel_z_i) if axis == "vd" else (gains.vel_xy_p, gains.vel_xy_i)
        error = v_sp[k] - velocity[k]
        out[f"next:i_{axis}"] = x(f"i_{axis}") + ki * T * error
        accel.append(kp * error + x(f"i_{axis}"))
        out[f"{axis}_sp"] = v_sp[k]
    cos_psi, sin_psi = math.cos(plant.trim.psi0), math.sin(plant.trim.psi0)
    forward = cos_psi * accel[0] + sin_psi * accel[1]
    right = -sin_psi * accel[0] + cos_psi * accel[1]
    attitude_sp = {"phi": right / G + w("exc_attitude_lat"), "theta": -forward / G + w("exc_attitude_lon")}
    rate_sp = {
        "p": gains.att_roll_p * (attitude_sp["phi"] - x("phi") - w("n_phi")) + w("exc_rate_lat"),
        "q": gains.att_pitch_p * (attitude_sp["theta"] - x("theta") - w("n_theta")) + w("exc_rate_lon"),
        "r": gains.att_yaw_p * (-x("psi") - w("n_psi")) + w("exc_rate_yaw"),
    }
    out["phi_sp"], out["theta_sp"] = attitude_sp["phi"], attitude_sp["theta"]
    alpha = math.exp(-2.0 * math.pi * gains.gyro_cutoff_hz * T)
    mixer: dict[str, np.ndarray] = {}
    for axis, name, (kp, ki, kd) in (
        ("p", "delta_lat", (gains.rate_roll_p, gains.rate_roll_i, gains.rate_roll_d)),
        ("q", "delta_lon", (gains.rate_pitch_p, gains.rate_pitch_i, gains.rate_pitch_d)),
        ("r", "delta_yaw", (gains.rate_yaw_p, gains.rate_yaw_i, 0.0)),
    ):
        filtered = alpha * x(f"gf_{axis}") + (1.0 - alpha) * (x(axis) + w(f"n_{axis}"))
        derivative = (filtered - x(f"gf_{axis}")) / T
        error = rate_sp[axis] - filtered
        out[f"next:gf_{axis}"] = filtered
        out[f"next:i_{axis}"] = x(f"i_{axis}") + ki * T * error
        mixer[name] = kp * error + x(f"i_{axis}") - kd * derivative + w(f"exc_mixer_{name[6:]}")
        out[f"{axis}_sp"] = rate_sp[axis]
    mixer["delta_thr"] = -gains.thrust_per_accel * accel[2] + w("exc_mixer_thr")
    for name in MIXER:
        out[name] = mixer[name]
    ordered = {name: out[name] for name in (*MIXER, "p_sp", "q_sp", "r_sp", "phi_sp", "theta_sp")}
    ordered.update({name: out[name] for name in ("vn_sp", "ve_sp", "vd_sp")})
    ordered.update({key: value for key, value in out.items() if key.startswith("next:")})
    return ordered, mixer
