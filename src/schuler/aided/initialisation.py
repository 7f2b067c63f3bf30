"""How the aided filter starts: from a given state, from a static alignment, or in motion from GNSS.

``--initialisation`` chooses (:func:`initialise`):

* ``given``: the start handed over (the truth of a simulated drive, a configuration's or a reference's state)
  with its stated 1-sigma;
* ``static``: the vehicle is at rest for the first ``alignment_duration`` seconds. Coarse alignment
  (:func:`schuler.alignment.coarse.coarse_attitude`) of the mean specific force and angular rate over that
  window gives roll, pitch and heading; their 1-sigma are the static limits of the IMU's error model
  (:func:`schuler.alignment.limits.accuracy_limit`, method ``coarse``: heading
  sigma^2 = (b_gE / (Omega cos L))^2 + (N_E / (Omega cos L sqrt(T)))^2 + (b_aE tan L / g)^2, roll and pitch
  b_a / g and N_a / (g sqrt(T))). Position is the last GNSS fix of the window (its 1-sigma), velocity zero
  with :data:`AT_REST_VELOCITY_SIGMA`; the filter starts at the window's end;
* ``in-motion``: the filter waits for the first GNSS epoch at which the horizontal speed V_H reaches
  ``speed_threshold`` (every member's, in a batch). A ground vehicle moves along its body x axis (no sideslip,
  the IMU aligned with the vehicle), so its heading is the course over ground and its pitch the flight-path
  angle:

      heading = atan2(v_E, v_N),   pitch = atan2(-v_D, V_H),   roll = 0 (level),

  with 1-sigma sigma_heading^2 = (sigma_vN sin(heading))^2 + (sigma_vE cos(heading))^2 over V_H^2 and
  sigma_pitch = sigma_vD / V_H, the first-order errors of the two arctangents; where sigma_pitch exceeds
  :data:`LEVEL_SIGMA` (position-only fixes) the pitch is taken level too. Roll's 1-sigma is
  :data:`LEVEL_SIGMA`. Without GNSS velocities the velocity is the central difference of the fixes either
  side, v = (r_k+1 - r_k-1) / (t_k+1 - t_k-1), sigma_v^2 = (sigma_k+1^2 + sigma_k-1^2) / (t_k+1 - t_k-1)^2
  (its error from the change of acceleration, jerk dt^2 / 6, is left out). Position and velocity are those
  of the fix, moved from the antenna to the IMU through the lever arm (v - C (omega_ib x l); the Earth and
  transport rates' part, below 1e-4 m/s per metre of arm, left out). When the data are known to be at rest from
  their start for at least ``alignment_duration`` (a simulated drive's first stop; on files the first stop the
  moving-variance detector, :func:`schuler.aided.sources.detect_stops`, finds at the record's start), the gyros'
  mean over that window is also the initial gyro bias: b_hat = mean(omega_tilde) - (0, 0, -Omega sin L) in the
  level body axes, with 1-sigma sqrt(N_g^2 / T + (Omega cos L)^2 / 2) about x and y (the Earth rate's level
  part, whose direction the unknown heading hides) and N_g / sqrt(T) about z. A consumer IMU's 20 deg/s turn-on
  bias, which GNSS alone never sees at a stop, is so known to about 13 deg/h before the filter starts.

The filter's error model is the psi angle's first-order one: a heading error of a few degrees from the GNSS
course leaves second-order terms (1 - cos 5 deg = 0.4 %) well below the measurement noise, and the first turns
and speed changes make the heading observable through the velocity fixes, so the filter converges
(tests/test_aided_initialisation.py). A start whose heading or tilt 1-sigma exceeds :data:`LARGEST_SIGMA` is
refused rather than linearised: a larger heading error needs a coarse heading search the filter does not make.
The initial psi covariance is diagonal: its level components take the larger of the roll and pitch 1-sigma,
its down component the heading's (heading error = -psi_D).

References
----------
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed., Artech
House, 2013, sec. 5.6.2 (coarse alignment) and sec. 14.4.1 (in-motion initialisation from the GNSS track).
E.-H. Shin, *Estimation Techniques for Low-Cost Inertial Navigation*, PhD thesis, University of Calgary, 2005,
sec. 5.3 (heading from the GNSS velocity of a land vehicle).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from schuler.aided.ekf import Start
from schuler.aided.gnss import GnssRecord
from schuler.aided.measurements import Solution, antenna_position, antenna_velocity
from schuler.alignment.coarse import coarse_attitude
from schuler.alignment.limits import accuracy_limit
from schuler.core.attitude import dcm_from_euler, quaternion_from_euler
from schuler.core.earth import EARTH_RATE, radii_of_curvature
from schuler.exceptions import InvalidParameter, renamed_keywords
from schuler.imu.error_model import ErrorModel
from schuler.params import Parameter

MODES = ("given", "static", "in-motion")
"""The ways the filter starts (module docstring)."""

DEFAULT_SPEED_THRESHOLD = 5.0
"""GNSS horizontal speed above which an in-motion start takes the course as heading, m/s (a heading 1-sigma of
0.6 deg from 0.05 m/s velocities)."""

DEFAULT_ALIGNMENT_DURATION = 20.0
"""Length of a static alignment's window, s (inside the simulated drive's first 25-s stop)."""

LEVEL_SIGMA = math.radians(2.0)
"""1-sigma of the level assumption's roll (and pitch, where taken level), rad: a road's 2 % cross slope and the
IMU's mounting."""

AT_REST_VELOCITY_SIGMA = 0.01
"""1-sigma of the zero velocity a static start takes, each axis, m/s (a vehicle at rest, engine running)."""

LARGEST_SIGMA = math.radians(10.0)
"""The largest start attitude 1-sigma the first-order psi model is trusted with, rad (1 - cos 10 deg = 1.5 %)."""

PARAMETERS = (
    Parameter("initialisation", "", "given", "How the filter starts: given (the truth, a configuration's or "
              "reference's state), static (coarse alignment over --alignment-duration at rest) or in-motion "
              "(heading from the GNSS course above --speed-threshold; on a drive at rest from its start, the gyro bias "
              "of its first --alignment-duration).", kind="choice", choices=MODES),
    Parameter("speed_threshold", "m/s", DEFAULT_SPEED_THRESHOLD, "GNSS horizontal speed an in-motion start "
              "waits for.", minimum=0.5, maximum=100.0),
    Parameter("alignment_duration", "s", DEFAULT_ALIGNMENT_DURATION, "Stationary window of a static start, from "
              "the data's first sample.", minimum=1.0, maximum=3600.0),
)
"""The initialisation's options (appended to ``aided``'s parameters)."""


@dataclass(frozen=True)
class Initialisation:
    """How the filter starts: its :class:`~schuler.aided.ekf.Start`, when, and the start's attitude 1-sigma.

    Attributes
    ----------
    mode : str
        One of :data:`MODES`.
    start : Start
        Every member's initial solution and the filter's initial 1-sigma.
    first_sample : int
        Index of the first IMU increment the filter reads (0: the data's start).
    t0_s : float
        Time of the start, s (the data's time scale).
    attitude_sigma_rad : ndarray, shape (3,)
        1-sigma of the start's roll, pitch and heading, rad.
    gyro_bias_rad_s : ndarray, shape (N, 3), or None
        Each member's gyro bias found at rest before an in-motion start (module docstring), rad/s; None: none.
    gyro_bias_sigma_rad_s : ndarray, shape (3,), or None
        Its 1-sigma, rad/s.
    """

    mode: str
    start: Start
    first_sample: int
    t0_s: float
    attitude_sigma_rad: np.ndarray
    gyro_bias_rad_s: np.ndarray | None = None
    gyro_bias_sigma_rad_s: np.ndarray | None = None


@renamed_keywords(at_rest_s="at_rest")
def initialise(mode: str, increments: np.ndarray, interval: float, gnss: GnssRecord | Sequence[GnssRecord], *,
               given: Callable[[], Start], t0: float = 0.0, lever_arm=(0.0, 0.0, 0.0),
               imu: ErrorModel | None = None, speed_threshold: float = DEFAULT_SPEED_THRESHOLD,
               alignment_duration: float = DEFAULT_ALIGNMENT_DURATION,
               at_rest: float | None = None) -> Initialisation:
    """The filter's start by ``mode`` (module docstring).

    Parameters
    ----------
    mode : str
        ``given``, ``static`` or ``in-motion``.
    increments : ndarray, shape (N, n, 6)
        Each member's measured dtheta (rad) and dv (m/s); row i ends at t0 + (i + 1) interval.
    interval : float
        IMU interval, s.
    gnss : GnssRecord or sequence of GnssRecord
        The members' GNSS epochs (one shared record or one per member, with the same epochs).
    given : callable
        Returns the given start (``given`` mode), no arguments.
    t0 : float
        Time of the data's start, s.
    lever_arm : array_like, shape (3,)
        IMU to GNSS antenna, body axes, m.
    imu : ErrorModel or None
        The IMU's error model, whose static limits are a static start's 1-sigma (``static`` needs it).
    speed_threshold : float
        Horizontal GNSS speed an in-motion start waits for, m/s.
    alignment_duration : float
        Length of a static start's window, and of the rest window an in-motion start takes its gyro bias from, s.
    at_rest : float or None
        How long the data are known to be at rest from their start, s (None: not known, not checked): ``static``
        and ``in-motion`` refuse a window longer than a rest; ``in-motion`` takes the gyro bias of the window.

    Returns
    -------
    Initialisation

    Raises
    ------
    InvalidParameter
        An unknown mode; no GNSS speed reaching the threshold; a window longer than the rest (in-motion: a rest
        that is not zero) or the data, or without a GNSS fix; a start attitude 1-sigma above :data:`LARGEST_SIGMA`.
    """
    increments = np.asarray(increments, dtype=float)
    records = [gnss] if isinstance(gnss, GnssRecord) else list(gnss)
    if mode == "given":
        start = given()
        sigma = np.asarray(start.attitude_sigma, dtype=float)
        return Initialisation(mode, start, 0, t0, np.array([max(sigma[0], sigma[1])] * 2 + [sigma[2]]))
    if mode == "static":
        return _static(increments, interval, records, t0, np.asarray(lever_arm, float), imu, alignment_duration,
                       at_rest)
    if mode == "in-motion":
        if at_rest is not None and 0.0 < at_rest < alignment_duration - 1e-9:
            raise InvalidParameter("alignment_duration", f"{alignment_duration:g} s is longer than the {at_rest:g} s "
                                   "the data are at rest from their start, whose gyro bias an in-motion start takes: "
                                   f"give {at_rest:g} s or less")
        moving = _in_motion(increments, interval, records, t0, np.asarray(lever_arm, float), speed_threshold)
        if at_rest is None or imu is None or at_rest == 0.0:
            return moving
        return _with_bias_at_rest(moving, increments, interval, records, imu, alignment_duration)
    raise InvalidParameter("initialisation", f"{mode!r} is not one of {', '.join(MODES)}")


def _stack(records: list[GnssRecord], name: str) -> np.ndarray:
    """One field of the members' GNSS records, members first."""
    return np.stack([getattr(record, name) for record in records])


def _attitude_sigma(roll: float, pitch: float, heading: float, what: str, remedy: str) -> np.ndarray:
    """Psi's 1-sigma (level: the larger tilt's; down: the heading's), refused above :data:`LARGEST_SIGMA`."""
    for name, value in (("roll", roll), ("pitch", pitch), ("heading", heading)):
        if not value <= LARGEST_SIGMA:
            raise InvalidParameter("initialisation", f"{what} gives a {name} 1-sigma of {math.degrees(value):.3g} "
                                   f"deg, above the {math.degrees(LARGEST_SIGMA):g} deg the filter's small-angle "
                                   f"model takes: {remedy}")
    return np.array([max(roll, pitch), max(roll, pitch), heading])


def _imu_position(latitude, longitude, height, body_to_ned, lever_arm):
    """The IMU's position from the antenna's: the antenna's offset C l taken back (C l at the antenna's site)."""
    members = np.size(latitude)
    at_antenna = Solution(latitude, longitude, height, np.zeros((members, 3)), body_to_ned, np.zeros((members, 3)))
    return antenna_position(at_antenna, -lever_arm)


def _static(increments, interval, records, t0, lever_arm, imu, duration, at_rest) -> Initialisation:
    if imu is None:
        raise InvalidParameter("initialisation", "a static start needs the IMU's error model for its 1-sigma: "
                               "give `imu`")
    if at_rest is not None and duration > at_rest + 1e-9:
        raise InvalidParameter("alignment_duration", f"{duration:g} s is longer than the {at_rest:g} s the data "
                               "are at rest from their start")
    samples = int(round(duration / interval))
    if not 2 <= samples < increments.shape[1]:
        raise InvalidParameter("alignment_duration", f"{duration:g} s must hold at least 2 IMU samples and leave "
                               f"some of the {increments.shape[1] * interval:g} s of data to navigate")
    span = samples * interval
    end = t0 + span
    first = records[0]
    inside = np.flatnonzero((first.t_s >= t0 - 1e-9) & (first.t_s < end - 1e-6))
    if inside.size == 0:
        raise InvalidParameter("alignment_duration", f"no GNSS fix in the first {duration:g} s to take the position "
                               "from")
    k = int(inside[-1])
    latitude = _stack(records, "latitude_rad")[:, k]
    mean = increments[:, :samples].sum(axis=1) / span
    roll, pitch, heading = coarse_attitude(mean[:, 3:], mean[:, :3], latitude)
    limit = accuracy_limit("coarse", imu, latitude=float(np.mean(latitude)),
                           heading=math.atan2(np.mean(np.sin(heading)), np.mean(np.cos(heading))), duration=span)
    psi_sigma = _attitude_sigma(limit.roll_rad, limit.pitch_rad, limit.heading_rad,
                                f"a static alignment over {duration:g} s",
                                "a better IMU, a longer stop or --initialisation in-motion")
    quaternion = quaternion_from_euler(roll, pitch, heading)
    position = _imu_position(latitude, _stack(records, "longitude_rad")[:, k], _stack(records, "height_m")[:, k],
                             dcm_from_euler(roll, pitch, heading), lever_arm)
    start = Start(position[0], position[1], position[2], np.zeros((latitude.size, 3)), quaternion,
                  first.position_sigma_m[k], np.full(3, AT_REST_VELOCITY_SIGMA), psi_sigma)
    return Initialisation("static", start, samples, end,
                          np.array([limit.roll_rad, limit.pitch_rad, limit.heading_rad]))


def _with_bias_at_rest(start: Initialisation, increments, interval, records, imu: ErrorModel,
                       duration: float) -> Initialisation:
    """``start`` with the gyro bias of the first ``duration`` seconds at rest (module docstring)."""
    samples = int(round(duration / interval))
    if samples > start.first_sample:
        return start  # the rest overlaps the motion the start waits for: no window
    span = samples * interval
    latitude = _stack(records, "latitude_rad")[:, 0]
    mean = increments[:, :samples, :3].sum(axis=1) / span
    bias = mean.copy()
    bias[:, 2] += EARTH_RATE * np.sin(latitude)  # the gyros read -Omega sin L about a level body's z (down)
    noise = np.asarray(imu.gyro.random_walk, dtype=float) ** 2 / span
    level = (EARTH_RATE * math.cos(float(np.mean(latitude)))) ** 2 / 2.0
    sigma = np.sqrt(noise + np.array([level, level, 0.0]))
    return dataclasses.replace(start, gyro_bias_rad_s=bias, gyro_bias_sigma_rad_s=sigma)


def _track(records: list[GnssRecord]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each epoch's antenna velocity (N, k, 3) and its 1-sigma (k, 3), and which epochs have one (k,).

    The records' own velocities, else the central difference of the fixes either side (module docstring).
    """
    first = records[0]
    if first.velocity_ned_m_s is not None and first.velocity_sigma_m_s is not None:
        return _stack(records, "velocity_ned_m_s"), first.velocity_sigma_m_s, np.ones(first.t_s.size, bool)
    latitude, longitude, height = (_stack(records, name) for name in ("latitude_rad", "longitude_rad", "height_m"))
    t = first.t_s
    velocity = np.zeros(latitude.shape + (3,))
    sigma = np.full((t.size, 3), np.inf)
    valid = np.zeros(t.size, bool)
    if t.size >= 3:
        span = t[2:] - t[:-2]
        R_N, R_E = radii_of_curvature(latitude[:, 1:-1])
        h = height[:, 1:-1]
        velocity[:, 1:-1] = np.stack([(latitude[:, 2:] - latitude[:, :-2]) * (R_N + h),
                                      (longitude[:, 2:] - longitude[:, :-2]) * (R_E + h) * np.cos(latitude[:, 1:-1]),
                                      -(height[:, 2:] - height[:, :-2])], axis=-1) / span[None, :, None]
        sigma[1:-1] = np.sqrt(first.position_sigma_m[2:] ** 2 + first.position_sigma_m[:-2] ** 2) / span[:, None]
        # a difference across an outage is no velocity at the epoch
        valid[1:-1] = span <= 2.0 * 1.5 * np.median(np.diff(t))
    return velocity, sigma, valid


def _in_motion(increments, interval, records, t0, lever_arm, threshold) -> Initialisation:
    first = records[0]
    velocity, velocity_sigma, valid = _track(records)
    end = t0 + increments.shape[1] * interval
    speed = np.hypot(velocity[..., 0], velocity[..., 1])
    fast = valid & (first.t_s > t0) & (first.t_s < end - interval) & np.all(speed >= threshold, axis=0)
    if not fast.any():
        inside = valid & (first.t_s > t0)
        largest = float(speed[:, inside].max()) if inside.any() else 0.0
        raise InvalidParameter("speed_threshold", f"the GNSS speed never reaches {threshold:g} m/s (at most "
                               f"{largest:.3g} m/s): lower it or start otherwise (`initialisation` given or static)")
    k = int(np.argmax(fast))
    t_k = float(first.t_s[k])
    i = int(round((t_k - t0) / interval))
    v_antenna = velocity[:, k]
    v_horizontal = speed[:, k]
    heading = np.arctan2(v_antenna[:, 1], v_antenna[:, 0])
    sigma_v = velocity_sigma[k]
    mean_speed, mean_heading = float(np.mean(v_horizontal)), math.atan2(np.mean(np.sin(heading)),
                                                                        np.mean(np.cos(heading)))
    heading_sigma = math.hypot(sigma_v[0] * math.sin(mean_heading), sigma_v[1] * math.cos(mean_heading)) / mean_speed
    pitch_sigma = float(sigma_v[2]) / mean_speed
    pitch = np.arctan2(-v_antenna[:, 2], v_horizontal)
    if pitch_sigma > LEVEL_SIGMA:
        pitch, pitch_sigma = np.zeros_like(pitch), LEVEL_SIGMA
    roll = np.zeros_like(heading)
    psi_sigma = _attitude_sigma(LEVEL_SIGMA, pitch_sigma, heading_sigma,
                                f"an in-motion start at {mean_speed:.3g} m/s", "a higher --speed-threshold")
    C = dcm_from_euler(roll, pitch, heading)
    latitude, longitude, height = (_stack(records, name)[:, k] for name in ("latitude_rad", "longitude_rad",
                                                                            "height_m"))
    rate = increments[:, max(i - 1, 0), :3] / interval  # the sample ending at the fix
    at_antenna = Solution(latitude, longitude, height, v_antenna, C, rate)
    v_imu = v_antenna - (antenna_velocity(at_antenna, lever_arm) - v_antenna)
    position = _imu_position(latitude, longitude, height, C, lever_arm)
    start = Start(position[0], position[1], position[2], v_imu, quaternion_from_euler(roll, pitch, heading),
                  first.position_sigma_m[k], np.asarray(sigma_v, dtype=float), psi_sigma)
    return Initialisation("in-motion", start, i, t_k, np.array([LEVEL_SIGMA, pitch_sigma, heading_sigma]))


def start_report(mode: str, run, errors) -> dict:
    """What the result says of the start: the mode, its time, the filter's initial psi 1-sigma, the heading error.

    Parameters
    ----------
    mode : str
        The initialisation that ran (:data:`MODES`).
    run : FilterRun
        A filter run of one member (its first stored covariance is the start's).
    errors : analysis.Errors or None
        Its errors (computed - true); the heading error is the first output's, one IMU interval after the start
        (None without a truth).
    """
    sigma = np.sqrt(np.diagonal(run.covariance[0, 0])[6:9])
    heading = None if errors is None or errors.heading.shape[-1] == 0 else float(errors.heading[0, 0])
    return {"mode": mode, "t_s": float(run.covariance_t_s[0]), "psi_sigma_rad": [float(value) for value in sigma],
            "heading_error_rad": heading}
