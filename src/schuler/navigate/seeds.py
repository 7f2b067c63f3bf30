"""The seeds' linear models held against the nonlinear INS on WGS-84: data for tables and figures.

* :func:`bollay_error_sources`: Bollay's (1966) five error sources (Problem 3:
  0.01 deg tilt, 1 ft/s, 1e-4 g, 0.01 deg/h, 0.01 deg azimuth; 0.5 mi/s for
  10,120 s) flown on WGS-84 by the nonlinear strapdown INS, beside Bollay's
  closed forms with his constants and with the flight's own radius and
  effective gravity.
* :func:`drozdovich_worked_example`: the worked example of Drozdovich (1959) (10 m/s due
  west at 60 deg) on the nonlinear platform whose computer leaves the Coriolis
  and centripetal terms uncompensated, beside the slowly-varying (29).

The gyrocompassing comparison (the KPI manual) is :func:`schuler.navigate.alignment.kpi_gyrocompassing`.

References
----------
Bollay, W., "A Critical Meeting on the Development of Inertial Navigation - Related to 'The Story of 84 Minutes'",
Engineering Case Library, Stanford University, 1966, Problems 1-4.
Drozdovich, V. N., "On an inertial method of measuring velocities", Izvestiya VUZ, Priborostroyeniye, no. 3,
pp. 29-39, 1959 (English translation JPRS 2912, 1960), eqs. (8), (13), (19)-(29).

Examples
--------
>>> comparison = drozdovich_worked_example(duration=6 * 3600.0, output_step=600.0)
>>> round(comparison.formula_dv_along_start_m_s, 3), round(comparison.source_constants_dv_along_m_s, 3)
(0.554, 0.557)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import partial

import numpy as np

from schuler.core.earth import (
    BOLLAY,
    EARTH_RATE,
    STANDARD_GRAVITY,
    centripetal_acceleration_ned,
    earth_rate_ned,
    somigliana_gravity,
    transverse_radius,
)
from schuler.gyro_vertical.model import GyroVertical
from schuler.gyro_vertical.quasi_steady import quasi_steady_response
from schuler.gyro_vertical.reproduction import worked_example
from schuler.gyro_vertical.trajectory import GreatCircleTrajectory, SpeedProfile
from schuler.navigate.errors import ConstantSensorErrors, InitialErrors
from schuler.navigate.mechanization import navigate
from schuler.navigate.trajectory import GreatCircle, WaypointProfile
from schuler.navigation_errors.reproduction import FLIGHT_TIME, MAGNITUDES, SPEED
from schuler.navigation_errors.single_channel import SOURCES, spherical_error
from schuler.results import Result

BOOST_TIME = 60.0
"""Launch from rest to 0.5 mi/s, s: the boost the azimuth error misresolves."""

DROZDOVICH_LATITUDE = math.radians(60.0)
DROZDOVICH_SPEED = 10.0


@dataclass
class BollayComparison(Result):
    """Bollay's (1966) five error sources: nonlinear WGS-84 beside the closed forms, at the output step.

    Each array has one row per source of :data:`~schuler.navigation_errors.single_channel.SOURCES`,
    the error in the source's channel of a flight due east along the equator
    (m): along track (east) for the tilt, velocity, accelerometer and drift
    errors, across track (north) for the azimuth error. ``closed_bollay_m`` uses
    Bollay's constants (R = 3960 mi, T = 5060 s); ``closed_local_m`` the
    flight's own: R_E (the equator's radius) and the effective gravity
    g - 2 Omega V - V^2 / R_E that the accelerometers feel in cruise (Bollay's
    footnote on the effective Schuler period).
    """

    sources: tuple[str, ...]
    magnitudes_si: np.ndarray
    effective_gravity_m_s2: float
    local_schuler_period_s: float
    t_s: np.ndarray = field(repr=False)
    nonlinear_m: np.ndarray = field(repr=False)
    closed_bollay_m: np.ndarray = field(repr=False)
    closed_local_m: np.ndarray = field(repr=False)

    def summary(self) -> list[dict]:
        """Per source: the error at the end and the largest |error| of each curve, m."""
        rows = []
        for i, source in enumerate(self.sources):
            row: dict[str, str | float] = {"source": source}
            for name in ("nonlinear_m", "closed_bollay_m", "closed_local_m"):
                curve = getattr(self, name)[i]
                row[f"{name[:-2]}_final_m"] = float(curve[-1])
                row[f"{name[:-2]}_max_m"] = float(np.abs(curve).max())
            rows.append(row)
        return rows

    def render(self):
        from rich.table import Table

        table = Table(title=f"Bollay's five error sources, {self.t_s[-1]:,.0f} s flight due east on the equator (m)")
        for column in ("source", "nonlinear end", "Bollay end", "local end", "nonlinear max", "Bollay max",
                       "local max"):
            table.add_column(column, justify="right")
        for row in self.summary():
            table.add_row(row["source"], *(f"{row[k]:,.1f}" for k in (
                "nonlinear_final_m", "closed_bollay_final_m", "closed_local_final_m", "nonlinear_max_m",
                "closed_bollay_max_m", "closed_local_max_m")))
        return table


def bollay_error_sources(imu_rate: float = 10.0, output_step: float = 10.0, earth_rate: float = EARTH_RATE,
                         boost_time: float = BOOST_TIME) -> BollayComparison:
    """Fly Bollay's (1966) Problem 3 on WGS-84 with each error source alone, beside the closed forms.

    The missile is launched due east on the equator (a great circle of the
    ellipsoid), boosted from rest to 0.5 mi/s in ``boost_time`` along a C^2 speed
    blend, and cruises to 10,120 s with its vertical channel held. Heading
    east the body axes are x east, y south, z down. Each source is set so that
    Bollay's closed form is a positive error: pitch error -Delta_theta (a tilt
    about north, psi_N < 0), east velocity error Delta_V, accelerometer bias
    Delta_a on body x, gyro bias -epsilon on body y (a drift of -epsilon about
    north: spec 06's epsilon = -C b_g), all in the along-track channel, and
    heading error -Delta_theta_z for the across-track (north) error. The
    along-track channel's tilt axis (north) is the frame's rotation axis, so
    Bollay's single channel holds there; a tilt about east would rotate into
    azimuth at Omega + V/R. Five members of one batch run.

    Parameters
    ----------
    imu_rate : float
        Hz.
    output_step : float
        s.
    earth_rate : float
        rad/s (0: a non-rotating Earth).
    boost_time : float
        s.

    Returns
    -------
    BollayComparison
    """
    east = math.radians(90.0)
    profile = WaypointProfile(latitude=0.0, longitude=0.0, height=0.0, times=np.array([0.0, boost_time, FLIGHT_TIME]),
                              speeds=np.array([0.0, SPEED, SPEED]), headings=np.full(3, east),
                              flight_path_angles=np.zeros(3),
                              name="Bollay Problem 3: launch due east on the equator")
    tilt, velocity, drift, azimuth = (MAGNITUDES[s] for s in ("tilt", "velocity", "drift", "azimuth"))
    accelerometer = 1e-4 * STANDARD_GRAVITY
    magnitudes = np.array([tilt, velocity, accelerometer, drift, azimuth])
    one_hot = np.eye(5)
    zeros = np.zeros(5)
    initial = InitialErrors(velocity_error_east=velocity * one_hot[1], pitch_error=-tilt * one_hot[0],
                            heading_error=-azimuth * one_hot[4])
    accel_bias = np.stack([accelerometer * one_hot[2], zeros, zeros], axis=1)
    gyro_bias = np.stack([zeros, -drift * one_hot[3], zeros], axis=1)
    run = navigate(profile, FLIGHT_TIME, imu_rate=imu_rate, output_step=output_step, initial_errors=initial,
                   sensor_errors=ConstantSensorErrors(gyro_bias=gyro_bias, accel_bias=accel_bias),
                   earth_rate=earth_rate)
    t = run.t_s
    channel = np.vstack([run.position_error_east_m[:4], run.position_error_north_m[4:]])
    R_E = float(transverse_radius(0.0))
    g_eff = float(somigliana_gravity(0.0)) - 2.0 * earth_rate * SPEED - SPEED**2 / R_E
    closed_bollay = np.array([spherical_error(source, size if source != "accelerometer" else
                                              1e-4 * BOLLAY.effective_gravity, t, BOLLAY.radius,
                                              BOLLAY.effective_gravity, speed=SPEED)
                              for source, size in zip(SOURCES, magnitudes)])
    closed_local = np.array([spherical_error(source, size, t, R_E, g_eff, speed=SPEED)
                             for source, size in zip(SOURCES, magnitudes)])
    return BollayComparison(tuple(SOURCES), magnitudes, g_eff, 2.0 * math.pi * math.sqrt(R_E / g_eff), t,
                            channel, closed_bollay, closed_local)


@dataclass
class DrozdovichComparison(Result):
    """The worked example of Drozdovich (1959) on the nonlinear platform (WGS-84) beside (29).

    Velocity errors are resolved in the source's frame along the track: x0 to
    the right of the velocity (north at the start), y0 along it (west). Means
    are over the whole run. ``quasi_steady_*`` is the seeds' own forced
    solution (26)/(29) with its tilt rates (:func:`~schuler.gyro_vertical.quasi_steady.quasi_steady_response`)
    along a sphere's great circle with the WGS-84 values at the start
    (R = R_E + h, g, Omega); ``formula_dv_along_start_m_s`` the slowly-varying
    (29) there, R omega_2 beta_r.
    """

    latitude_rad: float
    speed_m_s: float
    W_star_x_m_s2: float
    beta_r_rad: float
    formula_dv_along_start_m_s: float
    quasi_steady_dv_along_mean_m_s: float
    quasi_steady_dv_across_mean_m_s: float
    nonlinear_dv_along_mean_m_s: float
    nonlinear_dv_across_mean_m_s: float
    compensated_dv_mean_m_s: float
    source_constants_dv_along_m_s: float
    printed_dv_along_m_s: float
    t_s: np.ndarray = field(repr=False)
    nonlinear_dv_along_m_s: np.ndarray = field(repr=False)
    nonlinear_dv_across_m_s: np.ndarray = field(repr=False)
    quasi_steady_dv_along_m_s: np.ndarray = field(repr=False)


def _track_components(velocity_error: np.ndarray, velocity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(across, along): components on x0 (the velocity turned 90 deg clockwise) and y0 (the velocity)."""
    unit = velocity[:, :2] / np.linalg.norm(velocity[:, :2], axis=1, keepdims=True)
    along = np.sum(velocity_error * unit, axis=1)
    across = velocity_error[:, 0] * -unit[:, 1] + velocity_error[:, 1] * unit[:, 0]
    return across, along


def _w_star(latitude, height, velocity) -> np.ndarray:
    """Horizontal W* (21) on WGS-84: centripetal Omega x (Omega x r) plus Coriolis 2 Omega x v, (n, 2) m/s^2."""
    return (centripetal_acceleration_ned(latitude, height)[:, :2]
            + np.cross(2.0 * earth_rate_ned(latitude), np.atleast_2d(velocity))[:, :2])


def drozdovich_worked_example(duration: float = 48 * 3600.0, imu_rate: float = 1.0,
                              output_step: float = 60.0) -> DrozdovichComparison:
    """10 m/s due west at 60 deg on the nonlinear platform INS without Coriolis and centripetal compensation.

    The computer integrates f + gravitation - omega_en x v: it omits 2 omega_ie x v
    and models gravitation (normal gravity minus the centrifugal acceleration),
    so W* = Omega^2 (R_E + h) sin L cos L north + 2 omega_ie x v stays in its
    velocity, as in the device of Drozdovich (1959), (21). Its Earth-rate compensation uses
    the true latitude, entered as in (8): a platform tilted by beta_r = W*/g
    then sees the vertical Earth rate omega_2 = Omega sin L turn the tilt, which
    the velocity error must hold by torquing: the systematic error (29),
    Delta v_y = R omega_2 beta_r (R = R_E + h, the east channel's radius). (An
    INS whose Earth rate comes from its own latitude explains the tilt as a
    position error of R W*/g instead, with no mean velocity error.) The run
    starts levelled on the accelerometers (tilt beta_r) with the true velocity,
    as the source's integrators; the path is the ellipsoid's great circle, the
    vertical channel held. A second run with both terms compensated shows the
    error vanish.

    Parameters
    ----------
    duration : float
        s (the mean is over the whole run: many Schuler periods).
    imu_rate : float
        Hz.
    output_step : float
        s.

    Returns
    -------
    DrozdovichComparison
    """
    path = GreatCircle(latitude=DROZDOVICH_LATITUDE, longitude=0.0, height=0.0, heading=math.radians(270.0),
                       speed=DROZDOVICH_SPEED, duration=duration)
    w_start = _w_star(np.array([DROZDOVICH_LATITUDE]), np.zeros(1), path.kinematics(0.0)[0])[0]
    g_start = float(somigliana_gravity(DROZDOVICH_LATITUDE))
    # levelled on the accelerometers: tilted about east (the body's -x, heading west) until g phi_E = -W*_N
    levelled = InitialErrors(roll_error=-w_start[0] / g_start)
    common = partial(navigate, path, duration, imu_rate=imu_rate, output_step=output_step, mode="platform",
                     earth_rate_latitude="true", azimuth_reference=True)
    run = common(coriolis_compensation=False, centripetal_compensation=False, initial_errors=levelled)
    compensated = common()
    v = run.truth.velocity_ned_m_s
    errors = np.stack([run.velocity_error_north_m_s, run.velocity_error_east_m_s], axis=1)
    across, along = _track_components(errors, v)
    radius = float(transverse_radius(DROZDOVICH_LATITUDE))
    sphere_path = GreatCircleTrajectory(DROZDOVICH_LATITUDE, 0.0, math.pi / 2, SpeedProfile.constant(DROZDOVICH_SPEED),
                                        radius=radius, rate=EARTH_RATE)
    forced = quasi_steady_response(GyroVertical(sphere_path, g_start), run.t_s)
    compensated_errors = np.stack([compensated.velocity_error_north_m_s, compensated.velocity_error_east_m_s], axis=1)
    return DrozdovichComparison(
        latitude_rad=DROZDOVICH_LATITUDE, speed_m_s=DROZDOVICH_SPEED, W_star_x_m_s2=float(w_start[0]),
        beta_r_rad=float(w_start[0] / g_start),
        formula_dv_along_start_m_s=radius * EARTH_RATE * math.sin(DROZDOVICH_LATITUDE) * float(w_start[0]) / g_start,
        quasi_steady_dv_along_mean_m_s=float(np.mean(forced.dv_y)),
        quasi_steady_dv_across_mean_m_s=float(np.mean(forced.dv_x)),
        nonlinear_dv_along_mean_m_s=float(np.mean(along)), nonlinear_dv_across_mean_m_s=float(np.mean(across)),
        compensated_dv_mean_m_s=float(np.linalg.norm(compensated_errors.mean(axis=0))),
        source_constants_dv_along_m_s=float(worked_example()["dv_y"]), printed_dv_along_m_s=0.67,
        t_s=run.t_s, nonlinear_dv_along_m_s=along, nonlinear_dv_across_m_s=across,
        quasi_steady_dv_along_m_s=np.asarray(forced.dv_y))
