"""Azimuth motion of a two-degree ground gyrocompass while its rotor runs down.

The sensitive element turns about a vertical suspension axis; ``alpha`` is the
angle of the rotor axis from north, positive in the sense in which the Earth's
horizontal rate ``Omega_h`` precesses it back towards the meridian (Fedorov et al. (2020),
eq. (1)). With the rotor's angular momentum decaying as H = H_m exp(-lambda t)
(eq. (2)) and B = H_m Omega_h / J (eq. (3)) the motion obeys (eq. (4))

    alpha'' + B exp(-lambda t) alpha = m,

where m = M / J is a constant harmful torque M about the suspension axis per unit
moment of inertia (zero in the source; the abstract names it as identifiable).

The substitution z = (2 / lambda) sqrt(B exp(-lambda t)) (eq. (5)) turns the
homogeneous equation into Bessel's equation of order zero (eq. (6)), so the motion
is a combination of J0(z) and Y0(z) (eq. (7)); with the initial angle and angular
rate at t = 0 it is eq. (9) written in time::

    alpha(t) = alpha0 u1(t) + alpha0_dot u2(t) + m u3(t),

    u1 = (pi z0 / 2) [J1(z0) Y0(z) - J0(z) Y1(z0)]            (eq. (9), first term)
    u2 = -(pi / lambda) [J0(z0) Y0(z) - J0(z) Y0(z0)]         (eq. (9), second term,
                                                              with d/dz = -(2 / (lambda z)) d/dt)
    u3 = (pi / lambda) [J0(z) I_Y(t) - Y0(z) I_J(t)]           (variation of parameters)

The Wronskian of J0(z(t)) and Y0(z(t)) in t is the constant -lambda / pi, so the
particular solution with zero initial state needs only I_J = int_0^t J0(z(s)) ds
and I_Y = int_0^t Y0(z(s)) ds = (2 / lambda) int_z^z0 Y0(x) / x dx. These integrals
have no elementary form, but scipy's ``it2j0y0`` tabulates int_0^x (1 - J0)/t dt
and int_x^inf Y0/t dt (Zhang and Jin's algorithms), which give them without
quadrature; the tests check them against adaptive quadrature and against the
numerical simulator :func:`simulate`.

Only B (not H_m, J, Omega_h separately) and lambda enter the motion: "identifying
H_m" means identifying B with J and Omega_h known.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.special import it2j0y0, j0, j1, y0, y1

from schuler.exceptions import InvalidParameter, SimulationError

# The source's machine experiment (Fedorov et al. (2020), text before Table 1).
SOURCE_INERTIA = 1.1607e-3  # J, kg m^2
SOURCE_OMEGA_H = 3.65e-5  # Omega_h, rad/s
SOURCE_HM = 0.432  # H_m, N m s
SOURCE_LAMBDA = 2.15e-3  # lambda, 1/s
SOURCE_ALPHA0 = 3.69 * math.pi / 540.0  # alpha0, rad
SOURCE_ALPHA0_DOT = 4.08e-4  # alpha0_dot, rad/s
SOURCE_DURATION = 200.0  # observation 0..200 s
SOURCE_STEP = 1.0  # every 1 s


def check_decay_rate(decay_rate, name: str = "lambda") -> None:
    """Raise InvalidParameter unless every decay rate lambda is finite and > 0.

    Parameters
    ----------
    decay_rate : float or ndarray
        lambda, 1/s.
    name : str
        Name used in the error message.
    """
    if isinstance(decay_rate, float) and 0.0 < decay_rate < math.inf:
        return  # a valid scalar, without numpy's per-call cost (checked once per fit)
    values = np.asarray(decay_rate, dtype=float)
    if not np.all(np.isfinite(values)) or np.any(values <= 0.0):
        raise InvalidParameter(name, f"{values.ravel()[0]:g} 1/s: the rotor's decay rate must be > 0")


def check_positive(value, name: str, unit: str) -> None:
    """Raise InvalidParameter unless every value is finite and > 0.

    Parameters
    ----------
    value : float or ndarray
        The values, in ``unit``.
    name : str
        Name used in the error message.
    unit : str
        Their unit, for the message.
    """
    if isinstance(value, float) and 0.0 < value < math.inf:
        return  # a valid scalar, without numpy's per-call cost
    values = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(values)) or np.any(values <= 0.0):
        bad = values.ravel()[~(np.isfinite(values.ravel()) & (values.ravel() > 0))][0]
        raise InvalidParameter(name, f"{bad:g} {unit}: must be > 0")


def directive_coefficient(hm, omega_h, inertia):
    """B = H_m Omega_h / J (Fedorov et al. (2020), eq. (3)), 1/s^2.

    Parameters
    ----------
    hm : float or ndarray
        Initial rotor angular momentum H_m, N m s.
    omega_h : float or ndarray
        Horizontal Earth rate Omega_h, rad/s (from the latitude:
        :func:`~schuler.core.geometry.horizontal_earth_rate`).
    inertia : float or ndarray
        Moment of inertia J of the sensitive element about the suspension axis, kg m^2.

    Examples
    --------
    >>> round(directive_coefficient(SOURCE_HM, SOURCE_OMEGA_H, SOURCE_INERTIA), 8)
    0.01358491
    """
    check_positive(hm, "Hm", "N m s")
    check_positive(omega_h, "omega_h", "rad/s")
    check_positive(inertia, "inertia", "kg m^2")
    coefficient = np.asarray(hm, dtype=float) * np.asarray(omega_h) / np.asarray(inertia)
    return float(coefficient) if coefficient.ndim == 0 else coefficient


def bessel_argument(time, decay_rate, coefficient):
    """z(t) = (2 / lambda) sqrt(B exp(-lambda t)) (Fedorov et al. (2020), eq. (5)) and z0 = z(0).

    Broadcasts ``time`` against ``decay_rate`` and ``coefficient``.

    Parameters
    ----------
    time : float or ndarray
        Time since release, s.
    decay_rate : float or ndarray
        lambda, 1/s.
    coefficient : float or ndarray
        B = H_m Omega_h / J, 1/s^2.

    """
    z0 = 2.0 / decay_rate * np.sqrt(coefficient)
    return z0 * np.exp(-0.5 * decay_rate * time), z0


MAX_BESSEL_ARGUMENT = 5e6
"""Largest z0 = 2 sqrt(B) / lambda at which the closed form (9) holds 1e-9 of the motion.

A Bessel function of a large argument x carries the phase x, which a double holds
to about eps x rad; against the numerical integration of (4), the closed form's
error grows as about 1.6e-16 z0 of the motion's amplitude (7.9e-10 at 5e6, 2.2e-9
at 1e7, measured on records of 200 to 2,000 s).
"""


def check_closed_form_reach(decay_rate, coefficient) -> None:
    """Raise InvalidParameter where lambda is so small that z0 exceeds :data:`MAX_BESSEL_ARGUMENT`.

    Parameters
    ----------
    decay_rate : float or ndarray
        lambda, the decay rate of the rotor's angular momentum during run-down, 1/s.
    coefficient : float or ndarray
        B = H_m Omega_h / J, 1/s^2.

    Examples
    --------
    >>> check_closed_form_reach(1e-9, 0.0135849)
    Traceback (most recent call last):
    ...
    schuler.exceptions.InvalidParameter: decay_rate: 1e-09 1/s: z0 = 2 sqrt(B) / lambda = 2.33e+08 is beyond
    the reach of the closed form (9) (at most 5e+06: its Bessel functions lose their phase); here lambda
    must be at least 4.66e-08 1/s
    """
    lam, b = np.broadcast_arrays(np.atleast_1d(np.asarray(decay_rate, dtype=float)),
                                 np.atleast_1d(np.asarray(coefficient, dtype=float)))
    _, z0 = bessel_argument(0.0, lam, b)
    beyond = np.flatnonzero(z0 > MAX_BESSEL_ARGUMENT)
    if beyond.size:
        k = beyond[0]
        raise InvalidParameter(
            "decay_rate",
            f"{lam.flat[k]:g} 1/s: z0 = 2 sqrt(B) / lambda = {z0.flat[k]:.3g} is beyond the reach of the "
            f"closed form (9) (at most {MAX_BESSEL_ARGUMENT:g}: its Bessel functions lose their phase); here "
            f"lambda must be at least {2.0 * math.sqrt(b.flat[k]) / MAX_BESSEL_ARGUMENT:.3g} 1/s",
        )


@dataclass(frozen=True)
class Basis:
    """Fundamental solutions of eq. (4) and their derivatives w.r.t. lambda and B.

    The arrays broadcast from ``time`` and the parameters.

    Attributes
    ----------
    angle : ndarray, shape (3, ...)
        u1 (alpha0 = 1 rad), u2 (alpha0_dot = 1 rad/s), u3 (m = 1 rad/s^2); rad per unit.
    d_decay_rate : ndarray, shape (3, ...)
        d u_k / d lambda.
    d_coefficient : ndarray, shape (3, ...)
        d u_k / d B.
    """

    angle: np.ndarray
    d_decay_rate: np.ndarray
    d_coefficient: np.ndarray


def basis(time, decay_rate, coefficient, torque: bool = True, derivatives: bool = True) -> Basis:
    """The motion's basis u1, u2, u3 in closed form (Fedorov et al. (2020), eq. (9)) with derivatives.

    Parameters
    ----------
    time : float or ndarray
        Time since release t, s (>= 0).
    decay_rate : float or ndarray
        Decay rate lambda of the rotor's angular momentum, 1/s (> 0).
    coefficient : float or ndarray
        B = H_m Omega_h / J, 1/s^2 (> 0).
    torque : bool
        Also compute u3, the response to a unit constant specific torque m (else zeros).
    derivatives : bool
        Also compute the derivatives w.r.t. lambda and B (else zeros).

    Returns
    -------
    Basis

    Notes
    -----
    The derivatives follow from J0' = -J1, Y0' = -Y1, J1' = J0 - J1/x,
    Y1' = Y0 - Y1/x, d/dx int (J0/x) = J0/x, and dz/dB = z/(2B),
    dz/dlambda = -z (1/lambda + t/2), dz0/dlambda = -z0/lambda.

    Examples
    --------
    >>> b = basis(np.array([0.0, 10.0]), SOURCE_LAMBDA, 0.0135849)
    >>> np.round(b.angle[:, 0], 12) + 0.0   # u1(0) = 1, u2(0) = 0, u3(0) = 0
    array([1., 0., 0.])
    """
    check_decay_rate(decay_rate)
    check_positive(coefficient, "B", "1/s^2")
    time = np.asarray(time, dtype=float)
    decay_rate = np.asarray(decay_rate, dtype=float)
    coefficient = np.asarray(coefficient, dtype=float)
    angle, d_lam, d_b = basis_columns(time, decay_rate, coefficient, torque, derivatives)
    shape = np.broadcast(time, decay_rate, coefficient).shape
    if not torque:
        angle.append(np.zeros(shape))
    angle = np.stack(np.broadcast_arrays(*angle))
    if not derivatives:
        zeros = np.zeros_like(angle)
        return Basis(angle, zeros, zeros)
    if not torque:
        d_lam.append(np.zeros(shape))
        d_b.append(np.zeros(shape))
    return Basis(angle, np.stack(np.broadcast_arrays(*d_lam)), np.stack(np.broadcast_arrays(*d_b)))


def basis_columns(time, decay_rate, coefficient, torque: bool, derivatives: bool):
    """The arithmetic of :func:`basis`, without its checks: lists of columns.

    For callers that evaluate the basis many times at parameters they have already
    validated (the least-squares fit's inner loop), where the checks and the
    stacking of :func:`basis` would cost more than the Bessel functions.

    Parameters
    ----------
    time : ndarray
        Time since release t, s (float array).
    decay_rate, coefficient : float or ndarray
        lambda (1/s) and B (1/s^2), both > 0 and finite (not checked).
    torque, derivatives : bool
        As in :func:`basis`.

    Returns
    -------
    angle, d_decay_rate, d_coefficient : list of ndarray
        [u1, u2] (+ [u3] with ``torque``) and their derivatives w.r.t. lambda and B
        (empty lists without ``derivatives``); arrays broadcast from the inputs
        (u1 and u2 always have the full broadcast shape).

    Examples
    --------
    >>> angle, d_lam, d_b = basis_columns(np.array([0.0, 10.0]), SOURCE_LAMBDA, 0.0135849, False, True)
    >>> len(angle), len(d_lam), float(np.round(angle[0][0], 12))
    (2, 2, 1.0)
    """
    z, z0 = bessel_argument(time, decay_rate, coefficient)
    lam = decay_rate
    j0z, y0z, j0a, y0a, j1a, y1a = j0(z), y0(z), j0(z0), y0(z0), j1(z0), y1(z0)
    c1 = j1a * y0z - j0z * y1a
    d = j0a * y0z - j0z * y0a
    u1 = 0.5 * math.pi * z0 * c1
    u2 = -math.pi / lam * d
    angle = [u1, u2]
    if torque:
        a0_, cy0 = it2j0y0(z0)
        a_, cy = it2j0y0(z)
        # int_z^z0 J0(x)/x dx = ln(z0/z) - [A(z0) - A(z)], ln(z0/z) = lambda t / 2
        p_j = 0.5 * lam * time - (a0_ - a_)
        p_y = cy - cy0  # int_z^z0 Y0(x)/x dx
        u3 = 2.0 * math.pi / lam**2 * (j0z * p_y - y0z * p_j)
        angle.append(u3)
    if not derivatives:
        return angle, [], []

    j1z, y1z = j1(z), y1(z)
    # Partial derivatives in z0 (z held) and in z (z0 held), simplified with the
    # recurrences so that c1 cancels:
    #   du1/dz0 = (pi z0 / 2) d,            du1/dz = (pi z0 / 2) e,
    #   du2/dz0 = (pi / lambda) c1,         du2/dz = -(pi / lambda) f,
    # e = J1(z) Y1(z0) - J1(z0) Y1(z), f = J1(z) Y0(z0) - J0(z0) Y1(z); then the
    # chain rule with dz0/dlambda = -z0/lambda, dz/dlambda = -g, dz0/dB = z0/(2B),
    # dz/dB = z/(2B), and the explicit du2/dlambda = (pi / lambda^2) d.
    e = j1z * y1a - j1a * y1z
    f = j1z * y0a - j0a * y1z
    g = z * (1.0 / lam + 0.5 * time)
    z0_c1 = z0 * c1
    d_lam = [
        -0.5 * math.pi * z0 * (z0 / lam * d + e * g),
        math.pi / lam**2 * (d - z0_c1) + math.pi / lam * (f * g),
    ]
    d_b = [
        0.25 * math.pi * z0 / coefficient * (z0 * d + z * e),
        0.5 * math.pi / (lam * coefficient) * (z0_c1 - z * f),
    ]
    if torque:
        k = 2.0 * math.pi / lam**2
        # p_j = int_z^z0 J0/x: d/dz0 = J0(z0)/z0, d/dz = -J0(z)/z; same for p_y with Y0,
        # so du3/dz0 = -k d / z0 and in du3/dz the J0 Y0 / z terms cancel
        du3_dz = k * (y1z * p_j - j1z * p_y)
        d_lam.append(k / lam * d - du3_dz * g - 2.0 / lam * u3)
        d_b.append((z * du3_dz - k * d) / (2.0 * coefficient))
    return angle, d_lam, d_b


def closed_form(time, alpha0, alpha0_dot, decay_rate, coefficient, specific_torque=0.0):
    """Azimuth alpha(t) in closed form (Fedorov et al. (2020), eq. (9), plus a constant torque), rad.

    Parameters
    ----------
    time : float or ndarray
        Time since release, s.
    alpha0 : float
        Initial angle of the rotor axis from north, rad.
    alpha0_dot : float
        Initial azimuth rate, rad/s.
    decay_rate : float
        lambda, 1/s.
    coefficient : float
        B = H_m Omega_h / J, 1/s^2.
    specific_torque : float
        m = M / J, the harmful torque about the suspension axis per unit inertia, rad/s^2.

    Examples
    --------
    >>> t = np.array([0.0, 50.0, 200.0])
    >>> a = closed_form(t, SOURCE_ALPHA0, SOURCE_ALPHA0_DOT, SOURCE_LAMBDA, 0.01358491)
    >>> round(float(a[0]), 10) == round(SOURCE_ALPHA0, 10)
    True
    """
    b = basis(time, decay_rate, coefficient, torque=specific_torque != 0.0, derivatives=False)
    return alpha0 * b.angle[0] + alpha0_dot * b.angle[1] + specific_torque * b.angle[2]


def simulate(time, alpha0, alpha0_dot, decay_rate, coefficient, specific_torque=0.0):
    """Integrate eqs. (1)-(2) numerically (the source's simulator), rad.

    Same parameters as :func:`closed_form`; ``time`` must be increasing from >= 0.
    The state is (alpha, alpha_dot), started at t = 0.

    Parameters
    ----------
    time : ndarray
        Time since release, s (increasing from >= 0).
    alpha0 : float
        Initial angle of the rotor axis from north, rad.
    alpha0_dot : float
        Initial azimuth rate, rad/s.
    decay_rate : float
        lambda, 1/s.
    coefficient : float
        B = H_m Omega_h / J, 1/s^2.
    specific_torque : float
        m = M / J, rad/s^2.

    Notes
    -----
    DOP853 with rtol = 1e-12 and atol = 1e-14 rad (rad/s): the angles are ~1e-2 rad,
    so the local error per step stays near 1e-14 rad, and the few hundred steps over
    a few hundred seconds keep the global error well under the 1e-9 rad to which the
    closed form is checked. The output comes from the solver's 7th-order dense
    output, accurate to the same tolerance. The equation is smooth, so no events.

    Examples
    --------
    >>> t = np.linspace(0.0, 200.0, 5)
    >>> sim = simulate(t, SOURCE_ALPHA0, SOURCE_ALPHA0_DOT, SOURCE_LAMBDA, 0.01358491)
    >>> ref = closed_form(t, SOURCE_ALPHA0, SOURCE_ALPHA0_DOT, SOURCE_LAMBDA, 0.01358491)
    >>> bool(np.max(np.abs(sim - ref)) < 1e-9)
    True
    """
    time = np.asarray(time, dtype=float)
    check_decay_rate(decay_rate)
    check_positive(coefficient, "B", "1/s^2")

    def rhs(t, state):
        return (state[1], -coefficient * math.exp(-decay_rate * t) * state[0] + specific_torque)

    solution = solve_ivp(
        rhs,
        (0.0, float(time[-1])),
        (alpha0, alpha0_dot),
        method="DOP853",
        t_eval=time,
        rtol=1e-12,
        atol=1e-14,
        # scipy's automatic first step divides by the state's size: 0/0 for a record at rest
        first_step=min(1e-3, float(time[-1])) or None,
    )
    if not solution.success:
        raise SimulationError(f"integration of eq. (4) failed: {solution.message}")
    return solution.y[0]
