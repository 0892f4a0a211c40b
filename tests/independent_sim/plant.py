"""The truth airframe: the chapter 3 hover octocopter, linearised as in Table 3.3.

The plant is written from the dissertation (eqs. 3.2, 3.4-3.7, 3.10-3.13 and
Tables 3.2, 3.3, 3.5), not from the workbench: it shares no code with
``simulator`` or ``sysid``. It is deliberately the *same model* as the
identification structures ``hover`` and ``hover-wind``
(``sysid/model/builtin/hover*.toml``), parameter by parameter, so that its
parameters are exactly what a correct identification must return.

Mixer scaling
-------------
The dissertation logs the mixer inputs "normalised to 0~100 %"; the control
derivatives of Table 3.3 are per percent. PX4 logs the torque setpoint in
-1..1 and the thrust setpoint in 0..1, ArduPilot its RATE outputs the same
way, so one unit of a logged mixer input is 100 %: every control derivative
(X_lon, M_lon, Y_lat, L_lat, N_yaw, Z_thr) is multiplied by
``control_scale = 100``. M_lon = 0.5251 rad/s² per % becomes 52.51 rad/s² per
unit of ``vehicle_torque_setpoint.xyz[1]``. The trim thrust (0.45) is set
apart from the local slope Z_thr: thrust is not linear in the command.

Parameters the table leaves out
-------------------------------
Z_w = 0 (dropped in chapter 3), N_r = 0 except in strong wind, tau_yaw =
13.3 ms in every condition and tau_thr = 15 ms (Table 3.3 takes it as zero;
here it is a real delay to find).

Wind
----
In light and strong wind the truth is the ``hover-wind`` structure taken
literally: the states u v w are air-relative (eq. 3.1), the along-nose gust
drives u and w through X_w_lon and Z_w_lon after tau_w_lon and tau_w_thr
(eq. 3.6, Table 3.5), the accelerometers follow eq. 3.7, and the vehicle's
ground velocity is its air velocity plus the wind.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import Literal

import numpy as np

from independent_sim._tables import MEAN_WIND, TABLE_3_3, TRIM_PITCH_DEG

__all__ = [
    "G",
    "STATES",
    "PLANT_INPUTS",
    "AIR_INPUTS",
    "HoverPlant",
    "Trim",
    "LinearPlant",
    "hover_plant",
    "in_wind",
    "linear_plant",
    "longitudinal_matrix",
]

#: Gravity, m/s² (SI: Table 3.7 of the dissertation used 32.174 ft/s² by mistake).
G = 9.81

#: Plant states: body air-relative velocity (m/s), body rates (rad/s), Euler
#: angles (rad), lagged mixer inputs (eq. 3.2, as logged) and NED position
#: perturbation (m). All are perturbations from trim.
STATES: tuple[str, ...] = (
    "u",
    "v",
    "w",
    "p",
    "q",
    "r",
    "phi",
    "theta",
    "psi",
    "d_lat",
    "d_lon",
    "d_thr",
    "x_n",
    "y_e",
    "z_d",
)

#: Plant inputs, each entering after its own delay: the four mixer inputs
#: (as logged), the along-nose wind for G_w on u and on w (m/s, eq. 3.6),
#: the NED wind moving the vehicle over the ground (m/s), unmeasured
#: disturbance accelerations (m/s², rad/s²) and the acceleration of the air
#: itself in heading axes (m/s²: a gust changes the air-relative velocity at
#: once, the ground velocity not; used where G_w is zero).
PLANT_INPUTS: tuple[str, ...] = (
    "delta_lat",
    "delta_lon",
    "delta_yaw",
    "delta_thr",
    "wind_lon_x",
    "wind_lon_z",
    "wind_n",
    "wind_e",
    "dist_u",
    "dist_v",
    "dist_w",
    "dist_p",
    "dist_q",
    "dist_r",
    "air_accel_lon",
    "air_accel_lat",
)
#: Inputs that change the air-relative velocity without a force (a gust arriving): no accelerometer feels them.
AIR_INPUTS: tuple[str, ...] = ("air_accel_lon", "air_accel_lat")

_CONTROL_DERIVATIVES = ("X_lon", "M_lon", "Y_lat", "L_lat", "N_yaw", "Z_thr")


@dataclass(frozen=True, slots=True, kw_only=True)
class Trim:
    """The flight condition the plant is linearised about (Table 3.2).

    Parameters
    ----------
    U0, W0 : float
        Body air-relative velocity at trim, m/s (V0 = 0: the nose faces the wind).
    theta0 : float
        Trim pitch, rad (phi0 = 0).
    psi0 : float
        Heading, rad clockwise from north; into the wind in a wind case.
    delta_lat, delta_lon, delta_yaw, delta_thr : float
        Mixer inputs at trim, as logged (normalised).
    """

    U0: float = 0.0
    W0: float = 0.0
    theta0: float = 0.0
    psi0: float = 0.0
    delta_lat: float = 0.0
    delta_lon: float = 0.0
    delta_yaw: float = 0.0
    delta_thr: float = 0.45

    def __post_init__(self) -> None:
        if abs(self.theta0) >= 0.5:
            raise ValueError(f"{self.theta0=} rad must be a small hover pitch (|theta0| < 0.5)")
        if not 0.0 < self.delta_thr < 1.0:
            raise ValueError(f"{self.delta_thr=} must be within (0, 1)")


@dataclass(frozen=True, slots=True, kw_only=True)
class HoverPlant:
    """Parameters of the hover model in the names and units of ``hover`` / ``hover-wind``.

    Parameters
    ----------
    X_u, Y_v, Z_w, N_r : float
        Speed and yaw damping, 1/s.
    M_u, L_v : float
        Speed stability, rad/(m s).
    X_lon, Y_lat, Z_thr : float
        Force control derivatives, m/s² per unit of the logged mixer input.
    M_lon, L_lat, N_yaw : float
        Moment control derivatives, rad/s² per unit of the logged mixer input.
    T_a : float
        Actuator lag of eq. 3.2 (lat, lon, thr), s.
    tau_lat, tau_lon, tau_yaw, tau_thr : float
        Transport delay of each mixer input, s.
    X_w_lon, Z_w_lon : float
        Along-nose wind derivatives of eq. 3.6 on u and w, 1/s (0 without wind).
    tau_w_lon, tau_w_thr : float
        Delays of the wind on u and on w, s.
    trim : Trim
        Flight condition.
    condition : str
        Label, e.g. ``"calm"`` or ``"strong"``.
    """

    X_u: float
    M_u: float
    X_lon: float
    M_lon: float
    Y_v: float
    L_v: float
    Y_lat: float
    L_lat: float
    N_r: float
    N_yaw: float
    Z_w: float
    Z_thr: float
    T_a: float
    tau_lat: float
    tau_lon: float
    tau_yaw: float
    tau_thr: float
    X_w_lon: float = 0.0
    Z_w_lon: float = 0.0
    tau_w_lon: float = 0.0
    tau_w_thr: float = 0.0
    trim: Trim = field(default_factory=Trim)
    condition: str = "custom"

    def __post_init__(self) -> None:
        if self.T_a <= 0.0:
            raise ValueError(f"{self.T_a=} s must be > 0")
        for name in ("tau_lat", "tau_lon", "tau_yaw", "tau_thr", "tau_w_lon", "tau_w_thr"):
            if not 0.0 <= getattr(self, name) <= 0.3:
                raise ValueError(f"{name}={getattr(self, name)} s must be within [0, 0.3]")

    @property
    def has_wind_terms(self) -> bool:
        """True when G_w is not zero (the truth is ``hover-wind``)."""
        return self.X_w_lon != 0.0 or self.Z_w_lon != 0.0

    def parameters(self, structure: Literal["hover", "hover-wind"] = "hover") -> dict[str, float]:
        """Values by parameter name of a structure (what identification must return).

        Parameters
        ----------
        structure : {"hover", "hover-wind"}
            ``hover`` has 17 parameters; ``hover-wind`` adds the four wind terms.

        Returns
        -------
        dict of str to float
            Units as in :class:`HoverPlant`.

        Examples
        --------
        >>> hover_plant("calm").parameters()["M_lon"]
        52.51
        """
        skip = {"trim", "condition"}
        if structure == "hover":
            skip |= {"X_w_lon", "Z_w_lon", "tau_w_lon", "tau_w_thr"}
        return {f.name: float(getattr(self, f.name)) for f in fields(self) if f.name not in skip}


def hover_plant(
    condition: Literal["calm", "light", "strong"] = "calm",
    *,
    control_scale: float = 100.0,
    tau_yaw: float = 0.0133,
    tau_thr: float = 0.015,
    hover_thrust: float = 0.45,
    psi0: float = 0.0,
) -> HoverPlant:
    """The Table 3.3 model of one wind condition, control derivatives scaled to the log's units.

    Parameters
    ----------
    condition : {"calm", "light", "strong"}
        Column of Table 3.3; light and strong add the Table 3.5 wind terms
        and the Table 3.2 trim pitch.
    control_scale : float
        Logged mixer units per dissertation percent: 100 for PX4's and
        ArduPilot's normalised outputs (1.0 = 100 %).
    tau_yaw, tau_thr : float
        Delays Table 3.3 leaves out for some conditions, s (dropped there,
        not zero in a real vehicle; here they are real and identifiable).
    hover_thrust : float
        Logged thrust at trim, normalised.
    psi0 : float
        Heading, rad.

    Returns
    -------
    HoverPlant
        Z_w = 0 (not in Table 3.3); N_r = 0 except in strong wind. In wind the
        trim is U0 = M cos(theta0), W0 = M sin(theta0) for the day's mean wind
        M (nose into the wind, holding position); the mixer trims are outside
        the linear model: a pitch torque of -0.005 per m/s of wind.

    Examples
    --------
    >>> plant = hover_plant("strong")
    >>> round(plant.trim.U0, 3), plant.N_r, plant.Z_w_lon
    (5.384, -0.2543, 1.323)
    """
    if condition not in TABLE_3_3:
        raise ValueError(f"{condition=} must be one of {sorted(TABLE_3_3)}")
    if control_scale <= 0.0:
        raise ValueError(f"{control_scale=} must be > 0")
    table = dict(TABLE_3_3[condition])
    for name in _CONTROL_DERIVATIVES:
        table[name] = round(table[name] * control_scale, 10)
    theta0 = math.radians(TRIM_PITCH_DEG[condition])
    speed = MEAN_WIND[condition]
    trim = _into_wind(speed, theta0, psi0, delta_lon=-0.005 * speed, hover_thrust=hover_thrust)
    return HoverPlant(**table, Z_w=0.0, tau_yaw=tau_yaw, tau_thr=tau_thr, trim=trim, condition=condition)


def in_wind(plant: HoverPlant, speed_m_s: float, psi0: float) -> HoverPlant:
    """The same airframe holding position in a steady wind: its own derivatives, trimmed against it.

    Parameters
    ----------
    plant : HoverPlant
        A calm airframe (U0 = W0 = 0).
    speed_m_s : float
        Mean wind speed, m/s; the nose faces the wind.
    psi0 : float
        Heading, rad.

    Returns
    -------
    HoverPlant
        The pitch trim cancels the moment of the wind (``M_lon delta_lon0 = -M_u U0``) and the trim
        pitch balances the specific force along the nose (``g sin(theta0) = X_u U0 + X_lon delta_lon0``);
        the air flows level (U0 = M cos(theta0), W0 = M sin(theta0)). G_w stays zero: the wind acts
        through the speed derivatives alone.

    Examples
    --------
    >>> plant = in_wind(hover_plant("calm"), 5.4, 0.0)
    >>> round(math.degrees(plant.trim.theta0), 2), round(plant.trim.delta_lon, 4)
    (-5.44, -0.0787)
    """
    theta0 = 0.0
    for _ in range(5):  # U0 depends on theta0 a little
        u0 = speed_m_s * math.cos(theta0)
        theta0 = math.asin(u0 * (plant.X_u - plant.X_lon * plant.M_u / plant.M_lon) / G)
    delta_lon = -plant.M_u * speed_m_s * math.cos(theta0) / plant.M_lon
    return replace(
        plant, trim=_into_wind(speed_m_s, theta0, psi0, delta_lon=delta_lon, hover_thrust=plant.trim.delta_thr)
    )


def _into_wind(speed_m_s: float, theta0: float, psi0: float, *, delta_lon: float, hover_thrust: float) -> Trim:
    """Holding position nose into a steady wind: the air flows level past the pitched body, thrust tilted."""
    return Trim(
        U0=speed_m_s * math.cos(theta0),
        W0=speed_m_s * math.sin(theta0),
        theta0=theta0,
        psi0=psi0,
        delta_lon=delta_lon,
        delta_thr=hover_thrust / math.cos(theta0),
    )


@dataclass(frozen=True, slots=True)
class LinearPlant:
    """Continuous-time plant ``x' = A x + sum_j B[:, j] u_j(t - delays[j])``.

    Parameters
    ----------
    A : ndarray, shape (15, 15)
        State matrix over :data:`STATES`, 1/s.
    B : ndarray, shape (15, 14)
        Input matrix over :data:`PLANT_INPUTS`.
    delays : ndarray, shape (14,)
        Delay of each input, s.
    accel_rows : ndarray, shape (3, 15 + 15)
        Specific-force perturbation ``[ax, ay, az] = accel_rows @ [x; x']``
        (eq. 3.7), m/s².
    accel_trim : ndarray, shape (3,)
        Specific force at trim, m/s² (``az`` ≈ -g).
    air_velocity_trim : ndarray, shape (3,)
        ``U0, 0, W0``, m/s.
    """

    A: np.ndarray
    B: np.ndarray
    delays: np.ndarray
    accel_rows: np.ndarray
    accel_trim: np.ndarray
    air_velocity_trim: np.ndarray

    def __post_init__(self) -> None:
        n, m = len(STATES), len(PLANT_INPUTS)
        shapes = {"A": (n, n), "B": (n, m), "delays": (m,), "accel_rows": (3, 2 * n), "accel_trim": (3,)}
        for name, shape in shapes.items():
            if np.shape(getattr(self, name)) != shape:
                raise ValueError(f"{name} has shape {np.shape(getattr(self, name))}, expected {shape}")

    def eigenvalues(self, states: tuple[str, ...] = STATES) -> np.ndarray:
        """Eigenvalues of the block of `A` over `states`, 1/s, sorted by real part.

        Parameters
        ----------
        states : tuple of str
            Names from :data:`STATES`.

        Returns
        -------
        ndarray of complex, shape (len(states),)
        """
        index = [STATES.index(s) for s in states]
        values = np.linalg.eigvals(self.A[np.ix_(index, index)])
        return values[np.argsort(values.real, kind="stable")]


def _rotation_body_to_ned(phi: float, theta: float, psi: float) -> np.ndarray:
    """Direction cosine matrix body (FRD) → NED, ZYX Euler angles in rad."""
    cf, sf, ct, st, cp, sp = (
        math.cos(phi),
        math.sin(phi),
        math.cos(theta),
        math.sin(theta),
        math.cos(psi),
        math.sin(psi),
    )
    return np.array(
        [
            [ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp],
            [ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp],
            [-st, sf * ct, cf * ct],
        ]
    )


def linear_plant(plant: HoverPlant) -> LinearPlant:
    """Assemble the state-space matrices of eqs. 3.4-3.7 about the plant's trim.

    Parameters
    ----------
    plant : HoverPlant
        Parameters and trim (phi0 = V0 = 0).

    Returns
    -------
    LinearPlant

    Notes
    -----
    Rows of eq. 3.5 with V0 = phi0 = 0::

        u' = X_u u - W0 q - g cos(theta0) theta + X_lon d_lon + X_w_lon wind(t - tau_w_lon)
        v' = Y_v v + W0 p - U0 r + g cos(theta0) phi + Y_lat d_lat
        w' = Z_w w + U0 q - g sin(theta0) theta + Z_thr d_thr + Z_w_lon wind(t - tau_w_thr)
        p' = L_v v + L_lat d_lat;  q' = M_u u + M_lon d_lon;  r' = N_r r + N_yaw delta_yaw(t - tau_yaw)
        phi' = p + tan(theta0) r;  theta' = q;  psi' = r / cos(theta0)
        d' = (delta(t - tau) - d) / T_a   (lat, lon, thr; eq. 3.2)

    The position is the integral of the ground velocity ``R (V0 + V) + wind``
    linearised about trim (the rotation of the trim air velocity included).
    The accelerometers follow eq. 3.7: ``ax = u' + W0 q + g cos(theta0) theta``,
    ``ay = v' + U0 r - W0 p - g cos(theta0) phi``, ``az = w' - U0 q + g sin(theta0) theta``.
    """
    t = plant.trim
    A, B = _state_and_input_matrices(plant)
    _position_rows(A, t)
    delays = np.zeros(len(PLANT_INPUTS))
    for name, tau in (
        ("delta_lat", plant.tau_lat),
        ("delta_lon", plant.tau_lon),
        ("delta_yaw", plant.tau_yaw),
        ("delta_thr", plant.tau_thr),
        ("wind_lon_x", plant.tau_w_lon),
        ("wind_lon_z", plant.tau_w_thr),
    ):
        delays[PLANT_INPUTS.index(name)] = tau
    ct, st = math.cos(t.theta0), math.sin(t.theta0)
    return LinearPlant(
        A=A,
        B=B,
        delays=delays,
        accel_rows=_accelerometer_rows(t),
        accel_trim=np.array([G * st, 0.0, -G * ct]),
        air_velocity_trim=np.array([t.U0, 0.0, t.W0]),
    )


def _state_and_input_matrices(plant: HoverPlant) -> tuple[np.ndarray, np.ndarray]:
    """F (eq. 3.5, with the lag states) and the input columns (G_u, G_w, wind kinematics, disturbances)."""
    t, s = plant.trim, {name: k for k, name in enumerate(STATES)}
    ct, st = math.cos(t.theta0), math.sin(t.theta0)
    rows = {
        "u": {"u": plant.X_u, "q": -t.W0, "theta": -G * ct, "d_lon": plant.X_lon},
        "v": {"v": plant.Y_v, "p": t.W0, "r": -t.U0, "phi": G * ct, "d_lat": plant.Y_lat},
        "w": {"w": plant.Z_w, "q": t.U0, "theta": -G * st, "d_thr": plant.Z_thr},
        "p": {"v": plant.L_v, "d_lat": plant.L_lat},
        "q": {"u": plant.M_u, "d_lon": plant.M_lon},
        "r": {"r": plant.N_r},
        "phi": {"p": 1.0, "r": st / ct},
        "theta": {"q": 1.0},
        "psi": {"r": 1.0 / ct},
        **{f"d_{axis}": {f"d_{axis}": -1.0 / plant.T_a} for axis in ("lat", "lon", "thr")},
    }
    A = np.zeros((len(STATES), len(STATES)))
    for row, entries in rows.items():
        for col, value in entries.items():
            A[s[row], s[col]] = value
    inputs = {
        **{(f"d_{axis}", f"delta_{axis}"): 1.0 / plant.T_a for axis in ("lat", "lon", "thr")},
        ("r", "delta_yaw"): plant.N_yaw,
        ("u", "wind_lon_x"): plant.X_w_lon,
        ("w", "wind_lon_z"): plant.Z_w_lon,
        ("x_n", "wind_n"): 1.0,
        ("y_e", "wind_e"): 1.0,
        **{(state, f"dist_{state}"): 1.0 for state in "uvwpqr"},
        ("u", "air_accel_lon"): -1.0,
        ("v", "air_accel_lat"): -1.0,
    }
    B = np.zeros((len(STATES), len(PLANT_INPUTS)))
    for (row, col), value in inputs.items():
        B[s[row], PLANT_INPUTS.index(col)] = value
    return A, B


def _accelerometer_rows(trim: Trim) -> np.ndarray:
    """Rows of eq. 3.7 over ``[x; x']`` (V0 = 0), shape (3, 2 n)."""
    n, s = len(STATES), {name: k for k, name in enumerate(STATES)}
    ct, st = math.cos(trim.theta0), math.sin(trim.theta0)
    accel = np.zeros((3, 2 * n))
    for k, (dot_state, entries) in enumerate(
        (
            ("u", {"q": trim.W0, "theta": G * ct}),
            ("v", {"r": trim.U0, "p": -trim.W0, "phi": -G * ct}),
            ("w", {"q": -trim.U0, "theta": G * st}),
        )
    ):
        accel[k, n + s[dot_state]] = 1.0
        for col, value in entries.items():
            accel[k, s[col]] = value
    return accel


def _position_rows(A: np.ndarray, trim: Trim) -> None:
    """Rows of x_n, y_e, z_d: rotated air velocity perturbation plus attitude terms (in place)."""
    s = {name: k for k, name in enumerate(STATES)}
    rotation = _rotation_body_to_ned(0.0, trim.theta0, trim.psi0)
    velocity0 = np.array([trim.U0, 0.0, trim.W0])
    step = 1e-6
    jacobian = np.zeros((3, 3))
    for k in range(3):
        angles_plus, angles_minus = [0.0, trim.theta0, trim.psi0], [0.0, trim.theta0, trim.psi0]
        angles_plus[k] += step
        angles_minus[k] -= step
        jacobian[:, k] = (
            _rotation_body_to_ned(*angles_plus) @ velocity0 - _rotation_body_to_ned(*angles_minus) @ velocity0
        ) / (2 * step)
    for k, row in enumerate(("x_n", "y_e", "z_d")):
        A[s[row], [s["u"], s["v"], s["w"]]] = rotation[k]
        A[s[row], [s["phi"], s["theta"], s["psi"]]] = jacobian[k]


def longitudinal_matrix(plant: HoverPlant) -> np.ndarray:
    """The 3×3 ``(u, q, theta)`` matrix of eq. 3.11, for eigenvalue checks (Table 3.7).

    Parameters
    ----------
    plant : HoverPlant
        Parameters (trim ignored: the calm form of eq. 3.11).

    Returns
    -------
    ndarray, shape (3, 3)

    Examples
    --------
    >>> values = np.linalg.eigvals(longitudinal_matrix(hover_plant("calm")))
    >>> np.round(np.sort_complex(values), 3)
    array([-2.073+0.j   ,  0.878-1.694j,  0.878+1.694j])
    """
    return np.array([[plant.X_u, 0.0, -G], [plant.M_u, 0.0, 0.0], [0.0, 1.0, 0.0]])
