"""Physical gyrocompassing of the platform, nonlinear: the KPI manual's control law (1.6) on a fixed base.

The KPI manual (Meleshko, n.d.) aligns a semi-analytic platform in azimuth by
driving it with its own accelerometers. This module simulates that platform
without linearisation: its orientation is a rotation (any size), the
accelerometers sense gravity through the true orientation, and the torquers
apply (1.6),

    omega_kx = U_xв - omega_dxв + c1 a_y,
    omega_ky = U_yв - omega_dyв - c1 a_x,
    omega_kz = U_zв - omega_dzв + c2 a_eta,   a_eta = a_y cos A - a_x sin A,

with c1 = -c_gamma / g, c2 = c_a / g, the computed Earth rate U_в at the entered
latitude phi + Delta phi, and the residual drifts Delta omega_d = estimate - true
(the platform turns at omega_k + omega_d).

Frames as in :mod:`schuler.gyrocompassing.models`: xi eta zeta = east, north,
up; x_g y_g z_g the level frame turned by the azimuth A (y_g at azimuth A,
clockwise from north); the platform xyz. Outputs: the azimuth error delta
(the azimuth of the platform's y axis minus A, clockwise positive: the
source's delta), and the level errors beta (about east) and alpha (about
north) from the platform's z axis, z_p = (sin alpha, -sin beta, ...) in
(east, north, up). To first order these are (1.17)/(1.18)'s delta, beta, alpha;
the linear models follow from this one by linearisation (tested).

References
----------
Meleshko, V. V. (compiler), "Physical gyrocompassing of a semi-analytic INS", KPI laboratory manual, n.d.,
Sec. 2: control law (1.6), models (1.17)-(1.19), steady state (1.21), transient (1.22)-(1.24).

Examples
--------
>>> from schuler.core.gyrocompass_design import loop_gains
>>> c_gamma, c_a = loop_gains(np.radians(50.0), 30.0, 0.8)
>>> run = gyrocompass_alignment(np.radians(50.0), 0.0, c_gamma, c_a, duration=1200.0,
...                             initial_azimuth_error=np.radians(1.0))
>>> bool(abs(run.azimuth_error_rad[-1]) < 1e-5)
True
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from scipy.spatial.transform import Rotation

from schuler.core.attitude import dcm_from_quaternion, quaternion_from_rotation_vector, wrap_angle
from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY
from schuler.core.gyrocompass_design import DESIGN_DAMPING, DESIGN_TIME_CONSTANT, loop_gains
from schuler.core.lti import simulate
from schuler.exceptions import InvalidParameter
from schuler.gyrocompassing.analytic import (
    band_settling_time,
    settling_time,
    steady_state,
)
from schuler.gyrocompassing.models import (
    full_mu_nu_model,
    initial_state,
    simplified_model,
)
from schuler.navigate._alignment_kernel import align
from schuler.results import Result


@dataclass
class AlignmentResult(Result):
    """Nonlinear gyrocompassing histories, shape (n_time,) or (N, n_time) for a batch.

    Angles in rad: azimuth error delta (clockwise), level errors beta (about
    east) and alpha (about north).
    """

    latitude_rad: float
    azimuth_rad: float
    c_gamma_per_s: float
    c_a_per_s: float
    t_s: np.ndarray
    azimuth_error_rad: np.ndarray
    beta_rad: np.ndarray
    alpha_rad: np.ndarray

    units: ClassVar[dict[str, str]] = {}


def _level_to_enu(azimuth) -> np.ndarray:
    """C_g^enu: columns x_g = (cos A, -sin A, 0), y_g = (sin A, cos A, 0), z_g = up."""
    c, s = np.cos(azimuth), np.sin(azimuth)
    zero, one = np.zeros_like(c), np.ones_like(c)
    return np.stack([np.stack([c, s, zero], -1), np.stack([-s, c, zero], -1), np.stack([zero, zero, one], -1)], -2)


def _quaternion_from_matrix(C: np.ndarray) -> np.ndarray:
    """Unit quaternions (scalar first) of rotation matrices (N, 3, 3)."""
    xyzw = Rotation.from_matrix(C).as_quat()
    return np.concatenate([xyzw[:, 3:], xyzw[:, :3]], axis=1)


def gyrocompass_alignment(latitude: float, azimuth: float, c_gamma: float, c_a: float, *, duration: float,
                          time_step: float = 0.1, output_step: float = 1.0, initial_azimuth_error=0.0,
                          initial_beta=0.0, initial_alpha=0.0, drift_x=0.0, drift_y=0.0, drift_z=0.0,
                          latitude_error=0.0, accel_error_x=0.0, accel_error_y=0.0, earth_rate: float = EARTH_RATE,
                          gravity: float = STANDARD_GRAVITY) -> AlignmentResult:
    """Simulate the nonlinear platform under the control law (1.6) on a fixed base.

    Parameters
    ----------
    latitude : float
        phi, rad (|phi| < 90 deg: at the poles there is no horizontal Earth rate).
    azimuth : float
        A, rad: the azimuth the platform's y axis is driven to.
    c_gamma, c_a : float
        Level and azimuth correction gains, 1/s (> 0).
    duration : float
        s.
    time_step : float
        Runge-Kutta step, s (small against 1 / sqrt(c_a U cos phi) and 1 / c_gamma).
    output_step : float
        s, a whole number of time steps.
    initial_azimuth_error, initial_beta, initial_alpha : float or array
        delta0, beta0, alpha0, rad; arrays of length N make a batch.
    drift_x, drift_y, drift_z : float or array
        Residual drifts Delta omega_d (estimate - true), platform axes, rad/s.
    latitude_error : float or array
        Delta phi, rad (entered latitude - true).
    accel_error_x, accel_error_y : float or array
        Delta a_x, Delta a_y, m/s^2.
    earth_rate : float
        U, rad/s.
    gravity : float
        g, m/s^2.

    Returns
    -------
    AlignmentResult
    """
    phi = float(latitude)
    if not (np.isfinite(phi) and abs(phi) < np.pi / 2):
        raise InvalidParameter("latitude", "must lie strictly within +/-90 deg (no azimuth reference at a pole)")
    for name, value in (("c_gamma", c_gamma), ("c_a", c_a), ("duration", duration), ("time_step", time_step),
                        ("gravity", gravity)):
        if not (np.isfinite(value) and value > 0):
            raise InvalidParameter(name, f"must be finite and > 0, got {value!r}")
    every = round(output_step / time_step)
    if every < 1 or abs(every * time_step - output_step) > 1e-9 * output_step:
        raise InvalidParameter("output_step", "must be a whole number of time steps")
    n_steps = round(duration / time_step / every) * every
    values = np.broadcast_arrays(*[np.atleast_1d(np.asarray(v, dtype=float)) for v in (
        initial_azimuth_error, initial_beta, initial_alpha, drift_x, drift_y, drift_z, latitude_error,
        accel_error_x, accel_error_y)])
    if not all(np.all(np.isfinite(v)) for v in values):
        raise InvalidParameter("initial_azimuth_error", "initial errors and residuals must be finite")
    delta0, beta0, alpha0, dwx, dwy, dwz, dphi, dax, day = values
    batch = any(np.ndim(v) > 0 for v in (initial_azimuth_error, initial_beta, initial_alpha, drift_x, drift_y,
                                          drift_z, latitude_error, accel_error_x, accel_error_y))
    n = delta0.size
    A = float(azimuth)
    U = earth_rate
    true_rate = np.array([-U * np.cos(phi) * np.sin(A), U * np.cos(phi) * np.cos(A), U * np.sin(phi)])
    entered = phi + dphi
    params = np.empty((n, 16))
    params[:, 0:3] = true_rate
    params[:, 3] = gravity
    params[:, 4] = -U * np.cos(entered) * np.sin(A)
    params[:, 5] = U * np.cos(entered) * np.cos(A)
    params[:, 6] = U * np.sin(entered)
    params[:, 7], params[:, 8], params[:, 9] = dwx, dwy, dwz
    params[:, 10], params[:, 11] = dax, day
    params[:, 12], params[:, 13] = np.sin(A), np.cos(A)
    params[:, 14], params[:, 15] = -c_gamma / gravity, c_a / gravity
    # initial platform: y axis at azimuth A + delta0, z axis tilted by (beta0 about east, alpha0 about north)
    tilt = quaternion_from_rotation_vector(np.stack([beta0, alpha0, np.zeros(n)], axis=-1))
    platform_to_enu = dcm_from_quaternion(tilt) @ _level_to_enu(A + delta0)
    platform_to_level = np.swapaxes(_level_to_enu(np.full(n, A)), -1, -2) @ platform_to_enu
    q = np.ascontiguousarray(_quaternion_from_matrix(platform_to_level))
    out = np.empty((n, n_steps // every + 1, 4))
    align(q, np.ascontiguousarray(params), float(time_step), n_steps, every, out)
    C = _level_to_enu(A) @ dcm_from_quaternion(out)  # platform -> ENU, (N, n_time, 3, 3)
    y_axis, z_axis = C[..., :, 1], C[..., :, 2]
    delta = wrap_angle(np.arctan2(y_axis[..., 0], y_axis[..., 1]) - A)
    beta = -np.arcsin(np.clip(z_axis[..., 1], -1.0, 1.0))
    alpha = np.arcsin(np.clip(z_axis[..., 0], -1.0, 1.0))

    def shaped(x):
        return x if batch else x[0]

    return AlignmentResult(phi, A, float(c_gamma), float(c_a), np.arange(out.shape[1]) * every * time_step,
                           shaped(delta), shaped(beta), shaped(alpha))



KYIV_LATITUDE = np.radians(50.45)
"""Latitude of the KPI laboratory (Kyiv), rad."""

DEPARTURE = 0.01
"""A nonlinear result departs from a linear one when they differ by more than 1 %."""


@dataclass
class GyrocompassingComparison(Result):
    """The KPI linear models (1.17), (1.19) beside the nonlinear platform, one row per initial azimuth error.

    Steady states are the azimuth error the alignment settles to (rad);
    settling times the time after which the azimuth error stays within 1 % of
    |delta0 - steady state| of its steady state (s), for the nonlinear run and
    for simulations of the full (1.17) and simplified (1.19) models from the
    same start; ``settling_formula_s`` is the source's 5 / h. A band crossing
    jumps when an overshoot grazes the band's edge, so the decay times
    tau = integral |delta - delta_ss| dt / |delta0 - delta_ss| (s, smooth in
    delta0; 1/h for an exponential envelope) are compared too. Departures are
    (nonlinear - linear) / |linear|; ``first_departure_rad`` gives, per
    comparison, the smallest delta0 whose departure exceeds 1 % (None: none
    in the range).
    """

    latitude_rad: float
    c_gamma_per_s: float
    c_a_per_s: float
    initial_azimuth_errors_rad: np.ndarray
    steady_nonlinear_rad: np.ndarray
    steady_full_rad: float
    steady_simplified_rad: float
    settling_nonlinear_s: np.ndarray
    settling_full_s: np.ndarray
    settling_simplified_s: np.ndarray
    settling_formula_s: float
    steady_departure_full: np.ndarray
    steady_departure_simplified: np.ndarray
    settling_departure_full: np.ndarray
    settling_departure_simplified: np.ndarray
    decay_nonlinear_s: np.ndarray
    decay_full_s: np.ndarray
    decay_departure_full: np.ndarray
    first_departure_rad: dict
    t_s: np.ndarray = field(repr=False)
    azimuth_error_nonlinear_rad: np.ndarray = field(repr=False)
    azimuth_error_full_rad: np.ndarray = field(repr=False)
    azimuth_error_simplified_rad: np.ndarray = field(repr=False)

    def render(self):
        from rich.console import Group
        from rich.table import Table

        table = Table(title="Gyrocompassing: nonlinear platform vs (1.17) full and (1.19) simplified")
        for column in ("delta0 (arcmin)", "steady nl (arcmin)", "vs (1.17)", "vs (1.19)", "settling nl (s)",
                       "(1.17) (s)", "(1.19) (s)", "vs (1.17)", "vs (1.19)", "decay nl (s)", "vs (1.17)"):
            table.add_column(column, justify="right")
        arcmin = 180.0 * 60.0 / np.pi
        for i, delta0 in enumerate(self.initial_azimuth_errors_rad):
            table.add_row(f"{delta0 * arcmin:,.1f}", f"{self.steady_nonlinear_rad[i] * arcmin:.4f}",
                          f"{self.steady_departure_full[i]:+.2%}", f"{self.steady_departure_simplified[i]:+.2%}",
                          f"{self.settling_nonlinear_s[i]:.1f}", f"{self.settling_full_s[i]:.1f}",
                          f"{self.settling_simplified_s[i]:.1f}", f"{self.settling_departure_full[i]:+.2%}",
                          f"{self.settling_departure_simplified[i]:+.2%}", f"{self.decay_nonlinear_s[i]:.2f}",
                          f"{self.decay_departure_full[i]:+.2%}")
        lines = [f"{name}: first departure > 1 % at delta0 = "
                 + ("none in range" if value is None else f"{value * arcmin:,.1f} arcmin ({value:.3g} rad)")
                 for name, value in self.first_departure_rad.items()]
        return Group(table, *lines)


def _departure(nonlinear, linear) -> np.ndarray:
    linear = np.asarray(linear, dtype=float)
    return (np.asarray(nonlinear) - linear) / np.abs(linear)


def _decay_time(t, signal, final, initial) -> np.ndarray:
    """tau = integral |delta - delta_ss| dt / |delta0 - delta_ss|, s (trapezoid rule)."""
    excess = np.abs(np.asarray(signal) - np.asarray(final)[..., None])
    return np.trapezoid(excess, t, axis=-1) / np.abs(np.asarray(initial) - np.asarray(final))


def _first(initial, departure) -> float | None:
    beyond = np.flatnonzero(np.abs(departure) > DEPARTURE)
    return float(initial[beyond[0]]) if beyond.size else None


def kpi_gyrocompassing(initial_azimuth_errors=None, *, latitude: float = KYIV_LATITUDE, azimuth: float = 0.0,
                       time_constant: float = DESIGN_TIME_CONSTANT, damping: float = DESIGN_DAMPING,
                       drift_east: float = np.radians(0.01) / 3600,
                       drift_up: float = 0.0, latitude_error: float = 0.0, accel_error_x: float = 0.0,
                       accel_error_y: float = 0.0, initial_beta: float = 0.0, initial_alpha: float = 0.0,
                       duration: float = 2400.0, time_step: float = 0.1) -> GyrocompassingComparison:
    """The KPI manual's linear gyrocompassing models beside the nonlinear platform for growing initial azimuth errors.

    Parameters
    ----------
    initial_azimuth_errors : array_like, optional
        delta0, rad (default: 12 values from 1 arcmin to 0.4 rad, geometric).
    latitude : float
        phi, rad (default Kyiv, 50.45 deg).
    azimuth : float
        A, rad (default 0: x east, y north, so drift_east is Delta omega_dx).
    time_constant, damping : float
        T (s) and zeta of the design (1.20): c_gamma = 2 zeta / T, c_a = 1 / (T^2 U cos phi).
    drift_east, drift_up : float
        Residual drifts Delta omega_d about east (platform x at A = 0) and up, rad/s
        (default 0.01 deg/h east: a steady azimuth error of a few arcmin to settle to).
    latitude_error : float
        Delta phi, rad.
    accel_error_x, accel_error_y : float
        Delta a_x, Delta a_y, m/s^2.
    initial_beta, initial_alpha : float
        Level errors left by the levelling, rad (about east and north).
    duration, time_step : float
        s: run length and Runge-Kutta step (outputs at every step).

    Returns
    -------
    GyrocompassingComparison
    """
    delta0 = (np.geomspace(np.radians(1.0 / 60.0), 0.4, 12) if initial_azimuth_errors is None
              else np.atleast_1d(np.asarray(initial_azimuth_errors, dtype=float)))
    c_gamma, c_a = loop_gains(latitude, time_constant, damping)
    drift_x = drift_east * np.cos(azimuth)
    drift_y = drift_east * np.sin(azimuth)
    run = gyrocompass_alignment(latitude, azimuth, c_gamma, c_a, duration=duration, time_step=time_step,
                                output_step=time_step, initial_azimuth_error=delta0, drift_x=drift_x, drift_y=drift_y,
                                drift_z=drift_up, latitude_error=latitude_error, accel_error_x=accel_error_x,
                                accel_error_y=accel_error_y, initial_beta=initial_beta, initial_alpha=initial_alpha)
    t = run.t_s
    inputs = [drift_x, drift_y, drift_up, latitude_error, accel_error_x, accel_error_y]
    full = simulate(full_mu_nu_model(latitude, azimuth, c_gamma, c_a), t,
                    initial_state=initial_state("full", delta0, initial_beta, initial_alpha, azimuth),
                    inputs=inputs)["delta"]
    simplified = simulate(simplified_model(latitude, azimuth, c_gamma, c_a), t,
                          initial_state=initial_state("simplified", delta0, initial_beta, initial_alpha, azimuth),
                          inputs=inputs)["delta"]
    tail = t >= 0.9 * t[-1]
    steady_nl = run.azimuth_error_rad[:, tail].mean(axis=1)
    steady_full = float(full[0, tail].mean())
    steady_simple = float(steady_state(latitude, c_gamma, c_a, drift_east=drift_east, drift_up=drift_up,
                                       latitude_error=latitude_error)[0])
    settle_nl = band_settling_time(t, run.azimuth_error_rad, steady_nl, delta0)
    settle_full = band_settling_time(t, full, steady_full, delta0)
    settle_simple = band_settling_time(t, simplified, simplified[:, tail].mean(axis=1), delta0)
    decay_nl = _decay_time(t, run.azimuth_error_rad, steady_nl, delta0)
    decay_full = _decay_time(t, full, np.full(delta0.size, steady_full), delta0)
    departures = {
        "steady state vs (1.17)": _departure(steady_nl, np.full(delta0.size, steady_full)),
        "steady state vs (1.19)": _departure(steady_nl, np.full(delta0.size, steady_simple)),
        "settling time vs (1.17)": _departure(settle_nl, settle_full),
        "settling time vs (1.19)": _departure(settle_nl, settle_simple),
        "decay time vs (1.17)": _departure(decay_nl, decay_full),
    }
    return GyrocompassingComparison(
        latitude_rad=float(latitude), c_gamma_per_s=c_gamma, c_a_per_s=c_a, initial_azimuth_errors_rad=delta0,
        steady_nonlinear_rad=steady_nl, steady_full_rad=steady_full, steady_simplified_rad=steady_simple,
        settling_nonlinear_s=settle_nl, settling_full_s=settle_full, settling_simplified_s=settle_simple,
        settling_formula_s=float(settling_time(c_gamma, c_a, latitude)),
        steady_departure_full=departures["steady state vs (1.17)"],
        steady_departure_simplified=departures["steady state vs (1.19)"],
        settling_departure_full=departures["settling time vs (1.17)"],
        settling_departure_simplified=departures["settling time vs (1.19)"],
        decay_nonlinear_s=decay_nl, decay_full_s=decay_full, decay_departure_full=departures["decay time vs (1.17)"],
        first_departure_rad={name: _first(delta0, value) for name, value in departures.items()},
        t_s=t, azimuth_error_nonlinear_rad=run.azimuth_error_rad, azimuth_error_full_rad=full,
        azimuth_error_simplified_rad=simplified)
