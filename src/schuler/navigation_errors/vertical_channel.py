"""The vertical channel: divergent pure-inertial altitude, and the baro-aided loop that tames it.

Bollay (1966), Problem 4: gravity falls off with height, g(h) ~ g0 (1 - 2 h / R),
so an altitude error delta_h makes the computed gravity wrong by
-2 (g0/R) delta_h, which pushes the error further:

    delta_h'' - 2 omega_s^2 delta_h = b,    omega_s^2 = g0 / R,

with b the accelerometer error (m/s^2, positive when it reads high; the source's
hovering pilot has b = -k g0). With delta_h(0) = delta_h'(0) = 0 the solution is

    delta_h = (b / (2 omega_s^2)) (cosh(sqrt(2) omega_s t) - 1).

The source prints (k R / 2) sinh(sqrt(2) omega_s t). It is zero at t = 0, but
its initial rate is k R omega_s / sqrt(2) instead of 0 (it solves the unforced
equation from that rate), so it breaks the condition delta_h'(0) = 0; with
b = -k g0 the two agree only for large t.

Frame and signs: delta_h is the indicated minus the true altitude, m, positive
up. The baro-aided loop (beyond the source; the standard second- and
third-order loops) feeds the difference between indicated and barometric
altitude, e = delta_h - delta_h_baro, back:

    delta_h' = delta_v - k1 e
    delta_v' = 2 omega_s^2 delta_h + b - k2 e - b_hat     (third order only: - b_hat)
    b_hat'   = k3 e                                        (third order only)

with characteristic polynomial s^2 + k1 s + (k2 - 2 omega_s^2) (second order)
or s^3 + k1 s^2 + (k2 - 2 omega_s^2) s + k3 (third order).

Examples
--------
>>> from schuler.core.earth import BOLLAY, STATUTE_MILE
>>> h = hover_altitude_error(BOLLAY.schuler_period, -1e-4 * BOLLAY.effective_gravity,
...                          BOLLAY.radius, BOLLAY.effective_gravity)
>>> round(float(-h) / STATUTE_MILE, 1)
715.4
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from schuler.core.lti import StateSpace
from schuler.exceptions import InvalidParameter


def _positive(value, name: str) -> float:
    number = float(value)
    if not np.isfinite(number) or number <= 0:
        raise InvalidParameter(name, f"must be finite and > 0, got {value!r}")
    return number


def hover_altitude_error(time, accelerometer_error, radius, gravity):
    """Pure-inertial altitude error delta_h(t) from a constant accelerometer error, m.

    Parameters
    ----------
    time : float or ndarray
        t, s (>= 0).
    accelerometer_error : float or ndarray
        b, m/s^2 (positive when the accelerometer reads high; Bollay (1966) Problem 4
        has b = -k g0).
    radius : float
        R, m (> 0).
    gravity : float
        g0, m/s^2 (> 0); omega_s^2 = g0 / R.

    Returns
    -------
    ndarray
        (b / (2 omega_s^2)) (cosh(sqrt(2) omega_s t) - 1), m: the solution of
        Bollay (1966) Problem 4's delta_h'' - 2 omega_s^2 delta_h = b from rest.

    Examples
    --------
    >>> round(float(hover_altitude_error(1.0, 1.0, 6.371e6, 9.80665)), 6)
    0.5
    """
    omega_squared = _positive(gravity, "gravity") / _positive(radius, "radius")
    t = np.asarray(time, dtype=float)
    b = np.asarray(accelerometer_error, dtype=float)
    # cosh x - 1 = 2 sinh^2(x/2): no cancellation at small t
    return b / omega_squared * np.sinh(np.sqrt(2.0 * omega_squared) * t / 2.0) ** 2


def printed_hover_expression(time, k, radius, gravity):
    """The source's printed hover solution (k R / 2) sinh(sqrt(2) omega_s t), m.

    Kept to show the erratum: it is zero at t = 0, but its initial rate is
    k R omega_s / sqrt(2) instead of 0 although the hovering vehicle starts at
    rest on the right height (the correct solution is
    (k R / 2)(cosh(sqrt(2) omega_s t) - 1)). ``k`` is the accelerometer error in
    units of g0 (dimensionless); other parameters as in :func:`hover_altitude_error`.

    Parameters
    ----------
    time : float or ndarray
        t, s (>= 0).
    k : float or ndarray
        Accelerometer error in units of g0, dimensionless, positive when it reads low (b = -k g0; Bollay (1966)
        Problem 4: 1e-4).
    radius : float
        R, m (> 0).
    gravity : float
        g0, m/s^2 (> 0); omega_s^2 = g0 / R.

    Returns
    -------
    ndarray
        (k R / 2) sinh(sqrt(2) omega_s t), m, as printed: how far the indicated height falls below the true
        one (positive for k > 0).

    Examples
    --------
    >>> float(printed_hover_expression(0.0, 1e-4, 6.371e6, 9.80665))
    0.0
    """
    omega = np.sqrt(_positive(gravity, "gravity") / _positive(radius, "radius"))
    return k * radius / 2.0 * np.sinh(np.sqrt(2.0) * omega * np.asarray(time, dtype=float))


def unaided_model(radius: float, gravity: float) -> StateSpace:
    """State-space model of the pure-inertial vertical channel (Bollay (1966), Problem 4).

    States ``altitude_error`` delta_h (m) and ``vertical_velocity_error`` (m/s),
    input ``accelerometer_error`` b (m/s^2). Eigenvalues +/- sqrt(2) omega_s: one is
    positive, the channel diverges.

    Parameters
    ----------
    radius : float
        R, m.
    gravity : float
        g0, m/s^2.

    Examples
    --------
    >>> import numpy as np
    >>> lam = unaided_model(6.371e6, 9.80665).eigenvalues().real
    >>> bool(np.isclose(lam.max(), np.sqrt(2 * 9.80665 / 6.371e6)))
    True
    """
    omega_squared = _positive(gravity, "gravity") / _positive(radius, "radius")
    return StateSpace(
        [[0.0, 1.0], [2.0 * omega_squared, 0.0]],
        [[0.0], [1.0]],
        states=("altitude_error", "vertical_velocity_error"),
        inputs=("accelerometer_error",),
        state_units=("m", "m/s"),
    )


@dataclass(frozen=True)
class BaroLoopGains:
    """Gains of the baro-aided vertical loop.

    Attributes
    ----------
    k1 : float
        Altitude feedback, 1/s.
    k2 : float
        Velocity feedback, 1/s^2.
    k3 : float
        Accelerometer-error estimator gain, 1/s^3 (0 for the second-order loop).
    order : int
        2 or 3.
    """

    k1: float
    k2: float
    k3: float
    order: int


def critically_damped_gains(order: int, time_constant: float, radius: float, gravity: float) -> BaroLoopGains:
    """Gains that put every pole of the aided loop at -1 / tau.

    Second order: (s + p)^2 gives k1 = 2p, k2 = p^2 + 2 omega_s^2; third order:
    (s + p)^3 gives k1 = 3p, k2 = 3p^2 + 2 omega_s^2, k3 = p^3 (p = 1 / tau): the
    2 omega_s^2 in k2 cancels the gravity feedback that makes the channel unstable.

    Parameters
    ----------
    order : {2, 3}
    time_constant : float
        tau, s (> 0).
    radius, gravity : float
        R (m) and g0 (m/s^2).

    Examples
    --------
    >>> critically_damped_gains(3, 100.0, 6.371e6, 9.80665).k1
    0.03
    """
    if order not in (2, 3):
        raise InvalidParameter("order", f"must be 2 or 3, got {order!r}")
    p = 1.0 / _positive(time_constant, "time_constant")
    gravity_feedback = 2.0 * _positive(gravity, "gravity") / _positive(radius, "radius")
    if order == 2:
        return BaroLoopGains(2.0 * p, p * p + gravity_feedback, 0.0, 2)
    return BaroLoopGains(3.0 * p, 3.0 * p * p + gravity_feedback, p**3, 3)


def check_stable(gains: BaroLoopGains, radius: float, gravity: float) -> None:
    """Raise InvalidParameter unless the aided loop is asymptotically stable (Routh-Hurwitz).

    Parameters
    ----------
    gains : BaroLoopGains
        k1 (1/s), k2 (1/s^2), k3 (1/s^3) and the order.
    radius : float
        R, m.
    gravity : float
        g0, m/s^2.

    Examples
    --------
    >>> check_stable(BaroLoopGains(0.02, 1e-6, 0.0, 2), 6.371e6, 9.80665)
    Traceback (most recent call last):
    ...
    schuler.exceptions.InvalidParameter: k2: must exceed 2 g/R = 3.0785e-06 1/s^2 for a stable loop, got 1e-06
    """
    net_stiffness = gains.k2 - 2.0 * gravity / radius
    if gains.k1 <= 0:
        raise InvalidParameter("k1", f"must be > 0 for a stable loop, got {gains.k1:g}")
    if net_stiffness <= 0:
        raise InvalidParameter(
            "k2", f"must exceed 2 g/R = {2.0 * gravity / radius:.5g} 1/s^2 for a stable loop, got {gains.k2:g}"
        )
    if gains.order == 3 and not 0 < gains.k3 < gains.k1 * net_stiffness:
        raise InvalidParameter(
            "k3", f"must lie in (0, k1 (k2 - 2 g/R)) = (0, {gains.k1 * net_stiffness:.5g}) 1/s^3, got {gains.k3:g}"
        )


def baro_aided_model(gains: BaroLoopGains, radius: float, gravity: float) -> StateSpace:
    """State-space model of the second- or third-order baro-aided vertical loop.

    States ``altitude_error`` (m), ``vertical_velocity_error`` (m/s) and, third
    order, ``accelerometer_error_estimate`` b_hat (m/s^2). Inputs
    ``accelerometer_error`` b (m/s^2) and ``baro_altitude_error`` delta_h_baro (m).
    Equations in the module docstring.

    Parameters
    ----------
    gains : BaroLoopGains
        k1 (1/s), k2 (1/s^2), k3 (1/s^3) and the order.
    radius : float
        R, m.
    gravity : float
        g0, m/s^2.

    Examples
    --------
    >>> gains = critically_damped_gains(2, 50.0, 6.371e6, 9.80665)
    >>> bool(np.allclose(baro_aided_model(gains, 6.371e6, 9.80665).eigenvalues(), -0.02))
    True
    """
    omega_squared = _positive(gravity, "gravity") / _positive(radius, "radius")
    k1, k2, k3 = gains.k1, gains.k2, gains.k3
    states: tuple[str, ...]
    units: tuple[str, ...]
    if gains.order == 2:
        A = [[-k1, 1.0], [2.0 * omega_squared - k2, 0.0]]
        B = [[0.0, k1], [1.0, k2]]
        states = ("altitude_error", "vertical_velocity_error")
        units = ("m", "m/s")
    else:
        A = [[-k1, 1.0, 0.0], [2.0 * omega_squared - k2, 0.0, -1.0], [k3, 0.0, 0.0]]
        B = [[0.0, k1], [1.0, k2], [0.0, -k3]]
        states = ("altitude_error", "vertical_velocity_error", "accelerometer_error_estimate")
        units = ("m", "m/s", "m/s^2")
    return StateSpace(A, B, states=states, inputs=("accelerometer_error", "baro_altitude_error"), state_units=units)


def aided_steady_state_error(gains: BaroLoopGains, accelerometer_error, baro_error, radius, gravity):
    """Steady altitude error of the aided loop for constant b and delta_h_baro, m.

    Second order: (b + k2 delta_h_baro) / (k2 - 2 omega_s^2): a constant
    accelerometer error leaves a standing offset. Third order: delta_h_baro (the
    integrator estimates b, only the barometer's own error remains).

    Parameters
    ----------
    gains : BaroLoopGains
        The loop's gains k1 (1/s), k2 (1/s^2), k3 (1/s^3) and order.
    accelerometer_error : float or ndarray
        b, m/s^2 (measured - true, positive up).
    baro_error : float or ndarray
        delta_h_baro, constant barometric altitude error, m (measured - true).
    radius : float
        R, m.
    gravity : float
        g0, m/s^2; omega_s^2 = g0 / R.

    Returns
    -------
    ndarray
        The standing altitude error, m (indicated - true, positive up), in the broadcast shape of the errors.

    Examples
    --------
    >>> gains = critically_damped_gains(2, 100.0, 6.371e6, 9.80665)
    >>> round(float(aided_steady_state_error(gains, 1e-3, 0.0, 6.371e6, 9.80665)), 6)
    10.0
    """
    if gains.order == 3:
        return np.asarray(baro_error, dtype=float) + 0.0 * np.asarray(accelerometer_error, dtype=float)
    net = gains.k2 - 2.0 * gravity / radius
    return (np.asarray(accelerometer_error, dtype=float) + gains.k2 * np.asarray(baro_error, dtype=float)) / net
