"""A mission resolved from its parameters: the instrument, the stages, the trajectory and the error sources.

Conventions (docs/conventions.md): NED navigation frame, body x forward / y
right / z down, errors = computed - true, sensor bias = measured - true, SI.

The life of the instrument, in the order the stages happen:

0. **The instrument** (``imu``): a grade's preset, a spec file, or a
   recording's identified noise terms (:func:`error_model`).

1. **Calibration** leaves a residual gyro bias per axis (and, for the
   multi-position method, residual accelerometer biases and scale factors):

   * ``pulse`` (schuler calibrate, alternating torque pulses, gyros only): the drift is
     measured with the method's relative error rho (the source's 0.34 %) and
     the angle-random-walk floor of averaging over the calibration time T_c:
     sigma_b^2 = (rho b)^2 + N_g^2 / T_c. Accelerometer biases and all scale
     factors keep their spec-sheet values.
   * ``multi-position`` (a static test in +/- positions of every axis over T_c,
     each axis seeing each sign for T_c / 2): the least-squares standard error
     of a bias from white noise, sigma_b = N / sqrt(T_c) (gyros and
     accelerometers), and of an accelerometer scale factor from the +/- g
     positions, sigma_S = N_a / (g sqrt(T_c)). Gyro scale factors keep their
     spec-sheet values (the Earth rate is too small to calibrate them without a
     rate table).

   Either way the slow terms (bias instability, rate random walk) change the
   bias after calibration; their change over the rest of the mission (alignment
   plus navigation) is added as sqrt(2) sigma_A(window) (IEEE 952; the IMU
   layer's :func:`~schuler.imu.system_inputs.residual_bias`) and held constant,
   the approximation the Monte Carlo makes too.

2. **Alignment** at rest at the start point, over T_a (closed forms in
   :mod:`schuler.mission.stages`).

3. **Navigation** along the trajectory (nonlinear INS or its psi-angle model).

Sources of error (independent, each one name in the budget): ``gyro_bias_x|y|z``,
``accel_bias_x|y|z`` (what calibration leaves), ``gyro_scale_factor_x|y|z``,
``accel_scale_factor_x|y|z``, ``north_reference`` (ground gyrocompass only),
``initial_position_north|east`` (constant, each with its 1-sigma) and the white
noises ``gyro_random_walk``, ``accel_random_walk`` (angle / velocity random walk,
acting during alignment and during navigation). Misalignments, g-sensitivity
and quantization are left out of this study.

4. **Aiding** (optional, ``aiding`` set): GNSS position, or position and
   velocity, at ``gnss_rate`` through scheduled outages, and on the ``drive``
   zero-velocity updates at its stops (``zupt``, at ``zupt_rate`` inside the
   drive's stationary intervals) and the wheel's odometer speed and
   non-holonomic constraint (``odometer``, ``nhc``, at ``odometer_rate``), with
   the keys and names of ``schuler aided`` (:class:`Aiding`; the measurements
   in :mod:`schuler.mission.aiding_measurements`, the analysis in
   :mod:`schuler.mission.aiding`). Their noises add the sources
   ``gnss_position_noise``, ``gnss_velocity_noise``, ``zupt_noise``,
   ``odometer_noise`` and ``nhc_noise``.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass
from functools import cached_property, lru_cache
from pathlib import Path

import numpy as np

from schuler.aided.aiding import named
from schuler.aided.evaluation import SIMULATED_SIGMA, SIMULATED_VELOCITY_SIGMA, aiding_of, lever_arm, outages_of
from schuler.core.earth import STANDARD_GRAVITY
from schuler.exceptions import InvalidParameter
from schuler.imu.error_model import ErrorModel
from schuler.imu.instrument import resolve_model
from schuler.imu.system_inputs import residual_bias
from schuler.navigate.drive import drive
from schuler.navigate.profile import load_profile
from schuler.navigate.trajectory import GreatCircle, Stationary, WaypointProfile

CALIBRATIONS = ("pulse", "multi-position")
ALIGNMENTS = ("kalman", "strapdown-gyrocompass", "gyrocompass", "ground-gyrocompass")
SELF_ALIGNMENTS = ("kalman", "strapdown-gyrocompass")
"""Strapdown self-alignments at rest: to first order, the same residuals (:mod:`schuler.mission.stages`)."""
TRAJECTORIES = ("stationary", "great-circle", "flight", "drive")
VERTICAL_CHANNELS = ("off", "free")

AXES = ("x", "y", "z")
CONSTANT_SOURCES = (
    *(f"gyro_bias_{a}" for a in AXES), *(f"accel_bias_{a}" for a in AXES),
    *(f"gyro_scale_factor_{a}" for a in AXES), *(f"accel_scale_factor_{a}" for a in AXES),
    "north_reference", "initial_position_north", "initial_position_east",
)
"""Constant error sources, in the order of :attr:`MissionSetup.constant_sigmas`."""
WHITE_SOURCES = ("gyro_random_walk", "accel_random_walk")
"""White-noise sources (angle and velocity random walk)."""
SOURCES = CONSTANT_SOURCES + WHITE_SOURCES
"""Every source of the budget."""

GNSS_SOURCES = ("gnss_position_noise", "gnss_velocity_noise")
"""White measurement-noise sources of GNSS (position, velocity)."""
VEHICLE_SOURCES = ("zupt_noise", "odometer_noise", "nhc_noise")
"""White measurement-noise sources of a drive's zero-velocity updates, odometer and non-holonomic constraint."""
AIDING_SOURCES = GNSS_SOURCES + VEHICLE_SOURCES
"""Every measurement-noise source an aided mission may add to the budget."""

AIDING_NAMES = ("gnss-position", "gnss-velocity", "zupt", "odometer", "nhc")
"""The measurements a mission's ``aiding`` may name (``schuler aided``'s names)."""
DRIVE_AIDING = ("zupt", "odometer", "nhc")
"""The measurements only the ``drive`` has: its stops and its wheels."""

FLIGHT_ACCELERATION_TIME = 300.0
"""Take-off run of the ``flight`` profile: 0 to cruise speed, s."""
FLIGHT_TURN_TIME = 120.0
"""Duration of each turn of the ``flight`` profile, s."""


@dataclass(frozen=True)
class Aiding:
    """The aiding of a mission: GNSS fixes through outages and a drive's stops and wheels, as ``schuler aided``
    simulates them (SI).

    Parameters
    ----------
    use_velocity : bool
        Whether GNSS velocities are used besides the positions.
    gnss_rate : float
        Epoch rate, Hz (epochs at j / rate, s).
    position_sigma : tuple of float
        1-sigma of a fix, north, east, down, m.
    velocity_sigma : float
        1-sigma of a GNSS velocity, each axis, m/s.
    lever_arm : tuple of float
        IMU to antenna, body axes, m.
    outages : tuple of (float, float)
        (start, duration) of each outage, s from the start of navigation.
    covariance_interval : float
        Step of the filter's covariance propagation, s.
    vehicle : tuple of str
        The drive's measurements used, in the order of :data:`DRIVE_AIDING` (``zupt``, ``odometer``, ``nhc``).
    zupt_rate : float
        Rate of the zero-velocity updates inside a stop, Hz.
    zupt_sigma : float
        1-sigma of the velocity at a stop, each axis, m/s.
    odometer_rate : float
        Rate of the odometer and of the non-holonomic constraint, Hz.
    odometer_sigma : float
        1-sigma of the odometer's speed, m/s.
    nhc_sigma : float
        1-sigma of the wheel point's lateral and vertical velocities, m/s.
    wheel_lever_arm : tuple of float
        IMU to the wheel's contact point, body axes, m.
    """

    use_velocity: bool
    gnss_rate: float
    position_sigma: tuple[float, float, float]
    velocity_sigma: float
    lever_arm: tuple[float, float, float]
    outages: tuple[tuple[float, float], ...]
    covariance_interval: float
    vehicle: tuple[str, ...]
    zupt_rate: float
    zupt_sigma: float
    odometer_rate: float
    odometer_sigma: float
    nhc_sigma: float
    wheel_lever_arm: tuple[float, float, float]

    @property
    def sources(self) -> tuple[str, ...]:
        """The measurement-noise sources this aiding adds to the budget, in the order of :data:`AIDING_SOURCES`."""
        gnss = GNSS_SOURCES if self.use_velocity else GNSS_SOURCES[:1]
        return gnss + tuple(f"{name}_noise" for name in DRIVE_AIDING if name in self.vehicle)


def aiding_setup(values) -> Aiding | None:
    """The :class:`Aiding` of a case's SI values, or None when ``aiding`` is not set (free-inertial).

    The defaults are ``schuler aided``'s: GNSS 1-sigma
    :data:`~schuler.aided.evaluation.SIMULATED_SIGMA` and
    :data:`~schuler.aided.evaluation.SIMULATED_VELOCITY_SIGMA`, the first outage at
    :data:`~schuler.aided.evaluation.SIMULATED_OUTAGE_START`, the lever arms zero, and the stops' and wheel's
    rates and 1-sigma of :data:`schuler.aided.aiding.PARAMETERS`.

    Parameters
    ----------
    values : Mapping of str to object
        ``aiding`` (comma-separated names of :data:`AIDING_NAMES`, or None), ``gnss_rate``
        (Hz), ``gnss_sigma_north|east|down`` (m or None), ``gnss_velocity_sigma`` (m/s or None),
        ``lever_arm_x|y|z`` (m or None), ``outage_start``, ``outage_duration``, ``outage_every``, ``duration`` and
        ``covariance_interval`` (s), ``zupt_rate`` and ``odometer_rate`` (Hz), ``zupt_sigma``, ``odometer_sigma``
        and ``nhc_sigma`` (m/s), ``wheel_lever_arm_x|y|z`` (m).

    Returns
    -------
    Aiding or None
        The aiding, SI.

    Raises
    ------
    InvalidParameter
        ``aiding`` names a measurement the mission does not have (``zaru`` and ``baro`` are ``schuler aided``'s
        only), or lacks ``gnss-position``.
    """
    if values["aiding"] is None:
        return None
    for name in (part.strip() for part in str(values["aiding"]).split(",")):
        if name and name not in AIDING_NAMES:
            hint = difflib.get_close_matches(name, AIDING_NAMES, n=1)
            raise InvalidParameter("aiding", f"{name!r} is not a measurement of a mission"
                                   + (f"; did you mean {hint[0]!r}?" if hint else "")
                                   + f" choose from {', '.join(AIDING_NAMES)}")
    _, use_velocity = aiding_of(values["aiding"])
    vehicle = tuple(name for name in DRIVE_AIDING if name in named(values["aiding"]))
    sigma = tuple(float(fallback if values[name] is None else values[name]) for name, fallback in
                  zip(("gnss_sigma_north", "gnss_sigma_east", "gnss_sigma_down"), SIMULATED_SIGMA))
    velocity_sigma = SIMULATED_VELOCITY_SIGMA if values["gnss_velocity_sigma"] is None \
        else float(values["gnss_velocity_sigma"])
    return Aiding(use_velocity=use_velocity, gnss_rate=float(values["gnss_rate"]),
                  position_sigma=sigma,  # type: ignore[arg-type]
                  velocity_sigma=velocity_sigma, lever_arm=lever_arm(values), outages=outages_of(values),
                  covariance_interval=float(values["covariance_interval"]), vehicle=vehicle,
                  zupt_rate=float(values["zupt_rate"]), zupt_sigma=float(values["zupt_sigma"]),
                  odometer_rate=float(values["odometer_rate"]), odometer_sigma=float(values["odometer_sigma"]),
                  nhc_sigma=float(values["nhc_sigma"]),
                  wheel_lever_arm=tuple(float(values[f"wheel_lever_arm_{axis}"])  # type: ignore[arg-type]
                                        for axis in AXES))


@dataclass(frozen=True)
class MissionSetup:
    """One mission: the instrument's error model, the stage choices and the trajectory (SI).

    Build it with :func:`mission_setup` from a case's values.
    """

    error_model: ErrorModel
    latitude: float
    longitude: float
    height: float
    calibration: str
    calibration_duration: float
    pulse_relative_error: float
    alignment: str
    alignment_duration: float
    gyrocompass_time_constant: float
    gyrocompass_damping: float
    north_reference_error: float
    trajectory_kind: str
    duration: float
    speed: float
    heading: float
    vertical_channel: str
    output_step: float
    initial_position_error: float
    profile: WaypointProfile | None = None
    aiding: Aiding | None = None

    @property
    def gravity(self) -> float:
        return STANDARD_GRAVITY

    def trajectory(self):
        """The vehicle's trajectory (:mod:`schuler.navigate.trajectory`).

        ``stationary``: at rest, level, at the heading. ``great-circle``: a geodesic at
        the speed and height from the start. ``flight``: at rest at t = 0, a
        take-off run to the speed over 300 s, a 90-deg right turn at 35 % and a
        90-deg left turn at 70 % of the mission (120 s each), level at the height.
        ``drive``: a car's drive over the duration (:func:`schuler.navigate.drive.drive`: four stops, 10 m/s in
        town, 20 m/s on the road, 90-deg turns, no banking) from the start point and heading; the speed is not
        used. ``profile``: the waypoint profile file's (:mod:`schuler.navigate.profile`;
        after its last waypoint it holds that waypoint's values).
        """
        if self.profile is not None:
            return self.profile
        if self.trajectory_kind == "stationary":
            return Stationary(latitude=self.latitude, longitude=self.longitude, height=self.height,
                              heading=self.heading)
        if self.trajectory_kind == "great-circle":
            return GreatCircle(latitude=self.latitude, longitude=self.longitude, height=self.height,
                               heading=self.heading, speed=self.speed, duration=self.duration)
        if self.trajectory_kind == "drive":
            return drive(latitude=self.latitude, longitude=self.longitude, height=self.height, heading=self.heading,
                         duration=self.duration)
        d = self.duration
        shortest = 4 * (FLIGHT_ACCELERATION_TIME + FLIGHT_TURN_TIME)
        if d < shortest:
            raise InvalidParameter("duration", f"a flight needs at least {shortest:g} s (take-off run and two turns), "
                                   f"got {d:g} s")
        times = [0.0, FLIGHT_ACCELERATION_TIME, 0.35 * d, 0.35 * d + FLIGHT_TURN_TIME, 0.7 * d,
                 0.7 * d + FLIGHT_TURN_TIME]
        speeds = [0.0] + [self.speed] * 5
        quarter = math.pi / 2
        headings = [self.heading] * 3 + [self.heading + quarter] * 2 + [self.heading]
        return WaypointProfile(latitude=self.latitude, longitude=self.longitude, height=self.height,
                               times=np.array(times), speeds=np.array(speeds), headings=np.array(headings),
                               flight_path_angles=np.zeros(6), name="flight")

    @property
    def window(self) -> float:
        """Time from calibration to the end of the mission, s (what the slow bias terms act over)."""
        return self.alignment_duration + self.duration

    def gyro_bias_sigma(self) -> np.ndarray:
        """1-sigma gyro bias per body axis left by calibration and the slow terms, rad/s."""
        gyro = self.error_model.gyro
        slow = residual_bias(gyro, self.window, include_turn_on=False)
        if self.calibration == "pulse":
            calibrated = np.hypot(self.pulse_relative_error * gyro.bias,
                                  gyro.random_walk / math.sqrt(self.calibration_duration))
        else:
            calibrated = gyro.random_walk / math.sqrt(self.calibration_duration)
        return np.hypot(calibrated, slow)

    def accel_bias_sigma(self) -> np.ndarray:
        """1-sigma accelerometer bias per body axis, m/s^2 (spec sheet, or multi-position residual)."""
        accel = self.error_model.accel
        if self.calibration == "multi-position":
            slow = residual_bias(accel, self.window, include_turn_on=False)
            return np.hypot(accel.random_walk / math.sqrt(self.calibration_duration), slow)
        return residual_bias(accel, self.window, include_turn_on=True)

    def accel_scale_factor_sigma(self) -> np.ndarray:
        accel = self.error_model.accel
        if self.calibration == "multi-position":
            return accel.random_walk / (self.gravity * math.sqrt(self.calibration_duration))
        return accel.scale_factor.copy()

    @cached_property
    def constant_sigmas(self) -> np.ndarray:
        """1-sigma of each of :data:`CONSTANT_SOURCES`, SI (computed once: the covariance and the Monte Carlo
        both read it, and the slow terms' Allan variances are its cost)."""
        north = self.north_reference_error if self.alignment == "ground-gyrocompass" else 0.0
        return np.concatenate([self.gyro_bias_sigma(), self.accel_bias_sigma(), self.error_model.gyro.scale_factor,
                               self.accel_scale_factor_sigma(),
                               [north, self.initial_position_error, self.initial_position_error]])

    @property
    def gyro_random_walk(self) -> np.ndarray:
        """Angle random walk per body axis, rad/sqrt(s)."""
        return np.asarray(self.error_model.gyro.random_walk, dtype=float)

    @property
    def accel_random_walk(self) -> np.ndarray:
        """Velocity random walk per body axis, m/s/sqrt(s)."""
        return np.asarray(self.error_model.accel.random_walk, dtype=float)


def error_model(imu: str) -> ErrorModel:
    """The instrument's error model from ``imu``: a grade, a TOML spec file or a recording.

    A recording (.csv, .imu, .parquet) gives its identified noise terms
    (:func:`~schuler.imu.instrument.resolve_model`, the resolution every system's
    ``imu`` uses: Allan analysis then :func:`~schuler.imu.characterise.model_from_analysis`).
    An Allan curve shows noise only, so such a model has no turn-on biases nor
    scale-factor errors: what calibration leaves of it is the noise floor and
    the slow terms' change.

    Parameters
    ----------
    imu : str
        A grade (:data:`~schuler.imu.spec.GRADES`), a TOML spec file or a recording (``.csv``, ``.imu``,
        ``.parquet``); its errors are SI.

    Returns
    -------
    ErrorModel
        The instrument's errors, SI.

    Raises
    ------
    InvalidParameter
        ``imu`` names neither a grade nor an existing file (named ``imu``).
    """
    path = Path(imu)
    # a recording is analysed once per process and file version (sweep chunks and Monte Carlo batches reuse it)
    stamp = (path.stat().st_mtime_ns, path.stat().st_size) if path.is_file() else None
    return _resolved(str(imu), stamp)


@lru_cache(maxsize=8)
def _resolved(imu: str, stamp: tuple[int, int] | None) -> ErrorModel:
    return resolve_model(imu)


def mission_setup(values, model: ErrorModel | None = None) -> MissionSetup:
    """A :class:`MissionSetup` from a case's SI values (a mapping with every parameter of the system).

    With a ``profile`` file, its ``[start]`` table and first waypoint's heading
    are the start point and heading (where the alignment happens).

    Parameters
    ----------
    values : Mapping of str to object
        Every parameter of :data:`~schuler.mission.evaluation.PARAMETERS` by name, SI (latitude, longitude,
        heading in rad; height in m; durations and steps in s; speed in m/s; ``pulse_relative_error`` a plain
        ratio; ``north_reference_error`` in rad; ``initial_position_error`` in m; the aiding's as
        :func:`aiding_setup` reads them), choices and paths as text.
    model : ErrorModel, optional
        The instrument's error model when the caller has resolved it already (a batch of cases of one
        instrument); not given: resolved from ``imu``.

    Returns
    -------
    MissionSetup
        The resolved mission: error model, stage choices, start point and trajectory.

    Raises
    ------
    InvalidParameter
        Bad aiding (:func:`aiding_setup`), or ``zupt``, ``odometer`` or ``nhc`` on a trajectory other than the
        drive (named ``aiding``).
    """
    if values["profile"]:
        profile = _profile(values["profile"])
        start = {"latitude": profile.latitude, "longitude": profile.longitude, "height": profile.height,
                 "heading": float(profile.headings[0])}
        kind = "profile"
    else:
        profile = None
        start = {name: float(values[name]) for name in ("latitude", "longitude", "height", "heading")}
        kind = str(values["trajectory"])
    aiding = aiding_setup(values)
    if aiding is not None and aiding.vehicle and kind != "drive":
        raise InvalidParameter("aiding", f"{', '.join(aiding.vehicle)}: on the drive trajectory only (its stops "
                                         f"and wheels), not on a {kind} trajectory")
    return MissionSetup(
        error_model=model if model is not None else error_model(values["imu"]),
        calibration=str(values["calibration"]), calibration_duration=float(values["calibration_duration"]),
        pulse_relative_error=float(values["pulse_relative_error"]),
        alignment=str(values["alignment"]), alignment_duration=float(values["alignment_duration"]),
        gyrocompass_time_constant=float(values["gyrocompass_time_constant"]),
        gyrocompass_damping=float(values["gyrocompass_damping"]),
        north_reference_error=float(values["north_reference_error"]),
        duration=float(values["duration"]), speed=float(values["speed"]),
        vertical_channel=str(values["vertical_channel"]), output_step=float(values["output_step"]),
        initial_position_error=float(values["initial_position_error"]), trajectory_kind=kind, profile=profile,
        aiding=aiding, **start,
    )


def _profile(path: str) -> WaypointProfile:
    """The waypoint profile file, its problems named by the ``profile`` parameter."""
    try:
        return load_profile(path)
    except InvalidParameter as error:
        # the reader names unreadable files as "trajectory" (navigate's option) and bad keys by their table
        reason = error.reason if error.name == "trajectory" else f"{path}: {error}"
        raise InvalidParameter("profile", reason) from None
