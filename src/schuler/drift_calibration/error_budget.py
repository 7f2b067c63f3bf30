"""The error budget of the alternating-pulse calibration.

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

The draws themselves are addressed per member
(:mod:`~schuler.drift_calibration.draws`). The source gives no budget for its
0.34 % / 2 arcmin; ours is stated here and
:mod:`schuler.drift_calibration.reproduction` compares.

Example
-------
>>> round(TYPICAL.scaled(0.5).turn_angle_error / ARCSEC, 9), TYPICAL.scaled(0.5).loop_time_constant
(2.5, 0.002)
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from schuler.core.geometry import ARCMIN, ARCSEC
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
        """Every random item times ``factor`` (the deterministic loop values kept).

        Parameters
        ----------
        factor : float
            Scale of every random item, plain number.
        """
        keep = {"loop_time_constant", "sway_frequency"}
        return dataclasses.replace(self, **{f.name: getattr(self, f.name) * factor
                                           for f in dataclasses.fields(self) if f.name not in keep})


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
    angle_random_walk=0.001 * ARCMIN,  # 0.001 deg/sqrt(h) = 0.001 arcmin/sqrt(s)
    turn_angle_error=5.0 * ARCSEC,
    levelling_residual=10.0 * ARCSEC,
    initial_angle=10.0 * ARCSEC,
    latitude_error=1.0 * math.pi / 180.0 / 60.0,
)
"""The documented typical budget (see :class:`ErrorBudget` for each value's origin)."""
