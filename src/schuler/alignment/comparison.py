"""Every self-alignment method on the same data, with the limits that come with the sensors.

:func:`compare_alignment` runs coarse, inertial-frame, Kalman and gyrocompass
alignment on one window of one record and returns an
:class:`AlignmentComparison`: per method roll, pitch, heading (aerospace,
NED, body x forward / y right / z down), its own 1-sigma where it has one
(Kalman), its convergence time and its accuracy limit
(:func:`~schuler.alignment.limits.accuracy_limit`), and the histories for the
heading-versus-time figure. :func:`record_batch` cuts a window out of a
recording and finds the error model its limits come from; :func:`simulated_batch`
makes a record of a grade at rest, whose true attitude and biases are known.

Agreement: all methods read the same samples, so the same biases move them
all alike (the bias part of the limit); what separates two methods is their
noise and what they do with disturbances. Two methods agree when their headings
differ by less than 3 sqrt(n_a^2 + n_b^2), n the noise parts of their limits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from schuler.alignment.coarse import align_coarse
from schuler.alignment.data import BYTES_PER_SAMPLE, MethodEstimate, StaticBatch, convergence_time, window_indices
from schuler.alignment.gyrocompass import align_gyrocompass
from schuler.alignment.inertial import align_inertial, net_rotation
from schuler.alignment.kalman import align_kalman
from schuler.alignment.limits import METHODS, accuracy_limit, horizontal_rate, static_errors
from schuler.alignment.staged_gyrocompass import (
    GyrocompassDesign,
    align_staged_gyrocompass,
    design_gyrocompass,
    staged_limit,
)
from schuler.core.attitude import wrap_angle
from schuler.core.gyrocompass_design import DESIGN_DAMPING, DESIGN_TIME_CONSTANT, loop_gains
from schuler.exceptions import InvalidParameter, renamed_keywords
from schuler.imu.error_model import ErrorModel
from schuler.imu.record import ImuRecord
from schuler.imu.simulate import ImuSimulator, simulate_members, static_truth
from schuler.imu.spec import preset
from schuler.memory import require
from schuler.results import Result

AGREEMENT_SIGMAS = 3.0
"""Methods agree when their headings differ by less than this many combined noise sigmas."""

GYROCOMPASS_DESIGNS = ("staged", "kpi")
"""The gyrocompass loop's designs: levelling then azimuth stages driven by velocity
(:mod:`~schuler.alignment.staged_gyrocompass`, the default), or the KPI platform design
(:mod:`~schuler.alignment.gyrocompass`, T and zeta)."""


@dataclass(frozen=True)
class AlignmentSettings:
    """How the methods are run (SI).

    Attributes
    ----------
    time_constant_s, damping : float
        T and zeta of the KPI design of the gyrocompass loop (KPI manual: T = 30 s, zeta = 0.8).
    gyrocompass_design : {"staged", "kpi"}
        The gyrocompass loop's design (:data:`GYROCOMPASS_DESIGNS`); the staged one takes its stages from the
        error model and the window.
    velocity_noise : float
        The Kalman filter's zero-velocity measurement noise, m/s.
    update_interval_s : float
        Time between Kalman updates, s.
    initial_window_s : float
        Coarse alignment over the first seconds starts the Kalman filter and the gyrocompass, s.
    history_step_s : float
        Step of the heading histories, s.
    """

    time_constant_s: float = DESIGN_TIME_CONSTANT
    damping: float = DESIGN_DAMPING
    velocity_noise: float = 0.01
    update_interval_s: float = 1.0
    initial_window_s: float = 30.0
    history_step_s: float = 1.0
    gyrocompass_design: str = "staged"

    def __post_init__(self):
        if self.gyrocompass_design not in GYROCOMPASS_DESIGNS:
            raise InvalidParameter("gyrocompass_design", f"{self.gyrocompass_design!r} is not one of "
                                   f"{', '.join(GYROCOMPASS_DESIGNS)}")


def staged_design(model: ErrorModel, batch: StaticBatch) -> GyrocompassDesign:
    """The staged gyrocompass's stages for this error model and window.

    Parameters
    ----------
    model : ErrorModel
        The sensors' errors (their white noise sets the level loop's bandwidth).
    batch : StaticBatch
        The window: its latitude, duration and gravity are used.

    Returns
    -------
    GyrocompassDesign
    """
    return design_gyrocompass(model, latitude=batch.latitude_rad, duration=batch.duration_s, gravity=batch.gravity)


def _gyrocompass(batch: StaticBatch, model: ErrorModel, settings: AlignmentSettings) -> MethodEstimate:
    if settings.gyrocompass_design == "kpi":
        return align_gyrocompass(batch, time_constant=settings.time_constant_s, damping=settings.damping,
                                 initial_window=settings.initial_window_s, history_step=settings.history_step_s)
    return align_staged_gyrocompass(batch, staged_design(model, batch), initial_window=settings.initial_window_s,
                                    history_step=settings.history_step_s)


def run_methods(batch: StaticBatch, model: ErrorModel, settings: AlignmentSettings) -> dict[str, MethodEstimate]:
    """The four methods on every record of ``batch`` (batched where each allows).

    Parameters
    ----------
    batch : StaticBatch
        The static records (angle and velocity increments, body axes) at one site.
    model : ErrorModel
        The sensors' errors: the Kalman filter's tuning.
    settings : AlignmentSettings
        How the methods are run (loop design, Kalman noise and update interval, windows; SI).

    Returns
    -------
    dict of str to MethodEstimate
        ``coarse``, ``inertial_frame``, ``kalman``, ``gyrocompass`` -> that method's attitude for every record.
    """
    return {
        "coarse": align_coarse(batch, settings.history_step_s),
        "inertial_frame": align_inertial(batch, settings.history_step_s),
        "kalman": align_kalman(batch, model, velocity_noise=settings.velocity_noise,
                               update_interval=settings.update_interval_s,
                               initial_window=settings.initial_window_s, history_step=settings.history_step_s),
        "gyrocompass": _gyrocompass(batch, model, settings),
    }


def method_limits(model: ErrorModel, batch: StaticBatch, heading: float, settings: AlignmentSettings):
    """Each method's :class:`~schuler.alignment.limits.AccuracyLimit` for this model, site and window.

    Parameters
    ----------
    model : ErrorModel
        The sensors' errors the limits come from.
    batch : StaticBatch
        The window: its latitude, duration and gravity are used.
    heading : float
        Heading of the body x axis, rad, clockwise from north.
    settings : AlignmentSettings
        The gyrocompass loop's design and the Kalman filter's noise and update interval (SI).

    Returns
    -------
    dict of str to AccuracyLimit
        Method name (:data:`~schuler.alignment.limits.METHODS`) -> its 1-sigma limits, rad.
    """
    c_gamma, c_a = loop_gains(batch.latitude_rad, settings.time_constant_s, settings.damping)
    limits = {method: accuracy_limit(method, model, latitude=batch.latitude_rad, heading=heading,
                                     duration=batch.duration_s, gravity=batch.gravity, c_gamma=c_gamma, c_a=c_a,
                                     velocity_noise=settings.velocity_noise, update_interval=settings.update_interval_s)
              for method in METHODS}
    if settings.gyrocompass_design == "staged":
        limits["gyrocompass"] = staged_limit(model, staged_design(model, batch), latitude=batch.latitude_rad,
                                             heading=heading, gravity=batch.gravity,
                                             initial_window=settings.initial_window_s)
    return limits


@dataclass
class AlignmentComparison(Result):
    """Every alignment method on the same data.

    ``methods[NAME]`` (NAME in coarse, inertial_frame, kalman, gyrocompass) holds
    ``roll_rad``, ``pitch_rad``, ``heading_rad`` (aerospace, heading clockwise from
    north, in (-180, 180] deg), ``roll_sigma_rad``, ``pitch_sigma_rad``,
    ``heading_sigma_rad`` (the method's own 1-sigma; null where it has none),
    ``convergence_time_s`` (after it the heading stays within the noise part of its
    limit of its final value: the bias part is common to all methods and never
    converges away), ``limit_roll_rad``, ``limit_pitch_rad``, ``limit_heading_rad`` (1-sigma
    limits), ``limit_heading_bias_rad`` and ``limit_heading_noise_rad`` (their two
    parts), and, when the truth is known, ``heading_error_rad`` (computed - true) and
    ``predicted_heading_error_rad`` (the static limit's formula with the record's own biases).
    ``gyrocompass_design`` names the loop's design; ``time_constant_s``, ``damping``, ``c_gamma`` and ``c_a`` are
    the KPI design's; ``gyrocompass_stages`` lists the staged design's stages (name, span, level loop's natural
    period, azimuth time constant at the stage's start, and whether it grows with the time spent in the stage),
    empty for the KPI design. ``estimates[NAME]`` is the method's
    :class:`~schuler.alignment.data.MethodEstimate` (its histories; not in ``to_dict``).
    """

    source: str
    latitude_rad: float
    start_s: float
    duration_s: float
    sample_interval_s: float
    error_model: str
    error_model_source: str
    methods: dict[str, dict[str, Any]]
    agreement: dict[str, dict[str, float | bool]]
    body_rotation_rad: tuple[float, float, float] = (0.0, 0.0, 0.0)
    coarse_disturbance_rad: float = 0.0
    true_attitude_rad: tuple[float, float, float] | None = None
    time_constant_s: float = DESIGN_TIME_CONSTANT
    damping: float = DESIGN_DAMPING
    c_gamma: float = 0.0
    c_a: float = 0.0
    notes: list[str] = field(default_factory=list)
    gyrocompass_design: str = "staged"
    gyrocompass_stages: list[dict[str, Any]] = field(default_factory=list)
    estimates: dict[str, MethodEstimate] = field(default_factory=dict, repr=False)

    units = {"latitude_rad": "rad", "c_gamma": "1/s", "c_a": "1/s", "damping": "1",
             "gyrocompass_stages": "s (start_s, end_s, level_period_s, azimuth_time_constant_s: null when the "
                                   "azimuth is open; growing: it grows by the time spent in the stage)",
             "body_rotation_rad": "rad, the body's net turn over the window (north, east, down)",
             "coarse_disturbance_rad": "rad, the heading shift that turn gives coarse alignment",
             "agreement": "heading difference from kalman (rad) and its ratio to the combined noise limit (1)"}

    def to_dataframe(self):
        """Each method's heading against time, ``{method}_t_s`` and ``{method}_heading_rad`` (first record; s, rad)."""
        import pandas as pd

        columns = {}
        for name, estimate in self.estimates.items():
            columns[f"{name}_t_s"] = pd.Series(estimate.time_s)
            columns[f"{name}_heading_rad"] = pd.Series(estimate.heading_history_rad[0])
        return pd.DataFrame(columns)

    def render(self):
        from rich.console import Group
        from rich.table import Table

        deg, arcmin = math.degrees(1.0), math.degrees(1.0) * 60.0
        window = f"{self.start_s:g} s + {self.duration_s:g} s"
        if self.gyrocompass_design == "kpi":
            loop = f"KPI design, T = {self.time_constant_s:g} s, zeta = {self.damping:g}"
        elif not self.gyrocompass_stages:
            loop = "staged design"
        else:
            last = self.gyrocompass_stages[-1]
            final = last["azimuth_time_constant_s"] + (last["end_s"] - last["start_s"] if last["growing"] else 0.0)
            loop = (f"staged design, level period {last['level_period_s']:.0f} s, azimuth time constant growing "
                    f"to {final:.0f} s")
        table = Table(title=f"Self-alignment of {self.source} ({window}, latitude "
                            f"{math.degrees(self.latitude_rad):.4f} deg)",
                      caption=f"' = arcmin; limits: {self.error_model} ({self.error_model_source}); gyrocompass "
                              f"{loop}")
        columns = ["method", "roll deg", "pitch deg", "heading deg", "1-sigma '", "converged s", "limit '"]
        if self.true_attitude_rad is not None:
            columns += ["error '", "predicted '"]
        for column in columns:
            table.add_column(column, justify="left" if column == "method" else "right")
        for name, row in self.methods.items():
            sigma = row["heading_sigma_rad"]
            cells = [name, f"{row['roll_rad'] * deg:.4f}", f"{row['pitch_rad'] * deg:.4f}",
                     f"{row['heading_rad'] * deg:.4f}", "-" if sigma is None else f"{sigma * arcmin:.3g}",
                     f"{row['convergence_time_s']:.0f}", f"{row['limit_heading_rad'] * arcmin:.3g}"]
            if self.true_attitude_rad is not None:
                cells += [f"{row['heading_error_rad'] * arcmin:+.3g}",
                          f"{row['predicted_heading_error_rad'] * arcmin:+.3g}"]
            table.add_row(*cells)
        lines = [f"{name}: heading {entry['difference_rad'] * arcmin:+.3g} arcmin from kalman = "
                 f"{entry['ratio']:.2g} x its combined noise limit ({'agrees' if entry['agrees'] else 'DISAGREES'})"
                 for name, entry in self.agreement.items()]
        return Group(table, *lines, *self.notes)


def _row(estimate: MethodEstimate, limit, truth, predicted) -> dict[str, Any]:
    sigma = estimate.sigma_rad
    row: dict[str, Any] = {
        "roll_rad": float(estimate.roll_rad[0]), "pitch_rad": float(estimate.pitch_rad[0]),
        "heading_rad": float(estimate.heading_rad[0]),
        "roll_sigma_rad": None if sigma is None else float(sigma[0, 0]),
        "pitch_sigma_rad": None if sigma is None else float(sigma[0, 1]),
        "heading_sigma_rad": None if sigma is None else float(sigma[0, 2]),
        "convergence_time_s": float(convergence_time(estimate.time_s, estimate.heading_history_rad,
                                                     estimate.heading_rad, limit.heading_noise_rad)[0]),
        "limit_roll_rad": float(limit.roll_rad), "limit_pitch_rad": float(limit.pitch_rad),
        "limit_heading_rad": float(limit.heading_rad), "limit_heading_bias_rad": float(limit.heading_bias_rad),
        "limit_heading_noise_rad": float(limit.heading_noise_rad)}
    if truth is not None:
        row["heading_error_rad"] = float(wrap_angle(estimate.heading_rad[0] - truth[2]))
        row["roll_error_rad"] = float(estimate.roll_rad[0] - truth[0])
        row["pitch_error_rad"] = float(estimate.pitch_rad[0] - truth[1])
        row["predicted_heading_error_rad"] = None if predicted is None else float(predicted)
    return row


@renamed_keywords(start_s="start")
def compare_alignment(batch: StaticBatch, model: ErrorModel, settings: AlignmentSettings = AlignmentSettings(), *,
                      source: str = "", start: float = 0.0, model_source: str = "", truth=None,
                      biases=None) -> AlignmentComparison:
    """Run every method on a batch of one record and compare them (module notes).

    Parameters
    ----------
    batch : StaticBatch
        One record (members = 1).
    model : ErrorModel
        The sensors' errors: the limits and the Kalman filter's tuning.
    settings : AlignmentSettings
    source, model_source : str
        What the data and the error model are, for the table.
    start : float
        Where the window starts in the record, s.
    truth : (roll, pitch, heading), optional
        The true attitude, rad (simulated records).
    biases : (gyro_bias, accel_bias), optional
        The record's own constant biases (body axes, measured - true): the predicted errors.
    """
    estimates = run_methods(batch, model, settings)
    heading = float(estimates["coarse"].heading_rad[0]) if truth is None else float(truth[2])
    limits = method_limits(model, batch, heading, settings)
    predicted = None
    if truth is not None and biases is not None:
        predicted = float(static_errors(batch.latitude_rad, heading, biases[0], biases[1], batch.gravity)[2])
    methods = {name: _row(estimates[name], limits[name], truth, predicted) for name in METHODS}
    reference = methods["kalman"]
    agreement = {}
    for name in METHODS:
        if name == "kalman":
            continue
        difference = float(wrap_angle(methods[name]["heading_rad"] - reference["heading_rad"]))
        combined = math.hypot(limits[name].heading_noise_rad, limits["kalman"].heading_noise_rad)
        ratio = abs(difference) / combined if combined > 0 else math.inf
        agreement[name] = {"difference_rad": difference, "ratio": ratio, "agrees": bool(ratio <= AGREEMENT_SIGMAS)}
    c_gamma, c_a = loop_gains(batch.latitude_rad, settings.time_constant_s, settings.damping)
    rotation = net_rotation(batch)[0]
    disturbance = float(-(rotation[1] / batch.duration_s) / horizontal_rate(batch.latitude_rad))
    notes = []
    if not agreement["coarse"]["agrees"]:
        arcsec, deg = math.degrees(1.0) * 3600.0, math.degrees(1.0)
        notes.append(f"coarse alignment disagrees: the body turned by {rotation[1] * arcsec:.0f} arcsec about east "
                     f"over the window (gyros integrated in the inertial frame), a mean rate coarse alignment takes "
                     f"for Earth rate: that alone moves its heading by {disturbance * deg:+.2f} deg (observed "
                     f"{agreement['coarse']['difference_rad'] * deg:+.2f} deg from Kalman); the inertial-frame "
                     "method, the filter and the loop follow the turn with the gyros")
    if not agreement["gyrocompass"]["agrees"] and settings.gyrocompass_design == "kpi":
        memory = 4.0 * settings.damping * settings.time_constant_s
        notes.append(f"the gyrocompass loop disagrees: it reads the instantaneous horizontal specific force as tilt, "
                     f"so the body's sway (horizontal accelerations) turns it in azimuth through c_a; it averages "
                     f"over about 4 zeta T = {memory:.0f} s only, where the inertial-frame method and the filter use "
                     "the integrated specific force over the whole window (the staged design integrates it too: "
                     "--gyrocompass-design staged)")
    elif not agreement["gyrocompass"]["agrees"]:
        notes.append("the gyrocompass loop disagrees beyond its stated noise: the base moved more than its linear "
                     "error model, driven by the sensors' white noise only, allows for")
    stages = staged_design(model, batch).as_dicts() if settings.gyrocompass_design == "staged" else []
    return AlignmentComparison(
        source=source, latitude_rad=batch.latitude_rad, start_s=start, duration_s=batch.duration_s,
        sample_interval_s=batch.sample_interval_s, error_model=model.name, error_model_source=model_source,
        methods=methods, agreement=agreement,
        true_attitude_rad=None if truth is None else (float(truth[0]), float(truth[1]), float(truth[2])),
        time_constant_s=settings.time_constant_s, damping=settings.damping, c_gamma=c_gamma, c_a=c_a,
        body_rotation_rad=(float(rotation[0]), float(rotation[1]), float(rotation[2])),
        coarse_disturbance_rad=disturbance, notes=notes, gyrocompass_design=settings.gyrocompass_design,
        gyrocompass_stages=stages,
        estimates=estimates)


@renamed_keywords(latitude_rad="latitude", heading_rad="heading", duration_s="duration",
                  sample_interval_s="sample_interval")
def simulated_batch(model: ErrorModel, *, latitude: float, heading: float, duration: float,
                    sample_interval: float, members, seed: int = 0):
    """Records of ``model`` at rest, level, at ``heading``: (batch, constants) with each member's true errors.

    ``members`` is a count or a sequence of member numbers (the addresses of the draws).

    Parameters
    ----------
    model : ErrorModel
        The simulated sensors' errors.
    latitude : float
        Site latitude L, rad.
    heading : float
        True heading of the body x axis, rad, clockwise from north (roll and pitch zero).
    duration : float
        Length of each record, s.
    sample_interval : float
        Sample interval dt, s.
    members : int or array_like of int
        Number of members (numbered 0, 1, ...), or the member numbers themselves.
    seed : int
        Seed of the addressed random streams.

    Returns
    -------
    batch : StaticBatch
        One record per member, gravity the simulated (normal gravity at L), m/s^2.
    constants : dict of str to ndarray
        Each member's constant errors (:meth:`~schuler.imu.simulate.ImuSimulator.constants`): ``gyro_bias``
        (m, 3) rad/s, ``accel_bias`` (m, 3) m/s^2 (measured - true, body axes), ``gyro_matrix`` and
        ``accel_matrix`` (m, 3, 3) plain numbers, ``gyro_g`` (m, 3, 3) rad/s per m/s^2.

    Raises
    ------
    MemoryBudgetExceeded
        The records would exceed the memory budget (:func:`schuler.memory.require`).
    """
    ids = np.arange(members) if np.ndim(members) == 0 else np.asarray(members, dtype=np.int64)
    samples = int(round(duration / sample_interval))
    require(ids.size * samples * BYTES_PER_SAMPLE * 2, f"simulating {ids.size:,} records of {samples:,} samples",
            "`duration`, `imu_rate` or the number of members")
    gyro_true, accel_true = static_truth(latitude, heading)
    gyro, accel = simulate_members(model, samples=samples, sample_interval=sample_interval, members=ids,
                                   seed=seed, true_gyro=gyro_true, true_accel=accel_true,
                                   max_memory_bytes=ids.size * samples * BYTES_PER_SAMPLE * 2 + 1)
    gyro *= sample_interval
    accel *= sample_interval
    constants = ImuSimulator(model, sample_interval, seed=seed).constants(ids)
    return StaticBatch(gyro, accel, sample_interval, latitude, float(-accel_true[2])), constants


@renamed_keywords(start_s="start", duration_s="duration")
def window_record(record: ImuRecord, start: float, duration: float | None) -> ImuRecord:
    """The samples of [start, start + duration) of a record, as a record.

    Parameters
    ----------
    record : ImuRecord
        The recording.
    start : float
        Start of the window, s from the record's first sample.
    duration : float or None
        Length of the window, s (None: to the record's end).

    Returns
    -------
    ImuRecord
        The same record restricted to the window.
    """
    first, stop = window_indices(record.samples, record.sample_interval_s, start, duration)
    return replace(record, time_s=record.time_s[first:stop], gyro=record.gyro[first:stop],
                   accel=record.accel[first:stop])


def record_model(record: ImuRecord, grade: str | None) -> tuple[ErrorModel, str]:
    """The error model of a recording's sensors: the grade given, or the grade closest to its Allan deviation.

    The limits are the sensors' (spec 06): the record's own motion is not folded into
    them. At short tau a vehicle's vibration looks like large white noise, yet it
    averages away; what the body's sway and settling do to each method is reported
    beside the limits instead (:func:`compare_alignment`).

    Parameters
    ----------
    record : ImuRecord
        The recording (its Allan deviation is analysed when no grade is given).
    grade : {"navigation", "tactical", "industrial", "consumer"} or None
        The IMU grade given by the user (None: found from the record).

    Returns
    -------
    model : ErrorModel
        The grade's preset.
    source : str
        How it was chosen, for the table.
    """
    if grade is not None:
        return preset(grade), "grade given"
    from schuler.imu.characterise import analyse_record

    analysis = analyse_record(record)
    found = analysis.grade or "consumer"
    return preset(found), ("closest grade to the record's Allan deviation" if analysis.grade else
                           "no grade below the record's Allan deviation: consumer assumed")
