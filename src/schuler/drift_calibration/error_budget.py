"""The error budget of the alternating-pulse calibration (its Monte Carlo: :mod:`.monte_carlo`).

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
from dataclasses import dataclass

import numpy as np

from schuler.core.geometry import ARCMIN, ARCSEC, DEGREE
from schuler.exceptions import InvalidParameter


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

    def scaled(self, factor: float) -> ErrorBudget:
        """Every random item times ``factor`` (the deterministic loop values kept)."""
        keep = {"loop_time_constant", "sway_frequency"}
        return dataclasses.replace(self, **{f.name: getattr(self, f.name) * factor
                                           for f in dataclasses.fields(self) if f.name not in keep})

    def only(self, *names: str) -> ErrorBudget:
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
    angle_random_walk=0.001 * DEGREE / math.sqrt(3600.0),  # 0.001 deg/sqrt(h)
    turn_angle_error=5.0 * ARCSEC,
    levelling_residual=10.0 * ARCSEC,
    initial_angle=10.0 * ARCSEC,
    latitude_error=1.0 * ARCMIN,
)
"""The documented typical budget (see :class:`ErrorBudget` for each value's origin)."""

NONE = ErrorBudget()
"""No errors: the procedure is exact."""
