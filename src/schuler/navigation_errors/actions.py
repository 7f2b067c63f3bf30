"""``schuler errors vertical`` and ``schuler errors period``: the vertical channel and the effective period.

* ``vertical``: the pure-inertial altitude error of Bollay's Problem 4
  (delta_h'' - 2 omega_s^2 delta_h = b, :mod:`~schuler.navigation_errors.vertical_channel`)
  beside the standard second- and third-order baro-aided loops that hold it
  (beyond the source). Altitude errors are indicated - true, positive up; the
  vertical accelerometer's bias is measured - true along the up axis (Bollay's z),
  so Problem 4's accelerometer, reading k g0 low, has ``accel_bias_up = -k g0``.
* ``period``: T = 2 pi sqrt(R / g_eff) under a vertical thrust of n times the
  weight and in level flight at speed V (Bollay's footnote,
  :mod:`~schuler.navigation_errors.effective_period`).

References
----------
Bollay, W., "A Critical Meeting on the Development of Inertial Navigation - Related
to 'The Story of 84 Minutes'", Engineering Case Library, Stanford University, 1966
(:data:`schuler.references.BOLLAY_1966`).
"""

from __future__ import annotations

import sys
import warnings

import numpy as np

from schuler.core.geometry import grid_points, time_grid
from schuler.core.lti import simulate
from schuler.exceptions import InvalidParameter
from schuler.memory import require
from schuler.navigation_errors.effective_period import (
    effective_schuler_period,
    flight_gravity,
    orbital_speed,
    thrust_gravity,
)
from schuler.navigation_errors.inputs import (
    EARTH_PARAMETERS,
    GRID_NAMES,
    check_vertical_growth,
    earth_constants,
)
from schuler.navigation_errors.results import PeriodResult, VerticalChannelResult
from schuler.navigation_errors.vertical_channel import (
    BaroLoopGains,
    aided_steady_state_error,
    baro_aided_model,
    check_stable,
    critically_damped_gains,
    hover_altitude_error,
    unaided_model,
)
from schuler.params import Parameter, ParameterSet

VERTICAL_BYTES_PER_POINT = 6 * 8 + 2 * 25 * 8 + 6 * 8
"""Memory per output point of ``vertical``: the grid and three histories, the engine's transition matrices, states."""

VERTICAL_PARAMETERS = ParameterSet((
    Parameter("accel_bias_up", "g", -1e-4,
              "Bias of the vertical accelerometer, measured - true along up (Problem 4: reads 1e-4 g low).",
              minimum=-0.1, maximum=0.1),
    Parameter("duration", "s", 5060.0, "Length of the run (the pure-inertial error grows as cosh(sqrt(2) omega_s t)).",
              minimum=0.0, exclusive_minimum=True, maximum=1e5),
    Parameter("output_step", "s", None, "Output step (not set: duration / 1000).", minimum=0.0,
              exclusive_minimum=True),
    Parameter("order", "", 3, "Order of the baro-aided loop.", minimum=2, maximum=3, kind="integer"),
    Parameter("time_constant", "s", 100.0, "Loop time constant tau: critically damped gains, all poles at -1/tau "
              "(gains not given explicitly).", minimum=1.0, maximum=1e6),
    Parameter("k1", "1/s", None, "Altitude feedback gain (not set: from tau).", minimum=0.0, exclusive_minimum=True,
              maximum=1e3),
    Parameter("k2", "1/s^2", None, "Velocity feedback gain (not set: from tau).", minimum=0.0,
              exclusive_minimum=True, maximum=1e3),
    Parameter("k3", "1/s^3", None, "Accelerometer-bias estimator gain, third order only (not set: from tau).",
              minimum=0.0, exclusive_minimum=True, maximum=1e3),
    Parameter("baro_bias", "m", 0.0, "Constant error of the barometric altitude, measured - true.", minimum=-1e4,
              maximum=1e4),
    *EARTH_PARAMETERS,
), owner="errors vertical", exclusive=(("time_constant", "k1"), ("time_constant", "k2"), ("time_constant", "k3")))
"""Options of ``schuler errors vertical``: an explicit gain and an explicit tau exclude each other."""

PERIOD_PARAMETERS = ParameterSet((
    Parameter("thrust_factor", "", 9.0, "Vertical thrust n in units of the weight (g_eff = n g).", minimum=0.0,
              exclusive_minimum=True, maximum=1e6),
    Parameter("speed", "m/s", 0.0, "Level-flight speed V (g_eff = g - V^2/r).", minimum=0.0, maximum=1e5),
    Parameter("path_radius", "km", None, "Radius of curvature r of the flight path (not set: R).", minimum=1e-3,
              maximum=1e6),
    *EARTH_PARAMETERS,
), owner="errors period")
"""Options of ``schuler errors period``."""


def altitude_errors(time, gains: BaroLoopGains, accel_bias_up: float, baro_bias: float, radius: float,
                    gravity: float):
    """Pure-inertial and baro-aided altitude errors on a time grid, m (indicated - true, up).

    Parameters
    ----------
    time : ndarray
        Output times from 0, s.
    gains : BaroLoopGains
        The aided loop's gains (checked stable by the caller).
    accel_bias_up : float
        b, m/s^2 (measured - true, up).
    baro_bias : float
        delta_h_baro, m.
    radius, gravity : float
        R (m), g0 (m/s^2).

    Returns
    -------
    unaided, aided : ndarray
        Simulations of Bollay's Problem 4 equation and of the aided loop.
    """
    unaided = simulate(unaided_model(radius, gravity), time, inputs=[accel_bias_up])["altitude_error"]
    aided = simulate(baro_aided_model(gains, radius, gravity), time,
                     inputs=[accel_bias_up, baro_bias])["altitude_error"]
    return unaided, aided


def loop_gains(order: int, time_constant: float, k1: float | None, k2: float | None, k3: float | None,
               radius: float, gravity: float) -> BaroLoopGains:
    """The aided loop's gains: explicit ones where given, the critically damped ones of tau otherwise.

    Parameters
    ----------
    order : {2, 3}
        Order of the baro-aided loop.
    time_constant : float
        tau, s (> 0): the default gains put every pole at -1/tau.
    k1 : float, optional
        Altitude feedback, 1/s (None: the critically damped one).
    k2 : float, optional
        Velocity feedback, 1/s^2 (None: the critically damped one).
    k3 : float, optional
        Accelerometer-error estimator gain, 1/s^3, third order only (None: the critically damped one).
    radius : float
        R, m.
    gravity : float
        g0, m/s^2.

    Returns
    -------
    BaroLoopGains
        k1 (1/s), k2 (1/s^2), k3 (1/s^3; 0 for the second order) and the order.

    Raises
    ------
    InvalidParameter
        ``k3`` given for the second order, or gains that leave the loop unstable.
    """
    if order == 2 and k3 is not None:
        raise InvalidParameter("k3", "applies to the third-order loop only (order 3)")
    default = critically_damped_gains(order, time_constant, radius, gravity)
    gains = BaroLoopGains(default.k1 if k1 is None else k1, default.k2 if k2 is None else k2,
                          (default.k3 if k3 is None else k3) if order == 3 else 0.0, order)
    check_stable(gains, radius, gravity)
    return gains


def vertical(*, accel_bias_up: float, duration: float, output_step: float | None, order: int, time_constant: float,
             k1: float | None, k2: float | None, k3: float | None, baro_bias: float, earth: str,
             radius: float | None, gravity: float | None) -> VerticalChannelResult:
    """Pure-inertial vertical channel (Bollay 1966, Problem 4) vs the baro-aided loop, SI in and out.

    Takes every option of :data:`VERTICAL_PARAMETERS` (build them with its
    ``case()``, which fills the defaults and refuses unknown names).

    Parameters
    ----------
    accel_bias_up : float
        b, m/s^2 (measured - true along up; Problem 4: -1e-4 g0).
    duration : float
        s.
    output_step : float, optional
        s (default duration / 1000).
    order : {2, 3}
        Order of the baro-aided loop.
    time_constant : float
        tau, s: gains put all poles at -1/tau unless k1, k2, k3 are given.
    k1, k2, k3 : float, optional
        Explicit gains (1/s, 1/s^2, 1/s^3); k3 for the third order only.
    baro_bias : float
        Constant barometric altitude error, m (measured - true).
    earth : str
        Preset of the Earth constants (:func:`~schuler.navigation_errors.inputs.earth_constants`).
    radius : float, optional
        R overriding the preset's, m.
    gravity : float, optional
        g0 overriding the preset's, m/s^2.

    Returns
    -------
    VerticalChannelResult
        The unaided and aided altitude errors (m) over time (s), the closed form beside them, and the loop's
        gains and poles.

    Examples
    --------
    >>> r = vertical(**VERTICAL_PARAMETERS.case(earth="bollay", order=2))
    >>> round(-r.final_closed_form_m / 1609.344, 1)   # -1e-4 standard g for one period; Bollay's k g_eff: 715.4
    714.0
    """
    R, g = earth_constants(earth, radius, gravity)
    check_vertical_growth(duration, R, g)
    gains = loop_gains(order, time_constant, k1, k2, k3, R, g)
    step = duration / 1000.0 if output_step is None else output_step
    require(grid_points(duration, step, names=GRID_NAMES) * VERTICAL_BYTES_PER_POINT, "this run",
            "`duration` or `output_step`")
    t = time_grid(duration, step, names=GRID_NAMES, max_points=sys.maxsize)  # sized by require above
    unaided, aided = altitude_errors(t, gains, accel_bias_up, baro_bias, R, g)
    closed = hover_altitude_error(t, accel_bias_up, R, g)
    poles = baro_aided_model(gains, R, g).eigenvalues()
    return VerticalChannelResult(
        order=order, k1_per_s=gains.k1, k2_per_s2=gains.k2, k3_per_s3=gains.k3, accel_bias_up_m_s2=accel_bias_up,
        baro_bias_m=baro_bias, duration_s=float(t[-1]), final_unaided_m=float(unaided[-1]),
        final_closed_form_m=float(closed[-1]), final_aided_m=float(aided[-1]),
        aided_steady_state_m=float(aided_steady_state_error(gains, accel_bias_up, baro_bias, R, g)),
        poles_real_per_s=poles.real, poles_imag_rad_s=poles.imag, t_s=t, unaided_m=unaided, closed_form_m=closed,
        aided_m=aided,
    )


def period(*, thrust_factor: float, speed: float, path_radius: float | None, earth: str, radius: float | None,
           gravity: float | None) -> PeriodResult:
    """Effective Schuler periods (Bollay 1966, footnote): vertical thrust n g and level flight at V.

    Takes every option of :data:`PERIOD_PARAMETERS` (build them with its ``case()``).

    Warns (:class:`UserWarning`) at or above the orbital speed, where the loop
    has no restoring force and the period is infinite.

    Parameters
    ----------
    thrust_factor : float
        n (> 0), vertical thrust in units of g: plain number.
    speed : float
        V, m/s (>= 0).
    path_radius : float, optional
        r, m (default R).
    earth : str
        Preset of the Earth constants (:func:`~schuler.navigation_errors.inputs.earth_constants`).
    radius : float, optional
        R overriding the preset's, m.
    gravity : float, optional
        g0 overriding the preset's, m/s^2.

    Returns
    -------
    PeriodResult
        R (m), g (m/s^2), the nominal Schuler period, the period under thrust n g and in level flight at V
        (all s), the orbital speed (m/s) and the flight's effective gravity (m/s^2).

    Examples
    --------
    >>> r = period(**PERIOD_PARAMETERS.case(thrust_factor=9.0))
    >>> round(r.nominal_period_s / r.thrust_period_s, 12)
    3.0
    """
    R, g = earth_constants(earth, radius, gravity)
    r = R if path_radius is None else path_radius
    g_flight = float(flight_gravity(g, speed, r))
    circular = float(orbital_speed(g, r))
    if speed >= circular:
        warnings.warn(f"speed {speed:g} m/s is at or above the orbital speed {circular:.0f} m/s: no restoring "
                      "force, the period is infinite", UserWarning, stacklevel=2)
    return PeriodResult(
        radius_m=R, gravity_m_s2=g, nominal_period_s=float(effective_schuler_period(R, g)),
        thrust_factor=thrust_factor,
        thrust_period_s=float(effective_schuler_period(R, thrust_gravity(thrust_factor, g))),
        speed_m_s=speed, path_radius_m=r, orbital_speed_m_s=circular,
        flight_effective_gravity_m_s2=g_flight,
        flight_period_s=float(np.asarray(effective_schuler_period(R, g_flight))),
    )
