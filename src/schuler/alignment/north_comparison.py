"""The turntable north finders side by side, against their analytic accuracy and the ground gyrocompass.

:func:`compare_north` simulates, for one grade, ``members`` turntable records
per method (the IMU layer's error model, draws addressed by seed and member),
finds north in all of them at once, and sets the Monte Carlo spread beside the
closed form (:func:`~schuler.alignment.north.north_sigma`); the accuracy versus
time (analytic, 30 s to 1 h) and versus grade (every preset at the chosen
time) go with it. The ground gyrocompass of schuler north enters through a function
the caller passes in (``ground_gyrocompass(durations, readout_noise, latitude)``
-> 1-sigma of north): this package does not import the seed systems, the
system that owns the command hands its own evaluation over.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from schuler.alignment.data import BYTES_PER_SAMPLE
from schuler.alignment.north import (
    DEFAULT_CAROUSEL_PERIOD,
    NORTH_METHODS,
    find_north,
    north_sigma,
    schedule,
    turntable_rates,
)
from schuler.core.attitude import wrap_angle
from schuler.exceptions import renamed_keywords
from schuler.imu.error_model import ErrorModel
from schuler.imu.simulate import ImuSimulator, iter_simulation
from schuler.imu.spec import GRADES, preset
from schuler.memory import require
from schuler.results import Result

TIMES_S = (30.0, 60.0, 120.0, 300.0, 600.0, 1200.0, 3600.0)
"""Observation times of the accuracy-versus-time curves, s."""

READOUT_STEP_S = 1.0
"""Sampling step of the ground gyrocompass's read-out at which a grade's noise is taken, s."""


@renamed_keywords(step_s="step")
def readout_noise(model: ErrorModel, step: float = READOUT_STEP_S) -> float:
    """The angle read-out noise a grade's gyro gives over a step h: sqrt(Q^2 + N^2 h), rad (z gyro).

    The mapping of :func:`schuler.imu.system_inputs.north_inputs`: the azimuth angle
    integrated over h carries the angle random walk N sqrt(h) and the quantisation Q.

    Parameters
    ----------
    model : ErrorModel
        The grade's errors: the z gyro's quantisation Q (rad) and angle random walk N (rad/sqrt(s)).
    step : float
        Read-out step h, s.

    Returns
    -------
    float
        1-sigma of the angle read-out, rad.
    """
    q, n = model.gyro.quantization[2], model.gyro.random_walk[2]
    return float(math.sqrt(q**2 + n**2 * step))


@renamed_keywords(latitude_rad="latitude", heading_rad="heading", sample_interval_s="sample_interval",
                  carousel_period_s="carousel_period")
def simulate_turntable(model: ErrorModel, method: str, *, latitude: float, heading: float, samples: int,
                       sample_interval: float, members, seed: int, axes: str,
                       carousel_period: float = DEFAULT_CAROUSEL_PERIOD):
    """Gyro records of a level IMU on the method's schedule: (rates (m, n, k), start, end).

    Parameters
    ----------
    model : ErrorModel
        The simulated sensors' errors.
    method : {"two_position", "four_position", "carousel"}
        The turntable schedule (:func:`~schuler.alignment.north.schedule`).
    latitude : float
        Site latitude L, rad.
    heading : float
        True azimuth psi of the x axis at table angle 0, rad, clockwise from north.
    samples : int
        Number of samples n per record.
    sample_interval : float
        Sample interval dt, s.
    members : int or array_like of int
        Number of members m (numbered 0, 1, ...), or the member numbers themselves.
    seed : int
        Seed of the addressed random streams.
    axes : {"x", "xy"}
        The x gyro alone or both horizontal gyros (k = 1 or 2).
    carousel_period : float
        One turn of the carousel, s (``carousel`` only).

    Returns
    -------
    rates : ndarray of shape (m, n, k)
        Mean measured angular rate over each sample interval, rad/s, body x (and y).
    start, end : ndarray of shape (n,)
        Table angle at the start and the end of each interval, rad.

    Raises
    ------
    MemoryBudgetExceeded
        The records would exceed the memory budget (:func:`schuler.memory.require`).
    """
    start, end = schedule(method, samples=samples, sample_interval=sample_interval,
                          carousel_period=carousel_period)
    truth = turntable_rates(latitude, heading, start, end, sample_interval)
    ids = np.arange(members) if np.ndim(members) == 0 else np.asarray(members, dtype=np.int64)
    require(ids.size * samples * BYTES_PER_SAMPLE, f"simulating {ids.size:,} turntable records",
            "`duration`, `imu_rate` or `monte_carlo`")
    # the accelerometers read (0, 0, -g) throughout: the table turns about the vertical
    simulator = ImuSimulator(model, sample_interval, true_gyro=truth,
                             true_accel=np.array([0.0, 0.0, -9.80665]), seed=seed)
    rates = np.empty((ids.size, samples, len(axes)))
    row = 0
    for group, first, gyro, _ in iter_simulation(simulator, ids, samples, member_chunk=64):
        rates[row:row + group.size, first:first + gyro.shape[1]] = gyro[:, :, :len(axes)]
        if first + gyro.shape[1] == samples:
            row += group.size
    return rates, start, end


@dataclass
class NorthComparison(Result):
    """North finders on simulated turntable records of one grade.

    ``methods[NAME]`` (two_position, four_position, carousel): ``heading_rad`` and
    ``sigma_rad`` of member 0 (its fit), ``error_rad`` (computed - true),
    ``analytic_sigma_rad`` (closed form, white noise), ``monte_carlo_sigma_rad`` and
    ``monte_carlo_mean_rad`` (spread and mean error over the members), ``ambiguous``
    (sign of psi unknown). ``versus_time`` holds ``duration_s`` and, per method and for
    ``ground_gyrocompass``, the 1-sigma at each; ``versus_grade[GRADE][NAME]`` the
    analytic 1-sigma at ``duration_s``.
    """

    grade: str
    latitude_rad: float
    heading_rad: float
    duration_s: float
    sample_interval_s: float
    axes: str
    carousel_period_s: float
    members: int
    seed: int
    methods: dict[str, dict]
    versus_time: dict[str, list]
    versus_grade: dict[str, dict[str, float]]
    ground_gyrocompass: dict[str, float]
    notes: list[str] = field(default_factory=list)

    units = {"latitude_rad": "rad", "heading_rad": "rad", "members": "1", "seed": "1",
             "versus_time": "s (duration_s), rad (1-sigma)", "versus_grade": "rad",
             "ground_gyrocompass": "rad (readout_noise_rad, sigma_rad)"}

    def to_dataframe(self):
        """Each method's 1-sigma (rad) against the observation time ``duration_s`` (s)."""
        import pandas as pd

        return pd.DataFrame(self.versus_time)

    def render(self):
        from rich.console import Group
        from rich.table import Table

        arcmin = math.degrees(1.0) * 60.0
        table = Table(title=f"North finding, {self.grade} grade, {self.duration_s:g} s, latitude "
                            f"{math.degrees(self.latitude_rad):g} deg, axes {self.axes}",
                      caption=f"{self.members} Monte Carlo members per method (seed {self.seed}); true azimuth "
                              f"{math.degrees(self.heading_rad):g} deg")
        for column in ("method", "azimuth (deg)", "fit 1-sigma (arcmin)", "error (arcmin)", "analytic (arcmin)",
                       "Monte Carlo (arcmin)"):
            table.add_column(column, justify="left" if column == "method" else "right")
        for name, row in self.methods.items():
            table.add_row(name + (" (sign ambiguous)" if row["ambiguous"] else ""),
                          f"{math.degrees(row['heading_rad']):.4f}", f"{row['sigma_rad'] * arcmin:.3g}",
                          f"{row['error_rad'] * arcmin:+.3g}", f"{row['analytic_sigma_rad'] * arcmin:.3g}",
                          f"{row['monte_carlo_sigma_rad'] * arcmin:.3g}")
        sigma = self.ground_gyrocompass["sigma_rad"]
        if sigma is not None and math.isfinite(sigma):
            table.add_row("ground gyrocompass (schuler north)", "", "", "", f"{sigma * arcmin:.3g}", "")
        return Group(table, *self.notes)


@renamed_keywords(latitude_rad="latitude", heading_rad="heading", duration_s="duration",
                  sample_interval_s="sample_interval", carousel_period_s="carousel_period")
def compare_north(grade: str, *, latitude: float, heading: float, duration: float, sample_interval: float,
                  axes: str = "x", carousel_period: float = DEFAULT_CAROUSEL_PERIOD, members: int = 200,
                  seed: int = 0, ground_gyrocompass: Callable | None = None) -> NorthComparison:
    """Every north finder for one grade (module notes).

    Parameters
    ----------
    grade : str
        An IMU preset (:data:`schuler.imu.spec.GRADES`).
    latitude, heading : float
        Site latitude and the true azimuth of the x axis at table angle 0, rad.
    duration, sample_interval : float
        Total observation time and sample interval, s.
    axes : {"x", "xy"}
        One gyro, or both horizontal gyros.
    carousel_period : float
        One carousel turn, s.
    members, seed : int
        Monte Carlo members per method and their seed.
    ground_gyrocompass : callable, optional
        ``f(durations, readout_noise, latitude) -> 1-sigma`` of schuler north.
    """
    model = preset(grade)
    samples = int(round(duration / sample_interval))
    methods = {}
    for method in NORTH_METHODS:
        rates, start, end = simulate_turntable(model, method, latitude=latitude, heading=heading,
                                               samples=samples, sample_interval=sample_interval,
                                               members=max(1, members), seed=seed, axes=axes,
                                               carousel_period=carousel_period)
        estimate = find_north(rates, start, end, latitude, method, axes)
        truth = abs(wrap_angle(heading)) if estimate.ambiguous else heading
        errors = wrap_angle(estimate.heading_rad - truth)
        methods[method] = {
            "heading_rad": float(estimate.heading_rad[0]), "sigma_rad": float(estimate.sigma_rad[0]),
            "error_rad": float(errors[0]), "ambiguous": estimate.ambiguous,
            "analytic_sigma_rad": float(north_sigma(method, axes, model.gyro.random_walk[0], latitude,
                                                    samples * sample_interval, heading)),
            "monte_carlo_sigma_rad": float(errors.std(ddof=1)) if errors.size > 1 else None,
            "monte_carlo_mean_rad": float(errors.mean())}
    times = np.asarray(TIMES_S)
    versus_time: dict[str, list] = {"duration_s": times.tolist()}
    for method in NORTH_METHODS:
        versus_time[method] = np.atleast_1d(north_sigma(method, axes, model.gyro.random_walk[0], latitude, times,
                                                        heading)).tolist()
    versus_grade = {name: {method: float(north_sigma(method, axes, preset(name).gyro.random_walk[0], latitude,
                                                     duration, heading)) for method in NORTH_METHODS}
                    for name in GRADES}
    noise = readout_noise(model)
    gyro_entry = {"readout_noise_rad": noise, "sigma_rad": math.nan}
    notes = ["the analytic 1-sigma counts white gyro noise only; bias instability (flicker) moves the bias between "
             "the dwells of the position methods and adds to their Monte Carlo spread"]
    if ground_gyrocompass is not None:
        curve = np.asarray(ground_gyrocompass(times, noise, latitude), dtype=float)
        versus_time["ground_gyrocompass"] = curve.tolist()
        gyro_entry["sigma_rad"] = float(np.asarray(ground_gyrocompass(np.array([duration]), noise,
                                                                       latitude))[0])
        notes.append("ground gyrocompass (schuler north): the source's instrument (rotor run-down, 4 unknowns "
                     f"identified) read every {READOUT_STEP_S:g} s with the grade's angle noise sqrt(Q^2 + N^2 h) = "
                     f"{math.degrees(noise) * 3600:.3g} arcsec; its directive torque H Omega cos L acts on a "
                     "sensitive element whose swing is observed directly, so the same read-out noise costs far less "
                     "azimuth than rate noise does a strapdown gyro (its own errors, e.g. suspension torques, "
                     "are not part of this comparison)")
    return NorthComparison(grade=grade, latitude_rad=latitude, heading_rad=heading,
                           duration_s=samples * sample_interval, sample_interval_s=sample_interval, axes=axes,
                           carousel_period_s=carousel_period, members=int(members), seed=seed, methods=methods,
                           versus_time=versus_time, versus_grade=versus_grade, ground_gyrocompass=gyro_entry,
                           notes=notes)
