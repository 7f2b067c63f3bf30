"""What the nonlinear INS system evaluates: its parameters, outputs and ``evaluate``.

One case is a trajectory (``stationary``, ``great-circle``, ``drive`` or a
waypoint profile ``FILE.toml``, :mod:`schuler.navigate.profile`), a
mechanization (``strapdown`` or ``platform``), a vertical channel, initial
errors (computed - true) and sensor errors (measured - true, body axes): the
biases given and, with ``imu``, the full error model of a grade or a spec file
(:mod:`schuler.navigate.imu_noise`). Without ``imu`` the IMU is ideal apart
from the biases given. With ``record`` (a recorded IMU file,
:mod:`schuler.navigate.recording`) the vehicle is static: the computer
integrates the record's increments (plus the biases given) and the errors are
against a stationary truth at the record's site and attitude; such a case is
one member (no Monte Carlo).

:func:`evaluate` runs the cases of a batch that share a trajectory and a time
grid as the members of one batched :func:`~schuler.navigate.mechanization.navigate`
and returns the final and the largest errors; with ``histories`` also the first
case's error histories (``navigate_errors``) and what it ran (trajectory, IMU,
grid, warnings). Random terms (``cases.random`` set: Monte Carlo members, sweep
draws): each member draws its initial errors and biases around the case's
values from the ``sigma_*`` parameters, and with ``imu`` the error model's
constant errors and noise, all at its member number; the nominal case
(``cases.random`` None, what ``run`` shows) has no noise and the model's
constant errors at +1 sigma.

Validity (:mod:`schuler.navigate.validity`): a run whose computed height leaves
-11 km .. 120 km or whose attitude error passes 0.1 rad warns (and says so in the
result's ``warnings``); one whose state leaves the mechanization's domain (half way
to the Earth's centre, a pole) is refused with a :class:`~schuler.exceptions.SimulationError`.

Memory: a run holds its error histories (N members x outputs x 23 values) and
one block of truth and noise; members are evaluated in parts that fit a
quarter of the budget (:mod:`schuler.memory`), and a single member that does not
fit is refused before anything is allocated.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from schuler.contract import Cases, Evaluation, Output
from schuler.exceptions import InvalidParameter
from schuler.imu.error_model import ErrorModel
from schuler.memory import budget, require
from schuler.navigate import imu_noise
from schuler.navigate.channels import DISPLAY_UNITS, ERROR_CHANNELS, suffix
from schuler.navigate.drive import drive
from schuler.navigate.errors import ConstantSensorErrors, InitialErrors
from schuler.navigate.mechanization import (
    MODES,
    NOISE_BLOCK_BYTES,
    VERTICAL_CHANNELS,
    estimate_memory,
    navigate,
    output_interval,
)
from schuler.navigate.profile import load_profile
from schuler.navigate.recording import RECORD_SUFFIXES, is_recording, replay
from schuler.navigate.results import HISTORIES, NavigationResult
from schuler.navigate.trajectory import GreatCircle, Stationary, WaypointProfile
from schuler.navigate.truth import DEFAULT_CHUNK, TruthGenerator
from schuler.params import Case, Parameter, ParameterSet

TRAJECTORIES = ("stationary", "great-circle", "drive")
"""Named trajectories; any other value of ``trajectory`` is a waypoint profile file."""

DRIVE_OPTIONS = ("stops", "stop_duration", "city_speed", "road_speed", "turn_speed", "turn_radius", "acceleration")
"""The parameters of the ``drive`` trajectory (:func:`schuler.navigate.drive.drive`), not set: the drive's own."""
DRIVE_START = {"latitude": math.radians(30.5), "longitude": math.radians(114.5), "height": 20.0}
"""The drive's start where not given: :func:`~schuler.navigate.drive.drive`'s (the drive of ``schuler aided``)."""

DEFAULT_LATITUDE = math.radians(45.0)
DEFAULT_SPEED = 250.0
"""Ground speed of a great circle when ``speed`` is not set, m/s."""
DEFAULT_IMU_RATE = 100.0
DEFAULT_DURATION = 3600.0
"""Simulated time of a stationary or great-circle case when ``duration`` is not set, s."""
MAX_DURATION = 10 * 86400.0

NOISE_MEMBERS = NOISE_BLOCK_BYTES // (DEFAULT_CHUNK * 48)
"""Members per run with sensor noise: ``navigate`` then streams blocks of exactly one random-number
block (65,536 samples), so that no window of the noise starts inside a block and redraws its start."""

_START = ("latitude", "longitude", "height", "heading", "speed")
_INITIAL_SIGMAS = {"position_error_north": "sigma_position_error", "position_error_east": "sigma_position_error",
                   "velocity_error_north": "sigma_velocity_error", "velocity_error_east": "sigma_velocity_error",
                   "roll_error": "sigma_level_error", "pitch_error": "sigma_level_error",
                   "heading_error": "sigma_heading_error"}
_AXES = "xyz"
_GROUPED = ("trajectory", *_START, *DRIVE_OPTIONS, "duration", "imu_rate", "output_step", "vertical_channel",
            "mode", "imu", "record")
_POSITION = 1e6
"""Largest initial position error, m (1000 km)."""
_VELOCITY = 1e3
"""Largest initial velocity error, m/s."""
_GYRO_BIAS = 3.6e6
"""Largest gyro bias, deg/h (1000 deg/s)."""
_ACCEL_BIAS = 1.0
"""Largest accelerometer bias, g."""

PARAMETERS = ParameterSet((
    Parameter("trajectory", "", "stationary", "stationary, great-circle, drive (a car's drive with stops, speed "
              "changes and 90-deg turns on a level road: schuler.navigate.drive), or a waypoint profile FILE.toml "
              "(format: schuler.navigate.profile).", kind="text"),
    Parameter("latitude", "deg", None, "Start latitude (not set: 45 deg, the drive's 30.5 deg; a profile sets its "
              "own).", minimum=-89, maximum=89),
    Parameter("longitude", "deg", None, "Start longitude (not set: 0 deg, the drive's 114.5 deg).", minimum=-360,
              maximum=360),
    Parameter("height", "m", None, "Height above the WGS-84 ellipsoid (not set: 0 m, the drive's 20 m).",
              minimum=-1e4, maximum=1e5),
    Parameter("heading", "deg", None, "Heading (the great circle's initial course), clockwise from north "
              "(not set: 0 deg).", minimum=-360, maximum=360),
    Parameter("speed", "m/s", None, f"Ground speed along the great circle (not set: {DEFAULT_SPEED:g} m/s).",
              minimum=0, maximum=1e4),
    Parameter("stops", "", None, "Drive: stationary periods, the first at the start and the last at the end "
              "(not set: 4).", minimum=2, maximum=100, kind="integer"),
    Parameter("stop_duration", "s", None, "Drive: length of each stop (not set: 25 s).", minimum=0,
              exclusive_minimum=True, maximum=1e5),
    Parameter("city_speed", "m/s", None, "Drive: cruising speed in town (not set: 10 m/s).", minimum=0,
              exclusive_minimum=True, maximum=70),
    Parameter("road_speed", "m/s", None, "Drive: cruising speed on the road (not set: 20 m/s).", minimum=0,
              exclusive_minimum=True, maximum=70),
    Parameter("turn_speed", "m/s", None, "Drive: speed through the 90-deg turns (not set: 8 m/s).", minimum=0,
              exclusive_minimum=True, maximum=70),
    Parameter("turn_radius", "m", None, "Drive: mean radius of the turns (not set: 40 m).", minimum=0,
              exclusive_minimum=True, maximum=1e4),
    Parameter("acceleration", "m/s^2", None, "Drive: mean acceleration and deceleration of its speed changes "
              "(not set: 1.5 m/s^2).", minimum=0, exclusive_minimum=True, maximum=10),
    Parameter("duration", "s", None, f"Simulated time (not set: {DEFAULT_DURATION:g} s, the drive's 1500 s, a "
              "profile's last waypoint time, or a recording's length in whole output steps; at most the "
              "recording's).",
              minimum=0, exclusive_minimum=True, maximum=MAX_DURATION),
    Parameter("imu_rate", "Hz", None, f"IMU sample rate (not set: {DEFAULT_IMU_RATE:g} Hz, or a recording's "
              "rate, the only one allowed with it).", minimum=0, exclusive_minimum=True, maximum=1e5),
    Parameter("output_step", "s", 10.0, "Step of the error histories, a whole number of IMU intervals "
              "(the largest errors are taken at these times).", minimum=0, exclusive_minimum=True, maximum=86400),
    Parameter("vertical_channel", "", "off", "free (pure inertial, unstable: a height beyond -11 km .. 120 km warns, "
              "one half way to the Earth's centre stops the run), off (height held to the truth) or baro (third-order "
              "baro-aided loop, 100 s).", choices=VERTICAL_CHANNELS, kind="choice"),
    Parameter("mode", "", "strapdown", "strapdown, or platform (gimballed, local level, torqued at the computed "
              "frame rate).", choices=MODES, kind="choice"),
    Parameter("position_error_north", "m", 0.0, "Initial error Delta latitude (R_N + h), computed - true.",
              minimum=-_POSITION, maximum=_POSITION),
    Parameter("position_error_east", "m", 0.0, "Initial error Delta longitude (R_E + h) cos(latitude).",
              minimum=-_POSITION, maximum=_POSITION),
    Parameter("velocity_error_north", "m/s", 0.0, "Initial north velocity error.", minimum=-_VELOCITY,
              maximum=_VELOCITY),
    Parameter("velocity_error_east", "m/s", 0.0, "Initial east velocity error.", minimum=-_VELOCITY,
              maximum=_VELOCITY),
    Parameter("roll_error", "arcmin", 0.0, "Initial roll error (difference of the roll angles).",
              minimum=-10800, maximum=10800),
    Parameter("pitch_error", "arcmin", 0.0, "Initial pitch error.", minimum=-5400, maximum=5400),
    Parameter("heading_error", "arcmin", 0.0, "Initial heading error.", minimum=-10800, maximum=10800),
    *(Parameter(f"gyro_bias_{a}", "deg/h", 0.0, f"Bias of the {a} gyro, body axes (measured - true).",
                minimum=-_GYRO_BIAS, maximum=_GYRO_BIAS) for a in _AXES),
    *(Parameter(f"accel_bias_{a}", "g", 0.0, f"Bias of the {a} accelerometer, body axes (measured - true).",
                minimum=-_ACCEL_BIAS, maximum=_ACCEL_BIAS) for a in _AXES),
    Parameter("imu", "", None, "Full sensor error model: a grade (navigation, tactical, industrial, consumer) or "
              "a spec file SPEC.toml (schuler.imu.spec); its constant errors at +1 sigma, and drawn with noise "
              "for Monte Carlo members (not set: ideal apart from the biases given). A recording is replayed with "
              "record.", kind="text"),
    Parameter("record", "", None, "A recorded IMU file (CSV, PSINS .imu, Parquet; schuler.navigate.recording) "
              "replayed as a static vehicle: its increments navigated, errors against a stationary truth at the "
              "record's site and attitude (--latitude, --longitude, --height, --heading override them), at the "
              "record's rate and length; one member, no Monte Carlo.", kind="text"),
    Parameter("sigma_position_error", "m", 0.0, "Monte Carlo: 1-sigma of the north and east initial position "
              "errors.", minimum=0, maximum=1e5),
    Parameter("sigma_velocity_error", "m/s", 0.0, "Monte Carlo: 1-sigma of the north and east initial velocity "
              "errors.", minimum=0, maximum=100),
    Parameter("sigma_level_error", "arcmin", 0.0, "Monte Carlo: 1-sigma of the roll and pitch errors.",
              minimum=0, maximum=600),
    Parameter("sigma_heading_error", "arcmin", 0.0, "Monte Carlo: 1-sigma of the heading error.",
              minimum=0, maximum=1200),
    Parameter("sigma_gyro_bias", "deg/h", 0.0, "Monte Carlo: 1-sigma of each gyro bias (besides the model's).",
              minimum=0, maximum=3.6e5),
    Parameter("sigma_accel_bias", "g", 0.0, "Monte Carlo: 1-sigma of each accelerometer bias (besides the "
              "model's).", minimum=0, maximum=0.1),
), owner="navigate")
"""Every option of ``schuler navigate run`` (and key of a ``navigate`` scenario)."""


def _outputs() -> tuple[Output, ...]:
    final, largest = [], []
    for channel in ERROR_CHANNELS:
        unit = suffix(channel)
        what = channel.removesuffix("_" + unit).replace("_", " ")
        si, shown = unit.replace("_", "/"), DISPLAY_UNITS[unit]
        final.append(Output(f"final_{channel}", si, shown, f"{what} at the end (computed - true)"))
        largest.append(Output(f"max_abs_{channel}", si, shown, f"largest |{what}| at the output times"))
    final.append(Output("final_horizontal_position_error_m", "m", "m", "horizontal position error at the end"))
    largest.append(Output("max_horizontal_position_error_m", "m", "m", "largest horizontal position error"))
    return tuple(final + largest)


OUTPUTS = _outputs()
"""Final and largest errors of every channel, SI (the height channel's are 0 when it is held to the truth)."""


@dataclass(frozen=True)
class Setup:
    """What the members of one run share: the trajectory, the time grid, the mechanization, the error model."""

    trajectory: object
    duration: float
    imu_rate: float
    output_step: float
    mode: str
    vertical_channel: str
    model: ErrorModel | None
    recorded: np.ndarray | None = None
    """(dtheta, dv) per IMU interval of a recording replayed instead of the ideal IMU (None: synthetic)."""

    @property
    def output_count(self) -> int:
        return round(self.duration * self.imu_rate) // output_interval(self.output_step, self.imu_rate) + 1


def _profile(text: str):
    path = Path(text)
    if path.suffix.lower() != ".toml":
        raise InvalidParameter("trajectory", f"{text!r} is neither {' nor '.join(TRAJECTORIES)} nor a waypoint "
                                             "profile FILE.toml")
    try:
        return load_profile(path)
    except InvalidParameter as error:
        if error.name == "trajectory":
            raise
        raise InvalidParameter("trajectory", f"{path}: {error}") from None


def setup(case: Case) -> Setup:
    """The shared part of a case (its trajectory built and checked, its error model or recording loaded).

    Parameters
    ----------
    case : Case
        A validated case of :data:`PARAMETERS` (SI values: rad, m, m/s, s, Hz).

    Returns
    -------
    Setup
        The trajectory, time grid, mechanization, vertical channel and error
        model (or recorded increments) its members share.

    Raises
    ------
    InvalidParameter
        A recording given as ``imu`` (it is replayed with ``record``), ``record`` with ``imu``, an option of
        another trajectory, a trajectory that is not one.
    """
    imu = None if case["imu"] is None else case["imu"].strip()
    if imu is not None and (is_recording(imu) or Path(imu).suffix.lower() in RECORD_SUFFIXES):
        raise InvalidParameter("imu", f"{Path(imu).name} is a recording: replay it with record (`record` FILE); "
                                      "imu is the sensor error model, a grade or SPEC.toml")
    name = case["trajectory"].strip()
    _refuse_drive_options(name, case)
    if case["record"] is not None:
        if imu is not None:
            raise InvalidParameter("record", "a recording carries its own sensor errors: leave imu out")
        recording = replay(case["record"].strip(), case)
        return Setup(recording.trajectory, recording.duration, recording.imu_rate, case["output_step"],
                     case["mode"], case["vertical_channel"], None, recording.increments)
    trajectory, duration = trajectory_of(name, case)
    model = imu_noise.load_error_model(imu) if imu is not None else None
    imu_rate = DEFAULT_IMU_RATE if case["imu_rate"] is None else case["imu_rate"]
    return Setup(trajectory, float(duration), imu_rate, case["output_step"], case["mode"],
                 case["vertical_channel"], model)


def _refuse_drive_options(name: str, case) -> None:
    given = [key for key in DRIVE_OPTIONS if case[key] is not None]
    if given and name != "drive":
        raise InvalidParameter(given[0], "applies to the drive trajectory only")


def trajectory_of(name: str, case: Case) -> tuple[Stationary | GreatCircle | WaypointProfile, float]:
    """The case's trajectory and duration: a named one of :data:`TRAJECTORIES` from the start options, or a
    waypoint profile file.

    Parameters
    ----------
    name : str
        ``stationary``, ``great-circle``, ``drive`` or the path of a profile FILE.toml.
    case : Mapping
        The start options ``latitude``, ``longitude``, ``height``, ``heading``, ``speed``, the drive's
        :data:`DRIVE_OPTIONS` and ``duration`` (SI; None: not set).

    Returns
    -------
    trajectory : Stationary, GreatCircle or WaypointProfile
        The trajectory (a drive is a :class:`~schuler.navigate.drive.GroundVehicleProfile`).
    duration : float
        Its simulated time, s (not set: :data:`DEFAULT_DURATION`, the drive's or the profile's own).

    Raises
    ------
    InvalidParameter
        An option of another trajectory; a start option beside a profile, which sets its own; a name that is
        neither a trajectory nor a profile file.
    """
    _refuse_drive_options(name, case)
    duration = case["duration"]
    if name not in TRAJECTORIES:
        given = [key for key in _START if case[key] is not None]
        if given:
            raise InvalidParameter(given[0], f"is set by the profile {name} (its [start] and [[waypoint]] tables); "
                                             "leave it out")
        profile = _profile(name)
        return profile, profile.duration if duration is None else duration
    if name != "great-circle" and case["speed"]:
        raise InvalidParameter("speed", "applies to the great-circle trajectory only (" + (
            "stationary is at rest)" if name == "stationary" else "the drive sets its own: `city_speed`, "
            "`road_speed`, `turn_speed`)"))
    defaults = DRIVE_START if name == "drive" else {"latitude": DEFAULT_LATITUDE, "longitude": 0.0, "height": 0.0}
    start: dict[str, Any] = {key: defaults.get(key, 0.0) if case[key] is None else case[key]
                             for key in ("latitude", "longitude", "height", "heading")}
    if name == "drive":
        path = drive(**start, **{key: case[key] for key in (*DRIVE_OPTIONS, "duration") if case[key] is not None})
        return path, path.duration
    duration = DEFAULT_DURATION if duration is None else duration
    if name == "stationary":
        return Stationary(**start), duration
    speed = DEFAULT_SPEED if case["speed"] is None else case["speed"]
    return GreatCircle(**start, speed=speed, duration=duration), duration


def member_errors(cases: Cases, shared: Setup, specific_force) -> tuple[InitialErrors, ConstantSensorErrors]:
    """Each case's initial and constant sensor errors, with its random draws when ``cases.random`` is set.

    Parameters
    ----------
    cases : Cases
        The batch's validated cases (SI values; random terms from ``cases.random`` at ``cases.members``).
    shared : Setup
        What the cases share (:func:`setup`): its error model adds its constant errors.
    specific_force : array_like, shape (3,)
        f0, the sensors' true specific force at the start, m/s^2, body axes (NED for the
        platform; :func:`~schuler.navigate.imu_noise.initial_inputs`): the nominal case's
        g-sensitivity G f0 joins the gyro bias.

    Returns
    -------
    InitialErrors, ConstantSensorErrors
        One entry per case (computed - true; bias = measured - true, body axes, SI).
    """
    initial = {name: cases.float(name) for name in _INITIAL_SIGMAS}
    gyro = np.stack([cases.float(f"gyro_bias_{a}") for a in _AXES], axis=1)
    accel = np.stack([cases.float(f"accel_bias_{a}") for a in _AXES], axis=1)
    random = cases.random
    if random is not None:
        for name, sigma in _INITIAL_SIGMAS.items():
            initial[name] = initial[name] + cases.float(sigma) * random.normal(f"navigate/{name}", cases.members)
        gyro = gyro + cases.float("sigma_gyro_bias")[:, None] * random.normal("navigate/gyro_bias", cases.members, 3)
        accel = accel + cases.float("sigma_accel_bias")[:, None] * random.normal("navigate/accel_bias",
                                                                               cases.members, 3)
    constants: dict[str, np.ndarray] = {}
    if shared.model is not None:
        drawn = (imu_noise.drawn_constants(shared.model, random.seed, cases.members) if random is not None
                 else imu_noise.representative_constants(shared.model, len(cases), specific_force))
        constants = drawn.as_dict()
        gyro = gyro + constants.pop("gyro_bias")
        accel = accel + constants.pop("accel_bias")
    return InitialErrors(**initial), ConstantSensorErrors(gyro_bias=gyro, accel_bias=accel, **constants)


def _noise_model(shared: Setup, cases: Cases) -> ErrorModel | None:
    """The model whose noise the members draw (None: no noise, the nominal case or a model without any)."""
    if shared.model is None or cases.random is None or not imu_noise.has_noise(shared.model):
        return None
    return shared.model


def bytes_per_member(shared: Setup, noisy: ErrorModel | None) -> int:
    """Memory one member of a run holds: its outputs and, with noise, its noise blocks and simulator state.

    Parameters
    ----------
    shared : Setup
        What the run's members share (its time grid sizes the outputs).
    noisy : ErrorModel or None
        The model whose noise the members draw (None: no noise).

    Returns
    -------
    int
        Memory per member, bytes.
    """
    held = estimate_memory(2, shared.output_count, DEFAULT_CHUNK, noisy is not None) \
        - estimate_memory(1, shared.output_count, DEFAULT_CHUNK, noisy is not None)
    if noisy is not None:
        # the simulator's window (six channels) and the slow processes' sums it may keep between windows
        held += DEFAULT_CHUNK * 6 * 8 * 2 + imu_noise.state_bytes(noisy, 1.0 / shared.imu_rate)
    return held


def _refuse_monte_carlo():
    raise InvalidParameter("monte_carlo", "`record` is one member (its own sensor errors, recorded once): run it "
                                          "without `monte_carlo`")


def runs(cases: Cases, shared: Setup) -> Iterator[tuple[np.ndarray, NavigationResult]]:
    """Run the cases as members of batched ``navigate`` calls, in parts that fit the memory budget.

    Yields (indices into ``cases``, the part's result with arrays of shape (members, outputs)).

    Parameters
    ----------
    cases : Cases
        Validated cases sharing ``shared`` (SI values; random terms from ``cases.random`` at ``cases.members``).
    shared : Setup
        What the cases share (:func:`setup`).

    Yields
    ------
    index : ndarray of int
        Indices into ``cases`` of the part's members.
    result : NavigationResult
        The part's error histories, arrays of shape (members, outputs), SI.
    """
    if shared.recorded is not None and cases.random is not None:
        _refuse_monte_carlo()
    generator = TruthGenerator(shared.trajectory, shared.duration, shared.imu_rate)
    rate, force = imu_noise.initial_inputs(generator, shared.mode)
    noisy = _noise_model(shared, cases)
    per_member = bytes_per_member(shared, noisy)
    fixed = estimate_memory(0, shared.output_count, DEFAULT_CHUNK, False)
    require(fixed + per_member, "this run", "`duration` or `output_step`")
    size = max(1, min(len(cases), (budget() // 4 - fixed) // per_member))
    if noisy is not None:
        size = min(size, NOISE_MEMBERS)
    for start in range(0, len(cases), size):
        index = np.arange(start, min(start + size, len(cases)))
        part = cases.take(index)
        initial, sensors = member_errors(part, shared, force)
        noise = (imu_noise.ImuNoise(noisy, cases.random.seed, 1.0 / shared.imu_rate, rate, force)
                 if noisy is not None and cases.random is not None else None)
        yield index, navigate(shared.trajectory, shared.duration, imu_rate=shared.imu_rate,
                              output_step=shared.output_step, mode=shared.mode,
                              vertical_channel=shared.vertical_channel, initial_errors=initial,
                              sensor_errors=sensors, noise=noise, member_ids=part.members,
                              max_memory=budget(), recorded_increments=shared.recorded)


def reduce(result: NavigationResult) -> dict[str, np.ndarray]:
    """The outputs of a batched run: each channel's final and largest absolute error per member.

    Parameters
    ----------
    result : NavigationResult
        A batched run's error histories, arrays of shape (members, outputs), SI.

    Returns
    -------
    dict of str to ndarray
        Every output of :data:`OUTPUTS`, SI (m, m/s, rad), shape (members,).
    """
    out = {}
    for channel in ERROR_CHANNELS:
        values = np.asarray(result.channel(channel))
        out[f"final_{channel}"] = values[:, -1]
        out[f"max_abs_{channel}"] = np.abs(values).max(axis=1)
    horizontal = np.hypot(result.position_error_north_m, result.position_error_east_m)
    out["final_horizontal_position_error_m"] = horizontal[:, -1]
    out["max_horizontal_position_error_m"] = horizontal.max(axis=1)
    return out


def evaluate(cases: Cases, histories: bool = False) -> Evaluation:
    """Every output of :data:`OUTPUTS` for a batch of cases, and with ``histories`` the first case's run in full.

    Cases sharing a trajectory, time grid, mechanization and error model run as
    the members of one batched simulation.

    Parameters
    ----------
    cases : Cases
        A batch of validated cases (SI values; random terms from ``cases.random`` at ``cases.members``).
    histories : bool
        Whether to return the first case's error histories (``navigate_errors``, SI) and what it ran
        (``trajectory``, ``mode``, ``vertical_channel``, ``imu``, ``duration_s``, ``imu_rate_hz``,
        ``output_step_s``, ``warnings``).
    """
    out = {output.name: np.full(len(cases), np.nan) for output in OUTPUTS}
    first = None
    for index, group in cases.groups(*_GROUPED):
        shared = setup(group.case(0))
        for part, result in runs(group, shared):
            for name, values in reduce(result).items():
                out[name][index[part]] = values
            if histories and 0 in index[part]:
                first = (group.case(0), shared, result, int(np.flatnonzero(index[part] == 0)[0]))
    if first is None:
        return Evaluation(out)
    case, shared, result, member = first
    extras = {"trajectory": case["trajectory"].strip(), "mode": shared.mode,
              "vertical_channel": shared.vertical_channel, "imu": _imu_name(case, shared),
              "duration_s": shared.duration, "imu_rate_hz": shared.imu_rate, "output_step_s": shared.output_step,
              "warnings": list(result.warnings)}
    return Evaluation(out, histories={HISTORIES: result.histories(member)}, extras=extras,
                      units={"imu_rate_hz": "Hz"})


def _imu_name(case: Case, shared: Setup) -> str | None:
    if shared.model is not None:
        return shared.model.name
    return f"recording {Path(case['record'].strip()).name} (static)" if shared.recorded is not None else None


def member_bytes(case: Case) -> int:
    """Memory one Monte Carlo member holds while evaluated (sizes the chunks).

    Parameters
    ----------
    case : Case
        A validated case (SI values); a recording is refused (one member, no Monte Carlo).

    Returns
    -------
    int
        Memory per member, bytes.
    """
    shared = setup(case)
    if shared.recorded is not None:
        _refuse_monte_carlo()
    noisy = shared.model if shared.model is not None and imu_noise.has_noise(shared.model) else None
    return bytes_per_member(shared, noisy)
