"""Attitude, once for the whole package: direction cosines, quaternions, rotation vectors, Euler angles.

Frames: the local-level navigation frame is North-East-Down (n); the body frame
(b) has x forward, y right, z down. The attitude is C_b^n, the matrix taking
body components into NED (a body vector in NED is ``C @ v_b``), written with
the aerospace roll phi, pitch theta and heading psi (rotations about z, then y,
then x; heading clockwise from north seen from above):

    C_b^n = R_z(psi) R_y(theta) R_x(phi)    (Groves 2013, eqs. (2.22), (2.23)).

Quaternions are Hamilton's, scalar first (q0, q1, q2, q3), and q_bn rotates
body vectors into NED: v_n = q v_b q*. A rotation vector phi (rad) is the
axis times the angle; q(phi) = (cos(|phi|/2), sin(|phi|/2) phi/|phi|) and
C(phi) = exp([phi x]) (Rodrigues).

Attitude error (errors are computed - true): the error vector phi of
:func:`attitude_error` is the small rotation of the computed attitude from the
true one in NED, C_hat = (I - [phi x]) C to first order (the psi-angle
convention of spec 06: Benson 1975). Earth's rate in NED is
:func:`schuler.core.earth.earth_rate_ned` (the one Earth module).

Groves, P. D., "Principles of GNSS, Inertial, and Multisensor Integrated
Navigation Systems", 2nd ed., Artech House, 2013. Every function is
vectorised over leading axes.

Examples
--------
>>> q = quaternion_from_euler(0.1, -0.2, 3.0)
>>> np.round(euler_from_quaternion(q), 12)
array([ 0.1, -0.2,  3. ])
>>> bool(np.allclose(dcm_from_quaternion(q), dcm_from_euler(0.1, -0.2, 3.0)))
True
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


def skew(vector) -> np.ndarray:
    """The cross-product matrix [a x] of a 3-vector: ``skew(a) @ b == np.cross(a, b)``; rows of a batch alike.

    Parameters
    ----------
    vector : array_like, shape ([N,] 3)
        a, in any unit (the matrix carries it); a batch gives one matrix per row.

    Returns
    -------
    ndarray, shape ([N,] 3, 3)
        Skew-symmetric [[0, -a3, a2], [a3, 0, -a1], [-a2, a1, 0]].

    Examples
    --------
    >>> skew([1.0, 2.0, 3.0]) @ np.array([4.0, 5.0, 6.0])
    array([-3.,  6., -3.])
    >>> skew(np.ones((2, 3))).shape
    (2, 3, 3)
    """
    a = np.asarray(vector, dtype=float)
    out = np.zeros(a.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -a[..., 2], a[..., 1]
    out[..., 1, 0], out[..., 1, 2] = a[..., 2], -a[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -a[..., 1], a[..., 0]
    return out


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


def dcm_from_quaternion(q) -> np.ndarray:
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
    >>> dcm_from_quaternion(quaternion_from_euler(0.0, 0.0, np.pi / 2)).round(12) @ [1.0, 0.0, 0.0]
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
    C = dcm_from_quaternion(q)
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


def rotation_vector_from_quaternion(q) -> np.ndarray:
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
    >>> rotation_vector_from_quaternion(quaternion_from_rotation_vector([1e-9, 0.5, -2.0])).round(12)
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


def dcm_from_rotation_vector(rotation_vector) -> np.ndarray:
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
    K = skew(phi)
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
    return -rotation_vector_from_quaternion(quaternion_multiply(q_computed, conjugate(q_true)))


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


def quaternion_from_dcm(C) -> np.ndarray:
    """q_bn of direction cosine matrices C_b^n, scalar first and non-negative, shape (..., 4).

    Shepperd's method: the largest of 4 q0^2, 4 q1^2, 4 q2^2, 4 q3^2 (from the
    trace and the diagonal) is taken first, so the division is never by a small
    number (Shepperd, "Quaternion from rotation matrix", J. Guidance and
    Control 1(3), 1978).

    Parameters
    ----------
    C : array_like
        Direction cosine matrices C_b^n (body to NED), dimensionless, shape (..., 3, 3).

    Returns
    -------
    ndarray
        Unit quaternions q_bn, Hamilton, scalar first with q0 >= 0, plain numbers, shape (..., 4).

    Examples
    --------
    >>> quaternion_from_dcm(dcm_from_euler(0.0, 0.0, np.pi / 2)).round(12)
    array([0.70710678, 0.        , 0.        , 0.70710678])
    """
    C = np.asarray(C, dtype=float)
    trace = C[..., 0, 0] + C[..., 1, 1] + C[..., 2, 2]
    # 4 q_i^2 for i = 0..3, and the off-diagonal sums and differences that give the products q_i q_j
    squares = np.stack([1.0 + trace, 1.0 + 2.0 * C[..., 0, 0] - trace, 1.0 + 2.0 * C[..., 1, 1] - trace,
                        1.0 + 2.0 * C[..., 2, 2] - trace], axis=-1)
    d32, d13, d21 = C[..., 2, 1] - C[..., 1, 2], C[..., 0, 2] - C[..., 2, 0], C[..., 1, 0] - C[..., 0, 1]
    s12, s13, s23 = C[..., 0, 1] + C[..., 1, 0], C[..., 0, 2] + C[..., 2, 0], C[..., 1, 2] + C[..., 2, 1]
    candidates = np.stack([
        np.stack([squares[..., 0], d32, d13, d21], axis=-1),
        np.stack([d32, squares[..., 1], s12, s13], axis=-1),
        np.stack([d13, s12, squares[..., 2], s23], axis=-1),
        np.stack([d21, s13, s23, squares[..., 3]], axis=-1),
    ], axis=-2)
    largest = np.argmax(squares, axis=-1)
    chosen = np.take_along_axis(candidates, largest[..., None, None], axis=-2)[..., 0, :]
    q = chosen / (2.0 * np.sqrt(np.take_along_axis(squares, largest[..., None], axis=-1)))
    return np.where(q[..., :1] < 0.0, -q, q)
