"""What ``schuler aided run`` evaluates on simulated data: parameters, outputs and ``evaluate``.

One case is a drive (:func:`schuler.navigate.drive.drive`), an IMU from the IMU
layer (``imu``: a grade, a spec file or a recording's identified terms) and GNSS
at ``gnss_rate`` with noise, lever arm, latency and scheduled outages
(:mod:`schuler.aided.gnss`). Each member draws its IMU errors
(:class:`schuler.imu.simulate.ImuSimulator`, streams addressed by member) and
its GNSS noise, and runs its own filter (:func:`schuler.aided.ekf.run_filter`;
the members of a batch run at once): the filter's sensor model comes from the
same IMU (:func:`schuler.aided.error_state.filter_model`), so the data match
the filter's model. The errors are computed - true against the drive
(:mod:`schuler.aided.analysis`). ``nominal`` evaluates ideal sensors and
noiseless GNSS; a run without Monte Carlo is member 0 of its seed.

The filter starts at the true solution with a 1-sigma of 1 m, 0.1 m/s, and
0.1, 0.1, 1 deg (roll, pitch, heading psi): the case of a prior alignment.

With ``record``, ``gnss_file``, ``reference`` or ``kf_gins_config`` set the case
runs on files instead (:mod:`schuler.aided.files`: times as in the data, the
outages the GNSS gaps, the errors against the reference or NaN without one);
the drive's own parameters (``duration``, ``latitude``, ``imu_rate``,
``gnss_rate``, ``gnss_latency``, ``nominal``) do not apply there. The options a
file can also set (``imu``, ``lever_arm_*``, ``gnss_sigma_*``, ``aiding``, the
outages) are "not set" by default, so that one given wins over the file.

Besides the error histories (``aided_errors``) every run keeps its navigation
solution with the filter's 1-sigma at every IMU epoch (``navigation``:
:mod:`schuler.aided.outputs` writes it as ``navigation.nav`` and
``navigation.csv``).

With ``smooth`` the first case's member 0 is also smoothed
(:func:`schuler.aided.smoother.smooth`, Rauch-Tung-Striebel over the forward
run): the extras gain ``smoothed``, the forward run's keys (outputs, outages,
NEES; the NIS and rejected epochs are the forward run's, the smoother
reprocesses no measurement) from the smoothed solution and covariance, and
``aided_errors`` the same channels prefixed ``smoothed_``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from schuler.aided import aiding as more_aiding
from schuler.aided import analysis, files, initialisation, smoother, sources
from schuler.aided.ekf import Start, run_filter
from schuler.aided.error_state import KINDS, FilterModel, filter_model, overridden
from schuler.aided.gnss import scheduled_outages, simulate_gnss
from schuler.aided.histories import error_histories, innovation_histories, navigation_histories, run_extras
from schuler.contract import Cases, Evaluation, Output
from schuler.exceptions import InvalidParameter
from schuler.imu.instrument import resolve_model
from schuler.imu.simulate import ImuSimulator
from schuler.memory import require
from schuler.navigate.evaluation import DRIVE_OPTIONS, trajectory_of
from schuler.navigate.evaluation import PARAMETERS as NAVIGATE_PARAMETERS
from schuler.navigate.trajectory import GreatCircle, Stationary, WaypointProfile, stationary_intervals
from schuler.navigate.truth import IdealImu, ideal_imu, sample_count
from schuler.params import Case, IntervalsParameter, Parameter, ParameterSet

TRAJECTORY_OPTIONS = ("longitude", "height", "heading", "speed", *DRIVE_OPTIONS)
"""``schuler navigate``'s options of the simulated trajectory, taken with their names and units."""

SIMULATED_ONLY = ("trajectory", "latitude", *TRAJECTORY_OPTIONS)
"""Options of a simulated case only: a record and its reference carry their own trajectory."""

AIDING = ("gnss-position", "gnss-velocity") + more_aiding.NAMES
"""The measurements ``aiding`` may name."""

SIMULATED_SIGMA = (0.5, 0.5, 1.0)
"""Simulated GNSS position 1-sigma when not set, north, east, down, m."""

SIMULATED_VELOCITY_SIGMA = 0.05
"""Simulated GNSS velocity 1-sigma when not set, each axis, m/s."""

SIMULATED_OUTAGE_START = 600.0
"""Start of a simulated drive's first outage when not set, s."""

START_SIGMA = (1.0, 0.1, (math.radians(0.1), math.radians(0.1), math.radians(1.0)))
"""The filter's initial 1-sigma: position (m, each axis), velocity (m/s), psi (rad: north, east, down)."""

PARAMETERS = ParameterSet((
    Parameter("trajectory", "", None, "The simulated vehicle's path: drive (a car's drive with stops, speed changes "
              "and 90-deg turns: schuler.navigate.drive), stationary, great-circle, or a waypoint profile FILE.toml "
              "(format: schuler.navigate.profile) (not set: drive).", kind="text"),
    Parameter("duration", "s", 1500.0, "Simulated time (the drive's length: its stops, turns, town and road "
              "speeds).", minimum=300.0, maximum=4 * 3600.0),
    Parameter("latitude", "deg", None, "Latitude of the start (not set: the drive's 30.5 deg, 45 deg on the other "
              "trajectories; a profile sets its own).", minimum=-80.0, maximum=80.0),
    *(NAVIGATE_PARAMETERS[name] for name in TRAJECTORY_OPTIONS),
    Parameter("imu", "", None, "IMU: a grade (navigation, tactical, industrial, consumer), a TOML spec file "
              "or a recording whose identified noise terms are used (not set: tactical; with --kf-gins-config its "
              "imunoise).", kind="text"),
    Parameter("imu_rate", "Hz", 100.0, "IMU sample rate.", minimum=10.0, maximum=1000.0),
    Parameter("gnss_rate", "Hz", 1.0, "GNSS epoch rate.", minimum=0.01, maximum=20.0),
    Parameter("gnss_sigma_north", "m", None, f"GNSS position 1-sigma, north (not set: {SIMULATED_SIGMA[0]:g} m "
              "simulated; a file's own).", minimum=0.0, exclusive_minimum=True, maximum=1e3),
    Parameter("gnss_sigma_east", "m", None, f"GNSS position 1-sigma, east (not set: {SIMULATED_SIGMA[1]:g} m "
              "simulated; a file's own).", minimum=0.0, exclusive_minimum=True, maximum=1e3),
    Parameter("gnss_sigma_down", "m", None, f"GNSS position 1-sigma, down (not set: {SIMULATED_SIGMA[2]:g} m "
              "simulated; a file's own).", minimum=0.0, exclusive_minimum=True, maximum=1e3),
    Parameter("gnss_velocity_sigma", "m/s", None, "GNSS velocity 1-sigma, each axis (not set: "
              f"{SIMULATED_VELOCITY_SIGMA:g} m/s simulated; a file's own).", minimum=0.0, exclusive_minimum=True,
              maximum=100.0),
    Parameter("lever_arm_x", "m", None, "IMU to GNSS antenna, body x (forward) (not set: 0; with --kf-gins-config "
              "its antlever).", minimum=-50.0, maximum=50.0),
    Parameter("lever_arm_y", "m", None, "IMU to GNSS antenna, body y (right) (not set: 0, or antlever).",
              minimum=-50.0, maximum=50.0),
    Parameter("lever_arm_z", "m", None, "IMU to GNSS antenna, body z (down) (not set: 0, or antlever).",
              minimum=-50.0, maximum=50.0),
    Parameter("gnss_latency", "s", 0.0, "Time between a fix's validity and its time tag.", minimum=0.0,
              maximum=1.0),
    Parameter("outage_start", "s", None, f"Start of the first GNSS outage (not set: {SIMULATED_OUTAGE_START:g} s "
              "on a simulated drive; none on files, whose outages are their gaps; times as in the data).",
              minimum=0.0),
    Parameter("outage_duration", "s", 60.0, "Length of each GNSS outage (0: none).", minimum=0.0),
    Parameter("outage_every", "s", None, "Time from one outage's start to the next's (not set: one outage).",
              minimum=0.0, exclusive_minimum=True),
    IntervalsParameter("outages", "s", None, "GNSS outages one by one, start:duration pairs (400:60,1000:90; "
                       "a scenario writes [[400, 60], [1000, 90]]; none: no outage); replaces the three options "
                       "above."),
    Parameter("aiding", "", None, "Measurements used, comma-separated: " + ", ".join(AIDING) + " (not set: both "
              "GNSS; with --kf-gins-config gnss-position, KF-GINS's model; odometer and baro simulated only).",
              kind="text"),
    *more_aiding.PARAMETERS,
    Parameter("covariance_interval", "s", 1.0, "Covariance propagation step (a whole number of IMU intervals; on "
              "files rounded to one).", minimum=0.0, exclusive_minimum=True, maximum=60.0),
    Parameter("filter_angle_random_walk", "deg/sqrt(h)", None, "The filter's gyro angle random walk, in place of "
              "the IMU model's (not set: the IMU's N; with --kf-gins-config its arw).", minimum=0.0, maximum=100.0),
    Parameter("filter_velocity_random_walk", "m/s/sqrt(h)", None, "The filter's velocity random walk, in place of "
              "the IMU model's (not set: the IMU's N; with --kf-gins-config its vrw).", minimum=0.0, maximum=100.0),
    Parameter("filter_gyro_bias", "deg/h", None, "The filter's gyro bias 1-sigma (steady for a Gauss-Markov model) "
              "(not set: from the IMU's bias terms; with --kf-gins-config its gbstd).", minimum=0.0, maximum=1e4),
    Parameter("filter_accel_bias", "mg", None, "The filter's accelerometer bias 1-sigma (not set: from the IMU's "
              "bias terms; with --kf-gins-config its abstd).", minimum=0.0, maximum=1e3),
    Parameter("filter_bias_model", "", None, "The filter's bias model (not set: random-walk, the turn-on "
              "bias a constant walked by the in-run terms; with --kf-gins-config gauss-markov).", kind="choice",
              choices=KINDS),
    Parameter("filter_correlation_time", "h", None, "T of the filter's Gauss-Markov biases (not set: the IMU's "
              "longest; with --kf-gins-config its corrtime).", minimum=0.0, exclusive_minimum=True, maximum=1e3),
    Parameter("nominal", "", False, "Ideal sensors and noiseless GNSS (every random term zero).", kind="flag"),
    Parameter("record", "", None, "IMU data file: KF-GINS increments (.txt and any other suffix), or the IMU "
              "layer's CSV, Parquet or PSINS .imu (not set: a simulated drive).", kind="text"),
    Parameter("gnss_file", "", None, "GNSS file in KF-GINS's format (7 columns, or 13 with velocities).",
              kind="text"),
    Parameter("reference", "", None, "Reference navigation in KF-GINS's format (11 columns): the truth of the "
              "errors, and the start without --kf-gins-config (not set: errors null).", kind="text"),
    Parameter("kf_gins_config", "", None, "KF-GINS YAML configuration (its paths relative to its folder, then to "
              "the working directory); options given here win over it.", kind="text"),
    Parameter("smooth", "", False, "Rauch-Tung-Striebel smoother over the forward run: the JSON's smoothed (the "
              "forward run's keys, outages included) and the smoothed errors and 1-sigma in aided_errors.",
              kind="flag"),
    *initialisation.PARAMETERS,
), owner="aided", exclusive=(("outages", "outage_start"), ("outages", "outage_duration"),
                               ("outages", "outage_every"), ("stop_intervals", "stops_from")))

OUTPUTS = (
    Output("position_error_horizontal_rms_m", "m", "", "RMS of the horizontal position error"),
    Output("position_error_horizontal_max_m", "m", "", "largest horizontal position error"),
    Output("position_error_vertical_rms_m", "m", "", "RMS of the vertical position error"),
    Output("velocity_error_horizontal_rms_m_s", "m/s", "", "RMS of the horizontal velocity error"),
    Output("heading_error_rms_rad", "rad", "deg", "RMS of the heading error"),
    Output("outage_horizontal_error_max_m", "m", "", "largest horizontal error in any outage"),
    Output("outage_horizontal_error_sigma_m", "m", "", "filter's horizontal 1-sigma at the end of that outage"),
    Output("rejected_measurements", "1", "", "measurement epochs the chi-square gate rejected, every source"),
    Output("start_heading_error_rad", "rad", "deg", "heading error at the filter's first output"),
    Output("start_heading_sigma_rad", "rad", "deg", "filter's initial heading 1-sigma (psi down)"),
)

SAMPLE_BYTES = 6 * 8 * 3 + 10 * 8 + 3 * 3 * 8
"""Bytes one member holds per IMU sample: its measured rates and increments (6 doubles, 3 copies at most), the
solution (10) and its three error histories (3 x 3)."""


def aiding_of(text: str | None, default: str = "gnss-position,gnss-velocity") -> tuple[bool, bool]:
    """Which GNSS measurements ``aiding`` names: (position, velocity); refuses an unknown one with a suggestion.

    The others it may name (:data:`schuler.aided.aiding.NAMES`) are read by :func:`schuler.aided.aiding.named`.

    Parameters
    ----------
    text : str or None
        Comma-separated names of :data:`AIDING`; None: ``default``.
    default : str
        The measurements used when ``text`` is None.
    """
    import difflib

    names = [name.strip() for name in str(default if text is None else text).split(",") if name.strip()]
    for name in names:
        if name not in AIDING:
            hint = difflib.get_close_matches(name, AIDING, n=1)
            raise InvalidParameter("aiding", f"{name!r} is not a measurement" + (f"; did you mean {hint[0]!r}?" if hint
                                   else "") + f" choose from {', '.join(AIDING)}")
    if "gnss-position" not in names:
        raise InvalidParameter("aiding", "gnss-position is needed (velocity alone leaves the position unobserved)")
    return True, "gnss-velocity" in names


def assumed(case: Case, model: FilterModel) -> FilterModel:
    """The filter's IMU model with the ``filter_*`` values the case states in place of the derived ones.

    Parameters
    ----------
    case : Case
        A validated case (SI: ``filter_angle_random_walk`` rad/sqrt(s), ``filter_velocity_random_walk``
        m/s/sqrt(s), ``filter_gyro_bias`` rad/s, ``filter_accel_bias`` m/s^2, ``filter_bias_model``,
        ``filter_correlation_time`` s; None keeps the model's).
    model : FilterModel
        The model derived from the IMU (or from KF-GINS's configuration).
    """
    return overridden(model, angle_random_walk=case["filter_angle_random_walk"],
                      velocity_random_walk=case["filter_velocity_random_walk"],
                      gyro_bias_sigma=case["filter_gyro_bias"], accel_bias_sigma=case["filter_accel_bias"],
                      bias=case["filter_bias_model"], correlation_time=case["filter_correlation_time"])


def outages_of(case: Case) -> tuple[tuple[float, float], ...]:
    """A simulated case's scheduled outages inside the drive, (start, duration) pairs, s.

    Parameters
    ----------
    case : Case
        A validated case (SI: ``outages``, else ``outage_start`` (None: :data:`SIMULATED_OUTAGE_START`),
        ``outage_duration``, ``outage_every``; ``duration`` in s).
    """
    return scheduled_outages(case, case["duration"], SIMULATED_OUTAGE_START)


def lever_arm(case: Case) -> tuple[float, float, float]:
    """A simulated case's lever arm, m (an axis not set: 0).

    Parameters
    ----------
    case : Case
        A validated case (``lever_arm_x|y|z`` in m or None).
    """
    return tuple(0.0 if case[name] is None else float(case[name])  # type: ignore[return-value]
                 for name in ("lever_arm_x", "lever_arm_y", "lever_arm_z"))


SMOOTHER_STATES = 21
"""States the smoother's memory estimate counts (the larger filter model)."""


def member_bytes(case: Case) -> int:
    """Memory one member holds while filtered, from its declared sizes per IMU sample (and per stored covariance
    time the smoother's prior P, Phi and correction with ``smooth``).

    Parameters
    ----------
    case : Case
        A validated case (SI: ``duration`` s, ``imu_rate`` and ``gnss_rate`` Hz, ``covariance_interval`` s).
    """
    kept = 0.0
    if case["smooth"]:
        stored = case["duration"] * (1.0 / case["covariance_interval"] + case["gnss_rate"]) + 1
        kept = 8.0 * stored * (2 * SMOOTHER_STATES**2 + SMOOTHER_STATES)
    return int(SAMPLE_BYTES * sample_count(case["duration"], case["imu_rate"]) + kept)


def _start(path, members: int) -> Start:
    v0, q0 = path.kinematics(np.array([0.0]))
    ones = np.ones(members)
    position, velocity, attitude = START_SIGMA
    return Start(path.latitude * ones, path.longitude * ones, path.height * ones, np.repeat(v0, members, 0),
                 np.repeat(q0, members, 0), np.full(3, position), np.full(3, velocity), np.asarray(attitude))


@dataclass(frozen=True, eq=False)
class SimulatedInputs:
    """What a simulated case's members are filtered from (SI; times from the drive's start).

    Attributes
    ----------
    path : Stationary, GreatCircle or WaypointProfile
        The trajectory (:func:`trajectory`; a drive: :func:`schuler.navigate.drive.drive`).
    truth : IdealImu
        Its truth and ideal increments at every IMU sample.
    increments : ndarray, shape (N, n, 6)
        Each member's measured dtheta (rad) and dv (m/s).
    gnss : list of GnssRecord
        Each member's GNSS epochs (outages removed).
    outages : tuple of (float, float)
        The scheduled outages, (start, duration), s.
    lever_arm : tuple of float
        IMU to antenna, body axes, m.
    use_velocity : bool
        Whether the GNSS velocities are simulated and used.
    """

    path: Stationary | GreatCircle | WaypointProfile
    truth: IdealImu
    increments: np.ndarray
    gnss: list
    outages: tuple[tuple[float, float], ...]
    lever_arm: tuple[float, float, float]
    use_velocity: bool


def trajectory(case: Case) -> Stationary | GreatCircle | WaypointProfile:
    """A simulated case's trajectory (``schuler navigate``'s, :func:`schuler.navigate.evaluation.trajectory_of`),
    not set a drive; its duration is the case's.

    Parameters
    ----------
    case : Case
        A validated simulated case (SI).
    """
    path, _ = trajectory_of("drive" if case["trajectory"] is None else case["trajectory"].strip(), case)
    return path


def simulated_inputs(case: Case, members: np.ndarray, streams) -> SimulatedInputs:
    """The drive, each member's IMU data and GNSS epochs of a simulated case (module docstring).

    Parameters
    ----------
    case : Case
        A validated simulated case (SI).
    members : ndarray of int
        Member numbers (the addresses of the random draws).
    streams : RandomStreams or None
        Where the IMU errors and the GNSS noise come from; None (or ``nominal``): none.
    """
    _, use_velocity = aiding_of(case["aiding"])
    path = trajectory(case)
    truth = ideal_imu(path, case["duration"], case["imu_rate"])
    dt = truth.interval_s
    ideal = np.concatenate([truth.angle_increment_rad, truth.velocity_increment_m_s], axis=1)
    noisy = streams is not None and not case["nominal"]
    if noisy:
        simulator = ImuSimulator(resolve_model(_imu(case)), dt, true_gyro=truth.angle_increment_rad / dt,
                                 true_accel=truth.velocity_increment_m_s / dt, seed=streams.seed)
        gyro, accel = simulator.window(members, 0, ideal.shape[0])
        increments = np.concatenate([gyro, accel], axis=-1) * dt
    else:
        increments = np.broadcast_to(ideal, (members.size,) + ideal.shape)
    sigma = tuple(fallback if case[name] is None else case[name] for name, fallback in
                  zip(("gnss_sigma_north", "gnss_sigma_east", "gnss_sigma_down"), SIMULATED_SIGMA))
    velocity_sigma = SIMULATED_VELOCITY_SIGMA if case["gnss_velocity_sigma"] is None else case["gnss_velocity_sigma"]
    lever, outages = lever_arm(case), outages_of(case)
    gnss = [simulate_gnss(path, case["duration"], imu_rate=case["imu_rate"], gnss_rate=case["gnss_rate"],
                          position_sigma=sigma, velocity_sigma=(velocity_sigma,) * 3 if use_velocity else None,
                          lever_arm=lever, latency=case["gnss_latency"], outages=outages,
                          streams=streams if noisy else None, member=int(m)) for m in members]
    return SimulatedInputs(path, truth, increments, gnss, outages, lever, use_velocity)


def _imu(case: Case) -> str:
    return "tactical" if case["imu"] is None else case["imu"]


def _simulated_group(case: Case, members: np.ndarray, streams, smooth: bool = False):
    """One group of members of the same simulated case: the filter run, its errors and the outages; with ``smooth``
    a fourth item, member 0's smoothed run and its errors."""
    require(member_bytes(case) * members.size, f"{members.size} members of this aided run", "`duration` or `imu_rate`")
    data = simulated_inputs(case, members, streams)
    imu = resolve_model(_imu(case))
    model = more_aiding.with_states(assumed(case, filter_model(imu)), case)
    stops = stationary_intervals(data.path, case["duration"])
    start = _initialisation(case, data.increments, data.truth.interval_s, data.gnss, lambda: _start(data.path,
                            members.size), lever_arm=data.lever_arm, imu=imu,
                            at_rest=stops[0][1] if stops and stops[0][0] == 0.0 else 0.0)
    noisy = streams is not None and not case["nominal"]
    extra = more_aiding.simulated_sources(case, data.path, data.increments, data.truth.interval_s, members,
                                          streams if noisy else None, model)
    run = run_filter(data.increments[:, start.first_sample:], data.truth.interval_s, start.start, model, data.gnss,
                     t0=start.t0_s, lever_arm=data.lever_arm, covariance_interval=case["covariance_interval"],
                     use_velocity=data.use_velocity, sources=extra, keep_for_smoother=smooth,
                     **_bias_at_rest(start, model))
    truth = data.truth
    true = _at(analysis.Truth(truth.latitude_rad, truth.longitude_rad, truth.height_m, truth.velocity_ned_m_s,
                              truth.quaternion), run.t_s, truth.t_s)
    if not smooth:
        return run, analysis.errors(run, true), data.outages
    smoothed = smoother.smooth(analysis.member(run, 0))
    return dataclasses.replace(run, prior_covariance=None, transition=None, correction=None), \
        analysis.errors(run, true), data.outages, (smoothed, analysis.errors(smoothed, true))


def _rest_at_start(increments: np.ndarray, interval: float, model: FilterModel) -> float | None:
    """How long a record is at rest from its start, s, by the stop detector (None: it starts moving)."""
    noise = math.sqrt(interval)
    stops = sources.detect_stops(increments, interval, float(np.max(model.angle_random_walk)) / noise,
                                 float(np.max(model.velocity_random_walk)) / noise)
    return stops[0][1] if stops and stops[0][0] == 0.0 else None


def _bias_at_rest(start: initialisation.Initialisation, model: FilterModel) -> dict:
    """``run_filter``'s initial sensor errors and 1-sigma from a gyro bias found at rest (none: no arguments).

    The rest's estimate b_r (1-sigma s_r) and the model's prior (zero, s_m) combine per axis as two Gaussians:
    b = b_r s_m^2 / (s_m^2 + s_r^2), sigma^2 = s_m^2 s_r^2 / (s_m^2 + s_r^2), so that a tactical gyro's bias, known
    better than the Earth rate's level part that hides in the rest's estimate, keeps its own 1-sigma.
    """
    if start.gyro_bias_rad_s is None or start.gyro_bias_sigma_rad_s is None:
        return {}
    sigma = model.initial_sigma()[:model.sensor_size - 9].copy()
    prior, rest = sigma[0:3] ** 2, start.gyro_bias_sigma_rad_s ** 2
    errors = np.zeros((start.gyro_bias_rad_s.shape[0], 12))
    errors[:, 0:3] = start.gyro_bias_rad_s * prior / (prior + rest)
    sigma[0:3] = np.sqrt(prior * rest / (prior + rest))
    return {"initial_sensor_errors": errors, "initial_sensor_sigma": sigma}


def _initialisation(case: Case, increments, interval: float, gnss, given, **options) -> initialisation.Initialisation:
    """The filter's start by the case's ``initialisation`` (:func:`schuler.aided.initialisation.initialise`)."""
    batch = np.reshape(increments, (-1,) + np.shape(increments)[-2:])  # a file's (n, 6): one member
    return initialisation.initialise(case["initialisation"], batch, interval, gnss, given=given,
                                     speed_threshold=case["speed_threshold"],
                                     alignment_duration=case["alignment_duration"], **options)


def _file_group(case: Case, members: np.ndarray, smooth: bool = False):
    """A case on files (one member: the data have no random terms of their own).

    Returns the run where the reference covers it, its errors (None without a reference), the outages, the whole
    run, and with ``smooth`` the smoothed run where the reference covers it and its errors (None without).
    """
    if members.size > 1:
        raise InvalidParameter("monte_carlo", "a run on files has no random terms: every member would be the same")
    given = [name for name in SIMULATED_ONLY if case[name] is not None]
    if given:
        raise InvalidParameter(given[0], "applies to a simulated case: the files carry their own trajectory")
    inputs = files.read_inputs(case)
    config = inputs.configuration
    kfgins_model = config is not None and case["imu"] is None
    _, use_velocity = aiding_of(case["aiding"], "gnss-position" if config is not None else
                                "gnss-position,gnss-velocity")
    if kfgins_model:
        assert config is not None
        model, initial, sigma = files.kfgins_model(config)
    else:
        model, initial, sigma = filter_model(resolve_model(_imu(case))), None, None
    model = assumed(case, model)
    dt = inputs.interval_s
    steps = max(round(case["covariance_interval"] / dt), 1)  # a whole number of the data's IMU intervals
    lever = files.lever_arm_of(case, config)
    at_rest = _rest_at_start(np.asarray(inputs.increments), dt, model) \
        if case["initialisation"] == "in-motion" and not kfgins_model else None
    start = _initialisation(case, inputs.increments, dt, inputs.gnss, lambda: files.start_of(inputs, START_SIGMA),
                            t0=inputs.t0_s, lever_arm=lever, imu=None if kfgins_model else resolve_model(_imu(case)),
                            at_rest=at_rest)
    extra = more_aiding.file_sources(case, np.asarray(inputs.increments), dt, inputs.t0_s, model)
    sensors = _bias_at_rest(start, model) or {"initial_sensor_errors": initial, "initial_sensor_sigma": sigma}
    run = run_filter(np.asarray(inputs.increments)[..., start.first_sample:, :], dt, start.start, model, inputs.gnss,
                     t0=start.t0_s, lever_arm=lever, covariance_interval=steps * dt,
                     use_velocity=use_velocity, sources=extra, keep_for_smoother=smooth, **sensors)
    smoothed_run = smoother.smooth(run) if smooth else None
    if inputs.reference is None:
        return run, None, inputs.outages, run, None if smoothed_run is None else (smoothed_run, None)
    kept, latitude, longitude, height, velocity, quaternion = files.reference_at(inputs.reference, run.t_s)
    if not kept.any():
        raise InvalidParameter("reference", "no output time falls inside the reference's span")
    truth = analysis.Truth(latitude, longitude, height, velocity, quaternion)
    inside = dataclasses.replace(run, t_s=run.t_s[kept], solution=run.solution[:, kept])
    smoothed = None
    if smoothed_run is not None:
        smoothed_inside = dataclasses.replace(smoothed_run, t_s=inside.t_s, solution=smoothed_run.solution[:, kept])
        smoothed = (smoothed_inside, analysis.errors(smoothed_inside, truth))
    return inside, analysis.errors(inside, truth), inputs.outages, run, smoothed


def _at(truth: analysis.Truth, t_s: np.ndarray, grid: np.ndarray) -> analysis.Truth:
    """The truth at the run's output times (every IMU epoch: the same grid)."""
    rows = np.searchsorted(grid, t_s - 1e-9)
    return analysis.Truth(truth.latitude[rows], truth.longitude[rows], truth.height[rows], truth.velocity[rows],
                          truth.quaternion[rows])


def _rms(values: np.ndarray) -> np.ndarray:
    return np.sqrt(np.mean(np.square(values), axis=-1))


def _summaries(run, errors, outages) -> dict[str, np.ndarray]:
    members = run.solution.shape[0]
    drifts = [analysis.outage_drift(analysis.member(run, m), None if errors is None else analysis.member(errors, m),
                                    outages) for m in range(members)]

    def largest(member):
        return max(member, key=lambda d: d.horizontal_error_max_m if errors is not None
                   else d.horizontal_error_sigma_m)

    worst = np.array([largest(member).horizontal_error_max_m if member else math.nan for member in drifts])
    sigma = np.array([largest(member).horizontal_error_sigma_m if member else math.nan for member in drifts])
    summary = {name: np.full(members, math.nan) for name in (
        "position_error_horizontal_rms_m", "position_error_horizontal_max_m", "position_error_vertical_rms_m",
        "velocity_error_horizontal_rms_m_s", "heading_error_rms_rad")}
    if errors is not None:
        velocity = np.hypot(errors.velocity[..., 0], errors.velocity[..., 1])
        summary.update({
            "position_error_horizontal_rms_m": _rms(errors.horizontal),
            "position_error_horizontal_max_m": errors.horizontal.max(axis=-1),
            "position_error_vertical_rms_m": _rms(errors.position[..., 2]),
            "velocity_error_horizontal_rms_m_s": _rms(velocity),
            "heading_error_rms_rad": _rms(errors.heading),
        })
    start = np.full(members, math.nan) if errors is None or errors.heading.shape[-1] == 0 else errors.heading[:, 0]
    return {**summary, "outage_horizontal_error_max_m": worst, "outage_horizontal_error_sigma_m": sigma,
            "rejected_measurements": run.rejected.astype(float), "start_heading_error_rad": start,
            "start_heading_sigma_rad": np.sqrt(run.covariance[:, 0, 8, 8])}


def evaluate(cases: Cases, histories: bool = False) -> Evaluation:
    """Every output of each case's member (a filter each), and with ``histories`` the first case's run in full.

    Parameters
    ----------
    cases : Cases
        A batch of validated cases (SI); ``cases.random`` draws the IMU errors and GNSS noise of member
        ``cases.members[i]`` (None: the nominal case). A case on files (:mod:`schuler.aided.files`) is one member.
    histories : bool
        Whether to return the first case's error histories, 1-sigma envelopes, navigation solution, outages and
        consistency (with its ``smooth``, its member 0 smoothed beside: module docstring).
    """
    outputs = {output.name: np.full(len(cases), math.nan) for output in OUTPUTS}
    kept = None
    for index, group in cases.groups(*[p.name for p in PARAMETERS]):
        case = group.case(0)
        first = histories and kept is None and 0 in index
        smooth = first and bool(case["smooth"])
        smoothed = None
        if files.is_file_case(case):
            run, errors, outages, full, smoothed = _file_group(case, group.members, smooth)
        elif smooth:
            run, errors, outages, smoothed = _simulated_group(case, group.members, cases.random, smooth)
            full = run
        else:
            run, errors, outages = _simulated_group(case, group.members, cases.random)
            full = run
        analysis.warn_if_nonlinear(run)
        for name, values in _summaries(run, errors, outages).items():
            outputs[name][index] = values
        if first:
            # the navigation at every IMU epoch (full), the errors where the reference covers the run (run)
            kept = (analysis.member(run, 0), None if errors is None else analysis.member(errors, 0), outages,
                    analysis.member(full, 0), smoothed, case["initialisation"])
    if not histories or kept is None:
        return Evaluation(outputs)
    run, errors, outages, full, smoothed, mode = kept
    extras = {**run_extras(run, errors, outages), "start": initialisation.start_report(mode, full, errors)}
    if smoothed is not None:
        # the forward run's keys from the smoothed run and its errors (a NaN, without a truth, is written as null)
        summary = {name: float(values[0]) for name, values in _summaries(smoothed[0], smoothed[1], outages).items()}
        extras["smoothed"] = {**summary, **run_extras(smoothed[0], smoothed[1], outages)}
    return Evaluation(outputs, histories={"aided_errors": error_histories(run, errors, smoothed),
                                          "navigation": navigation_histories(full),
                                          "aided_innovations": innovation_histories(run)},
                      extras=extras,
                      units={"inside": "1", "band": "1", **{name: "1" for name in ("gnss",) + more_aiding.SOURCES}})
