"""The error budget of the alternating-pulse calibration and its Monte Carlo.

Every item is a standard deviation of a zero-mean Gaussian error (SI), except
the two deterministic loop values; :data:`TYPICAL` holds defaults taken from
typical data of precision floated gyros and their electronics, each justified
below. Items are drawn at the level where they physically change:

* per procedure (shared by every run, so they bias omega_d but cancel in
  omega_X0 when equal at both positions): command-sensor scale error (one per
  channel), integrator offset (one per channel), +/- pulse amplitude and
  duration mismatch and pulse asymmetry (one generator), the latitude error,
  the error of the loop time constant used to compensate the loop lag;
* per platform position (the platform is re-levelled after each turn): turn
  angle error, levelling residual of each horizontal axis;
* per cycle: initial sensor angle U0/K1, base sway phase and amplitude, and
  inside the cycle the white sensor noise and the gyro angle random walk.

The source gives no budget for its 0.34 % / 2 arcmin; ours is stated here
and :mod:`schuler.drift_calibration.reproduction` compares.

Example
-------
>>> import numpy as np
>>> d = TYPICAL.draw("position", 3, np.random.default_rng(0))
>>> sorted(d)
['elevation_x', 'elevation_y', 'turn_error']
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from schuler.core.earth import EARTH_RATE
from schuler.drift_calibration.procedure import ProcedureOutcome, run_procedure
from schuler.drift_calibration.stabilizer import Stabilizer
from schuler.exceptions import InvalidParameter

ARCSEC = math.pi / 180.0 / 3600.0
DEG_PER_HOUR = math.pi / 180.0 / 3600.0


@dataclass(frozen=True)
class ErrorBudget:
    """Standard deviations of the instrument and procedure errors (SI).

    Parameters
    ----------
    sensor_noise_density : float
        White noise of the command angle sensor, rad/sqrt(Hz). Typical 0.01
        arcsec/sqrt(Hz): an inductive angle sensor resolving 0.1 arcsec in 100 Hz.
    sensor_scale_error : float
        Relative error of K1 (per channel), dimensionless. Typical 1e-4: K1
        calibrated on a dividing head, with its temperature drift.
    amplitude_mismatch : float
        Relative amplitude difference of the - and + pulse, dimensionless.
        Typical 1e-5: one precision current source switched in polarity.
    duration_mismatch : float
        Relative duration difference of the - and + pulse, dimensionless.
        Typical 1e-6: quartz-timed gating, microseconds on seconds.
    pulse_asymmetry : float
        Tilt of the pulse top, ``i -> i + tilt * (2 t / tau - 1) i_max``,
        dimensionless. Typical 1e-5 (droop of the current source).
    integrator_offset : float
        Input offset of the integrator referred to the sensor angle, rad.
        Typical 2 milliarcsec (about 0.6 uV at K1 = 1 V/deg: a chopper-stabilised integrator).
    loop_time_constant : float
        Time constant of the stabilization loop, s (deterministic). Typical 2 ms
        (a loop of about 80 Hz bandwidth).
    lag_compensation_error : float
        Relative error of the loop time constant used to compensate the lag,
        dimensionless. Typical 0.02.
    sway_amplitude : float
        Base sway angle about the measured axis, rad. Typical 0.2 arcsec (a
        rigid stand; a launch pad in wind sways by arcseconds, which dominates the budget).
    sway_frequency : float
        Base sway frequency, Hz (deterministic). Typical 0.7 Hz (a sway over a
        whole number of periods per pulse would cancel exactly).
    angle_random_walk : float
        Gyro angle random walk, rad/sqrt(s). Typical 0.001 deg/sqrt(h) (a
        precision floated gyro).
    turn_angle_error : float
        Error of each platform turn about the vertical, rad. Typical 5 arcsec.
    levelling_residual : float
        Residual tilt (elevation) of each horizontal axis after levelling, rad.
        Typical 10 arcsec (couples Omega sin(phi) into the channel: 7e-4 deg/h at 70 deg).
    initial_angle : float
        Command-sensor angle at the start of a cycle, rad. Typical 10 arcsec
        (cancels with an ideal integrator).
    latitude_error : float
        Error of the site latitude, rad. Typical 1 arcmin (matters only for the
        single-axis asin).
    """

    sensor_noise_density: float = 0.0
    sensor_scale_error: float = 0.0
    amplitude_mismatch: float = 0.0
    duration_mismatch: float = 0.0
    pulse_asymmetry: float = 0.0
    integrator_offset: float = 0.0
    loop_time_constant: float = 0.0
    lag_compensation_error: float = 0.0
    sway_amplitude: float = 0.0
    sway_frequency: float = 0.7
    angle_random_walk: float = 0.0
    turn_angle_error: float = 0.0
    levelling_residual: float = 0.0
    initial_angle: float = 0.0
    latitude_error: float = 0.0

    def __post_init__(self):
        for item in dataclasses.fields(self):
            value = getattr(self, item.name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise InvalidParameter(item.name, f"must be a finite number >= 0, got {value!r}")
        if self.sway_frequency <= 0:
            raise InvalidParameter("sway_frequency", "must be > 0")

    def scaled(self, factor: float) -> "ErrorBudget":
        """Every random item times ``factor`` (the deterministic loop values kept)."""
        keep = {"loop_time_constant", "sway_frequency"}
        return dataclasses.replace(self, **{f.name: getattr(self, f.name) * factor
                                           for f in dataclasses.fields(self) if f.name not in keep})

    def only(self, *names: str) -> "ErrorBudget":
        """This budget with every item but ``names`` set to zero (loop lag off unless named)."""
        zero = {f.name: 0.0 for f in dataclasses.fields(self)}
        zero["sway_frequency"] = self.sway_frequency
        zero.update({name: getattr(self, name) for name in names})
        return ErrorBudget(**zero)

    def draw(self, level: str, count: int, rng: np.random.Generator, channels: int = 2) -> dict:
        """Random errors of one level ("procedure", "position" or "cycle") for ``count`` members."""
        normal = rng.standard_normal
        if level == "procedure":
            return {
                "sensor_scale_error": self.sensor_scale_error * normal((count, channels)),
                "integrator_offset": self.integrator_offset * normal((count, channels)),
                "amplitude_mismatch": self.amplitude_mismatch * normal(count),
                "duration_mismatch": self.duration_mismatch * normal(count),
                "tilt": self.pulse_asymmetry * normal(count),
                "latitude_error": self.latitude_error * normal(count),
                "lag_compensation_error": self.lag_compensation_error * normal(count),
            }
        if level == "position":
            return {
                "turn_error": self.turn_angle_error * normal(count),
                "elevation_x": self.levelling_residual * normal(count),
                "elevation_y": self.levelling_residual * normal(count),
            }
        if level == "cycle":
            omega = 2.0 * math.pi * self.sway_frequency
            return {
                "initial_angle": self.initial_angle * normal(count),
                "sway_angle": self.sway_amplitude * normal(count),
                "sway_rate": omega * self.sway_amplitude * normal(count),
            }
        raise InvalidParameter("level", f"{level!r} is not procedure, position or cycle")


TYPICAL = ErrorBudget(
    sensor_noise_density=0.01 * ARCSEC,
    sensor_scale_error=1e-4,
    amplitude_mismatch=1e-5,
    duration_mismatch=1e-6,
    pulse_asymmetry=1e-5,
    integrator_offset=0.002 * ARCSEC,
    loop_time_constant=0.002,
    lag_compensation_error=0.02,
    sway_amplitude=0.2 * ARCSEC,
    sway_frequency=0.7,
    angle_random_walk=0.001 * math.radians(1.0) / 60.0,
    turn_angle_error=5.0 * ARCSEC,
    levelling_residual=10.0 * ARCSEC,
    initial_angle=10.0 * ARCSEC,
    latitude_error=1.0 * math.pi / 180.0 / 60.0,
)
"""The documented typical budget (see :class:`ErrorBudget` for each value's origin)."""

NONE = ErrorBudget()
"""No errors: the procedure is exact."""


@dataclass(frozen=True)
class MonteCarloSummary:
    """Statistics of the recovered drifts and azimuth over Monte Carlo trials (SI).

    Attributes
    ----------
    trials : int
    mean_relative_drift_error, rms_relative_drift_error : float
        Mean of |omega_d error| / |omega_d| and the RMS of the signed relative
        error, over both gyros in three-axis mode (dimensionless).
    mean_drift_error, rms_drift_error : float
        Signed mean and RMS of the drift error, rad/s.
    mean_azimuth_error, rms_azimuth_error, mean_abs_azimuth_error : float
        Of the azimuth error, rad.
    drift_errors, azimuth_errors : ndarray
        Every trial's errors (rad/s, shape (trials, channels); rad, shape (trials,)).
    """

    trials: int
    mean_relative_drift_error: float
    rms_relative_drift_error: float
    mean_drift_error: float
    rms_drift_error: float
    mean_azimuth_error: float
    rms_azimuth_error: float
    mean_abs_azimuth_error: float
    drift_errors: np.ndarray = field(repr=False)
    azimuth_errors: np.ndarray = field(repr=False)


def drift_errors_of(outcome: ProcedureOutcome, drift_x, drift_y, mode: str) -> np.ndarray:
    """Recovered minus true own drifts, shape (M, channels), rad/s."""
    columns = [outcome.drift_x - drift_x]
    if mode == "three-axis":
        columns.append(outcome.drift_y - drift_y)
    return np.column_stack(columns)


def monte_carlo(
    stabilizer: Stabilizer,
    latitude: float,
    azimuth: float,
    drift_x: float,
    drift_y: float | None = None,
    *,
    budget: ErrorBudget = TYPICAL,
    trials: int = 1000,
    mode: str = "three-axis",
    positions: int = 2,
    cycles: int = 1,
    seed: int = 0,
    chunk_size: int = 2000,
    earth_rate: float = EARTH_RATE,
    steps: int = 40,
) -> MonteCarloSummary:
    """Vectorised Monte Carlo of the whole procedure over an error budget.

    The stabilizer's loop time constant is replaced by the budget's. Members are
    simulated ``chunk_size`` at a time (bounded memory), all of a chunk at once.

    Parameters
    ----------
    stabilizer : Stabilizer
    latitude, azimuth : float
        Site latitude and true azimuth A0, rad.
    drift_x, drift_y : float
        True own drifts, rad/s (drift_y defaults to drift_x; must be nonzero for relative errors).
    budget : ErrorBudget
    trials : int
        Number of simulated procedures (>= 1).
    mode, positions, cycles : as in :func:`~schuler.drift_calibration.procedure.run_procedure`.
    seed : int
        Seed of the random generator.

    Example
    -------
    >>> from schuler.drift_calibration.pulses import rectangular
    >>> stab = Stabilizer(57.3, 0.02, 0.1, 1e-3, 5.0, rectangular())
    >>> s = monte_carlo(stab, np.radians(70), np.radians(80), 1e-6, trials=50, budget=TYPICAL.only("latitude_error"))
    >>> s.rms_azimuth_error   # three-axis: atan2 ignores the latitude
    0.0
    """
    if trials < 1:
        raise InvalidParameter("monte_carlo", "need at least one trial")
    drift_y = drift_x if drift_y is None else drift_y
    if drift_x == 0 or drift_y == 0:
        raise InvalidParameter("drift", "relative drift errors need a nonzero drift")
    instrument = dataclasses.replace(stabilizer, loop_time_constant=budget.loop_time_constant,
                                     sway_frequency=budget.sway_frequency)
    rng = np.random.default_rng(seed)
    drift_parts, azimuth_parts = [], []
    for start in range(0, trials, chunk_size):
        count = min(chunk_size, trials - start)
        outcome = run_procedure(instrument, latitude, azimuth, drift_x, drift_y, mode=mode, positions=positions,
                                cycles=cycles, budget=budget, members=count, rng=rng, earth_rate=earth_rate,
                                steps=steps)
        drift_parts.append(drift_errors_of(outcome, drift_x, drift_y, mode))
        azimuth_parts.append(outcome.azimuth_error)
    drift_errors = np.concatenate(drift_parts)
    azimuth_errors = np.concatenate(azimuth_parts)
    truth = np.array([drift_x, drift_y][: drift_errors.shape[1]])
    relative = drift_errors / np.abs(truth)
    return MonteCarloSummary(
        trials=trials,
        mean_relative_drift_error=float(np.mean(np.abs(relative))),
        rms_relative_drift_error=float(np.sqrt(np.mean(relative**2))),
        mean_drift_error=float(np.mean(drift_errors)),
        rms_drift_error=float(np.sqrt(np.mean(drift_errors**2))),
        mean_azimuth_error=float(np.mean(azimuth_errors)),
        rms_azimuth_error=float(np.sqrt(np.mean(azimuth_errors**2))),
        mean_abs_azimuth_error=float(np.mean(np.abs(azimuth_errors))),
        drift_errors=drift_errors,
        azimuth_errors=azimuth_errors,
    )
