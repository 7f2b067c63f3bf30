"""The strapdown gyrocompass for a disturbed base: levelling, then azimuth, each loop driven by velocity.

Structure: the compass (gyrocompass) alignment of strapdown practice, levelling
loops first and the azimuth loop after them, each a second- or third-order loop fed
by the velocity the computed frame accumulates (Titterton, D. H. and Weston, J. L.,
*Strapdown Inertial Navigation Technology*, 2nd ed., IET, 2004, ch. 10, gyrocompass
alignment; Savage, P. G., *Strapdown Analytics*, Strapdown Associates, 2000, on
initial alignment; the compass alignment of Yan Gongmin's PSINS toolbox works the
same way). A computed level frame C_b^n is carried by the
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

Stages (:func:`design_gyrocompass`; level damping zeta = 1/sqrt(2); the gains follow from omega_L and sigma):

1. coarse levelling: natural period 10 s, azimuth open (k3 = 0), 4 envelope time constants 1 / (zeta omega_L);
2. fine levelling at omega_L = sqrt(1 + 4 zeta^2) g N_g / N_a, the bandwidth that minimises the level loop's
   tilt variance N_a^2 omega_L / (4 zeta g^2) + N_g^2 (1 + 4 zeta^2) / (4 zeta omega_L) for the gyro and
   accelerometer white noise N_g, N_a, kept between the natural periods 20 s (a decade below the 0.5-50 Hz
   band of a vehicle's sway) and 300 s; 4 envelope time constants;
3. coarse azimuth: the azimuth root at its fastest, sigma_max = zeta omega_L / 2, for 5 of its time
   constants (a start error shrinks by e^-5; at most half of what is left of the window);
4. fine azimuth to the window's end, the time constant 1 / sigma growing with the time t spent in it as
   the minimum-variance estimate of a constant seen in white noise does (Gelb, A. (ed.), *Applied Optimal
   Estimation*, MIT Press, 1974, sec. 4.2): sigma = 1 / (tau0 + t). The optimal tau0 is q / P0, q =
   (N_E / W)^2 the east gyro noise seen as heading and P0 = q sigma_max / 2 the heading variance the coarse
   azimuth stage leaves, so 2 / sigma_max; tau0 = 1 / sigma_max is taken instead, so that k3 has no step:
   a step in k3 freezes the sway's heading ripple k3 X / g into the heading, which then decays only as
   slowly as the fine stage averages.

Stated limit (:func:`staged_limit`): its noise part is the exact 1-sigma of the
linear error model above (both channels, the Omega sin L coupling included) driven by
the sensors' white noise through the stages from the start's own noise (covariance
propagated in steps of 1 s, Van Loan's method); its bias part is the steady error at
the end's gains for the constant errors: the east drift over Omega cos L,
-b_gE / W, the accelerometer's b_aE tan L / g, and the loop's small own terms. It
leaves out what the base's motion does, which :mod:`~schuler.alignment.sway` measures
(tests/test_alignment_staged.py).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from schuler.alignment import _kernels
from schuler.alignment.data import MethodEstimate, StaticBatch
from schuler.alignment.inertial import start_attitude
from schuler.alignment.limits import (
    AccuracyLimit,
    accuracy_limit,
    effective_bias_sigma,
    horizontal_rate,
)
from schuler.core.attitude import euler_from_dcm
from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY, earth_rate_ned
from schuler.core.propagation import discretise_noise
from schuler.exceptions import InvalidParameter, renamed_keywords

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
class LoopStage:
    """One stage of the loop: its span, its level loop and its azimuth root (SI).

    Attributes
    ----------
    name : str
        ``coarse levelling``, ``fine levelling``, ``coarse azimuth`` or ``fine azimuth``.
    start_s, end_s : float
        Span from the window's start, s.
    level_period_s : float
        Natural period 2 pi / omega_L of the level loop, s.
    azimuth_time_constant_s : float or None
        1 / sigma of the azimuth root at the stage's start, s (None: azimuth open).
    growing : bool
        The azimuth time constant grows by the time spent in the stage (fine azimuth).
    """

    name: str
    start_s: float
    end_s: float
    level_period_s: float
    azimuth_time_constant_s: float | None
    growing: bool = False

    def azimuth_rate(self, time_s):
        """sigma at times ``time_s`` (s from the window's start) inside the stage, 1/s (0: azimuth open).

        Parameters
        ----------
        time_s : ndarray
            Times, s from the window's start.
        """
        time_s = np.asarray(time_s, dtype=float)
        if self.azimuth_time_constant_s is None:
            return np.zeros_like(time_s)
        if not self.growing:
            return np.full_like(time_s, 1.0 / self.azimuth_time_constant_s)
        return 1.0 / (self.azimuth_time_constant_s + (time_s - self.start_s))


def stage_gains(level_frequency: float, azimuth_rate, latitude: float):
    """(k1, k2, k3) placing the north channel's roots at the level pair and -sigma (module notes).

    Parameters
    ----------
    level_frequency : float
        omega_L of the level loop, rad/s.
    azimuth_rate : float or ndarray
        sigma of the azimuth root, 1/s (0: azimuth open, k3 = 0).
    latitude : float
        L, rad.

    Returns
    -------
    k1, k2, k3 : ndarray
        1/s, 1/s^2, 1/s^2, the shape of ``azimuth_rate``.
    """
    rate = float(horizontal_rate(latitude))
    w, sigma = level_frequency, np.asarray(azimuth_rate, dtype=float)
    k1 = 2.0 * LEVEL_DAMPING * w + sigma
    k2 = w**2 + 2.0 * LEVEL_DAMPING * w * sigma - rate**2
    k3 = np.where(sigma > 0, (sigma * w**2 - k1 * rate**2) / rate, 0.0)
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
    """The stages of one window's loop.

    Attributes
    ----------
    stages : tuple of LoopStage
        In time order, the first starting at 0 s and the last ending at the window's end.
    """

    stages: tuple[LoopStage, ...]

    def as_dicts(self) -> list[dict]:
        """The stages as plain dictionaries (JSON)."""
        return [asdict(stage) for stage in self.stages]

    def gains(self, time_s, latitude: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(k1, k2, k3) at times ``time_s`` (s from the window's start; beyond the last stage: its end gains).

        Parameters
        ----------
        time_s : ndarray
            Times, s.
        latitude : float
            L, rad.

        Returns
        -------
        k1, k2, k3 : ndarray
            1/s, 1/s^2, 1/s^2, one per time.
        """
        time_s = np.asarray(time_s, dtype=float)
        ends = np.array([stage.end_s for stage in self.stages])
        which = np.minimum(np.searchsorted(ends, time_s, side="right"), len(self.stages) - 1)
        gains = np.empty((3, time_s.size))
        for index, stage in enumerate(self.stages):
            chosen = which == index
            if np.any(chosen):
                inside = np.minimum(time_s[chosen], stage.end_s)
                gains[:, chosen] = stage_gains(2.0 * math.pi / stage.level_period_s,
                                               stage.azimuth_rate(inside), latitude)
        return gains[0], gains[1], gains[2]


def design_gyrocompass(errors, *, latitude: float, duration: float,
                       gravity: float = STANDARD_GRAVITY) -> GyrocompassDesign:
    """The stages for a window of ``duration`` s and these sensors (module notes).

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
    horizontal_rate(latitude)    # refuses a latitude where heading is unobservable
    n_g = float(np.mean(errors.gyro.random_walk[:2]))
    n_a = float(np.mean(errors.accel.random_walk[:2]))
    shortest, longest = (2.0 * math.pi / period for period in FINE_LEVEL_PERIOD_RANGE_S)
    fine = min(max(math.sqrt(1.0 + 4.0 * LEVEL_DAMPING**2) * gravity * n_g / max(n_a, 1e-30), longest), shortest)
    coarse = 2.0 * math.pi / COARSE_LEVEL_PERIOD_S
    coarse_end = min(STAGE_TIME_CONSTANTS / (LEVEL_DAMPING * coarse), LEVELLING_SHARE[0] * duration)
    fine_end = coarse_end + min(STAGE_TIME_CONSTANTS / (LEVEL_DAMPING * fine), LEVELLING_SHARE[1] * duration)
    fastest = LEVEL_DAMPING * fine / AZIMUTH_SEPARATION
    azimuth_end = fine_end + min(AZIMUTH_SETTLING / fastest, COARSE_AZIMUTH_SHARE * (duration - fine_end))
    fine_period = 2.0 * math.pi / fine
    return GyrocompassDesign((
        LoopStage("coarse levelling", 0.0, coarse_end, COARSE_LEVEL_PERIOD_S, None),
        LoopStage("fine levelling", coarse_end, fine_end, fine_period, None),
        LoopStage("coarse azimuth", fine_end, azimuth_end, fine_period, 1.0 / fastest),
        # sigma = 1 / (tau0 + t) from tau0 = 1 / sigma_max: no step in k3, which would freeze the sway's
        # heading ripple k3 X / g into the heading
        LoopStage("fine azimuth", azimuth_end, duration, fine_period, 1.0 / fastest, growing=True)))


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
    # steps of at most PROPAGATION_STEP_S inside each stage, the gains taken at each step's middle
    edges = np.unique(np.concatenate([np.linspace(stage.start_s, stage.end_s,
                                                  max(2, math.ceil((stage.end_s - stage.start_s)
                                                                   / PROPAGATION_STEP_S) + 1))
                                      for stage in design.stages]))
    k1, k2, k3 = design.gains((edges[:-1] + edges[1:]) / 2.0, latitude)
    for step in range(edges.size - 1):
        A, B = error_model(latitude, k1[step], k2[step], k3[step], gravity)
        transition, driven = discretise_noise(A, B @ intensity @ B.T, float(edges[step + 1] - edges[step]))
        P = transition @ P @ transition.T + driven
    end_k1, end_k2, end_k3 = design.gains(np.array([design.stages[-1].end_s]), latitude)
    A, B = error_model(latitude, float(end_k1[0]), float(end_k2[0]), float(end_k3[0]), gravity)
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


@renamed_keywords(initial_window_s="initial_window", history_step_s="history_step")
def align_staged_gyrocompass(batch: StaticBatch, design: GyrocompassDesign, *, initial_window: float = 30.0,
                             history_step: float = 1.0) -> MethodEstimate:
    """The staged strapdown gyrocompass over every record of ``batch``, started from inertial-frame alignment.

    Parameters
    ----------
    batch : StaticBatch
        The static records.
    design : GyrocompassDesign
        Stages and gains (:func:`design_gyrocompass` for this window).
    initial_window : float
        Inertial-frame alignment over the first seconds gives the start, s.
    history_step : float
        Step of the histories, s.

    Returns
    -------
    MethodEstimate
        No 1-sigma of its own: its accuracy is its stated limit (:func:`staged_limit`).
    """
    dt = batch.sample_interval_s
    attitude = start_attitude(batch.head(initial_window))
    ends = batch.history_indices(history_step)
    k1, k2, k3 = design.gains(dt * (np.arange(batch.samples) + 0.5), batch.latitude_rad)
    history = np.empty((batch.members, ends.size, 3, 3))
    _kernels.staged_gyrocompass_loop(batch.gyro_increment, batch.accel_increment, dt, attitude,
                                     earth_rate_ned(batch.latitude_rad), batch.gravity, k1, k2, k3, ends, history)
    roll, pitch, heading = euler_from_dcm(history)
    return MethodEstimate("gyrocompass", roll[:, -1], pitch[:, -1], heading[:, -1], None, ends * dt, roll, pitch,
                          heading)
