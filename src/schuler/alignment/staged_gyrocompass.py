"""The strapdown gyrocompass for a disturbed base: levelling, then azimuth, each loop driven by velocity.

Structure (the compass alignment of strapdown practice: Titterton, D. H. and
Weston, J. L., *Strapdown Inertial Navigation Technology*, 2nd ed., IET, 2004,
ch. 10, "gyrocompass alignment"; Savage, P. G., *Strapdown Analytics*, Strapdown
Associates, 2000, ch. 6 on initial alignment; Yan Gongmin's compass alignment
in the PSINS toolbox, as described in Qin Yongyuan, *Inertial Navigation*,
Science Press, 2006, ch. 9). A computed level frame C_b^n is carried by the
gyros; the horizontal velocity v in it integrates the sensed specific force and
is damped, and v, not the specific force itself, torques the frame:

    v_N' = f_N - k1 v_N,   v_E' = f_E - k1 v_E
    omega_command = omega_ie + (k2 v_E / g, -k2 v_N / g, -k3 v_N / g)   (NED)

Integrating the specific force first is what lets the loop sit on a swaying
base: a sway of displacement amplitude X moves the heading by about k3 X / g,
where a loop torqued by the specific force (the KPI platform design,
:mod:`~schuler.alignment.gyrocompass`) moves it by c_a X omega / g at sway
frequency omega. Linearised at rest (tilt/heading errors phi, psi-angle form,
spec 06), the north channel is

    v_N' = g phi_E - k1 v_N + b_aN,  phi_E' = Omega cos L phi_D - k2 v_N / g - b_gE,
    phi_D' = -Omega cos L phi_E - k3 v_N / g - b_gD,

with characteristic polynomial s^3 + k1 s^2 + (k2 + W^2) s + W (k1 W + k3), W = Omega cos L.
Its roots are placed at a level pair (natural frequency omega_L, damping zeta) and
an azimuth root -sigma: k1 = 2 zeta omega_L + sigma, k2 = omega_L^2 + 2 zeta omega_L sigma - W^2,
k3 = (sigma omega_L^2 - k1 W^2) / W (:func:`stage_gains`).

Stages (:func:`design_gyrocompass`), each with constant gains (level damping zeta = 1/sqrt(2)):

1. coarse levelling: natural period 10 s, azimuth open (k3 = 0), 4 envelope time constants 1 / (zeta omega_L);
2. fine levelling at omega_L = sqrt(1 + 4 zeta^2) g N_g / N_a, the bandwidth that minimises the level loop's
   tilt variance N_a^2 omega_L / (4 zeta g^2) + N_g^2 (1 + 4 zeta^2) / (4 zeta omega_L) for the gyro and
   accelerometer white noise N_g, N_a, kept between the natural periods 20 s (a decade below the 0.5-50 Hz
   band of a vehicle's sway) and 300 s; 4 envelope time constants;
3. coarse azimuth: the azimuth root at its fastest, sigma_max = zeta omega_L / 2, for 5 of its time
   constants (a start error shrinks by e^-5; at most half of what is left of the window);
4. fine azimuth to the window's end, the time constant 1 / sigma growing with the time t spent in it as
   the minimum-variance estimate of a constant seen in white noise does (Gelb, A. (ed.), *Applied Optimal
   Estimation*, MIT Press, 1974, sec. 4.2): sigma = 1 / (tau0 + t), with tau0 = q / P0 = 2 / sigma_max
   from the heading variance P0 = q sigma_max / 2 the coarse azimuth stage leaves for the east gyro noise
   seen as heading, q = (N_E / W)^2; sigma is held constant over sub-stages of doubling length.

Stated limit (:func:`staged_limit`): its noise part is the exact 1-sigma of the
linear error model above (both channels, Omega sin L coupling included) driven by
the sensors' white noise through the stages from the start's own uncertainty
(covariance propagated stage by stage, Van Loan's method); its bias part is the
last stage's steady error for the constant errors, -b_gE / (W) (the east drift over
Omega cos L) plus the loop's small own terms.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from schuler.alignment import _kernels
from schuler.alignment.attitude import earth_rate_ned, euler_from_dcm
from schuler.alignment.data import MethodEstimate, StaticBatch
from schuler.alignment.inertial import start_attitude
from schuler.alignment.limits import (
    AccuracyLimit,
    accuracy_limit,
    effective_bias_sigma,
    horizontal_rate,
)
from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY
from schuler.exceptions import InvalidParameter

PROPAGATION_STEP_S = 1.0
"""Longest step of the covariance propagation, s."""

LEVEL_DAMPING = 1.0 / math.sqrt(2.0)
"""zeta of the level loops."""

COARSE_LEVEL_PERIOD_S = 10.0
"""Natural period of the coarse levelling loop, s."""

FINE_LEVEL_PERIOD_RANGE_S = (20.0, 300.0)
"""Shortest and longest natural period of the fine levelling loop, s (the shortest a decade below 0.5 Hz sway)."""

STAGE_TIME_CONSTANTS = 4.0
"""A levelling stage lasts this many envelope time constants 1 / (zeta omega_L)."""

LEVELLING_SHARE = (0.05, 0.15)
"""At most these shares of the window go to coarse and fine levelling (short windows)."""

AZIMUTH_SEPARATION = 2.0
"""The azimuth root is at most zeta omega_L / this: well inside the level loop's bandwidth."""

AZIMUTH_SETTLING = 5.0
"""The coarse azimuth stage lasts this many of its time constants (a start error shrinks by e^-5)."""

COARSE_AZIMUTH_SHARE = 0.5
"""At most this share of the time after levelling goes to the coarse azimuth stage (short windows)."""


@dataclass(frozen=True)
class Stage:
    """One stage of the loop: its span and its constant gains (SI).

    Attributes
    ----------
    name : str
        ``coarse levelling``, ``fine levelling`` or ``azimuth``.
    start_s, end_s : float
        Span from the window's start, s.
    k_velocity, k_level, k_azimuth : float
        k1 (1/s), k2 (1/s^2), k3 (1/s^2) of the module notes.
    level_period_s : float
        Natural period 2 pi / omega_L of the level loop, s.
    azimuth_time_constant_s : float or None
        1 / sigma of the azimuth root, s (None: azimuth open).
    """

    name: str
    start_s: float
    end_s: float
    k_velocity: float
    k_level: float
    k_azimuth: float
    level_period_s: float
    azimuth_time_constant_s: float | None


def stage_gains(level_frequency: float, azimuth_rate: float, latitude: float) -> tuple[float, float, float]:
    """(k1, k2, k3) placing the north channel's roots at the level pair and -sigma (module notes).

    Parameters
    ----------
    level_frequency : float
        omega_L of the level loop, rad/s.
    azimuth_rate : float
        sigma of the azimuth root, 1/s (0: azimuth open, k3 = 0).
    latitude : float
        L, rad.

    Returns
    -------
    k1, k2, k3 : float
        1/s, 1/s^2, 1/s^2.
    """
    rate = float(horizontal_rate(latitude))
    w, sigma = level_frequency, azimuth_rate
    k1 = 2.0 * LEVEL_DAMPING * w + sigma
    k2 = w**2 + 2.0 * LEVEL_DAMPING * w * sigma - rate**2
    k3 = (sigma * w**2 - k1 * rate**2) / rate if sigma > 0 else 0.0
    return k1, k2, k3


def error_model(latitude: float, k1: float, k2: float, k3: float, gravity: float = STANDARD_GRAVITY):
    """The loop's linear error model x' = A x + B u, x = (v_N, v_E, phi_N, phi_E, phi_D) (m/s, rad).

    Parameters
    ----------
    latitude : float
        L, rad.
    k1, k2, k3 : float
        Gains of one stage, 1/s, 1/s^2, 1/s^2.
    gravity : float
        g, m/s^2.

    Returns
    -------
    A : ndarray (5, 5)
    B : ndarray (5, 6)
        Inputs u = (b_gN, b_gE, b_gD, b_aN, b_aE, b_aD), rad/s and m/s^2, NED, measured - true.
        Heading error = -phi_D.
    """
    cos_rate, sin_rate = EARTH_RATE * math.cos(latitude), EARTH_RATE * math.sin(latitude)
    A = np.array([[-k1, 0.0, 0.0, gravity, 0.0],
                  [0.0, -k1, -gravity, 0.0, 0.0],
                  [0.0, k2 / gravity, 0.0, -sin_rate, 0.0],
                  [-k2 / gravity, 0.0, sin_rate, 0.0, cos_rate],
                  [-k3 / gravity, 0.0, 0.0, -cos_rate, 0.0]])
    B = np.zeros((5, 6))
    B[0, 3] = B[1, 4] = 1.0
    B[2, 0] = B[3, 1] = B[4, 2] = -1.0
    return A, B


def _north_east_down(heading: float, sigma_xyz) -> list[float]:
    s = np.asarray(sigma_xyz, dtype=float)
    c, n = math.cos(heading), math.sin(heading)
    return [math.hypot(c * s[0], n * s[1]), math.hypot(n * s[0], c * s[1]), float(s[2])]


def _start_noise(errors, latitude: float, heading: float, initial_window: float, gravity: float) -> np.ndarray:
    """Covariance of the start (inertial-frame alignment over the initial window): noise part, (5, 5)."""
    start = accuracy_limit("inertial_frame", errors, latitude=latitude, heading=heading, duration=initial_window,
                           gravity=gravity)
    tilt = (start.roll_noise_rad**2 + start.pitch_noise_rad**2) / 2.0
    return np.diag([0.0, 0.0, tilt, tilt, start.heading_noise_rad**2])


@dataclass(frozen=True)
class GyrocompassDesign:
    """The stages of one window's loop, and the noise they were chosen from.

    Attributes
    ----------
    stages : tuple of Stage
    fine_level_period_s : float
        2 pi / omega_L of the fine levelling and azimuth stages, s.
    start_tau_s : float
        tau0 of the fine azimuth stages, s.
    """

    stages: tuple[Stage, ...]
    fine_level_period_s: float
    start_tau_s: float

    def as_dicts(self) -> list[dict]:
        """The stages as plain dictionaries (JSON)."""
        return [asdict(stage) for stage in self.stages]


def design_gyrocompass(errors, *, latitude: float, duration: float,
                       gravity: float = STANDARD_GRAVITY) -> GyrocompassDesign:
    """The stages and gains for a window of ``duration`` s and these sensors (module notes).

    Parameters
    ----------
    errors : ErrorModel
        The sensors' errors: their horizontal white noise sets omega_L.
    latitude : float
        Site latitude L, rad.
    duration : float
        Length of the window, s.
    gravity : float
        g, m/s^2.

    Returns
    -------
    GyrocompassDesign

    Raises
    ------
    InvalidParameter
        A duration not finite and positive.
    NotObservable
        Beyond :data:`~schuler.alignment.limits.MAX_LATITUDE`.
    """
    if not (math.isfinite(duration) and duration > 0):
        raise InvalidParameter("duration", f"must be finite and > 0 s, got {duration!r}")
    n_g = float(np.mean(errors.gyro.random_walk[:2]))
    n_a = float(np.mean(errors.accel.random_walk[:2]))
    shortest, longest = (2.0 * math.pi / period for period in FINE_LEVEL_PERIOD_RANGE_S)
    fine = min(max(math.sqrt(1.0 + 4.0 * LEVEL_DAMPING**2) * gravity * n_g / max(n_a, 1e-30), longest), shortest)
    coarse = 2.0 * math.pi / COARSE_LEVEL_PERIOD_S
    coarse_end = min(STAGE_TIME_CONSTANTS / (LEVEL_DAMPING * coarse), LEVELLING_SHARE[0] * duration)
    fine_end = coarse_end + min(STAGE_TIME_CONSTANTS / (LEVEL_DAMPING * fine), LEVELLING_SHARE[1] * duration)
    stages = [Stage("coarse levelling", 0.0, coarse_end, *stage_gains(coarse, 0.0, latitude),
                    2.0 * math.pi / coarse, None),
              Stage("fine levelling", coarse_end, fine_end, *stage_gains(fine, 0.0, latitude), 2.0 * math.pi / fine,
                    None)]
    fastest = LEVEL_DAMPING * fine / AZIMUTH_SEPARATION
    remaining = duration - fine_end
    coarse_azimuth = min(AZIMUTH_SETTLING / fastest, COARSE_AZIMUTH_SHARE * remaining)
    stages.append(Stage("coarse azimuth", fine_end, fine_end + coarse_azimuth, *stage_gains(fine, fastest, latitude),
                        2.0 * math.pi / fine, 1.0 / fastest))
    # the coarse azimuth loop leaves a heading variance of about q / (2 tau_min): tau0 = q / P0 = 2 tau_min
    tau0 = 2.0 / fastest
    elapsed, remaining = 0.0, remaining - coarse_azimuth
    start = fine_end + coarse_azimuth
    while elapsed < remaining:
        end = min(2.0 * elapsed + tau0, remaining)
        tau = tau0 + (elapsed + end) / 2.0
        stages.append(Stage("fine azimuth", start + elapsed, start + end, *stage_gains(fine, 1.0 / tau, latitude),
                            2.0 * math.pi / fine, tau))
        elapsed = end
    return GyrocompassDesign(tuple(stages), 2.0 * math.pi / fine, tau0)


def _propagate(A: np.ndarray, intensity: np.ndarray, span: float) -> tuple[np.ndarray, np.ndarray]:
    """(Phi, Q_d) of x' = A x + w, E[w w^T] = intensity delta, over ``span`` s (Van Loan 1978)."""
    from scipy.linalg import expm

    size = A.shape[0]
    steps = max(1, math.ceil(span / PROPAGATION_STEP_S))
    M = np.zeros((2 * size, 2 * size))
    M[:size, :size], M[:size, size:], M[size:, size:] = -A, intensity, A.T
    E = expm(M * (span / steps))
    step = E[size:, size:].T
    step_noise = step @ E[:size, size:]
    # short steps keep the exponential of the stiff (fast level, slow azimuth) system accurate
    transition, driven = np.eye(size), np.zeros((size, size))
    for _ in range(steps):
        transition, driven = step @ transition, step @ driven @ step.T + step_noise
    return transition, driven


def staged_limit(errors, design: GyrocompassDesign, *, latitude: float, heading: float,
                 gravity: float = STANDARD_GRAVITY, initial_window: float = 30.0) -> AccuracyLimit:
    """The stated 1-sigma limit of the staged loop at the window's end (module notes), rad.

    Parameters
    ----------
    errors : ErrorModel
        The sensors' errors: constant part at rest (:func:`~schuler.alignment.limits.effective_bias_sigma`) and
        white noise N.
    design : GyrocompassDesign
        The stages the loop ran.
    latitude, heading : float
        Site latitude and (approximate) heading of the level body, rad.
    gravity : float
        g, m/s^2.
    initial_window : float
        Length of the start's inertial-frame alignment, s.

    Returns
    -------
    AccuracyLimit
        ``gyrocompass``: the noise part propagated through the stages, the bias part the last stage's steady error.
    """
    gyro_noise = _north_east_down(heading, errors.gyro.random_walk)
    accel_noise = _north_east_down(heading, errors.accel.random_walk)
    intensity = np.diag(np.square(gyro_noise + accel_noise))
    P = _start_noise(errors, latitude, heading, initial_window, gravity)
    for stage in design.stages:
        A, B = error_model(latitude, stage.k_velocity, stage.k_level, stage.k_azimuth, gravity)
        transition, driven = _propagate(A, B @ intensity @ B.T, stage.end_s - stage.start_s)
        P = transition @ P @ transition.T + driven
    last = design.stages[-1]
    A, B = error_model(latitude, last.k_velocity, last.k_level, last.k_azimuth, gravity)
    steady = -np.linalg.solve(A, B)      # (5, 6): steady error per unit constant input
    gyro_b, accel_b = effective_bias_sigma(errors, gravity)
    bias_sigma = np.array(_north_east_down(heading, gyro_b) + _north_east_down(heading, accel_b))
    c, s = math.cos(heading), math.sin(heading)
    # body roll, pitch and heading of a level body at heading psi from the NED errors (limits.gyrocompass_error_model)
    to_body = np.array([[0.0, 0.0, -c, -s, 0.0], [0.0, 0.0, s, -c, 0.0], [0.0, 0.0, 0.0, 0.0, -1.0]])
    bias = np.sqrt(((to_body @ steady) ** 2) @ bias_sigma**2)
    noise = np.sqrt(np.maximum(np.diag(to_body @ P @ to_body.T), 0.0))
    return AccuracyLimit("gyrocompass", float(bias[0]), float(bias[1]), float(bias[2]), float(noise[0]),
                         float(noise[1]), float(noise[2]))


def align_staged_gyrocompass(batch: StaticBatch, design: GyrocompassDesign, *, initial_window_s: float = 30.0,
                             history_step_s: float = 1.0) -> MethodEstimate:
    """The staged strapdown gyrocompass over every record of ``batch``, started from inertial-frame alignment.

    Parameters
    ----------
    batch : StaticBatch
        The static records.
    design : GyrocompassDesign
        Stages and gains (:func:`design_gyrocompass` for this window).
    initial_window_s : float
        Inertial-frame alignment over the first seconds gives the start, s.
    history_step_s : float
        Step of the histories, s.

    Returns
    -------
    MethodEstimate
        No 1-sigma of its own: its accuracy is its stated limit (:func:`staged_limit`).
    """
    dt = batch.sample_interval_s
    attitude = start_attitude(batch.head(initial_window_s))
    ends = batch.history_indices(history_step_s)
    stage_ends = np.array([max(1, int(round(stage.end_s / dt))) for stage in design.stages], dtype=np.int64)
    stage_ends[-1] = max(stage_ends[-1], batch.samples)
    gains = np.array([[stage.k_velocity, stage.k_level, stage.k_azimuth] for stage in design.stages])
    history = np.empty((batch.members, ends.size, 3, 3))
    _kernels.staged_gyrocompass_loop(batch.gyro_increment, batch.accel_increment, dt, attitude,
                                     earth_rate_ned(batch.latitude_rad), batch.gravity, stage_ends,
                                     gains[:, 0].copy(), gains[:, 1].copy(), gains[:, 2].copy(), ends, history)
    roll, pitch, heading = euler_from_dcm(history)
    return MethodEstimate("gyrocompass", roll[:, -1], pitch[:, -1], heading[:, -1], None, ends * dt, roll, pitch,
                          heading)
