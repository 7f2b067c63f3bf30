"""Numba time loops of the strapdown and platform mechanizations, a batch of members at once.

Private. Each function advances every member (in parallel over members) through
one chunk of IMU samples, writing its state back in place and its computed
position, velocity and attitude into the output array at every ``out_every``-th
sample. The step equations are those of :mod:`schuler.navigate._kernels`. A member
whose state leaves the mechanization's domain (:func:`~schuler.navigate._kernels.inside_domain`)
is stopped there: its state keeps the first sample outside (``LEFT_AT`` holds its number)
and it is skipped from then on; the caller reports it.

Per-member sensor errors come as rows of 12 values: a row-major 3x3 matrix and a
bias (rad/s or m/s^2). For the strapdown the matrix is I + S + M (measured = M
true + b dt); for the platform's gyros it is (I + S + M)^-1, since the torquing
loop turns the platform until the gyro reads the command.
"""

from __future__ import annotations

import math

import numba

from schuler.navigate._kernels import (
    BARO,
    BARO_BIAS,
    COS_LAT,
    DTHETA_PREV,
    DV_PREV,
    ERROR_MODEL,
    FAST_MATH,
    HELD,
    HGT,
    LAT,
    LEFT_AT,
    LON,
    QUAT,
    SIN_LAT,
    VEL,
    VEL_PREV,
    apply_sensor,
    attitude_step,
    frame_step,
    geometry,
    inside_domain,
    normalize,
    position_step,
    quat_from_rotation_vector,
    quat_multiply,
    rotate,
    sensor_row,
    store_output,
)


@numba.njit(cache=True, fastmath=FAST_MATH, error_model=ERROR_MODEL)
def _vertical(mode, h, vd, vd1, dt, h_true, vd_true, baro_error, k1, k2, k3, b_hat):
    """Vertical channel after the velocity update: returns (v_D, height override, use it, b_hat).

    HELD replaces the height and vertical velocity by the truth; BARO runs the
    loop of :mod:`schuler.navigation_errors.vertical_channel` on the error
    e = h - (h_true + baro_error): h' = -v_D - k1 e, v_D' = ... + k2 e + b_hat, b_hat' = k3 e.
    """
    if mode == HELD:
        return vd_true, h_true, True, b_hat
    if mode == BARO:
        h1 = h - 0.5 * dt * (vd + vd1)
        e = h1 - (h_true + baro_error)
        return vd1 + (k2 * e + b_hat) * dt, h1 - k1 * e * dt, True, b_hat + k3 * e * dt
    return vd1, 0.0, False, b_hat


@numba.njit(cache=True, parallel=True, fastmath=FAST_MATH, error_model=ERROR_MODEL)
def strapdown_chunk(dt, first_sample, increments, truth_vertical, state, gyro, accel, gyro_noise, accel_noise,
                    has_noise, out, out_every, vertical_mode, baro, rate, coriolis, centripetal, entered_earth_rate,
                    use_entered):
    """Advance every member through ``increments.shape[0]`` strapdown steps.

    Parameters
    ----------
    dt : float
        IMU interval, s.
    first_sample : int
        Global index of the chunk's first interval (the sample at its end is ``first_sample + 1``).
    increments : (n, 6)
        Ideal (dtheta, dv) of each interval, body axes, rad and m/s.
    truth_vertical : (n, 2)
        True height (m) and v_D (m/s) at the end of each interval (vertical channel held or baro).
    state : (N, STATE_SIZE)
        Members' states, advanced in place.
    gyro, accel : (N, 12)
        Sensor error rows (see the module docstring).
    gyro_noise, accel_noise : (N, n, 3)
        Additive increment errors (rad, m/s), read when ``has_noise``.
    out : (N, n_out, OUTPUT_SIZE)
        Output rows, row ``(first_sample + k + 1) // out_every`` when divisible.
    out_every : int
        Samples per output step.
    vertical_mode : int
        FREE, HELD or BARO.
    baro : (4,)
        k1 (1/s), k2 (1/s^2), k3 (1/s^3), barometric altitude error (m).
    rate : float
        Earth rate, rad/s.
    coriolis, centripetal : float
        1 and 0 for a correct computer (see :func:`frame_step`).
    entered_earth_rate : (n, 2)
        Omega cos L, -Omega sin L (rad/s) at the true latitude at the start of each
        interval, used instead of the computed latitude's when ``use_entered``
        (an Earth-rate compensation from an entered latitude, as Drozdovich (1959), eq. (8)).
    """
    n_members = state.shape[0]
    n = increments.shape[0]
    k1, k2, k3, baro_error = baro[0], baro[1], baro[2], baro[3]
    for m in numba.prange(n_members):
        st = state[m]
        if st[LEFT_AT] != 0.0:  # stopped when it left the domain
            continue
        lat, lon, h = st[LAT], st[LON], st[HGT]
        vn, ve, vd = st[VEL], st[VEL + 1], st[VEL + 2]
        vnp, vep, vdp = st[VEL_PREV], st[VEL_PREV + 1], st[VEL_PREV + 2]
        q0, q1, q2, q3 = st[QUAT], st[QUAT + 1], st[QUAT + 2], st[QUAT + 3]
        t0, t1, t2 = st[DTHETA_PREV], st[DTHETA_PREV + 1], st[DTHETA_PREV + 2]
        u0, u1, u2 = st[DV_PREV], st[DV_PREV + 1], st[DV_PREV + 2]
        b_hat = st[BARO_BIAS]
        s, c = st[SIN_LAT], st[COS_LAT]
        r_n, r_e, inv_sqrt_w, inv_rn_h, inv_re_h, inv_c = geometry(s, c, h)
        g_row = sensor_row(gyro[m])
        a_row = sensor_row(accel[m])
        # samples to the next output and its row (no integer division in the loop)
        countdown = out_every - first_sample % out_every
        row = first_sample // out_every
        for k in range(n):
            d0, d1, d2 = apply_sensor(g_row, increments[k, 0], increments[k, 1], increments[k, 2], dt)
            e0, e1, e2 = apply_sensor(a_row, increments[k, 3], increments[k, 4], increments[k, 5], dt)
            if has_noise:
                d0 += gyro_noise[m, k, 0]
                d1 += gyro_noise[m, k, 1]
                d2 += gyro_noise[m, k, 2]
                e0 += accel_noise[m, k, 0]
                e1 += accel_noise[m, k, 1]
                e2 += accel_noise[m, k, 2]
            # coning, rotation and sculling corrections
            p0 = d0 + (t1 * d2 - t2 * d1) / 12.0
            p1 = d1 + (t2 * d0 - t0 * d2) / 12.0
            p2 = d2 + (t0 * d1 - t1 * d0) / 12.0
            x = e0 + 0.5 * (d1 * e2 - d2 * e1) + ((t1 * e2 - t2 * e1) + (u1 * d2 - u2 * d1)) / 12.0
            y = e1 + 0.5 * (d2 * e0 - d0 * e2) + ((t2 * e0 - t0 * e2) + (u2 * d0 - u0 * d2)) / 12.0
            z = e2 + 0.5 * (d0 * e1 - d1 * e0) + ((t0 * e1 - t1 * e0) + (u0 * d1 - u1 * d0)) / 12.0
            if use_entered:
                ie_n, ie_d = entered_earth_rate[k, 0], entered_earth_rate[k, 1]
            else:
                ie_n, ie_d = rate * c, -rate * s
            zn, ze, zd, an, ae, ad = frame_step(s, c, r_e, inv_sqrt_w, inv_rn_h, inv_re_h, inv_c, h, vn, ve, vd,
                                                vnp, vep, vdp, dt, ie_n, ie_d, rate, coriolis, centripetal)
            wn, we, wd = rotate(q0, q1, q2, q3, x, y, z)
            vn1 = vn + wn - 0.5 * (ze * wd - zd * we) + an * dt
            ve1 = ve + we - 0.5 * (zd * wn - zn * wd) + ae * dt
            vd1 = vd + wd - 0.5 * (zn * we - ze * wn) + ad * dt
            vd1, h_set, use_set, b_hat = _vertical(vertical_mode, h, vd, vd1, dt, truth_vertical[k, 0],
                                                   truth_vertical[k, 1], baro_error, k1, k2, k3, b_hat)
            lat, lon, h, s, c, r_n, r_e, inv_sqrt_w, inv_rn_h, inv_re_h, inv_c = position_step(
                lat, lon, h, s, c, r_n, inv_re_h, inv_c, vn, ve, vd, vn1, ve1, vd1, dt, h_set, use_set)
            q0, q1, q2, q3 = attitude_step(q0, q1, q2, q3, zn, ze, zd, p0, p1, p2)
            vnp, vep, vdp = vn, ve, vd
            vn, ve, vd = vn1, ve1, vd1
            t0, t1, t2 = d0, d1, d2
            u0, u1, u2 = e0, e1, e2
            if not inside_domain(h, c, vn, ve, vd):
                st[LEFT_AT] = first_sample + k + 1
                break
            countdown -= 1
            if countdown == 0:  # the sample first_sample + k + 1 is an output time
                countdown = out_every
                row += 1
                store_output(out[m], row, lat, lon, h, vn, ve, vd, q0, q1, q2, q3)
        st[LAT], st[LON], st[HGT], st[SIN_LAT], st[COS_LAT] = lat, lon, h, s, c
        st[VEL], st[VEL + 1], st[VEL + 2] = vn, ve, vd
        st[VEL_PREV], st[VEL_PREV + 1], st[VEL_PREV + 2] = vnp, vep, vdp
        st[QUAT], st[QUAT + 1], st[QUAT + 2], st[QUAT + 3] = q0, q1, q2, q3
        st[DTHETA_PREV], st[DTHETA_PREV + 1], st[DTHETA_PREV + 2] = t0, t1, t2
        st[DV_PREV], st[DV_PREV + 1], st[DV_PREV + 2] = u0, u1, u2
        st[BARO_BIAS] = b_hat


@numba.njit(cache=True, parallel=True, fastmath=FAST_MATH, error_model=ERROR_MODEL)
def platform_chunk(dt, first_sample, nav_increments, truth_vertical, state, gyro, accel, gyro_noise, accel_noise,
                   has_noise, out, out_every, vertical_mode, baro, rate, coriolis, centripetal, entered_earth_rate,
                   use_entered, slave_azimuth):
    """Advance every member through one chunk of the platform (gimballed, local-level) mechanization.

    The platform carries the sensors and is torqued at the computed frame rate
    zeta_c = (omega_ie + omega_en)(computed) dt; its gyros make it turn by
    rho = (I + S + M)^-1 (zeta_c - b dt - noise) in platform axes, while the true
    NED frame turns by zeta (the truth's). Its orientation q_pn (platform axes ->
    true NED) follows q <- q(-zeta) q q(rho). The accelerometers measure the true
    specific-force increment in platform axes, (I + S + M) R(q_pn)^T f dt + b dt
    (q_pn at the step's middle), which the computer takes as NED. Parameters as :func:`strapdown_chunk`, with
    ``nav_increments`` (n, 6): the truth's zeta (rad) and NED specific-force
    increment (m/s), and ``gyro`` rows holding (I + S + M)^-1. With ``slave_azimuth``
    the platform's turn about its vertical is removed after every step (the
    twist of q_pn about z): an external azimuth reference, leaving the gyros
    only the level axes (the two-axis gyro vertical of Drozdovich (1959)).
    """
    n_members = state.shape[0]
    n = nav_increments.shape[0]
    k1, k2, k3, baro_error = baro[0], baro[1], baro[2], baro[3]
    for m in numba.prange(n_members):
        st = state[m]
        if st[LEFT_AT] != 0.0:  # stopped when it left the domain
            continue
        lat, lon, h = st[LAT], st[LON], st[HGT]
        vn, ve, vd = st[VEL], st[VEL + 1], st[VEL + 2]
        vnp, vep, vdp = st[VEL_PREV], st[VEL_PREV + 1], st[VEL_PREV + 2]
        q0, q1, q2, q3 = st[QUAT], st[QUAT + 1], st[QUAT + 2], st[QUAT + 3]
        b_hat = st[BARO_BIAS]
        s, c = st[SIN_LAT], st[COS_LAT]
        r_n, r_e, inv_sqrt_w, inv_rn_h, inv_re_h, inv_c = geometry(s, c, h)
        g_row = sensor_row(gyro[m])
        a_row = sensor_row(accel[m])
        # samples to the next output and its row (no integer division in the loop)
        countdown = out_every - first_sample % out_every
        row = first_sample // out_every
        for k in range(n):
            if use_entered:
                ie_n, ie_d = entered_earth_rate[k, 0], entered_earth_rate[k, 1]
            else:
                ie_n, ie_d = rate * c, -rate * s
            zn, ze, zd, an, ae, ad = frame_step(s, c, r_e, inv_sqrt_w, inv_rn_h, inv_re_h, inv_c, h, vn, ve, vd,
                                                vnp, vep, vdp, dt, ie_n, ie_d, rate, coriolis, centripetal)
            c0, c1, c2 = zn - g_row[9] * dt, ze - g_row[10] * dt, zd - g_row[11] * dt
            if has_noise:
                c0 -= gyro_noise[m, k, 0]
                c1 -= gyro_noise[m, k, 1]
                c2 -= gyro_noise[m, k, 2]
            r0, r1, r2 = apply_sensor(g_row, c0, c1, c2, 0.0)
            a0, a1, a2, a3 = quat_from_rotation_vector(-nav_increments[k, 0], -nav_increments[k, 1],
                                                       -nav_increments[k, 2])
            b0, b1, b2, b3 = quat_from_rotation_vector(r0, r1, r2)
            n0, n1, n2, n3 = quat_multiply(a0, a1, a2, a3, q0, q1, q2, q3)
            n0, n1, n2, n3 = normalize(*quat_multiply(n0, n1, n2, n3, b0, b1, b2, b3))
            if slave_azimuth:  # q <- q twist*, twist = (q0, 0, 0, q3) / |.| taken with q0 >= 0 (keeps q's sign)
                scale = math.copysign(1.0 / math.sqrt(n0 * n0 + n3 * n3), n0)
                n0, n1, n2, n3 = quat_multiply(n0, n1, n2, n3, n0 * scale, 0.0, 0.0, -n3 * scale)
            # true specific force in platform axes at the step's middle, then the accelerometer errors
            m0, m1, m2, m3 = q0 + n0, q1 + n1, q2 + n2, q3 + n3
            scale = 1.0 / math.sqrt(m0 * m0 + m1 * m1 + m2 * m2 + m3 * m3)
            x, y, z = rotate(m0 * scale, -m1 * scale, -m2 * scale, -m3 * scale, nav_increments[k, 3],
                             nav_increments[k, 4], nav_increments[k, 5])
            e0, e1, e2 = apply_sensor(a_row, x, y, z, dt)
            if has_noise:
                e0 += accel_noise[m, k, 0]
                e1 += accel_noise[m, k, 1]
                e2 += accel_noise[m, k, 2]
            vn1 = vn + e0 + an * dt
            ve1 = ve + e1 + ae * dt
            vd1 = vd + e2 + ad * dt
            vd1, h_set, use_set, b_hat = _vertical(vertical_mode, h, vd, vd1, dt, truth_vertical[k, 0],
                                                   truth_vertical[k, 1], baro_error, k1, k2, k3, b_hat)
            lat, lon, h, s, c, r_n, r_e, inv_sqrt_w, inv_rn_h, inv_re_h, inv_c = position_step(
                lat, lon, h, s, c, r_n, inv_re_h, inv_c, vn, ve, vd, vn1, ve1, vd1, dt, h_set, use_set)
            q0, q1, q2, q3 = n0, n1, n2, n3
            vnp, vep, vdp = vn, ve, vd
            vn, ve, vd = vn1, ve1, vd1
            if not inside_domain(h, c, vn, ve, vd):
                st[LEFT_AT] = first_sample + k + 1
                break
            countdown -= 1
            if countdown == 0:  # the sample first_sample + k + 1 is an output time
                countdown = out_every
                row += 1
                store_output(out[m], row, lat, lon, h, vn, ve, vd, q0, q1, q2, q3)
        st[LAT], st[LON], st[HGT], st[SIN_LAT], st[COS_LAT] = lat, lon, h, s, c
        st[VEL], st[VEL + 1], st[VEL + 2] = vn, ve, vd
        st[VEL_PREV], st[VEL_PREV + 1], st[VEL_PREV + 2] = vnp, vep, vdp
        st[QUAT], st[QUAT + 1], st[QUAT + 2], st[QUAT + 3] = q0, q1, q2, q3
        st[BARO_BIAS] = b_hat
