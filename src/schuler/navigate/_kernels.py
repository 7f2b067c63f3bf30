"""Numba kernels shared by the truth generator and the navigation loops: Earth model, rotations, one step.

Private: plain floats and arrays in, plain floats and arrays out. The public
functions live in :mod:`schuler.core.earth` (the same formulas, vectorised with
numpy; the tests hold the two together) and :mod:`schuler.core.attitude`.

Quaternions are Hamilton's, scalar first, q = (q0, q1, q2, q3); q_bn maps body
vectors into the navigation frame, v_n = q v_b q*, so that C_b^n = R(q_bn).

One navigation step from t_{k-1} to t_k (Groves 2013, Sec. 5.4 and 5.5; the
two-sample coning and sculling corrections of Savage 1998, JGCD 21(1), (2), as
in spec 06) with the increments dtheta_k (rad) and dv_k (m/s) of the interval:

* rotation vector with the coning correction, phi = dtheta_k + dtheta_{k-1} x dtheta_k / 12;
* specific-force increment with the rotation and sculling corrections,
  u = dv_k + dtheta_k x dv_k / 2 + (dtheta_{k-1} x dv_k + dv_{k-1} x dtheta_k) / 12;
* frame rates at the step's middle: velocity extrapolated, v_m = v_{k-1} + (v_{k-1} - v_{k-2}) / 2,
  position at t_{k-1}: zeta = (omega_ie + omega_en) dt (eqs. (2.123), (5.44));
* velocity (eq. (5.54) with the specific force transformed as in (5.86)):
  v_k = v_{k-1} + (I - [zeta x] / 2) C_{k-1} u + (g - (2 omega_ie + omega_en) x v_m) dt;
* position by the trapezoid rule (eq. (5.56));
* attitude (eqs. (5.73), (5.77) in exact rotation form): q_k = q(-zeta) q_{k-1} q(phi)
  (:func:`attitude_step`).

The inverse step recovers (dtheta_k, dv_k) from the truth at t_{k-1} and t_k
by solving these same equations backwards (both corrections are linear in the
unknown increment), so that the forward step reproduces the truth to rounding.
"""

from __future__ import annotations

import math
from typing import Final

import numba

from schuler.core.earth import (
    NORTH_GRAVITY_PER_HEIGHT,
    WGS84_ECCENTRICITY_SQUARED,
    WGS84_FLATTENING,
    WGS84_GAMMA_EQUATOR,
    WGS84_M,
    WGS84_SEMI_MAJOR_AXIS,
    WGS84_SOMIGLIANA_K,
)

_A = WGS84_SEMI_MAJOR_AXIS
_E2 = WGS84_ECCENTRICITY_SQUARED
_F = WGS84_FLATTENING
_M = WGS84_M
_GAMMA_E = WGS84_GAMMA_EQUATOR
_K = WGS84_SOMIGLIANA_K
_NORTH_G = NORTH_GRAVITY_PER_HEIGHT

# layout of a member's navigation state (one row of the state array)
LAT, LON, HGT = 0, 1, 2
SIN_LAT, COS_LAT = 3, 4  # carried along the path: rotated by each step's latitude change, no trigonometry
VEL = 5  # v_N, v_E, v_D at t_k
VEL_PREV = 8  # the velocity one step earlier (for the mid-step extrapolation)
QUAT = 11  # q0..q3: q_bn (strapdown) or q_pn (platform: platform axes -> true NED)
DTHETA_PREV = 15  # the previous step's angle increment (coning)
DV_PREV = 18  # the previous step's velocity increment (sculling)
BARO_BIAS = 21  # the baro loop's accelerometer-error estimate b_hat, m/s^2
LEFT_AT = 22  # 0 while inside the mechanization's domain; else the sample at which the member left it (stopped)
STATE_SIZE = 23

OUTPUT_SIZE = 10  # latitude, longitude, height, v_N, v_E, v_D, q0..q3

# vertical channel modes
FREE, HELD, BARO = 0, 1, 2

FAST_MATH = {"contract", "arcp", "nsz", "nnan", "ninf"}
"""LLVM may fuse multiply-adds and use reciprocals, never reassociate (the compensated sums and the series
depend on the order of operations) nor approximate functions: 25 % faster, results within rounding."""

ERROR_MODEL: Final = "numpy"
"""Divisions never raise inside the kernels (no zero test per division): :func:`inside_domain` stops a member
before any denominator nears 0 or any value leaves the finite numbers that ``FAST_MATH`` assumes."""

jit = numba.njit(cache=True, fastmath=FAST_MATH, error_model=ERROR_MODEL)

# The domain where the mechanization's equations are defined; each step of a member checks it.
LOWEST_HEIGHT = -0.5 * _A
"""m: half way to the Earth's centre; the frame rates v / (R + h) grow without bound as h nears -R."""
HIGHEST_HEIGHT = _A
"""m: one equatorial radius up; gravity's height series there (1 - k1 h + 3 h^2 / a^2) grows again with height
(2 g0 at h = a, against the inverse square's g0 / 4), so a diverging height runs away."""
POLE_COSINE = 1e-6
"""|cos L| below which the computed position is at a pole (within 6 m): the north-pointing frame's azimuth rate
v_E tan L / (R_E + h) is unbounded there. (Past a pole, cos L < 0, the equations hold again: the frame is the
other side's, turned half a turn about the vertical.)"""
HIGHEST_SPEED = 1e5
"""m/s: nine times the escape velocity; no trajectory or error the parameters allow comes near it."""


@jit
def inside_domain(h, c, vn, ve, vd):
    """Whether a computed state is inside the mechanization's domain (bounds above)."""
    return (LOWEST_HEIGHT < h < HIGHEST_HEIGHT and abs(c) > POLE_COSINE
            and vn * vn + ve * ve + vd * vd < HIGHEST_SPEED * HIGHEST_SPEED)


@jit
def reciprocal_near_one(x):
    """1 / (1 + x): a short series when |x| < 1e-4 (error below 1e-16), else a division."""
    if abs(x) < 1e-4:
        return 1.0 - x * (1.0 - x * (1.0 - x))
    return 1.0 / (1.0 + x)


@jit
def geometry(s, c, h):
    """Radii and the reciprocals a step needs at sin L = s, cos L = c, height h (eqs. (2.105), (2.106)).

    Returns R_N, R_E (m), 1/sqrt(1 - e^2 s^2), 1/(R_N + h), 1/(R_E + h) (1/m) and 1/cos L.
    """
    inv_sqrt_w = 1.0 / math.sqrt(1.0 - _E2 * s * s)
    r_e = _A * inv_sqrt_w
    r_n = r_e * (1.0 - _E2) * inv_sqrt_w * inv_sqrt_w
    return r_n, r_e, inv_sqrt_w, 1.0 / (r_n + h), 1.0 / (r_e + h), 1.0 / c


@jit
def rotate_latitude(s, c, delta):
    """(sin, cos) of L + delta from those of L; a series for |delta| < 1e-3 rad (error below 1e-20)."""
    if abs(delta) < 1e-3:
        d2 = delta * delta
        cos_d = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0)
        sin_d = delta * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0))
    else:
        cos_d = math.cos(delta)
        sin_d = math.sin(delta)
    return s * cos_d + c * sin_d, c * cos_d - s * sin_d


@jit
def gravity(s, c, inv_sqrt_w, height):
    """Normal gravity (g_N, g_D) in NED (eqs. (2.134), (2.139), (2.140)); inv_sqrt_w from :func:`geometry`."""
    s2 = s * s
    g0 = _GAMMA_E * (1.0 + _K * s2) * inv_sqrt_w
    k1 = 2.0 / _A * (1.0 + _F + _M - 2.0 * _F * s2)
    g_down = g0 * (1.0 - k1 * height + 3.0 * height * height / (_A * _A))
    g_north = _NORTH_G * height * 2.0 * s * c
    return g_north, g_down


@jit
def quat_multiply(a0, a1, a2, a3, b0, b1, b2, b3):
    """Hamilton product a b."""
    return (a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
            a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
            a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0)


@jit
def quat_delta(x, y, z):
    """exp of the rotation vector (x, y, z), rad, as (cos(a/2) - 1, sin(a/2) n): the departure from identity.

    Keeping cos(a/2) - 1 apart from the 1 lets small rotations compose without
    the rounding of the unit scalar part (which would otherwise bias a long
    stationary run by ~1e-16 rad per step).
    """
    angle2 = x * x + y * y + z * z
    if angle2 < 4e-4:  # |angle| < 0.02 rad: series, truncation below 1e-20
        h2 = 0.25 * angle2
        cos_minus_one = -h2 / 2.0 * (1.0 - h2 / 12.0 * (1.0 - h2 / 30.0))
        sin_ratio = 0.5 * (1.0 - h2 / 6.0 * (1.0 - h2 / 20.0 * (1.0 - h2 / 42.0)))
    else:
        angle = math.sqrt(angle2)
        cos_minus_one = -2.0 * math.sin(0.25 * angle) ** 2
        sin_ratio = math.sin(0.5 * angle) / angle
    return cos_minus_one, sin_ratio * x, sin_ratio * y, sin_ratio * z


@jit
def quat_from_rotation_vector(x, y, z):
    """exp of the rotation vector (x, y, z), rad: (cos(a/2), sin(a/2) n)."""
    c, v1, v2, v3 = quat_delta(x, y, z)
    return 1.0 + c, v1, v2, v3


@jit
def compose_deltas(a0, a1, a2, a3, b0, b1, b2, b3):
    """(1 + a0, a) (1 + b0, b) - 1 for two quaternions in the form of :func:`quat_delta`."""
    return (a0 + b0 + a0 * b0 - (a1 * b1 + a2 * b2 + a3 * b3),
            a1 + b1 + a0 * b1 + b0 * a1 + (a2 * b3 - a3 * b2),
            a2 + b2 + a0 * b2 + b0 * a2 + (a3 * b1 - a1 * b3),
            a3 + b3 + a0 * b3 + b0 * a3 + (a1 * b2 - a2 * b1))


@jit
def attitude_step(q0, q1, q2, q3, zn, ze, zd, p0, p1, p2):
    """q_k = q(-zeta) q_{k-1} q(phi) = q_{k-1} q(-zeta_b) q(phi), zeta_b = R(q_{k-1})^T zeta; renormalised.

    The two small rotations are composed first, and their departure from the
    identity is added to q_{k-1}: a step that does not turn the body leaves q
    unchanged to the last bit.
    """
    x, y, z = rotate(q0, -q1, -q2, -q3, zn, ze, zd)
    a0, a1, a2, a3 = quat_delta(-x, -y, -z)
    b0, b1, b2, b3 = quat_delta(p0, p1, p2)
    r0, r1, r2, r3 = compose_deltas(a0, a1, a2, a3, b0, b1, b2, b3)
    d0, d1, d2, d3 = quat_multiply(q0, q1, q2, q3, r0, r1, r2, r3)
    return normalize(q0 + d0, q1 + d1, q2 + d2, q3 + d3)


@jit
def rotation_vector_from_quat(q0, q1, q2, q3):
    """The rotation vector of a unit quaternion (the shorter rotation), rad."""
    if q0 < 0.0:
        q0, q1, q2, q3 = -q0, -q1, -q2, -q3
    n2 = q1 * q1 + q2 * q2 + q3 * q3
    if n2 < 1e-4 * q0 * q0:
        # 2 atan(x) / (x q0), x = |q_v| / q0 < 0.01: series, truncation below 1e-17
        x2 = n2 / (q0 * q0)
        factor = 2.0 / q0 * (1.0 - x2 * (1.0 / 3.0 - x2 * (0.2 - x2 / 7.0)))
    else:
        n = math.sqrt(n2)
        factor = 2.0 * math.atan2(n, q0) / n
    return factor * q1, factor * q2, factor * q3


@jit
def rotate(q0, q1, q2, q3, x, y, z):
    """R(q) (x, y, z) for a unit quaternion: v + 2 q0 (w x v) + 2 w x (w x v), w = (q1, q2, q3)."""
    tx = 2.0 * (q2 * z - q3 * y)
    ty = 2.0 * (q3 * x - q1 * z)
    tz = 2.0 * (q1 * y - q2 * x)
    return (x + q0 * tx + q2 * tz - q3 * ty,
            y + q0 * ty + q3 * tx - q1 * tz,
            z + q0 * tz + q1 * ty - q2 * tx)


@jit
def normalize(q0, q1, q2, q3):
    """Renormalise a quaternion within rounding of unit length (one Newton step for 1/|q|)."""
    scale = 1.5 - 0.5 * (q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
    return q0 * scale, q1 * scale, q2 * scale, q3 * scale


@jit
def solve_cross(a0, a1, a2, b0, b1, b2):
    """x with x + a x x = b: (I + [a x])^-1 b = (b - a x b + a (a . b)) / (1 + |a|^2)."""
    ab = a0 * b0 + a1 * b1 + a2 * b2
    scale = reciprocal_near_one(a0 * a0 + a1 * a1 + a2 * a2)
    return ((b0 - (a1 * b2 - a2 * b1) + a0 * ab) * scale,
            (b1 - (a2 * b0 - a0 * b2) + a1 * ab) * scale,
            (b2 - (a0 * b1 - a1 * b0) + a2 * ab) * scale)


@jit
def frame_step(s, c, r_e, inv_sqrt_w, inv_rn_h, inv_re_h, inv_c, h, vn, ve, vd, vn_prev, ve_prev, vd_prev, dt,
               ie_n, ie_d, rate, coriolis, centripetal):
    """The navigation frame's rotation zeta over a step and the non-specific-force acceleration.

    Returns (zeta_N, zeta_E, zeta_D) in rad and (a_N, a_E, a_D) in m/s^2 with
    a = g - (coriolis 2 omega_ie + omega_en) x v_m + centripetal omega_ie x (omega_ie x r),
    omega_ie = (ie_n, 0, ie_d) (rad/s; Omega (cos L, 0, -sin L) at the computed
    or an entered latitude): ``coriolis`` = 1 and ``centripetal`` = 0 for a
    correct computer; 0 and 1 leave the Coriolis and centripetal terms
    uncompensated (Drozdovich (1959): W*).
    """
    vn_m = 1.5 * vn - 0.5 * vn_prev
    ve_m = 1.5 * ve - 0.5 * ve_prev
    vd_m = 1.5 * vd - 0.5 * vd_prev
    en_n = ve_m * inv_re_h
    en_e = -vn_m * inv_rn_h
    en_d = -en_n * s * inv_c
    g_n, g_d = gravity(s, c, inv_sqrt_w, h - 0.5 * dt * vd_m)
    # (2 omega_ie + omega_en) x v_m, Coriolis part weighted
    w_n = coriolis * 2.0 * ie_n + en_n
    w_e = en_e
    w_d = coriolis * 2.0 * ie_d + en_d
    a_n = g_n - (w_e * vd_m - w_d * ve_m)
    a_e = -(w_d * vn_m - w_n * vd_m)
    a_d = g_d - (w_n * ve_m - w_e * vn_m)
    if centripetal != 0.0:
        radial = centripetal * rate * rate * (r_e + h) * c
        a_n += radial * s
        a_d += radial * c
    return (ie_n + en_n) * dt, en_e * dt, (ie_d + en_d) * dt, a_n, a_e, a_d


@jit
def position_step(lat, lon, h, s, c, r_n, inv_re_h, inv_c, vn0, ve0, vd0, vn1, ve1, vd1, dt, height_override,
                  use_override):
    """Trapezoid position update (eq. (5.56), meridian radius at the mid height).

    Returns the new latitude, longitude, height, sin L, cos L and the :func:`geometry` there.
    """
    if use_override:
        h1 = height_override
    else:
        h1 = h - 0.5 * dt * (vd0 + vd1)
    lat1 = lat + 0.5 * dt * (vn0 + vn1) / (r_n + 0.5 * (h + h1))
    s1, c1 = rotate_latitude(s, c, lat1 - lat)
    r_n1, r_e1, inv_sqrt_w1, inv_rn_h1, inv_re_h1, inv_c1 = geometry(s1, c1, h1)
    lon1 = lon + 0.5 * dt * (ve0 * inv_re_h * inv_c + ve1 * inv_re_h1 * inv_c1)
    return lat1, lon1, h1, s1, c1, r_n1, r_e1, inv_sqrt_w1, inv_rn_h1, inv_re_h1, inv_c1


@jit
def inverse_steps(dt, quaternions, velocities, state, increments, positions, nav_increments, rate):
    """Truth -> ideal IMU for one chunk: the inverse of the strapdown step, sample by sample.

    Parameters (arrays written in place)
    ------------------------------------
    dt : float
        IMU interval, s.
    quaternions : (n + 1, 4)
        Truth q_bn at t_{k-1} (row 0, the last sample of the previous chunk) .. t_{k+n-1}.
    velocities : (n + 1, 3)
        Truth v_N, v_E, v_D at the same times, m/s.
    state : (STATE_SIZE,)
        Truth state at row 0's time (position, velocity one step earlier, previous increments); advanced.
    increments : (n, 6)
        Output: dtheta (rad) and dv (m/s) of each interval.
    positions : (n, 3)
        Output: latitude, longitude (rad) and height (m) at the end of each interval.
    nav_increments : (n, 6)
        Output: zeta (rad, the NED frame's turn) and the specific-force increment
        in NED, v_k - v_{k-1} - a dt (m/s), for the platform mechanization.
    rate : float
        Earth rate, rad/s.
    """
    lat, lon, h = state[LAT], state[LON], state[HGT]
    s, c = state[SIN_LAT], state[COS_LAT]
    vn_prev, ve_prev, vd_prev = state[VEL_PREV], state[VEL_PREV + 1], state[VEL_PREV + 2]
    t0, t1, t2 = state[DTHETA_PREV], state[DTHETA_PREV + 1], state[DTHETA_PREV + 2]
    u0, u1, u2 = state[DV_PREV], state[DV_PREV + 1], state[DV_PREV + 2]
    r_n, r_e, inv_sqrt_w, inv_rn_h, inv_re_h, inv_c = geometry(s, c, h)
    for k in range(increments.shape[0]):
        vn, ve, vd = velocities[k, 0], velocities[k, 1], velocities[k, 2]
        vn1, ve1, vd1 = velocities[k + 1, 0], velocities[k + 1, 1], velocities[k + 1, 2]
        zn, ze, zd, an, ae, ad = frame_step(s, c, r_e, inv_sqrt_w, inv_rn_h, inv_re_h, inv_c, h, vn, ve, vd,
                                            vn_prev, ve_prev, vd_prev, dt, rate * c, -rate * s, rate, 1.0, 0.0)
        # specific-force increment in NED, then back through (I - [zeta x]/2) and C_{k-1}
        fn = vn1 - vn - an * dt
        fe = ve1 - ve - ae * dt
        fd = vd1 - vd - ad * dt
        wn, we, wd = solve_cross(-0.5 * zn, -0.5 * ze, -0.5 * zd, fn, fe, fd)
        a0, a1, a2, a3 = quaternions[k, 0], quaternions[k, 1], quaternions[k, 2], quaternions[k, 3]
        b0, b1, b2, b3 = quaternions[k + 1, 0], quaternions[k + 1, 1], quaternions[k + 1, 2], quaternions[k + 1, 3]
        x, y, z = rotate(a0, -a1, -a2, -a3, wn, we, wd)
        # q(phi) = q_{k-1}* q(zeta) q_k = q(zeta_b) (q_{k-1}* q_k), zeta_b = R(q_{k-1})^T zeta
        zb0, zb1, zb2 = rotate(a0, -a1, -a2, -a3, zn, ze, zd)
        z0, z1, z2, z3 = quat_from_rotation_vector(zb0, zb1, zb2)
        p0, p1, p2, p3 = quat_multiply(a0, -a1, -a2, -a3, b0, b1, b2, b3)
        p0, p1, p2, p3 = quat_multiply(z0, z1, z2, z3, p0, p1, p2, p3)
        phi0, phi1, phi2 = rotation_vector_from_quat(p0, p1, p2, p3)
        # coning: phi = dtheta + dtheta_prev x dtheta / 12
        d0, d1, d2 = solve_cross(t0 / 12.0, t1 / 12.0, t2 / 12.0, phi0, phi1, phi2)
        # rotation and sculling: u = dv + (dtheta / 2 + dtheta_prev / 12) x dv + dv_prev x dtheta / 12
        r0 = x - (u1 * d2 - u2 * d1) / 12.0
        r1 = y - (u2 * d0 - u0 * d2) / 12.0
        r2 = z - (u0 * d1 - u1 * d0) / 12.0
        e0, e1, e2 = solve_cross(0.5 * d0 + t0 / 12.0, 0.5 * d1 + t1 / 12.0, 0.5 * d2 + t2 / 12.0, r0, r1, r2)
        increments[k, 0], increments[k, 1], increments[k, 2] = d0, d1, d2
        increments[k, 3], increments[k, 4], increments[k, 5] = e0, e1, e2
        nav_increments[k, 0], nav_increments[k, 1], nav_increments[k, 2] = zn, ze, zd
        nav_increments[k, 3], nav_increments[k, 4], nav_increments[k, 5] = fn, fe, fd
        lat, lon, h, s, c, r_n, r_e, inv_sqrt_w, inv_rn_h, inv_re_h, inv_c = position_step(
            lat, lon, h, s, c, r_n, inv_re_h, inv_c, vn, ve, vd, vn1, ve1, vd1, dt, 0.0, False)
        positions[k, 0], positions[k, 1], positions[k, 2] = lat, lon, h
        vn_prev, ve_prev, vd_prev = vn, ve, vd
        t0, t1, t2 = d0, d1, d2
        u0, u1, u2 = e0, e1, e2
    n = increments.shape[0]
    state[LAT], state[LON], state[HGT], state[SIN_LAT], state[COS_LAT] = lat, lon, h, s, c
    state[VEL], state[VEL + 1], state[VEL + 2] = velocities[n, 0], velocities[n, 1], velocities[n, 2]
    state[VEL_PREV], state[VEL_PREV + 1], state[VEL_PREV + 2] = vn_prev, ve_prev, vd_prev
    for i in range(4):
        state[QUAT + i] = quaternions[n, i]
    state[DTHETA_PREV], state[DTHETA_PREV + 1], state[DTHETA_PREV + 2] = t0, t1, t2
    state[DV_PREV], state[DV_PREV + 1], state[DV_PREV + 2] = u0, u1, u2


@jit
def store_output(out, row, lat, lon, h, vn, ve, vd, q0, q1, q2, q3):
    out[row, 0], out[row, 1], out[row, 2] = lat, lon, h
    out[row, 3], out[row, 4], out[row, 5] = vn, ve, vd
    out[row, 6], out[row, 7], out[row, 8], out[row, 9] = q0, q1, q2, q3


@jit
def sensor_row(row):
    """The 12 values of a sensor-error row as a tuple (matrix row-major, then bias), for register use."""
    return (row[0], row[1], row[2], row[3], row[4], row[5], row[6], row[7], row[8], row[9], row[10], row[11])


@jit
def apply_sensor(m, x, y, z, dt):
    """(I + S + M) v + b dt for one sensor triad, ``m`` from :func:`sensor_row`."""
    return (m[0] * x + m[1] * y + m[2] * z + m[9] * dt,
            m[3] * x + m[4] * y + m[5] * z + m[10] * dt,
            m[6] * x + m[7] * y + m[8] * z + m[11] * dt)
