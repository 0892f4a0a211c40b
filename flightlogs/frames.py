"""Rotations between body (FRD) and earth (NED) axes."""

from __future__ import annotations

import numpy as np

__all__ = ["quaternion_to_euler"]


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
