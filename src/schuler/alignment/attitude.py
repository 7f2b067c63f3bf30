"""Attitude in the alignment suite: direction cosines and aerospace angles, batched over records.

Frames: navigation frame NED (north, east, down); body x forward, y right,
z down. ``C`` is C_b^n (a body vector in NED is ``C @ v_b``), built from the
aerospace angles as C_b^n = R_z(heading) R_y(pitch) R_x(roll), heading
clockwise from north seen from above (Groves 2013, eqs. (2.22), (2.23)).
Every function takes leading batch dimensions (``(..., 3, 3)``, ``(..., 3)``).

Examples
--------
>>> C = dcm_from_euler(0.01, -0.02, 1.5)
>>> [round(float(a), 12) for a in euler_from_dcm(C)]
[0.01, -0.02, 1.5]
"""

from __future__ import annotations

import math

import numpy as np

from schuler.core.earth import EARTH_RATE


def dcm_from_euler(roll, pitch, heading) -> np.ndarray:
    """C_b^n = R_z(heading) R_y(pitch) R_x(roll), shape (..., 3, 3).

    Parameters
    ----------
    roll, pitch, heading : float or ndarray
        Aerospace angles, rad (broadcast together).
    """
    roll, pitch, heading = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (roll, pitch, heading)))
    cr, sr, cp, sp, ch, sh = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(heading), np.sin(heading)
    C = np.empty(roll.shape + (3, 3))
    C[..., 0, 0] = cp * ch
    C[..., 0, 1] = -cr * sh + sr * sp * ch
    C[..., 0, 2] = sr * sh + cr * sp * ch
    C[..., 1, 0] = cp * sh
    C[..., 1, 1] = cr * ch + sr * sp * sh
    C[..., 1, 2] = -sr * ch + cr * sp * sh
    C[..., 2, 0] = -sp
    C[..., 2, 1] = sr * cp
    C[..., 2, 2] = cr * cp
    return C


def euler_from_dcm(C) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Roll, pitch, heading (rad) of C_b^n; heading in (-pi, pi], pitch in [-pi/2, pi/2].

    Parameters
    ----------
    C : array_like of shape (..., 3, 3)
        Direction cosine matrix C_b^n (body x fwd/y right/z down to NED), plain numbers.

    Returns
    -------
    roll, pitch, heading : ndarray of shape (...)
        Aerospace angles, rad.
    """
    C = np.asarray(C, dtype=float)
    roll = np.arctan2(C[..., 2, 1], C[..., 2, 2])
    pitch = -np.arcsin(np.clip(C[..., 2, 0], -1.0, 1.0))
    heading = np.arctan2(C[..., 1, 0], C[..., 0, 0])
    return roll, pitch, heading


def wrap_angle(angle):
    """An angle (or angle difference) wrapped to (-pi, pi].

    Parameters
    ----------
    angle : float or array_like
        Angle, rad (any shape).

    Returns
    -------
    ndarray
        The same angle in (-pi, pi], rad, same shape.
    """
    return -np.remainder(-np.asarray(angle, dtype=float) + math.pi, 2.0 * math.pi) + math.pi


def earth_rate_ned(latitude) -> np.ndarray:
    """omega_ie^n = Omega [cos L, 0, -sin L], rad/s, shape (..., 3).

    Parameters
    ----------
    latitude : float or array_like
        Latitude L, rad (any shape).

    Returns
    -------
    ndarray of shape (..., 3)
        Earth rate in NED, rad/s.
    """
    latitude = np.asarray(latitude, dtype=float)
    out = np.zeros(latitude.shape + (3,))
    out[..., 0] = EARTH_RATE * np.cos(latitude)
    out[..., 2] = -EARTH_RATE * np.sin(latitude)
    return out


def skew_batch(vector) -> np.ndarray:
    """[a x] for vectors of shape (..., 3): shape (..., 3, 3).

    Parameters
    ----------
    vector : array_like of shape (..., 3)
        Vector a in any unit (the matrix carries the same unit).

    Returns
    -------
    ndarray of shape (..., 3, 3)
        Skew-symmetric cross-product matrix, [a x] b = a x b.
    """
    a = np.asarray(vector, dtype=float)
    out = np.zeros(a.shape + (3,))
    out[..., 0, 1], out[..., 0, 2] = -a[..., 2], a[..., 1]
    out[..., 1, 0], out[..., 1, 2] = a[..., 2], -a[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -a[..., 1], a[..., 0]
    return out


def rotation_matrix(rotation_vector) -> np.ndarray:
    """exp([phi x]) for rotation vectors phi (..., 3), rad (Rodrigues; exact for any angle).

    Parameters
    ----------
    rotation_vector : array_like of shape (..., 3)
        Rotation vector phi (axis times angle), rad.

    Returns
    -------
    ndarray of shape (..., 3, 3)
        The rotation matrix exp([phi x]), plain numbers.
    """
    phi = np.asarray(rotation_vector, dtype=float)
    angle = np.linalg.norm(phi, axis=-1)[..., None, None]
    small = angle < 1e-8
    safe = np.where(small, 1.0, angle)
    a = np.where(small, 1.0 - angle**2 / 6.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - angle**2 / 24.0, (1.0 - np.cos(safe)) / safe**2)
    K = skew_batch(phi)
    return np.eye(3) + a * K + b * (K @ K)


def orthonormalise(C) -> np.ndarray:
    """The rotation closest to C (polar factor by SVD), shape (..., 3, 3).

    Parameters
    ----------
    C : array_like of shape (..., 3, 3)
        Nearly orthonormal direction cosine matrix, plain numbers.

    Returns
    -------
    ndarray of shape (..., 3, 3)
        The orthonormal matrix closest to C in the Frobenius norm, plain numbers.
    """
    u, _, vt = np.linalg.svd(np.asarray(C, dtype=float))
    return u @ vt


def triad(primary_body, secondary_body, primary_nav, secondary_nav) -> np.ndarray:
    """C_b^n from two vector pairs by TRIAD: the primary pair exactly, the secondary fixes the turn about it.

    Parameters
    ----------
    primary_body, secondary_body : ndarray (..., 3)
        The two vectors measured in the body frame (x fwd, y right, z down), any unit (only their
        directions are used; e.g. specific force in m/s^2 and Earth rate in rad/s).
    primary_nav, secondary_nav : ndarray (..., 3)
        The same vectors known in the navigation frame (NED), any unit (directions only).

    Returns
    -------
    ndarray (..., 3, 3)
        C_b^n = [n1 n2 n3] [b1 b2 b3]^T with b1 = u1/|u1|, b2 = (u1 x u2)/|u1 x u2|, b3 = b1 x b2
        (Shuster and Oh, "Three-axis attitude determination from vector observations",
        J. Guidance and Control 4(1), 1981).
    """
    def frame(first, second):
        first = np.asarray(first, dtype=float)
        b1 = first / np.linalg.norm(first, axis=-1, keepdims=True)
        cross = np.cross(first, np.asarray(second, dtype=float))
        b2 = cross / np.linalg.norm(cross, axis=-1, keepdims=True)
        return np.stack([b1, b2, np.cross(b1, b2)], axis=-1)

    return frame(primary_nav, secondary_nav) @ np.swapaxes(frame(primary_body, secondary_body), -1, -2)
