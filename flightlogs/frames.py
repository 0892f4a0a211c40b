"""Rotations between body (FRD) and earth (NED) axes."""

from __future__ import annotations

import numpy as np

_CHUNK = 1 << 16  # samples rotated at a time

__all__ = [
    "quaternion_to_euler",
    "earth_to_body",
    "euler_rates_to_body",
    "air_velocity_body",
    "air_velocity_per_wind",
    "wind_to_body_axes",
]


def quaternion_to_euler(quaternion: np.ndarray) -> np.ndarray:
    """Convert attitude quaternions to 3-2-1 Euler angles.

    Parameters
    ----------
    quaternion : ndarray, shape (n_samples, 4)
        Unit quaternions ``(w, x, y, z)`` rotating FRD body axes into NED
        earth axes (PX4's ``vehicle_attitude.q``).

    Returns
    -------
    ndarray, shape (n_samples, 3)
        Roll ``phi``, pitch ``theta`` and yaw ``psi``, rad; yaw in (-π, π].

    Examples
    --------
    >>> half = np.pi / 8  # a 45 deg yaw
    >>> np.round(np.degrees(quaternion_to_euler(np.array([[np.cos(half), 0, 0, np.sin(half)]]))), 6)
    array([[ 0.,  0., 45.]])
    """
    q = np.asarray(quaternion, dtype=np.float64)
    if q.ndim != 2 or q.shape[1] != 4:
        raise ValueError(f"quaternion must have shape (n_samples, 4), got {q.shape}")
    norm = np.linalg.norm(q, axis=1, keepdims=True)
    q = q / np.where(norm > 0, norm, 1.0)
    w, x, y, z = q.T
    phi = np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    theta = np.arcsin(np.clip(2.0 * (w * y - z * x), -1.0, 1.0))
    psi = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return np.column_stack([phi, theta, psi])


def _earth_to_body_matrices(phi: np.ndarray, theta: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Rotation matrices R_i^b (NED → FRD) of 3-2-1 Euler angles, shape (n_samples, 3, 3)."""
    cf, sf = np.cos(phi), np.sin(phi)
    ct, st = np.cos(theta), np.sin(theta)
    cp, sp = np.cos(psi), np.sin(psi)
    return np.stack(
        [
            np.stack([ct * cp, ct * sp, -st], axis=-1),
            np.stack([sf * st * cp - cf * sp, sf * st * sp + cf * cp, sf * ct], axis=-1),
            np.stack([cf * st * cp + sf * sp, cf * st * sp - sf * cp, cf * ct], axis=-1),
        ],
        axis=-2,
    )


def earth_to_body(vectors_ned: np.ndarray, phi: np.ndarray, theta: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Rotate NED vectors into FRD body axes.

    Parameters
    ----------
    vectors_ned : ndarray, shape (n_samples, 3)
        Vectors in earth axes (north, east, down).
    phi, theta, psi : ndarray, shape (n_samples,)
        Roll, pitch and yaw, rad (3-2-1 sequence).

    Returns
    -------
    ndarray, shape (n_samples, 3)
        The same vectors in body axes (forward, right, down).

    Examples
    --------
    >>> north = np.array([[1.0, 0.0, 0.0]])
    >>> np.round(earth_to_body(north, np.zeros(1), np.zeros(1), np.array([np.pi / 2])), 12)
    array([[ 0., -1.,  0.]])
    """
    vectors_ned = np.asarray(vectors_ned, dtype=np.float64)
    if vectors_ned.ndim != 2 or vectors_ned.shape[1] != 3:
        raise ValueError(f"vectors_ned must have shape (n_samples, 3), got {vectors_ned.shape}")
    angles = [np.asarray(a) for a in (phi, theta, psi)]
    out = np.empty_like(vectors_ned)
    for lo in range(0, out.shape[0], _CHUNK):  # a block of (n, 3, 3) matrices at a time: 72 bytes a sample
        part = slice(lo, lo + _CHUNK)
        matrices = _earth_to_body_matrices(*(a[part] for a in angles))
        np.einsum("nij,nj->ni", matrices, vectors_ned[part], out=out[part])
    return out


def euler_rates_to_body(
    phi: np.ndarray, theta: np.ndarray, phi_dot: np.ndarray, theta_dot: np.ndarray, psi_dot: np.ndarray
) -> np.ndarray:
    """Body rates ``p q r`` from 3-2-1 Euler angles and their rates of change (the attitude's kinematics).

    Parameters
    ----------
    phi, theta : ndarray, shape (n_samples,)
        Roll and pitch, rad.
    phi_dot, theta_dot, psi_dot : ndarray, shape (n_samples,)
        Rates of change of roll, pitch and yaw, rad/s.

    Returns
    -------
    ndarray, shape (n_samples, 3)
        ``p q r``, rad/s.

    Examples
    --------
    >>> zero = np.zeros(1)
    >>> euler_rates_to_body(np.array([np.pi / 2]), zero, zero, zero, np.ones(1)).round(12)
    array([[0., 1., 0.]])
    """
    cf, sf = np.cos(phi), np.sin(phi)
    ct, st = np.cos(theta), np.sin(theta)
    return np.column_stack(
        [phi_dot - psi_dot * st, theta_dot * cf + psi_dot * sf * ct, -theta_dot * sf + psi_dot * cf * ct]
    )


def air_velocity_body(
    velocity_ned: np.ndarray, wind_ne: np.ndarray, phi: np.ndarray, theta: np.ndarray, psi: np.ndarray
) -> np.ndarray:
    """Body-axis velocity relative to the air, eq. 3.1: V_b = R_i^b (V_i - V_wind).

    Parameters
    ----------
    velocity_ned : ndarray, shape (n_samples, 3)
        Ground velocity ``vn, ve, vd``, m/s.
    wind_ne : ndarray, shape (n_samples, 2)
        Horizontal wind ``wind_n, wind_e`` (velocity of the air), m/s; the
        vertical wind is taken as zero, as in the dissertation.
    phi, theta, psi : ndarray, shape (n_samples,)
        Euler angles, rad.

    Returns
    -------
    ndarray, shape (n_samples, 3)
        ``u, v, w``, m/s.

    Examples
    --------
    A vehicle hovering in a 3 m/s wind blowing towards the north, nose north,
    sees the air coming at it: u = -3 m/s.

    >>> air_velocity_body(np.zeros((1, 3)), np.array([[3.0, 0.0]]), *np.zeros((3, 1)))
    array([[-3.,  0.,  0.]])
    """
    wind_ne = np.asarray(wind_ne, dtype=np.float64)
    relative = np.asarray(velocity_ned, dtype=np.float64).copy()
    relative[:, :2] -= wind_ne
    return earth_to_body(relative, phi, theta, psi)


def air_velocity_per_wind(phi: np.ndarray, theta: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """How the body-axis air velocity of eq. 3.1 answers the wind: ``d(u, v, w) / d(wind_n, wind_e)``.

    Minus the first two columns of ``R_i^b``: :func:`air_velocity_body` is linear in the wind, so a change
    ``dW`` of it (n_samples, 2) changes ``u v w`` by ``einsum("nij,nj->ni", air_velocity_per_wind(...), dW)``,
    without rotating anything again.

    Parameters
    ----------
    phi, theta, psi : ndarray, shape (n_samples,)
        Euler angles, rad.

    Returns
    -------
    ndarray, shape (n_samples, 3, 2)
        Per sample, the change of ``u v w`` (m/s) per m/s of north wind (column 0) and of east wind (column 1).

    Examples
    --------
    Nose east, a north wind blows from the left: the air comes at the vehicle from its right, v = +1 per m/s.

    >>> air_velocity_per_wind(np.zeros(1), np.zeros(1), np.array([np.pi / 2]))[0].round(12)
    array([[-0., -1.],
           [ 1., -0.],
           [-0., -0.]])
    """
    out = np.empty((np.size(psi), 3, 2))
    for lo in range(0, out.shape[0], _CHUNK):  # a block of (n, 3, 3) matrices at a time
        part = slice(lo, lo + _CHUNK)
        out[part] = -_earth_to_body_matrices(*(np.asarray(a)[part] for a in (phi, theta, psi)))[:, :, :2]
    return out


def wind_to_body_axes(wind_ne: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Horizontal wind in heading-aligned body axes (the inputs of G_w, eq. 3.6).

    Parameters
    ----------
    wind_ne : ndarray, shape (n_samples, 2)
        ``wind_n, wind_e``, m/s (velocity of the air).
    psi : ndarray, shape (n_samples,)
        Heading, rad.

    Returns
    -------
    ndarray, shape (n_samples, 2)
        ``wind_lon`` (along the nose) and ``wind_lat`` (to the right), m/s.

    Examples
    --------
    >>> np.round(wind_to_body_axes(np.array([[0.0, 2.0]]), np.array([np.pi / 2])), 12)
    array([[2., 0.]])
    """
    wind_ne = np.asarray(wind_ne, dtype=np.float64)
    cos_psi, sin_psi = np.cos(psi), np.sin(psi)
    wind_lon = wind_ne[:, 0] * cos_psi + wind_ne[:, 1] * sin_psi
    wind_lat = -wind_ne[:, 0] * sin_psi + wind_ne[:, 1] * cos_psi
    return np.column_stack([wind_lon, wind_lat])
