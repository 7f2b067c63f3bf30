"""What the alignment leaves: the initial errors of navigation as a linear map of the error sources.

The alignment happens at rest at the mission's start point, with the start
attitude C0 = C_b^n(0), over T_a seconds. At rest the body senses
omega0^b = C0^T Omega^n and f0^b = C0^T (0, 0, -g), so that every constant
source j of :data:`~schuler.mission.setup.CONSTANT_SOURCES` (unit size) makes
an accelerometer error nabla_j = C0 (b_a + S_a f0^b) and a drift
epsilon_j = -C0 (b_g + S_g omega0^b) in NED (psi-angle model's inputs, spec 06).

Levelling (every method): the computed vertical settles where the sensed
horizontal specific force vanishes, f x psi + nabla = 0 with f = (0, 0, -g):

    psi_N = nabla_E / g,    psi_E = -nabla_N / g.

Heading (psi_D; the heading error is -phi_D):

* ``kalman`` (strapdown fine alignment, steady state): the estimate converges
  to the unobservable equilibrium of the psi equation's east line,
  -(Omega x psi)_E + epsilon_E = 0, so

      psi_D = -(epsilon_E + Omega sin L psi_N) / (Omega cos L)

  (Britting 1971, Sec. 10; Groves 2013, Sec. 5.6.2 gives the leading term
  epsilon_E / (Omega cos L)). Its noise-limited part is the white rate noise
  averaged over T_a, sigma = N_E / (Omega cos L sqrt(T_a)), and the tilts'
  sigma = N_a / (g sqrt(T_a)).
* ``strapdown-gyrocompass`` (analytic, double-vector alignment, Groves 2013,
  Sec. 5.6.2; Britting 1971, Sec. 10): the means of f^b and omega^b over T_a
  give C_b^n by TRIAD with gravity first: the tilts level the averaged
  specific force (as above) and the heading puts the averaged Earth rate's
  east component, computed through the tilted frame, at zero:
  -(Omega x psi)_E + epsilon_E = 0. That is the Kalman fine alignment's
  steady-state equation, so to first order (small angles, the vehicle at
  rest, constant sensor errors) both leave the same residuals, heading error
  -b_gE / (Omega cos L) + (b_aE / g) tan L; the averages of the white noises
  over T_a are the least-squares estimates of constants from white noise,
  which is also the limit the Kalman filter reaches, so the noise-limited
  terms are the same too. The methods differ beyond this model: the
  analytic alignment takes disturbances (sway) into its averages, which a
  Kalman filter with a motion model rejects.
* ``gyrocompass`` (schuler align, physical gyrocompassing of a platform under the
  control law (1.6)): the steady state (1.21) of the KPI manual, azimuth error
  delta = Dw_xi / (U cos phi) + c_Gamma Dw_z / (c_a U cos phi) with the platform
  drifts Dw_xi = epsilon_E and Dw_z = -epsilon_D (drift = -bias, z up), psi_D =
  -delta; its noise-limited part is the steady variance of the simplified loop
  (1.19) driven by the white drift and accelerometer noise (Lyapunov equation
  A P + P A^T + B Q B^T = 0). The duration must cover the loop's settling time
  5 / h (KPI manual, after (1.25)).
* ``ground-gyrocompass`` (schuler north gives north): the heading error is the
  ground gyrocompass's own error (source ``north_reference``), independent of
  the IMU's gyros; the platform is levelled as above.

Navigation starts with zero velocity error (the vehicle is at rest) and the
position error of the source ``initial_position_north|east``; psi0 = phi0 -
delta_theta0 with delta_theta0 = (dr_E / (R_E + h), -dr_N / (R_N + h),
-dr_E tan L / (R_E + h)) (:mod:`schuler.navigate.linear`).

References
----------
K. R. Britting, *Inertial Navigation Systems Analysis*, Wiley, 1971.
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed.,
Artech House, 2013.
A. V. Meleshko, "Physical gyrocompassing of a semi-analytic INS", KPI laboratory manual (schuler align's source).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import solve_continuous_lyapunov

from schuler.core.earth import EARTH_RATE, earth_rate_ned, radii_of_curvature
from schuler.core.gyrocompass_design import loop_gains
from schuler.exceptions import InvalidParameter
from schuler.gyrocompassing.analytic import settling_time, steady_state
from schuler.gyrocompassing.models import simplified_model
from schuler.mission.setup import AXES, CONSTANT_SOURCES, SELF_ALIGNMENTS, MissionSetup


def sensor_inputs(body_to_ned, body_rate, body_force) -> np.ndarray:
    """NED inputs (nabla, epsilon) of each unit constant source: shape (..., n_sources, 6).

    ``body_to_ned`` (..., 3, 3), ``body_rate`` and ``body_force`` (..., 3): the
    rotation and the body's angular rate and specific force where they act.

    Every source has unit size here: the mission's 1-sigma sizes scale the result where it is used.

    Parameters
    ----------
    body_to_ned : array_like
        C_b^n, shape (..., 3, 3), plain numbers (direction cosines), body x forward, y right, z down.
    body_rate : array_like
        omega_ib^b, rad/s, shape (..., 3), body axes (what gyro scale factors multiply).
    body_force : array_like
        f^b, m/s^2, shape (..., 3), body axes (what accelerometer scale factors multiply).

    Returns
    -------
    ndarray
        Shape (..., n_sources, 6): NED accelerometer error nabla (m/s^2) then drift epsilon (rad/s) per unit
        of each of :data:`~schuler.mission.setup.CONSTANT_SOURCES` (1 rad/s, 1 m/s^2, a scale factor of 1);
        zero for the sources that act only through the initial state.
    """
    C = np.asarray(body_to_ned, dtype=float)
    rate = np.asarray(body_rate, dtype=float)
    force = np.asarray(body_force, dtype=float)
    out = np.zeros((*C.shape[:-2], len(CONSTANT_SOURCES), 6))
    for i, axis in enumerate(AXES):
        column = C[..., :, i]
        out[..., CONSTANT_SOURCES.index(f"gyro_bias_{axis}"), 3:] = -column
        out[..., CONSTANT_SOURCES.index(f"accel_bias_{axis}"), :3] = column
        out[..., CONSTANT_SOURCES.index(f"gyro_scale_factor_{axis}"), 3:] = -column * rate[..., i, None]
        out[..., CONSTANT_SOURCES.index(f"accel_scale_factor_{axis}"), :3] = column * force[..., i, None]
    return out


def _levelling(nabla: np.ndarray, gravity: float) -> tuple[np.ndarray, np.ndarray]:
    return nabla[..., 1] / gravity, -nabla[..., 0] / gravity


def gyrocompass_gains(setup: MissionSetup) -> tuple[float, float]:
    """c_Gamma, c_a (1/s) of schuler align's loop from its time constant and damping (KPI manual, Sec. 2).

    Parameters
    ----------
    setup : MissionSetup
        The mission: its ``gyrocompass_time_constant`` T (s), ``gyrocompass_damping`` zeta (plain number) and
        ``latitude`` (rad).

    Returns
    -------
    c_gamma, c_a : float
        The loop's correction gains, 1/s.
    """
    c_gamma, c_a = loop_gains(setup.latitude, setup.gyrocompass_time_constant, setup.gyrocompass_damping)
    return float(c_gamma), float(c_a)


def initial_state_map(setup: MissionSetup, body_to_ned: np.ndarray, n_states: int) -> np.ndarray:
    """Initial psi-model state per unit constant source: shape (n_sources, n_states).

    States as :func:`schuler.navigation_errors.three_d.wgs84_psi_angle_model`
    (7 with the vertical channel off, 9 with it free).

    Parameters
    ----------
    setup : MissionSetup
        The mission: latitude (rad), height (m), alignment method and its gyrocompass design.
    body_to_ned : ndarray
        C_b^n at the start (where the alignment happens), shape (3, 3), plain numbers (direction cosines).
    n_states : int
        Number of states of the psi-angle model, 7 or 9.

    Returns
    -------
    ndarray
        Shape (n_sources, n_states): position (m), velocity (m/s) and psi (rad) errors per unit of each
        constant source (1 rad/s, 1 m/s^2, 1 scale factor, 1 rad of north reference, 1 m of position).
    """
    L, g = setup.latitude, setup.gravity
    omega = earth_rate_ned(L, EARTH_RATE)
    rate0 = body_to_ned.T @ omega
    force0 = body_to_ned.T @ np.array([0.0, 0.0, -g])
    inputs = sensor_inputs(body_to_ned, rate0, force0)
    nabla, epsilon = inputs[:, :3], inputs[:, 3:]
    psi_n, psi_e = _levelling(nabla, g)
    cos_l = EARTH_RATE * math.cos(L)
    if setup.alignment in SELF_ALIGNMENTS:
        psi_d = -(epsilon[:, 1] + EARTH_RATE * math.sin(L) * psi_n) / cos_l
    elif setup.alignment == "gyrocompass":
        c_gamma, c_a = gyrocompass_gains(setup)
        delta, _ = steady_state(L, c_gamma, c_a, drift_east=epsilon[:, 1], drift_up=-epsilon[:, 2])
        psi_d = -delta
    else:
        psi_d = np.zeros(len(CONSTANT_SOURCES))
        psi_d[CONSTANT_SOURCES.index("north_reference")] = -1.0
    x0 = np.zeros((len(CONSTANT_SOURCES), n_states))
    down = n_states - 3
    x0[:, down], x0[:, down + 1], x0[:, down + 2] = psi_n, psi_e, psi_d
    radius_north, radius_east = radii_of_curvature(L)
    for name, row in (("initial_position_north", 0), ("initial_position_east", 1)):
        j = CONSTANT_SOURCES.index(name)
        x0[j, row] = 1.0
        d_north, d_east = x0[j, 0], x0[j, 1]
        delta_theta = np.array([d_east / (radius_east + setup.height), -d_north / (radius_north + setup.height),
                                -d_east * math.tan(L) / (radius_east + setup.height)])
        x0[j, down:] -= delta_theta
    return x0


def alignment_noise(setup: MissionSetup, body_to_ned: np.ndarray, n_states: int) -> dict[str, np.ndarray]:
    """Initial covariance the white noises leave through the alignment: {source: (n, n)}.

    Parameters
    ----------
    setup : MissionSetup
        The mission: latitude (rad), alignment method and duration T_a (s), angle random walk (rad/sqrt(s)) and
        velocity random walk (m/s/sqrt(s)) per body axis.
    body_to_ned : ndarray
        C_b^n at the start, shape (3, 3), plain numbers (direction cosines).
    n_states : int
        Number of states of the psi-angle model, 7 or 9.

    Returns
    -------
    dict of str to ndarray
        ``gyro_random_walk`` and ``accel_random_walk`` -> covariance, shape (n_states, n_states), in the states'
        units squared (only the psi block, rad^2, is non-zero).
    """
    L, g, T = setup.latitude, setup.gravity, setup.alignment_duration
    ned_gyro = (body_to_ned**2) @ setup.gyro_random_walk**2
    ned_accel = (body_to_ned**2) @ setup.accel_random_walk**2
    down = n_states - 3
    # tilts from the accelerometer noise averaged over T: psi_N from east, psi_E from north
    tilt = np.zeros((n_states, 2))
    tilt[down, 0] = tilt[down + 1, 1] = 1.0
    if setup.alignment in SELF_ALIGNMENTS:
        tilt[down + 2, 0] = -math.tan(L)
    accel = tilt @ np.diag([ned_accel[1], ned_accel[0]]) @ tilt.T / (g**2 * T)
    gyro = np.zeros((n_states, n_states))
    if setup.alignment in SELF_ALIGNMENTS:
        gyro[down + 2, down + 2] = ned_gyro[1] / ((EARTH_RATE * math.cos(L))**2 * T)
    elif setup.alignment == "gyrocompass":
        # the loop's azimuth answers to both noises; its correlation with the levelling tilt is left out
        variance_gyro, variance_accel = _gyrocompass_noise(setup)
        gyro[down + 2, down + 2] = variance_gyro
        accel[down + 2, down + 2] += variance_accel
    return {"gyro_random_walk": gyro, "accel_random_walk": accel}


def _gyrocompass_noise(setup: MissionSetup) -> tuple[float, float]:
    """Steady azimuth variance of the simplified loop (1.19) under white drift and accelerometer noise, rad^2."""
    c_gamma, c_a = gyrocompass_gains(setup)
    settle = float(settling_time(c_gamma, c_a, setup.latitude))
    if setup.alignment_duration < settle:
        raise InvalidParameter("alignment_duration", f"{setup.alignment_duration:g} s is shorter than the "
                               f"gyrocompass loop's settling time {settle:.0f} s (5/h): its residuals are "
                               "the steady state only after it")
    model = simplified_model(setup.latitude, setup.heading, c_gamma, c_a)
    A, B = np.asarray(model.A), np.asarray(model.B)
    delta = list(model.states).index("delta")
    variances = []
    for columns, density in (([0, 1, 2], setup.gyro_random_walk), ([4, 5], setup.accel_random_walk)):
        Q = np.diag(np.asarray(density, dtype=float)[: len(columns)] ** 2)
        Bn = B[:, columns]
        P = solve_continuous_lyapunov(A, -Bn @ Q @ Bn.T)
        variances.append(float(P[delta, delta]))
    return variances[0], variances[1]
