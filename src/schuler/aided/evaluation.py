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
"""

from __future__ import annotations

import math

import numpy as np

from schuler.aided import analysis
from schuler.aided.ekf import Start, run_filter
from schuler.aided.error_state import filter_model
from schuler.aided.gnss import schedule_outages, simulate_gnss
from schuler.contract import Cases, Evaluation, Output
from schuler.core.response import Histories
from schuler.exceptions import InvalidParameter
from schuler.imu.instrument import resolve_model
from schuler.imu.simulate import ImuSimulator
from schuler.memory import require
from schuler.navigate.drive import drive
from schuler.navigate.truth import ideal_imu, sample_count
from schuler.params import Case, Parameter, ParameterSet

AIDING = ("gnss-position", "gnss-velocity")
"""The measurements ``aiding`` may name."""

START_SIGMA = (1.0, 0.1, (math.radians(0.1), math.radians(0.1), math.radians(1.0)))
"""The filter's initial 1-sigma: position (m, each axis), velocity (m/s), psi (rad: north, east, down)."""

PARAMETERS = ParameterSet((
    Parameter("duration", "s", 1500.0, "Length of the drive (stops, turns, town and road speeds).",
              minimum=300.0, maximum=4 * 3600.0),
    Parameter("latitude", "deg", 30.5, "Latitude of the drive's start.", minimum=-80.0, maximum=80.0),
    Parameter("imu", "", "tactical", "IMU: a grade (navigation, tactical, industrial, consumer), a TOML spec file "
              "or a recording whose identified noise terms are used.", kind="text"),
    Parameter("imu_rate", "Hz", 100.0, "IMU sample rate.", minimum=10.0, maximum=1000.0),
    Parameter("gnss_rate", "Hz", 1.0, "GNSS epoch rate.", minimum=0.01, maximum=20.0),
    Parameter("gnss_sigma_north", "m", 0.5, "GNSS position 1-sigma, north.", minimum=0.0, exclusive_minimum=True,
              maximum=1e3),
    Parameter("gnss_sigma_east", "m", 0.5, "GNSS position 1-sigma, east.", minimum=0.0, exclusive_minimum=True,
              maximum=1e3),
    Parameter("gnss_sigma_down", "m", 1.0, "GNSS position 1-sigma, down.", minimum=0.0, exclusive_minimum=True,
              maximum=1e3),
    Parameter("gnss_velocity_sigma", "m/s", 0.05, "GNSS velocity 1-sigma, each axis.", minimum=0.0,
              exclusive_minimum=True, maximum=100.0),
    Parameter("lever_arm_x", "m", 0.0, "IMU to GNSS antenna, body x (forward).", minimum=-50.0, maximum=50.0),
    Parameter("lever_arm_y", "m", 0.0, "IMU to GNSS antenna, body y (right).", minimum=-50.0, maximum=50.0),
    Parameter("lever_arm_z", "m", 0.0, "IMU to GNSS antenna, body z (down).", minimum=-50.0, maximum=50.0),
    Parameter("gnss_latency", "s", 0.0, "Time between a fix's validity and its time tag.", minimum=0.0,
              maximum=1.0),
    Parameter("outage_start", "s", 600.0, "Start of the first GNSS outage.", minimum=0.0),
    Parameter("outage_duration", "s", 60.0, "Length of each GNSS outage (0: none).", minimum=0.0),
    Parameter("outage_every", "s", None, "Time from one outage's start to the next's (not set: one outage).",
              minimum=0.0, exclusive_minimum=True),
    Parameter("aiding", "", "gnss-position,gnss-velocity", "Measurements used, comma-separated: "
              + ", ".join(AIDING) + ".", kind="text"),
    Parameter("covariance_interval", "s", 1.0, "Covariance propagation step (a whole number of IMU intervals).",
              minimum=0.0, exclusive_minimum=True, maximum=60.0),
    Parameter("nominal", "", False, "Ideal sensors and noiseless GNSS (every random term zero).", kind="flag"),
), owner="aided")

OUTPUTS = (
    Output("position_error_horizontal_rms_m", "m", "", "RMS of the horizontal position error"),
    Output("position_error_horizontal_max_m", "m", "", "largest horizontal position error"),
    Output("position_error_vertical_rms_m", "m", "", "RMS of the vertical position error"),
    Output("velocity_error_horizontal_rms_m_s", "m/s", "", "RMS of the horizontal velocity error"),
    Output("heading_error_rms_rad", "rad", "deg", "RMS of the heading error"),
    Output("outage_horizontal_error_max_m", "m", "", "largest horizontal error in any outage"),
    Output("outage_horizontal_error_sigma_m", "m", "", "filter's horizontal 1-sigma at the end of that outage"),
    Output("rejected_measurements", "1", "", "GNSS epochs the chi-square gate rejected"),
)

SAMPLE_BYTES = 6 * 8 * 3 + 10 * 8 + 3 * 3 * 8
"""Bytes one member holds per IMU sample: its measured rates and increments (6 doubles, 3 copies at most), the
solution (10) and its three error histories (3 x 3)."""


def aiding_of(text: str) -> tuple[bool, bool]:
    """Which GNSS measurements ``aiding`` names: (position, velocity); refuses an unknown one with a suggestion.

    Parameters
    ----------
    text : str
        Comma-separated names of :data:`AIDING`.
    """
    import difflib

    names = [name.strip() for name in str(text).split(",") if name.strip()]
    for name in names:
        if name not in AIDING:
            hint = difflib.get_close_matches(name, AIDING, n=1)
            raise InvalidParameter("aiding", f"{name!r} is not a measurement" + (f"; did you mean {hint[0]!r}?" if hint
                                   else "") + f" choose from {', '.join(AIDING)}")
    if "gnss-position" not in names:
        raise InvalidParameter("aiding", "gnss-position is needed (velocity alone leaves the position unobserved)")
    return True, "gnss-velocity" in names


def outages_of(case: Case) -> tuple[tuple[float, float], ...]:
    """The case's scheduled outages inside the drive, (start, duration) pairs, s.

    Parameters
    ----------
    case : Case
        A validated case (SI: ``outage_start``, ``outage_duration``, ``outage_every``, ``duration`` in s).
    """
    if case["outage_duration"] <= 0 or case["outage_start"] >= case["duration"]:
        return ()
    return schedule_outages(case["outage_start"], case["outage_duration"], case["outage_every"],
                            end=case["duration"])


def member_bytes(case: Case) -> int:
    """Memory one member holds while filtered, from its declared sizes per IMU sample.

    Parameters
    ----------
    case : Case
        A validated case (SI: ``duration`` s, ``imu_rate`` Hz).
    """
    return int(SAMPLE_BYTES * sample_count(case["duration"], case["imu_rate"]))


def _start(path, members: int) -> Start:
    v0, q0 = path.kinematics(np.array([0.0]))
    ones = np.ones(members)
    position, velocity, attitude = START_SIGMA
    return Start(path.latitude * ones, path.longitude * ones, path.height * ones, np.repeat(v0, members, 0),
                 np.repeat(q0, members, 0), np.full(3, position), np.full(3, velocity), np.asarray(attitude))


def _group(case: Case, members: np.ndarray, streams):
    """One group of members of the same case: the filter run, its errors and the outages."""
    _, use_velocity = aiding_of(case["aiding"])
    require(member_bytes(case) * members.size, f"{members.size} members of this aided run", "--duration or --imu-rate")
    path = drive(latitude=case["latitude"], duration=case["duration"])
    truth = ideal_imu(path, case["duration"], case["imu_rate"])
    dt = truth.interval_s
    ideal = np.concatenate([truth.angle_increment_rad, truth.velocity_increment_m_s], axis=1)
    model = resolve_model(case["imu"])
    noisy = streams is not None and not case["nominal"]
    if noisy:
        simulator = ImuSimulator(model, dt, true_gyro_rad_s=truth.angle_increment_rad / dt,
                                 true_accel_m_s2=truth.velocity_increment_m_s / dt, seed=streams.seed)
        gyro, accel = simulator.window(members, 0, ideal.shape[0])
        increments = np.concatenate([gyro, accel], axis=-1) * dt
    else:
        increments = np.broadcast_to(ideal, (members.size,) + ideal.shape)
    sigma = (case["gnss_sigma_north"], case["gnss_sigma_east"], case["gnss_sigma_down"])
    lever = (case["lever_arm_x"], case["lever_arm_y"], case["lever_arm_z"])
    outages = outages_of(case)
    gnss = [simulate_gnss(path, case["duration"], imu_rate=case["imu_rate"], gnss_rate=case["gnss_rate"],
                          position_sigma=sigma, velocity_sigma=(case["gnss_velocity_sigma"],) * 3 if use_velocity
                          else None, lever_arm=lever, latency=case["gnss_latency"], outages=outages,
                          streams=streams if noisy else None, member=int(m)) for m in members]
    run = run_filter(increments, dt, _start(path, members.size), filter_model(model), gnss, lever_arm=lever,
                     covariance_interval=case["covariance_interval"], use_velocity=use_velocity)
    true = analysis.Truth(truth.latitude_rad, truth.longitude_rad, truth.height_m, truth.velocity_ned_m_s,
                          truth.quaternion)
    errors = analysis.errors(run, _at(true, run.t_s, truth.t_s))
    return run, errors, outages


def _at(truth: analysis.Truth, t_s: np.ndarray, grid: np.ndarray) -> analysis.Truth:
    """The truth at the run's output times (every IMU epoch: the same grid)."""
    rows = np.searchsorted(grid, t_s - 1e-9)
    return analysis.Truth(truth.latitude[rows], truth.longitude[rows], truth.height[rows], truth.velocity[rows],
                          truth.quaternion[rows])


def _rms(values: np.ndarray) -> np.ndarray:
    return np.sqrt(np.mean(np.square(values), axis=-1))


def _summaries(run, errors, outages) -> dict[str, np.ndarray]:
    drifts = [analysis.outage_drift(_member(run, m), _member(errors, m), outages) for m in range(run.solution.shape[0])]
    worst = np.array([max((d.horizontal_error_max_m for d in member), default=math.nan) for member in drifts])
    sigma = np.array([max(member, key=lambda d: d.horizontal_error_max_m).horizontal_error_sigma_m if member
                      else math.nan for member in drifts])
    velocity = np.hypot(errors.velocity[..., 0], errors.velocity[..., 1])
    return {
        "position_error_horizontal_rms_m": _rms(errors.horizontal),
        "position_error_horizontal_max_m": errors.horizontal.max(axis=-1),
        "position_error_vertical_rms_m": _rms(errors.position[..., 2]),
        "velocity_error_horizontal_rms_m_s": _rms(velocity),
        "heading_error_rms_rad": _rms(errors.heading),
        "outage_horizontal_error_max_m": worst,
        "outage_horizontal_error_sigma_m": sigma,
        "rejected_measurements": run.rejected.astype(float),
    }


def _member(value, m: int):
    """Member ``m`` alone of a filter run or of its errors (leading axis kept, length 1)."""
    import dataclasses

    fields = {}
    for f in dataclasses.fields(value):
        item = getattr(value, f.name)
        per_member = isinstance(item, np.ndarray) and item.ndim >= 2 and f.name not in ("t_s", "covariance_t_s",
                                                                                         "epoch_t_s")
        fields[f.name] = item[m:m + 1] if per_member else item
    return dataclasses.replace(value, **fields)


def evaluate(cases: Cases, histories: bool = False) -> Evaluation:
    """Every output of each case's member (a filter each), and with ``histories`` the first case's run in full.

    Parameters
    ----------
    cases : Cases
        A batch of validated cases (SI); ``cases.random`` draws the IMU errors and GNSS noise of member
        ``cases.members[i]`` (None: the nominal case).
    histories : bool
        Whether to return the first case's error histories, 1-sigma envelopes, outages and consistency.
    """
    outputs = {output.name: np.full(len(cases), math.nan) for output in OUTPUTS}
    kept = None
    for index, group in cases.groups(*[p.name for p in PARAMETERS]):
        case = group.case(0)
        run, errors, outages = _group(case, group.members, cases.random)
        for name, values in _summaries(run, errors, outages).items():
            outputs[name][index] = values
        if histories and kept is None and 0 in index:
            kept = (case, _member(run, 0), _member(errors, 0), outages)
    if not histories or kept is None:
        return Evaluation(outputs)
    case, run, errors, outages = kept
    return Evaluation(outputs, histories={"aided_errors": error_histories(run, errors)},
                      extras=run_extras(run, errors, outages), units={"inside": "1", "band": "1"})


def error_histories(run, errors) -> Histories:
    """One member's errors and the filter's 1-sigma of each, at every output time (SI).

    Parameters
    ----------
    run : FilterRun
        A filter run of one member.
    errors : analysis.Errors
        Its errors against the truth.
    """
    rows = np.maximum(np.searchsorted(run.covariance_t_s, errors.t_s + 1e-9) - 1, 0)
    P = run.covariance[0][rows]
    channels = {
        "north_error_m": errors.position[0, :, 0], "east_error_m": errors.position[0, :, 1],
        "down_error_m": errors.position[0, :, 2], "horizontal_error_m": errors.horizontal[0],
        "velocity_north_error_m_s": errors.velocity[0, :, 0], "velocity_east_error_m_s": errors.velocity[0, :, 1],
        "velocity_down_error_m_s": errors.velocity[0, :, 2], "heading_error_rad": errors.heading[0],
        "north_sigma_m": np.sqrt(P[:, 0, 0]), "east_sigma_m": np.sqrt(P[:, 1, 1]), "down_sigma_m": np.sqrt(P[:, 2, 2]),
        "horizontal_sigma_m": np.sqrt(P[:, 0, 0] + P[:, 1, 1]), "heading_sigma_rad": np.sqrt(P[:, 8, 8]),
    }
    units = {name: "rad" if name.endswith("_rad") else "m/s" if name.endswith("_m_s") else "m" for name in channels}
    return Histories(errors.t_s, channels, units)


def run_extras(run, errors, outages) -> dict:
    """The JSON-safe results beside the outputs: each outage's drift, NEES and NIS consistency, rejected epochs.

    Parameters
    ----------
    run : FilterRun
        A filter run of one member.
    errors : analysis.Errors
        Its errors against the truth.
    outages : sequence of (float, float)
        The outages, (start, duration), s.
    """
    drifts = analysis.outage_drift(run, errors, outages)
    check = analysis.consistency(run, errors)
    accepted = run.accepted[0]
    nis = run.nis[0][accepted]
    dof = run.residual.shape[-1]
    import scipy.stats

    low, high = scipy.stats.chi2.ppf([0.005, 0.995], dof)
    return {
        "outages": [{"start_s": d.start_s, "duration_s": d.duration_s,
                     "horizontal_error_max_m": d.horizontal_error_max_m, "vertical_error_max_m": d.vertical_error_max_m,
                     "heading_error_max_rad": d.heading_error_max_rad,
                     "horizontal_error_sigma_m": d.horizontal_error_sigma_m} for d in drifts],
        "nees": {name: {"inside": check.inside[name], "band": list(check.band)} for name in check.inside},
        "nis": {"inside": float(np.mean((nis >= low) & (nis <= high))) if nis.size else None,
                "band": [float(low), float(high)]},
    }
