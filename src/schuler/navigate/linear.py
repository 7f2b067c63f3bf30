"""The WGS-84 linear error model beside the nonlinear INS: the same run, to first order.

:func:`linear_reference` propagates :mod:`schuler.navigation_errors.three_d`'s
psi-angle model along the run's truth (coefficients = the truth's means over
each output step, exact within it) from the run's own initial errors and
biases, and returns both in psi-angle variables. Converting the nonlinear
errors to those variables (spec 06; Benson 1975):

* delta_r = (north, east, -height error), m;
* delta_theta = (delta_r_E / (R_E + h), -delta_r_N / (R_N + h), -delta_r_E tan L / (R_E + h)),
  the computed NED frame's turn from the true one;
* delta_v = v_computed - v_true + delta_theta x v_true (the true velocity
  resolved in the computed frame);
* psi = phi - delta_theta, with phi the attitude error rotation vector.

The difference of the two is of second order in the errors: halving every
error quarters it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from schuler.core.earth import EARTH_RATE, radii_of_curvature
from schuler.exceptions import InvalidParameter
from schuler.navigate.errors import ConstantSensorErrors
from schuler.navigate.results import NavigationResult
from schuler.navigation_errors.three_d import propagate_along


@dataclass(frozen=True)
class LinearComparison:
    """Nonlinear and linear errors of one run in psi-angle states, shape ([N,] n_out, n).

    Attributes
    ----------
    t_s : ndarray
    states : tuple of str
        State names as :func:`schuler.navigation_errors.three_d.psi_angle_model`.
    nonlinear, linear : ndarray
    """

    t_s: np.ndarray
    states: tuple[str, ...]
    nonlinear: np.ndarray
    linear: np.ndarray

    def residual(self) -> dict[str, float]:
        """Largest |nonlinear - linear| per state."""
        difference = np.abs(self.nonlinear - self.linear).reshape(-1, len(self.states)).max(axis=0)
        return dict(zip(self.states, difference.tolist()))


def psi_states(result: NavigationResult) -> np.ndarray:
    """A run's errors as psi-angle states (conversion in the module docstring), shape ([N,] n_out, 7 or 9).

    Parameters
    ----------
    result : NavigationResult
        A run of :func:`~schuler.navigate.mechanization.navigate` (its truth gives L, h and v).

    Returns
    -------
    ndarray
        Per output time: delta_r north, east (and down with the vertical channel
        ``free``), m; delta_v north, east (and down), m/s; psi north, east, down, rad.
    """
    truth = result.truth
    L, h, v = truth.latitude_rad, truth.height_m, truth.velocity_ned_m_s
    R_N, R_E = radii_of_curvature(L)
    north, east = result.position_error_north_m, result.position_error_east_m
    down = -result.height_error_m
    d_theta = np.stack([east / (R_E + h), -north / (R_N + h), -east * np.tan(L) / (R_E + h)], axis=-1)
    dv = np.stack([result.velocity_error_north_m_s, result.velocity_error_east_m_s,
                   result.velocity_error_down_m_s], axis=-1) + np.cross(d_theta, v)
    psi = result.attitude_error_rad - d_theta
    if result.vertical_channel == "free":
        return np.concatenate([np.stack([north, east, down], axis=-1), dv, psi], axis=-1)
    return np.concatenate([np.stack([north, east], axis=-1), dv[..., :2], psi], axis=-1)


def linear_reference(result: NavigationResult, sensor_errors: ConstantSensorErrors | None = None,
                     earth_rate: float = EARTH_RATE) -> LinearComparison:
    """Propagate the WGS-84 psi-angle model beside a nonlinear run (first-order check).

    Parameters
    ----------
    result : NavigationResult
        From :func:`~schuler.navigate.mechanization.navigate` with
        ``record_interval_means=True`` and vertical channel ``off`` or ``free``.
    sensor_errors : ConstantSensorErrors, optional
        The run's sensor errors; the linear model takes the biases
        (nabla = C_b^n b_a, epsilon = -C_b^n b_g with the step's mean C_b^n; the
        platform's sensors sit in NED).
    earth_rate : float
        The run's Earth rate, rad/s.

    Returns
    -------
    LinearComparison
    """
    means = result.truth.interval_means
    if means is None:
        raise InvalidParameter("result", "run navigate() with record_interval_means=True")
    if result.vertical_channel == "baro":
        raise InvalidParameter("vertical_channel", "the linear model has no baro loop: use 'off' or 'free'")
    nonlinear = psi_states(result)
    sensor_errors = sensor_errors or ConstantSensorErrors()
    K = result.t_s.size - 1
    if result.mode == "platform":
        rotation = np.broadcast_to(np.eye(3), (K, 3, 3))
    else:
        rotation = means["body_to_ned"]
    accel = np.asarray(sensor_errors.accel_bias)
    gyro = np.asarray(sensor_errors.gyro_bias)
    nabla = np.einsum("kij,...j->...ki", rotation, accel)
    epsilon = -np.einsum("kij,...j->...ki", rotation, gyro)
    inputs = np.concatenate([nabla, epsilon], axis=-1)
    if inputs.ndim == 3 and nonlinear.ndim == 2:
        raise InvalidParameter("sensor_errors", "per-member sensor errors need a batch run")
    linear = propagate_along(result.t_s, means["latitude_rad"], means["height_m"], means["velocity_ned_m_s"],
                             means["specific_force_ned_m_s2"], nonlinear[..., 0, :], inputs, earth_rate,
                             vertical_channel=result.vertical_channel == "free")
    names = (("position_error_north", "position_error_east")
             + (("position_error_down",) if result.vertical_channel == "free" else ())
             + ("velocity_error_north", "velocity_error_east")
             + (("velocity_error_down",) if result.vertical_channel == "free" else ())
             + ("psi_north", "psi_east", "psi_down"))
    return LinearComparison(result.t_s, names, nonlinear, linear)
