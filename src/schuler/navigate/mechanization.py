"""Run the nonlinear INS: a trajectory's truth, its ideal IMU with errors, and the navigation computer.

:func:`navigate` streams the truth and the ideal IMU (:mod:`schuler.navigate.truth`)
in blocks through the numba loops (:mod:`schuler.navigate._loops`) for a batch
of N members at once, and returns the errors (computed - true) at every output
step. Memory is the output (N x n_out x 10 values) plus one block of samples;
it is estimated before anything is allocated.

Two mechanizations share the navigation equations (Groves 2013, Sec. 5.4-5.5;
Savage 2000):

* ``strapdown``: the sensors are fixed to the body; the computer integrates
  the attitude from the gyros' angle increments (with coning correction) and
  transforms the velocity increments (rotation and sculling corrections).
* ``platform``: the sensors sit on a gimballed platform torqued at the
  computed frame rate omega_ie + omega_en so that it stays level and north-
  pointing (Britting 1971); a gyro bias b_g turns it away:
  psi' = -(omega_ie + omega_en) x psi - b_g (in platform axes). The computed
  body attitude is read off the gimbals: C_b^p = C_n^p C_b^n.

The vertical channel is ``free`` (pure inertial: diverges, spec 01 Problem 4),
``off`` (height and vertical velocity held to the truth, as by an ideal
altimeter) or ``baro`` (the third-order baro-aided loop of
:mod:`schuler.navigation_errors.vertical_channel` with critically damped gains,
on a barometric height with a constant error).

References
----------
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation
Systems*, 2nd ed., Artech House, 2013, ch. 5.
P. G. Savage, *Strapdown Analytics*, Strapdown Associates, 2000.
P. G. Savage, "Strapdown inertial navigation integration algorithm design, part 1: attitude
algorithms" and "part 2: velocity and position algorithms", *Journal of Guidance, Control, and
Dynamics* 21(1), 19-28 and 21(2), 208-221, 1998 (the two-sample coning and sculling corrections).
K. R. Britting, *Inertial Navigation Systems Analysis*, Wiley, 1971.

Examples
--------
>>> from schuler.navigate.trajectory import Stationary
>>> result = navigate(Stationary(latitude=np.radians(45.0)), duration=600.0, imu_rate=10.0, output_step=60.0,
...                   initial_errors=InitialErrors(velocity_error_north=0.1))
>>> round(float(result.position_error_north_m[-1]), 2)   # (dV / w_s) sin(w_s t) = 54.6 m
54.57
"""

from __future__ import annotations

import warnings

import numpy as np

from schuler.core.attitude import (
    attitude_error,
    conjugate,
    dcm_from_quaternion,
    euler_from_quaternion,
    quaternion_from_euler,
    quaternion_multiply,
    wrap_angle,
)
from schuler.core.earth import EARTH_RATE, radii_of_curvature, somigliana_gravity
from schuler.exceptions import InvalidParameter, SimulationError
from schuler.navigate import _kernels, _loops
from schuler.navigate.errors import ConstantSensorErrors, InitialErrors, SensorNoise
from schuler.navigate.results import NavigationResult, TruthSamples
from schuler.navigate.truth import DEFAULT_CHUNK, TruthGenerator
from schuler.navigate.validity import ModelValidityWarning, domain_message, validity_messages
from schuler.navigation_errors.vertical_channel import critically_damped_gains

MODES = ("strapdown", "platform")
VERTICAL_CHANNELS = ("free", "off", "baro")
_VERTICAL_CODES = {"free": _kernels.FREE, "off": _kernels.HELD, "baro": _kernels.BARO}

DEFAULT_MAX_MEMORY = 2 * 1024**3
"""Largest memory a run may plan for (outputs + one block of samples), bytes."""

NOISE_BLOCK_BYTES = 64 * 1024**2
"""Budget of one block of noise samples for all members, bytes."""


def output_interval(output_step: float, imu_rate: float) -> int:
    """IMU samples per output step; the step must be a whole number of IMU intervals.

    Parameters
    ----------
    output_step : float
        Time between outputs, s (> 0).
    imu_rate : float
        IMU sample rate, Hz (> 0).

    Returns
    -------
    int
        IMU intervals per output step, number of (>= 1).

    Raises
    ------
    InvalidParameter
        Naming ``imu_rate`` when it is not finite and positive; naming ``output_step``
        when it is not finite and positive or not a whole number of IMU intervals
        (to 1e-6 of the count).

    Examples
    --------
    >>> output_interval(10.0, 100.0)
    1000
    """
    if not (np.isfinite(imu_rate) and imu_rate > 0):
        raise InvalidParameter("imu_rate", f"must be finite and > 0 Hz, got {imu_rate!r}")
    if not (np.isfinite(output_step) and output_step > 0):
        raise InvalidParameter("output_step", f"must be finite and > 0, got {output_step!r}")
    count = output_step * imu_rate
    if round(count) < 1 or abs(count - round(count)) > 1e-6 * count:
        raise InvalidParameter("output_step", f"{output_step:g} s is not a whole number of IMU intervals "
                                              f"at {imu_rate:g} Hz")
    return round(count)


def _check_choice(name: str, value: str, choices: tuple[str, ...]) -> int:
    if value not in choices:
        raise InvalidParameter(name, f"{value!r} is not one of {', '.join(choices)}")
    return choices.index(value)


def _members(initial_errors: InitialErrors, sensor_errors: ConstantSensorErrors,
             member_ids) -> tuple[int | None, np.ndarray]:
    sizes = {name: n for name, n in (("initial_errors", initial_errors.members),
                                      ("sensor_errors", sensor_errors.members),
                                      ("member_ids", None if member_ids is None else np.size(member_ids)))
             if n is not None}
    if len(set(sizes.values())) > 1:
        raise InvalidParameter(next(iter(sizes)), f"member counts disagree: {sizes}")
    batch = next(iter(sizes.values())) if sizes else None
    n = batch or 1
    ids = np.arange(n) if member_ids is None else np.asarray(member_ids, dtype=np.int64).reshape(n)
    if ids.size and ids.min() < 0:
        raise InvalidParameter("member_ids", "member numbers must be >= 0")
    return batch, ids


def estimate_memory(members: int, n_outputs: int, chunk: int, with_noise: bool) -> int:
    """Bytes a run holds at once: outputs and errors per member, one block of truth and noise.

    Parameters
    ----------
    members : int
        Batch size N, number of members.
    n_outputs : int
        Output times per member, number of (the start included).
    chunk : int
        IMU samples per streamed block of truth (and noise), number of.
    with_noise : bool
        Whether the members carry sensor noise (one block of gyro and accelerometer noise each).

    Returns
    -------
    int
        Memory, bytes.

    Examples
    --------
    >>> estimate_memory(1000, 1081, 65536, False) // 2**20
    210
    """
    outputs = members * n_outputs * (_kernels.OUTPUT_SIZE + 13) * 8
    truth = n_outputs * 40 * 8 + chunk * 40 * 8
    noise = members * chunk * 6 * 8 * 2 if with_noise else 0
    return outputs + truth + noise


def _initial_states(generator: TruthGenerator, errors: InitialErrors, members: int, mode: str) -> np.ndarray:
    """Members' computed states at t = 0 (no previous increments: the truth starts the same way)."""
    truth = generator.initial_state()
    states = np.tile(truth, (members, 1))
    lat, lon, h = generator.initial_position
    states[:, _kernels.LAT], states[:, _kernels.LON], states[:, _kernels.HGT] = errors.apply_position(
        lat, lon, h, members)
    states[:, _kernels.SIN_LAT] = np.sin(states[:, _kernels.LAT])
    states[:, _kernels.COS_LAT] = np.cos(states[:, _kernels.LAT])
    dv = np.stack([errors.column(f"velocity_error_{axis}", members) for axis in ("north", "east", "down")], axis=1)
    states[:, _kernels.VEL:_kernels.VEL + 3] += dv
    states[:, _kernels.VEL_PREV:_kernels.VEL_PREV + 3] += dv
    euler = euler_from_quaternion(generator.initial_quaternion)
    computed = quaternion_from_euler(euler[0] + errors.column("roll_error", members),
                                     euler[1] + errors.column("pitch_error", members),
                                     euler[2] + errors.column("heading_error", members))
    if mode == "platform":
        # C_p^n = C_b^n C_b^p^T with the gimbals reading C_b^p = the computed attitude
        computed = quaternion_multiply(generator.initial_quaternion, conjugate(computed))
    # one sign for all (q and -q are the same rotation): the platform's q_pn starts near +1
    states[:, _kernels.QUAT:_kernels.QUAT + 4] = np.where(computed[..., :1] < 0.0, -computed, computed)
    return states


def _recorded(increments, n_samples: int, mode: str) -> np.ndarray | None:
    """The first ``n_samples`` rows of recorded increments, checked (None: the ideal IMU of the truth)."""
    if increments is None:
        return None
    if mode != "strapdown":
        raise InvalidParameter("mode", "recorded increments are body-axis (strapdown) samples; the platform "
                                       "mechanization senses in its own axes")
    array = np.asarray(increments, dtype=float)
    if array.ndim != 2 or array.shape[1] != 6 or array.shape[0] < n_samples:
        raise InvalidParameter("recorded_increments", f"shape {array.shape} must be (n, 6) with n >= {n_samples} "
                                                      "(the IMU intervals of the duration)")
    array = np.ascontiguousarray(array[:n_samples])
    if not np.all(np.isfinite(array)):
        raise InvalidParameter("recorded_increments", "must be finite")
    return array


def _baro_parameters(generator: TruthGenerator, time_constant: float, baro_error: float) -> np.ndarray:
    """k1, k2, k3 of the critically damped third-order loop (all poles at -1/tau) and the baro error."""
    if not (np.isfinite(baro_error) and abs(baro_error) <= 1e4):
        raise InvalidParameter("baro_error", f"must be finite and within 10 km, got {baro_error!r}")
    lat, _, h = generator.initial_position
    R_N, R_E = radii_of_curvature(lat)
    gains = critically_damped_gains(3, time_constant, float(np.sqrt(R_N * R_E)) + h,
                                    float(somigliana_gravity(lat, h)))
    return np.array([gains.k1, gains.k2, gains.k3, baro_error])


def _entered_earth_rate(part, previous_latitude: float, rate: float) -> np.ndarray:
    """Omega (cos L, -sin L) at the true latitude at the start of each interval of a chunk, (n, 2)."""
    latitude = np.concatenate([[previous_latitude], part.positions[:-1, 0]])
    return np.ascontiguousarray(np.stack([rate * np.cos(latitude), -rate * np.sin(latitude)], axis=1))


class _IntervalMeans:
    """Sums of the truth over each output interval, for the linear model's frozen coefficients."""

    def __init__(self, n_intervals: int, every: int, dt: float):
        self.every, self.dt = every, dt
        self.sums = {"latitude_rad": np.zeros(n_intervals), "height_m": np.zeros(n_intervals),
                     "velocity_ned_m_s": np.zeros((n_intervals, 3)),
                     "specific_force_ned_m_s2": np.zeros((n_intervals, 3)),
                     "body_to_ned": np.zeros((n_intervals, 3, 3))}

    def add(self, chunk) -> None:
        n = chunk.increments.shape[0]
        bins = (chunk.start + np.arange(n)) // self.every
        for name, values in (("latitude_rad", chunk.positions[:, 0]), ("height_m", chunk.positions[:, 2]),
                             ("velocity_ned_m_s", chunk.velocities),
                             ("specific_force_ned_m_s2", chunk.nav_increments[:, 3:] / self.dt),
                             ("body_to_ned", dcm_from_quaternion(chunk.quaternions))):
            np.add.at(self.sums[name], bins, values)

    def means(self) -> dict:
        return {name: total / self.every for name, total in self.sums.items()}


def navigate(trajectory, duration: float, *, imu_rate: float = 100.0, output_step: float = 10.0,
             mode: str = "strapdown", vertical_channel: str = "off", initial_errors: InitialErrors | None = None,
             sensor_errors: ConstantSensorErrors | None = None, noise: SensorNoise | None = None, member_ids=None,
             earth_rate: float = EARTH_RATE, coriolis_compensation: bool = True,
             centripetal_compensation: bool = True, earth_rate_latitude: str = "computed",
             azimuth_reference: bool = False, baro_error: float = 0.0,
             baro_time_constant: float = 100.0, max_memory: int = DEFAULT_MAX_MEMORY,
             record_interval_means: bool = False, recorded_increments=None) -> NavigationResult:
    """Simulate the nonlinear INS along a trajectory and return its errors at the output step.

    Parameters
    ----------
    trajectory : Stationary, GreatCircle or WaypointProfile
        A trajectory of :mod:`schuler.navigate.trajectory` (start position, velocity and attitude).
    duration : float
        s, a whole number of IMU intervals.
    imu_rate : float
        IMU sample rate, Hz.
    output_step : float
        s between outputs, a whole number of IMU intervals.
    mode : {"strapdown", "platform"}
    vertical_channel : {"free", "off", "baro"}
    initial_errors : InitialErrors, optional
        Errors of the initial state (default none).
    sensor_errors : ConstantSensorErrors, optional
        Constant sensor errors (default an ideal IMU).
    noise : SensorNoise, optional
        Additive increment noise (e.g. :class:`~schuler.navigate.errors.WhiteNoise`).
    member_ids : array_like of int, optional
        Global member numbers (default 0 .. N-1): the noise of a member depends on
        its number, so a Monte Carlo split into parts gives the same members.
    earth_rate : float
        Omega, rad/s (0 gives a non-rotating Earth for truth and computer alike).
    coriolis_compensation, centripetal_compensation : bool
        Whether the computer subtracts the Coriolis acceleration 2 omega_ie x v and
        uses gravity (with the centrifugal part) rather than gravitation. Turning
        both off gives the uncompensated W* of Drozdovich (1959).
    earth_rate_latitude : {"computed", "true"}
        The latitude of the computer's Earth rate: its own (an INS) or the true
        one, entered from outside (the compensation torques of Drozdovich (1959), eq. (8)).
    azimuth_reference : bool
        Platform only: slave the platform's azimuth to the true heading (an
        external azimuth reference), so that only its level axes answer to the
        gyros, as the two-axis gyro vertical of Drozdovich (1959).
    baro_error : float
        Constant barometric height error, m (``vertical_channel="baro"``).
    baro_time_constant : float
        tau of the baro loop, s: all three poles at -1/tau.
    max_memory : int
        Refuse runs that would hold more than this many bytes.
    record_interval_means : bool
        Also keep the truth's means over each output interval (for the linear model).
    recorded_increments : array_like, shape (n, 6), optional
        Measured (dtheta, dv) of each IMU interval, body axes x forward, y right,
        z down, rad and m/s (a recording, :mod:`schuler.navigate.recording`): the
        computer integrates these instead of the truth's ideal increments (the
        sensor errors and noise given still add to them). Strapdown only; at
        least as many rows as the duration has IMU intervals (the first are used).

    Returns
    -------
    NavigationResult

    Raises
    ------
    InvalidParameter
        For a bad argument or a run that would not fit in ``max_memory``.
    SimulationError
        When a member's computed state leaves the mechanization's domain (:mod:`schuler.navigate.validity`):
        the run stops at the end of that block of samples.

    Warns
    -----
    ModelValidityWarning
        When the computed height or the attitude error leaves the models' validity (also in the
        result's ``warnings``).
    """
    _check_choice("mode", mode, MODES)
    entered = _check_choice("earth_rate_latitude", earth_rate_latitude, ("computed", "true")) == 1
    if azimuth_reference and mode != "platform":
        raise InvalidParameter("azimuth_reference", "slaving the azimuth needs the platform mechanization")
    vertical_code = _VERTICAL_CODES[VERTICAL_CHANNELS[_check_choice("vertical_channel", vertical_channel,
                                                                    VERTICAL_CHANNELS)]]
    initial_errors = initial_errors or InitialErrors()
    sensor_errors = sensor_errors or ConstantSensorErrors()
    generator = TruthGenerator(trajectory, duration, imu_rate, earth_rate)
    recorded = _recorded(recorded_increments, generator.n_samples, mode)
    every = output_interval(output_step, imu_rate)
    batch, ids = _members(initial_errors, sensor_errors, member_ids)
    n_members = ids.size
    if generator.n_samples % every:
        raise InvalidParameter("duration", f"{duration:g} s is not a whole number of output steps of "
                                           f"{output_step:g} s")
    n_out = generator.n_samples // every + 1
    chunk = DEFAULT_CHUNK
    if noise is not None:
        chunk = int(min(DEFAULT_CHUNK, max(256, NOISE_BLOCK_BYTES // (n_members * 48))))
    needed = estimate_memory(n_members, n_out, chunk, noise is not None)
    if needed > max_memory:
        raise InvalidParameter("output_step", f"{n_members} member(s) x {n_out} outputs need about "
                                              f"{needed / 2**20:,.0f} MiB, above the {max_memory / 2**20:,.0f} MiB "
                                              "limit: use a coarser output step, fewer members per run, or a "
                                              "larger max_memory")
    baro = _baro_parameters(generator, baro_time_constant, baro_error)
    states = _initial_states(generator, initial_errors, n_members, mode)
    platform = mode == "platform"
    gyro = sensor_errors.rows("gyro", n_members, invert=platform)
    accel = sensor_errors.rows("accel", n_members)
    out = np.empty((n_members, n_out, _kernels.OUTPUT_SIZE))
    out[:, 0, :6] = states[:, [_kernels.LAT, _kernels.LON, _kernels.HGT, _kernels.VEL, _kernels.VEL + 1,
                               _kernels.VEL + 2]]
    out[:, 0, 6:] = states[:, _kernels.QUAT:_kernels.QUAT + 4]
    truth = np.empty((n_out, _kernels.OUTPUT_SIZE))
    truth[0] = np.concatenate([generator.initial_position, generator.initial_velocity, generator.initial_quaternion])
    means = _IntervalMeans(n_out - 1, every, generator.dt) if record_interval_means else None
    empty_noise = np.zeros((n_members, 0, 3))
    kernel = _loops.platform_chunk if platform else _loops.strapdown_chunk
    no_rate = np.zeros((0, 2))
    previous_latitude = generator.initial_position[0]
    flags = (float(coriolis_compensation), 0.0 if centripetal_compensation else 1.0)
    for part in generator.chunks(chunk):
        n = part.increments.shape[0]
        if noise is not None:
            gyro_noise, accel_noise = (np.ascontiguousarray(a) for a in
                                       noise.increments(ids, part.start, part.start + n, generator.dt))
        else:
            gyro_noise = accel_noise = empty_noise
        vertical = np.ascontiguousarray(np.stack([part.positions[:, 2], part.velocities[:, 2]], axis=1))
        sensed = part.nav_increments if platform else part.increments
        if recorded is not None:
            sensed = recorded[part.start:part.start + n]
        entered_rate = _entered_earth_rate(part, previous_latitude, generator.earth_rate) if entered else no_rate
        previous_latitude = part.positions[-1, 0]
        kernel(generator.dt, part.start, sensed, vertical, states, gyro, accel, gyro_noise, accel_noise,
               noise is not None, out, every, vertical_code, baro, generator.earth_rate, *flags, entered_rate, entered,
               *((azimuth_reference,) if platform else ()))
        if states[:, _kernels.LEFT_AT].any():
            raise SimulationError(domain_message(states, ids, batch, generator.dt, vertical_channel))
        ends = part.start + np.arange(1, n + 1)
        rows = np.flatnonzero(ends % every == 0)
        truth[ends[rows] // every] = np.concatenate([part.positions[rows], part.velocities[rows],
                                                     part.quaternions[rows]], axis=1)
        if means is not None and n_out > 1:
            means.add(part)
    result = _result(out, truth, generator, every, mode, vertical_channel, batch,
                     means.means() if means is not None else None)
    result.warnings = validity_messages(result.t_s, out[..., 2], np.reshape(result.attitude_error_rad,
                                                                             (n_members, n_out, 3)),
                                        ids, batch, vertical_channel)
    for message in result.warnings:
        warnings.warn(message, ModelValidityWarning, stacklevel=2)
    return result


def _result(out, truth, generator, every, mode, vertical_channel, batch, interval_means) -> NavigationResult:
    """Errors computed - true from the computed and true states at the output times."""
    lat_t, lon_t, h_t = truth[:, 0], truth[:, 1], truth[:, 2]
    lat_c, lon_c, h_c = out[..., 0], out[..., 1], out[..., 2]
    lat_m, h_m = 0.5 * (lat_c + lat_t), 0.5 * (h_c + h_t)
    R_N, R_E = radii_of_curvature(lat_m)
    q_true = truth[:, 6:]
    q_computed = out[..., 6:]
    if mode == "platform":  # the gimbals read C_b^p = C_n^p C_b^n
        q_computed = quaternion_multiply(conjugate(q_computed), q_true)
    angles = euler_from_quaternion(q_computed) - euler_from_quaternion(q_true)
    velocity = out[..., 3:6] - truth[:, 3:6]

    def shaped(array):
        return array if batch is not None else array[0]

    t = np.arange(truth.shape[0]) * every * generator.dt
    return NavigationResult(
        mode=mode,
        vertical_channel=vertical_channel,
        imu_rate_hz=1.0 / generator.dt,
        output_step_s=every * generator.dt,
        members=batch,
        t_s=t,
        position_error_north_m=shaped((lat_c - lat_t) * (R_N + h_m)),
        position_error_east_m=shaped(wrap_angle(lon_c - lon_t) * (R_E + h_m) * np.cos(lat_m)),
        height_error_m=shaped(h_c - h_t),
        velocity_error_north_m_s=shaped(velocity[..., 0]),
        velocity_error_east_m_s=shaped(velocity[..., 1]),
        velocity_error_down_m_s=shaped(velocity[..., 2]),
        roll_error_rad=shaped(wrap_angle(angles[..., 0])),
        pitch_error_rad=shaped(angles[..., 1]),
        heading_error_rad=shaped(wrap_angle(angles[..., 2])),
        attitude_error_rad=shaped(attitude_error(q_computed, q_true)),
        truth=TruthSamples(t, lat_t, lon_t, h_t, truth[:, 3:6], q_true, interval_means),
    )
