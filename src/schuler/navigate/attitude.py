"""Attitude conventions of the navigation layer: aerospace Euler angles, quaternions, rotation vectors.

Frames: the local-level navigation frame is North-East-Down (n); the body frame
(b) has x forward, y right, z down. The attitude is C_b^n, the matrix taking
body components into NED, written with the aerospace roll phi, pitch theta and
heading psi (rotations about z, then y, then x):

    C_b^n = R_z(psi) R_y(theta) R_x(phi).

Quaternions are Hamilton's, scalar first (q0, q1, q2, q3), and q_bn rotates
body vectors into NED: v_n = q v_b q*. A rotation vector phi (rad) is the
axis times the angle; q(phi) = (cos(|phi|/2), sin(|phi|/2) phi/|phi|).

Attitude error (errors are computed - true): the angle errors are differences
of the Euler angles (heading wrapped to (-pi, pi]); the error vector phi of
:func:`attitude_error` is the small rotation of the computed attitude from the
true one in NED, C_hat = (I - [phi x]) C to first order (the psi-angle
convention of spec 06: Benson 1975).

All functions are vectorised over leading axes.

Examples
--------
>>> q = quaternion_from_euler(0.1, -0.2, 3.0)
>>> np.round(euler_from_quaternion(q), 12)
array([ 0.1, -0.2,  3. ])
"""

from __future__ import annotations

import numpy as np


def wrap_angle(angle):
    """Angle wrapped to (-pi, pi], rad.

    Parameters
    ----------
    angle : float or array_like
        Angle, rad, any shape.

    Returns
    -------
    ndarray
        The same angle in (-pi, pi], rad, shape of ``angle``.

    Examples
    --------
    >>> float(wrap_angle(3 * np.pi / 2))
    -1.5707963267948966
    """
    wrapped = np.remainder(np.asarray(angle, dtype=float) + np.pi, 2.0 * np.pi) - np.pi
    return np.where(wrapped == -np.pi, np.pi, wrapped)


def quaternion_from_euler(roll, pitch, heading) -> np.ndarray:
    """q_bn from roll, pitch and heading (rad): q = q_z(psi) q_y(theta) q_x(phi), shape (..., 4).

    Parameters
    ----------
    roll : float or array_like
        Roll phi, rad (rotation about body x, forward).
    pitch : float or array_like
        Pitch theta, rad (rotation about body y, right; nose up positive).
    heading : float or array_like
        Heading psi, rad (rotation about z, down; clockwise from north seen from above).
        The three angles broadcast against each other.

    Returns
    -------
    ndarray
        Unit quaternion q_bn, Hamilton, scalar first (plain numbers), shape (..., 4).

    Examples
    --------
    >>> quaternion_from_euler(0.0, 0.0, np.pi).round(12)
    array([0., 0., 0., 1.])
    """
    half = 0.5 * np.stack(np.broadcast_arrays(np.asarray(roll, float), np.asarray(pitch, float),
                                              np.asarray(heading, float)), axis=-1)
    c = np.cos(half)
    s = np.sin(half)
    cr, cp, cy = c[..., 0], c[..., 1], c[..., 2]
    sr, sp, sy = s[..., 0], s[..., 1], s[..., 2]
    return np.stack([cy * cp * cr + sy * sp * sr,
                     cy * cp * sr - sy * sp * cr,
                     cy * sp * cr + sy * cp * sr,
                     sy * cp * cr - cy * sp * sr], axis=-1)


def rotation_matrix(q) -> np.ndarray:
    """C_b^n = R(q) of unit quaternions, shape (..., 3, 3).

    Parameters
    ----------
    q : array_like
        Unit quaternions q_bn, Hamilton, scalar first, plain numbers, shape (..., 4).

    Returns
    -------
    ndarray
        Direction cosine matrices C_b^n (body to NED), dimensionless, shape (..., 3, 3).

    Examples
    --------
    >>> rotation_matrix(quaternion_from_euler(0.0, 0.0, np.pi / 2)).round(12) @ [1.0, 0.0, 0.0]
    array([0., 1., 0.])
    """
    q = np.asarray(q, dtype=float)
    q0, q1, q2, q3 = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    rows = [
        [q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3, 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
        [2 * (q1 * q2 + q0 * q3), q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3, 2 * (q2 * q3 - q0 * q1)],
        [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3],
    ]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def euler_from_quaternion(q) -> np.ndarray:
    """Roll, pitch, heading (rad) of q_bn, shape (..., 3); heading in (-pi, pi].

    Pitch is taken by atan2 of the matrix's third row, so it stays accurate
    near +/- 90 deg (where roll and heading become one degree of freedom).

    Parameters
    ----------
    q : array_like
        Unit quaternions q_bn, Hamilton, scalar first, plain numbers, shape (..., 4).

    Returns
    -------
    ndarray
        Roll, pitch and heading, rad, shape (..., 3).
    """
    C = rotation_matrix(q)
    roll = np.arctan2(C[..., 2, 1], C[..., 2, 2])
    pitch = np.arctan2(-C[..., 2, 0], np.hypot(C[..., 2, 1], C[..., 2, 2]))
    heading = np.arctan2(C[..., 1, 0], C[..., 0, 0])
    return np.stack([roll, pitch, heading], axis=-1)


def quaternion_multiply(p, q) -> np.ndarray:
    """Hamilton product p q, shape (..., 4).

    Parameters
    ----------
    p, q : array_like
        Quaternions, scalar first, plain numbers, shape (..., 4); they broadcast.
        With rotation quaternions, p q applies q first, then p.

    Returns
    -------
    ndarray
        The product p q, plain numbers, shape (..., 4).
    """
    p = np.asarray(p, dtype=float)
    q = np.asarray(q, dtype=float)
    p0, p1, p2, p3 = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
    q0, q1, q2, q3 = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([p0 * q0 - p1 * q1 - p2 * q2 - p3 * q3,
                     p0 * q1 + p1 * q0 + p2 * q3 - p3 * q2,
                     p0 * q2 - p1 * q3 + p2 * q0 + p3 * q1,
                     p0 * q3 + p1 * q2 - p2 * q1 + p3 * q0], axis=-1)


def conjugate(q) -> np.ndarray:
    """q* (the inverse rotation of a unit quaternion).

    Parameters
    ----------
    q : array_like
        Quaternions, scalar first, plain numbers, shape (..., 4).

    Returns
    -------
    ndarray
        (q0, -q1, -q2, -q3), plain numbers, shape (..., 4).
    """
    return np.asarray(q, dtype=float) * np.array([1.0, -1.0, -1.0, -1.0])


def rotation_vector(q) -> np.ndarray:
    """Rotation vector (rad) of unit quaternions, the shorter of q and -q, shape (..., 3).

    Parameters
    ----------
    q : array_like
        Unit quaternions, Hamilton, scalar first, plain numbers, shape (..., 4).

    Returns
    -------
    ndarray
        Rotation vectors (axis times angle), rad, angle at most pi, shape (..., 3).

    Examples
    --------
    >>> rotation_vector(quaternion_from_rotation_vector([1e-9, 0.5, -2.0])).round(12)
    array([ 1.e-09,  5.e-01, -2.e+00])
    """
    q = np.asarray(q, dtype=float)
    q = np.where(q[..., :1] < 0.0, -q, q)
    norm = np.linalg.norm(q[..., 1:], axis=-1)
    safe = np.where(norm > 1e-12, norm, 1.0)
    factor = np.where(norm > 1e-12, 2.0 * np.arctan2(norm, q[..., 0]) / safe, 2.0 / q[..., 0])
    return factor[..., None] * q[..., 1:]


def quaternion_from_rotation_vector(phi) -> np.ndarray:
    """exp(phi / 2) for rotation vectors phi (rad), shape (..., 4).

    Parameters
    ----------
    phi : array_like
        Rotation vectors (axis times angle), rad, shape (..., 3).

    Returns
    -------
    ndarray
        Unit quaternions, Hamilton, scalar first, plain numbers, shape (..., 4).
    """
    phi = np.asarray(phi, dtype=float)
    angle = np.linalg.norm(phi, axis=-1)
    # sin(a/2)/a = sinc(a / (2 pi)) / 2 in numpy's normalised sinc: exact at a = 0
    factor = 0.5 * np.sinc(angle / (2.0 * np.pi))
    return np.concatenate([np.cos(0.5 * angle)[..., None], factor[..., None] * phi], axis=-1)


def attitude_error(q_computed, q_true) -> np.ndarray:
    """Error rotation vector phi (rad, NED) with C_computed = exp(-[phi x]) C_true, shape (..., 3).

    To first order C_computed = (I - [phi x]) C_true: phi is the small rotation
    of the computed attitude from the true one (spec 06's psi-angle sign).

    Parameters
    ----------
    q_computed : array_like
        Computed attitude q_bn, unit quaternions, scalar first, plain numbers, shape (..., 4).
    q_true : array_like
        True attitude q_bn, unit quaternions, scalar first, plain numbers, shape (..., 4).

    Returns
    -------
    ndarray
        Error rotation vector phi, rad, NED axes (north, east, down), shape (..., 3).

    Examples
    --------
    >>> q = quaternion_from_euler(0.0, 0.0, 0.3)
    >>> [round(float(x), 15) for x in attitude_error(quaternion_from_euler(0.0, 0.0, 0.3 + 1e-6), q)]
    [0.0, 0.0, -1e-06]
    """
    return -rotation_vector(quaternion_multiply(q_computed, conjugate(q_true)))
