"""numba kernels of the alignment suite: the strapdown time loops, on plain arrays, members in an outer loop.

Every kernel reads angle and velocity increments ``(m, n, 3)`` (rad, m/s, body
x forward / y right / z down) and writes its outputs in place; the drivers in
:mod:`~schuler.alignment.inertial`, :mod:`~schuler.alignment.kalman` and
:mod:`~schuler.alignment.gyrocompass` own the arrays. Attitude updates use the
rotation vector with the coning correction, dtheta_k + (1/12) dtheta_{k-1} x dtheta_k,
and velocity updates the rotation and sculling terms
dv_k + 1/2 dtheta_k x dv_k + (1/12)(dtheta_{k-1} x dv_k + dv_{k-1} x dtheta_k)
(Savage 2000, ch. 7; spec 06).
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def _rotation(phi0: float, phi1: float, phi2: float, out: np.ndarray) -> None:
    """out = exp([phi x]) (Rodrigues)."""
    angle2 = phi0 * phi0 + phi1 * phi1 + phi2 * phi2
    if angle2 < 1e-16:
        a = 1.0 - angle2 / 6.0
        b = 0.5 - angle2 / 24.0
    else:
        angle = math.sqrt(angle2)
        a = math.sin(angle) / angle
        b = (1.0 - math.cos(angle)) / angle2
    out[0, 0] = 1.0 - b * (phi1 * phi1 + phi2 * phi2)
    out[1, 1] = 1.0 - b * (phi0 * phi0 + phi2 * phi2)
    out[2, 2] = 1.0 - b * (phi0 * phi0 + phi1 * phi1)
    out[0, 1] = -a * phi2 + b * phi0 * phi1
    out[1, 0] = a * phi2 + b * phi0 * phi1
    out[0, 2] = a * phi1 + b * phi0 * phi2
    out[2, 0] = -a * phi1 + b * phi0 * phi2
    out[1, 2] = -a * phi0 + b * phi1 * phi2
    out[2, 1] = a * phi0 + b * phi1 * phi2


@numba.njit(cache=True, nogil=True)
def _step(C: np.ndarray, dtheta: np.ndarray, dv: np.ndarray, prev_theta: np.ndarray, prev_v: np.ndarray,
          rot: np.ndarray, scratch: np.ndarray, velocity: np.ndarray) -> None:
    """One strapdown step in a frame fixed in inertial space: velocity += C dv', then C = C exp([phi x])."""
    # velocity increment with rotation and sculling terms, in the body frame at the interval's start
    s0 = dv[0] + 0.5 * (dtheta[1] * dv[2] - dtheta[2] * dv[1]) \
        + (prev_theta[1] * dv[2] - prev_theta[2] * dv[1] + prev_v[1] * dtheta[2] - prev_v[2] * dtheta[1]) / 12.0
    s1 = dv[1] + 0.5 * (dtheta[2] * dv[0] - dtheta[0] * dv[2]) \
        + (prev_theta[2] * dv[0] - prev_theta[0] * dv[2] + prev_v[2] * dtheta[0] - prev_v[0] * dtheta[2]) / 12.0
    s2 = dv[2] + 0.5 * (dtheta[0] * dv[1] - dtheta[1] * dv[0]) \
        + (prev_theta[0] * dv[1] - prev_theta[1] * dv[0] + prev_v[0] * dtheta[1] - prev_v[1] * dtheta[0]) / 12.0
    for i in range(3):
        velocity[i] += C[i, 0] * s0 + C[i, 1] * s1 + C[i, 2] * s2
    # rotation vector with the coning term
    p0 = dtheta[0] + (prev_theta[1] * dtheta[2] - prev_theta[2] * dtheta[1]) / 12.0
    p1 = dtheta[1] + (prev_theta[2] * dtheta[0] - prev_theta[0] * dtheta[2]) / 12.0
    p2 = dtheta[2] + (prev_theta[0] * dtheta[1] - prev_theta[1] * dtheta[0]) / 12.0
    _rotation(p0, p1, p2, rot)
    for i in range(3):
        for j in range(3):
            scratch[i, j] = C[i, 0] * rot[0, j] + C[i, 1] * rot[1, j] + C[i, 2] * rot[2, j]
    for i in range(3):
        for j in range(3):
            C[i, j] = scratch[i, j]


@numba.njit(cache=True, nogil=True)
def inertial_integrate(gyro: np.ndarray, accel: np.ndarray, ends: np.ndarray, attitude_out: np.ndarray,
                       velocity_out: np.ndarray) -> None:
    """C_b^{ib0}(t) and v^{ib0}(t) = int C_b^{ib0} f dt from C(0) = I, at sample counts ``ends``.

    Parameters
    ----------
    gyro, accel : ndarray (m, n, 3)
        Angle (rad) and velocity (m/s) increments.
    ends : ndarray (K,) of int
        Sample counts (1-based, increasing) at which to write the outputs.
    attitude_out : ndarray (m, K, 3, 3)
    velocity_out : ndarray (m, K, 3)
    """
    m, n = gyro.shape[0], gyro.shape[1]
    C = np.empty((3, 3))
    rot = np.empty((3, 3))
    scratch = np.empty((3, 3))
    velocity = np.empty(3)
    prev_theta = np.empty(3)
    prev_v = np.empty(3)
    dtheta = np.empty(3)
    dv = np.empty(3)
    for member in range(m):
        C[:, :] = 0.0
        for i in range(3):
            C[i, i] = 1.0
            velocity[i] = 0.0
            prev_theta[i] = 0.0
            prev_v[i] = 0.0
        out = 0
        for k in range(n):
            for i in range(3):
                dtheta[i] = gyro[member, k, i]
                dv[i] = accel[member, k, i]
            _step(C, dtheta, dv, prev_theta, prev_v, rot, scratch, velocity)
            for i in range(3):
                prev_theta[i] = dtheta[i]
                prev_v[i] = dv[i]
            if out < ends.size and k + 1 == ends[out]:
                attitude_out[member, out] = C
                velocity_out[member, out] = velocity
                out += 1


@numba.njit(cache=True, nogil=True)
def navigate_at_rest(gyro: np.ndarray, accel: np.ndarray, start: int, stop: int, dt: float,
                     attitude: np.ndarray, velocity: np.ndarray, gyro_bias: np.ndarray, accel_bias: np.ndarray,
                     earth_rate: np.ndarray, gravity: np.ndarray, previous: np.ndarray) -> None:
    """NED strapdown mechanisation over samples [start, stop) of every member, state updated in place.

    C' = C [omega_ib x] - [omega_ie x] C and v' = C f + g - 2 omega_ie x v at a fixed site
    (spec 06, Groves 2013 ch. 5; transport rate and position change neglected at rest).

    Parameters
    ----------
    gyro, accel : ndarray (m, n, 3)
        Increments, rad and m/s.
    start, stop : int
        Sample range.
    dt : float
        Sample interval, s.
    attitude : ndarray (m, 3, 3)
        C_b^n, updated.
    velocity : ndarray (m, 3)
        NED velocity, m/s, updated.
    gyro_bias, accel_bias : ndarray (m, 3)
        Estimated biases subtracted from the increments (rad/s, m/s^2).
    earth_rate : ndarray (3,)
        omega_ie^n, rad/s.
    gravity : ndarray (3,)
        g^n, m/s^2.
    previous : ndarray (m, 6)
        The last compensated increments (dtheta, dv) of each member, for coning and sculling; updated.
    """
    m = gyro.shape[0]
    rot = np.empty((3, 3))
    scratch = np.empty((3, 3))
    C = np.empty((3, 3))
    dtheta = np.empty(3)
    dv = np.empty(3)
    prev_theta = np.empty(3)
    prev_v = np.empty(3)
    nav_dv = np.empty(3)
    w0, w1, w2 = earth_rate[0] * dt, earth_rate[1] * dt, earth_rate[2] * dt
    for member in range(m):
        C[:, :] = attitude[member]
        bias_g = gyro_bias[member] * dt
        bias_a = accel_bias[member] * dt
        for i in range(3):
            prev_theta[i] = previous[member, i]
            prev_v[i] = previous[member, 3 + i]
        v0, v1, v2 = velocity[member, 0], velocity[member, 1], velocity[member, 2]
        for k in range(start, stop):
            for i in range(3):
                dtheta[i] = gyro[member, k, i] - bias_g[i]
                dv[i] = accel[member, k, i] - bias_a[i]
            nav_dv[:] = 0.0
            _step(C, dtheta, dv, prev_theta, prev_v, rot, scratch, nav_dv)
            # gravity and Coriolis over the interval
            c0 = 2.0 * (earth_rate[1] * v2 - earth_rate[2] * v1)
            c1 = 2.0 * (earth_rate[2] * v0 - earth_rate[0] * v2)
            c2 = 2.0 * (earth_rate[0] * v1 - earth_rate[1] * v0)
            v0 += nav_dv[0] + (gravity[0] - c0) * dt
            v1 += nav_dv[1] + (gravity[1] - c1) * dt
            v2 += nav_dv[2] + (gravity[2] - c2) * dt
            # the navigation frame turns with the Earth: C <- (I - [omega_ie dt x]) C
            for j in range(3):
                a0, a1, a2 = C[0, j], C[1, j], C[2, j]
                C[0, j] = a0 + w2 * a1 - w1 * a2
                C[1, j] = a1 - w2 * a0 + w0 * a2
                C[2, j] = a2 + w1 * a0 - w0 * a1
            for i in range(3):
                prev_theta[i] = dtheta[i]
                prev_v[i] = dv[i]
        attitude[member] = C
        velocity[member, 0], velocity[member, 1], velocity[member, 2] = v0, v1, v2
        for i in range(3):
            previous[member, i] = prev_theta[i]
            previous[member, 3 + i] = prev_v[i]


@numba.njit(cache=True, nogil=True)
def gyrocompass_loop(gyro: np.ndarray, accel: np.ndarray, dt: float, attitude: np.ndarray, earth_rate: np.ndarray,
                     gravity: float, c_gamma: float, c_a: float, ends: np.ndarray, attitude_out: np.ndarray) -> None:
    """The strapdown gyrocompass: a computed level frame torqued by its own sensed specific force.

    The computed frame turns at omega_ie + u with u = (c_gamma f_E / g, -c_gamma f_N / g, -c_a f_N / g),
    f = C dv / dt the specific force resolved in it (KPI manual (1.6) with c_Gamma = -c1 g,
    c_a = c2 g; see :func:`~schuler.alignment.limits.gyrocompass_error_model`).

    Parameters
    ----------
    gyro, accel : ndarray (m, n, 3)
        Increments, rad and m/s.
    dt : float
        s.
    attitude : ndarray (m, 3, 3)
        Initial C_b^n, updated to the final one.
    earth_rate : ndarray (3,)
        omega_ie^n, rad/s.
    gravity : float
        g, m/s^2.
    c_gamma, c_a : float
        Gains, 1/s.
    ends : ndarray (K,) of int
        Sample counts at which to write ``attitude_out`` (m, K, 3, 3).
    """
    m, n = gyro.shape[0], gyro.shape[1]
    rot = np.empty((3, 3))
    scratch = np.empty((3, 3))
    C = np.empty((3, 3))
    dtheta = np.empty(3)
    dv = np.empty(3)
    prev_theta = np.empty(3)
    prev_v = np.empty(3)
    nav_dv = np.empty(3)
    for member in range(m):
        C[:, :] = attitude[member]
        prev_theta[:] = 0.0
        prev_v[:] = 0.0
        out = 0
        for k in range(n):
            for i in range(3):
                dtheta[i] = gyro[member, k, i]
                dv[i] = accel[member, k, i]
            nav_dv[:] = 0.0
            _step(C, dtheta, dv, prev_theta, prev_v, rot, scratch, nav_dv)
            f_n = nav_dv[0] / (dt * gravity)
            f_e = nav_dv[1] / (dt * gravity)
            w0 = (earth_rate[0] + c_gamma * f_e) * dt
            w1 = (earth_rate[1] - c_gamma * f_n) * dt
            w2 = (earth_rate[2] - c_a * f_n) * dt
            _rotation(-w0, -w1, -w2, rot)
            for i in range(3):
                for j in range(3):
                    scratch[i, j] = rot[i, 0] * C[0, j] + rot[i, 1] * C[1, j] + rot[i, 2] * C[2, j]
            for i in range(3):
                for j in range(3):
                    C[i, j] = scratch[i, j]
            for i in range(3):
                prev_theta[i] = dtheta[i]
                prev_v[i] = dv[i]
            if out < ends.size and k + 1 == ends[out]:
                attitude_out[member, out] = C
                out += 1
        attitude[member] = C


@numba.njit(cache=True, nogil=True)
def partial_rotations(rates: np.ndarray, lengths: np.ndarray, dt: float, noise: np.ndarray, with_noise: bool,
                      R: np.ndarray, S: np.ndarray, Q: np.ndarray) -> None:
    """Per motion j: R_j = prod_k exp([w_k dt x]), S_j = integral of R_j(t) dt (trapezoid), Q_j = rotation noise.

    Parameters
    ----------
    rates : ndarray, shape (J, L, 3)
        Calibrated angular rates of each motion, rad/s, sensor axes (samples past ``lengths`` unused).
    lengths : ndarray of int64, shape (J,)
        Samples of each motion, number of.
    dt : float
        Sample interval, s.
    noise : ndarray, shape (3, 3)
        Per-sample covariance of the rates, (rad/s)^2 (read when ``with_noise``).
    with_noise : bool
        Whether to accumulate Q_j = sum_k R_j(t_k) noise R_j(t_k)^T dt^2, rad^2.
    R, S, Q : ndarray, shape (J, 3, 3)
        Written: the rotations (plain numbers), their time integrals (s) and noise covariances (rad^2).
    """
    step = np.empty((3, 3))
    after = np.empty((3, 3))
    for j in range(rates.shape[0]):
        current = np.eye(3)
        S[j] = 0.0
        Q[j] = 0.0
        for k in range(lengths[j]):
            _rotation(rates[j, k, 0] * dt, rates[j, k, 1] * dt, rates[j, k, 2] * dt, step)
            for r in range(3):
                for c in range(3):
                    after[r, c] = current[r, 0] * step[0, c] + current[r, 1] * step[1, c] + current[r, 2] * step[2, c]
            S[j] += 0.5 * (current + after) * dt
            if with_noise:
                Q[j] += after @ noise @ after.T * (dt * dt)
            current[:] = after
        R[j] = current


@numba.njit(cache=True, nogil=True)
def staged_gyrocompass_loop(gyro: np.ndarray, accel: np.ndarray, dt: float, attitude: np.ndarray,
                            earth_rate: np.ndarray, gravity: float, k_velocity: np.ndarray, k_level: np.ndarray,
                            k_azimuth: np.ndarray, ends: np.ndarray, attitude_out: np.ndarray) -> None:
    """The staged strapdown gyrocompass: a computed level frame torqued by its own computed velocity.

    Per sample the horizontal velocity v in the computed frame integrates the sensed specific force and is
    damped, v += (C dv)_h - k1 v dt, and the frame turns at omega_ie + u with
    u = (k2 v_E / g, -k2 v_N / g, -k3 v_N / g) (see :mod:`~schuler.alignment.staged_gyrocompass`).
    The gains follow the design's schedule, one value per sample.

    Parameters
    ----------
    gyro, accel : ndarray (m, n, 3)
        Increments, rad and m/s.
    dt : float
        s.
    attitude : ndarray (m, 3, 3)
        Initial C_b^n, updated to the final one.
    earth_rate : ndarray (3,)
        omega_ie^n, rad/s.
    gravity : float
        g, m/s^2.
    k_velocity, k_level, k_azimuth : ndarray (n,)
        k1 (1/s), k2 (1/s^2) and k3 (1/s^2) over each sample.
    ends : ndarray (K,) of int
        Sample counts at which to write ``attitude_out`` (m, K, 3, 3).
    """
    m, n = gyro.shape[0], gyro.shape[1]
    rot = np.empty((3, 3))
    scratch = np.empty((3, 3))
    C = np.empty((3, 3))
    dtheta = np.empty(3)
    dv = np.empty(3)
    prev_theta = np.empty(3)
    prev_v = np.empty(3)
    nav_dv = np.empty(3)
    for member in range(m):
        C[:, :] = attitude[member]
        prev_theta[:] = 0.0
        prev_v[:] = 0.0
        v_n = 0.0
        v_e = 0.0
        out = 0
        for k in range(n):
            k1, k2, k3 = k_velocity[k], k_level[k], k_azimuth[k]
            for i in range(3):
                dtheta[i] = gyro[member, k, i]
                dv[i] = accel[member, k, i]
            nav_dv[:] = 0.0
            _step(C, dtheta, dv, prev_theta, prev_v, rot, scratch, nav_dv)
            v_n += nav_dv[0] - k1 * v_n * dt
            v_e += nav_dv[1] - k1 * v_e * dt
            w0 = (earth_rate[0] + k2 * v_e / gravity) * dt
            w1 = (earth_rate[1] - k2 * v_n / gravity) * dt
            w2 = (earth_rate[2] - k3 * v_n / gravity) * dt
            _rotation(-w0, -w1, -w2, rot)
            for i in range(3):
                for j in range(3):
                    scratch[i, j] = rot[i, 0] * C[0, j] + rot[i, 1] * C[1, j] + rot[i, 2] * C[2, j]
            for i in range(3):
                for j in range(3):
                    C[i, j] = scratch[i, j]
            for i in range(3):
                prev_theta[i] = dtheta[i]
                prev_v[i] = dv[i]
            if out < ends.size and k + 1 == ends[out]:
                attitude_out[member, out] = C
                out += 1
        attitude[member] = C
