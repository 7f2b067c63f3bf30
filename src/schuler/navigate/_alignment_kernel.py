"""Numba kernel of the nonlinear platform under the KPI gyrocompassing control law (1.6). Private.

The platform's orientation relative to the level frame x_g y_g z_g is the unit
quaternion q (platform axes -> level axes). Its rate relative to the level frame,
in platform axes, is

    omega_gp = omega_k + (omega_d - omega_d_est) - C_g^p U^g,

with the commanded rate (1.6) omega_k = U_est + control(a), the accelerometers
a = C_g^p (0, 0, g) + Delta a, and q' = q (0, omega_gp) / 2. Fourth-order
Runge-Kutta on q with renormalisation, a batch of members in parallel.
"""

from __future__ import annotations

import math

import numba

from schuler.navigate._kernels import FAST_MATH, quat_multiply, rotate


@numba.njit(cache=True, fastmath=FAST_MATH)
def _relative_rate(q0, q1, q2, q3, p):
    """omega_gp in platform axes; p holds the member's constants (see :func:`align`)."""
    # level-frame vectors in platform axes: C_g^p = R(q)^T
    ux, uy, uz = rotate(q0, -q1, -q2, -q3, p[0], p[1], p[2])
    fx, fy, _ = rotate(q0, -q1, -q2, -q3, 0.0, 0.0, p[3])
    a_x = fx + p[10]
    a_y = fy + p[11]
    a_eta = a_y * p[13] - a_x * p[12]
    return (p[4] - p[7] + p[14] * a_y - ux,
            p[5] - p[8] - p[14] * a_x - uy,
            p[6] - p[9] + p[15] * a_eta - uz)


@numba.njit(cache=True, fastmath=FAST_MATH)
def _derivative(q0, q1, q2, q3, p):
    wx, wy, wz = _relative_rate(q0, q1, q2, q3, p)
    d0, d1, d2, d3 = quat_multiply(q0, q1, q2, q3, 0.0, wx, wy, wz)
    return 0.5 * d0, 0.5 * d1, 0.5 * d2, 0.5 * d3


@numba.njit(cache=True, parallel=True, fastmath=FAST_MATH)
def align(quaternions, parameters, step, n_steps, out_every, out):
    """Integrate every member's platform quaternion and record it every ``out_every`` steps.

    Parameters
    ----------
    quaternions : (N, 4)
        Initial q (platform -> level axes); advanced in place.
    parameters : (N, 16)
        Per member: U^g (3, rad/s), g (m/s^2), the computed U (3, rad/s, (1.6)'s U_xв, U_yв,
        U_zв), the residual drifts Delta omega_d (3, rad/s, estimate - true), the
        accelerometer errors Delta a_x, Delta a_y (m/s^2), sin A, cos A, c1 and c2 (s/m).
    step : float
        s.
    n_steps : int
    out_every : int
    out : (N, n_steps // out_every + 1, 4)
        Recorded quaternions (row 0 the initial one).
    """
    for m in numba.prange(quaternions.shape[0]):
        p = parameters[m]
        q0, q1, q2, q3 = quaternions[m, 0], quaternions[m, 1], quaternions[m, 2], quaternions[m, 3]
        out[m, 0, 0], out[m, 0, 1], out[m, 0, 2], out[m, 0, 3] = q0, q1, q2, q3
        for k in range(1, n_steps + 1):
            a0, a1, a2, a3 = _derivative(q0, q1, q2, q3, p)
            h = 0.5 * step
            b0, b1, b2, b3 = _derivative(q0 + h * a0, q1 + h * a1, q2 + h * a2, q3 + h * a3, p)
            c0, c1, c2, c3 = _derivative(q0 + h * b0, q1 + h * b1, q2 + h * b2, q3 + h * b3, p)
            d0, d1, d2, d3 = _derivative(q0 + step * c0, q1 + step * c1, q2 + step * c2, q3 + step * c3, p)
            w = step / 6.0
            q0 += w * (a0 + 2.0 * b0 + 2.0 * c0 + d0)
            q1 += w * (a1 + 2.0 * b1 + 2.0 * c1 + d1)
            q2 += w * (a2 + 2.0 * b2 + 2.0 * c2 + d2)
            q3 += w * (a3 + 2.0 * b3 + 2.0 * c3 + d3)
            norm = 1.0 / math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
            q0, q1, q2, q3 = q0 * norm, q1 * norm, q2 * norm, q3 * norm
            if k % out_every == 0:
                row = k // out_every
                out[m, row, 0], out[m, row, 1], out[m, row, 2], out[m, row, 3] = q0, q1, q2, q3
        quaternions[m, 0], quaternions[m, 1], quaternions[m, 2], quaternions[m, 3] = q0, q1, q2, q3
