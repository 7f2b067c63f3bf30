"""From an error model to the inputs of the other systems: one documented mapping, SI values.

Conventions (spec 06, Groves 2013 ch. 14): sensor bias = measured - true, body
axes x forward, y right, z down; NED navigation frame; a level IMU with
heading psi has C_b^n = R_z(psi). A **platform drift** is the rotation rate the
gyro errors give the platform, epsilon = -C b_g (the seeds' "own drift").

**Platform axes.** ``align`` (KPI manual) and ``calibrate`` (pulse method) use
a level platform frame x, y, z with z up and the azimuth A of the y axis
clockwise from north (align: U_y = U cos(phi) cos A; calibrate: A0 of the Y
axis). The IMU is that platform's sensor triad, mounted x forward along the
platform y axis: platform x = body y (right), platform y = body x (forward),
platform z = -body z (up). So a platform x accelerometer bias is the body y
one, and the drift about platform z is -(-b_gz) = +b_gz.

Which bias counts as **residual**: the error left after the system has measured
what it can. Gyro turn-on biases are what drift calibration (``calibrate``)
estimates, so the residual gyro drift of ``align`` and ``errors`` is the change
of the bias between calibration and use: the standard deviation of the
difference of two consecutive averages over ``window_s`` is sqrt(2) times the
Allan deviation of the slow terms (flicker B, Gauss-Markov, K; white noise N and
quantisation Q average out and enter separately as random walk). Accelerometer
turn-on biases stay: at rest a bias is indistinguishable from a tilt, so nothing
before navigation removes it. ``calibrate`` itself gets the whole turn-on bias:
that is the drift it is there to measure.

Values and sigmas: ``values`` is one representative case, every body-axis
error at +1 sigma, resolved into the frames the system uses, plus the
system's Monte Carlo sigmas where it has them (``sigma_drift`` ...);
``sigmas`` are the 1-sigma spreads of the error values (independent axes).

Examples
--------
>>> from schuler.imu.spec import preset
>>> inputs = calibrate_inputs(preset("tactical"))
>>> round(inputs.values["drift_x"] / 4.84813681109536e-06, 6)   # -(1 deg/h): drift = -bias
-1.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY
from schuler.exceptions import InvalidParameter, renamed_keywords
from schuler.imu.error_model import ErrorModel, SensorErrors
from schuler.results import Result

DEFAULT_WINDOW_S = 600.0
"""Default time between calibration and use (and the averaging window), s."""


@dataclass
class SystemInputs(Result):
    """Parameters for one system, SI, from an error model.

    Attributes
    ----------
    system : str
        ``align``, ``calibrate``, ``north`` or ``errors``.
    model : str
        The error model's name.
    values : dict
        Parameter name -> SI value (one representative +1-sigma case, and the
        system's Monte Carlo sigmas where it has them); for ``errors``, source
        name -> magnitude.
    sigmas : dict
        Name -> 1-sigma spread of the error value (random quantities only).
    parameter_units : dict
        Parameter name -> SI unit.
    notes : list of str
        What each value means.
    """

    system: str
    model: str
    values: dict[str, float]
    sigmas: dict[str, float] = field(default_factory=dict)
    parameter_units: dict[str, str] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

    def render(self):
        from rich.table import Table

        table = Table(title=f"{self.system} inputs from {self.model}")
        for column in ("parameter", "value", "1-sigma", "unit"):
            table.add_column(column, justify="right" if column in ("value", "1-sigma") else "left")
        for name, value in self.values.items():
            sigma = self.sigmas.get(name)
            table.add_row(name, f"{value:.4g}", "" if sigma is None else f"{sigma:.4g}", self.parameter_units[name])
        if self.notes:
            table.caption = "; ".join(self.notes)
        return table


def _check_window(window_s: float, name: str = "window") -> float:
    if not (math.isfinite(window_s) and window_s > 0):
        raise InvalidParameter(name, f"must be finite and > 0 s, got {window_s!r}")
    return float(window_s)


def _check_latitude(latitude_rad: float, limit: float = math.radians(89.0)) -> float:
    if not (math.isfinite(latitude_rad) and abs(latitude_rad) <= limit):
        raise InvalidParameter("latitude", f"{math.degrees(latitude_rad):g} deg must be within +/-"
                               f"{math.degrees(limit):g} deg (azimuth is unobservable at the pole)")
    return float(latitude_rad)


@renamed_keywords(window_s="window")
def residual_bias(errors: SensorErrors, window: float, include_turn_on: bool) -> np.ndarray:
    """1-sigma residual bias per body axis: sqrt(b^2 [if kept] + 2 sigma_A,slow^2(window)).

    ``sigma_A,slow`` is the Allan deviation of the slow terms only (flicker,
    Gauss-Markov, rate random walk).

    Parameters
    ----------
    errors : SensorErrors
        The triad's error model, SI.
    window : float
        Time between the bias estimate and use, which is also the averaging window, s (> 0).
    include_turn_on : bool
        True: the turn-on bias b stays in the residual (nothing removed it); False: only its change counts.

    Returns
    -------
    ndarray
        Residual bias, shape (3,), body axes x forward, y right, z down: rad/s (gyro triad) or m/s^2
        (accelerometer triad).
    """
    window = _check_window(window)
    slow = replace(errors, random_walk=np.zeros(3), quantization=np.zeros(3))
    drift = np.array([2.0 * float(slow.allan_variance(np.array([window]), axis)[0]) for axis in range(3)])
    if include_turn_on:
        drift = drift + errors.bias**2
    return np.sqrt(drift)


def _level_rotation(heading_rad: float) -> np.ndarray:
    c, s = math.cos(heading_rad), math.sin(heading_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _horizontal_rms(values: np.ndarray) -> float:
    """One figure for the two horizontal axes: sqrt((v_x^2 + v_y^2) / 2)."""
    return float(math.sqrt((values[0] ** 2 + values[1] ** 2) / 2.0))


@renamed_keywords(heading_rad="heading", window_s="window")
def align_inputs(model: ErrorModel, *, heading: float = 0.0, window: float = DEFAULT_WINDOW_S,
                 calibrated_gyros: bool = True) -> SystemInputs:
    """``align`` (gyrocompassing) inputs: residual platform drifts, accelerometer biases and their sigmas.

    Parameters
    ----------
    model : ErrorModel
    heading : float
        Heading of the body x axis, rad: align's azimuth A of the platform y axis.
    window : float
        Time between the gyro calibration and the alignment, s.
    calibrated_gyros : bool
        True: the gyro turn-on bias is removed (residual = its change over the window).

    Returns
    -------
    SystemInputs
        ``drift_east``, ``drift_north`` (rad/s): epsilon = -C_b^n b_g for b_g at
        +1 sigma on each axis, NED east and north components; ``drift_z`` (rad/s,
        platform z = up): -epsilon_down = +b_gz; ``accel_bias_x``, ``accel_bias_y``
        (m/s^2, platform x = body y, platform y = body x): turn-on bias and its
        change over the window; ``sigma_drift`` (rms of the horizontal residual
        drifts), ``sigma_drift_z`` and ``sigma_accel`` (rms of the two horizontal
        accelerometers) for align's Monte Carlo.
    """
    gyro = residual_bias(model.gyro, window, include_turn_on=not calibrated_gyros)
    accel = residual_bias(model.accel, window, include_turn_on=True)
    rotation = _level_rotation(heading)
    drift_ned = -rotation @ gyro
    spread_ned = np.sqrt((rotation**2) @ gyro**2)
    values = {"drift_east": float(drift_ned[1]) + 0.0, "drift_north": float(drift_ned[0]) + 0.0,
              "drift_z": float(-drift_ned[2]) + 0.0,  # + 0.0: no negative zero in tables and JSON
              "accel_bias_x": float(accel[1]), "accel_bias_y": float(accel[0]),
              "sigma_drift": _horizontal_rms(gyro), "sigma_drift_z": float(gyro[2]),
              "sigma_accel": _horizontal_rms(accel)}
    sigmas = {"drift_east": float(spread_ned[1]), "drift_north": float(spread_ned[0]), "drift_z": float(gyro[2]),
              "accel_bias_x": float(accel[1]), "accel_bias_y": float(accel[0])}
    units = {name: "rad/s" for name in ("drift_east", "drift_north", "drift_z", "sigma_drift", "sigma_drift_z")}
    units.update(accel_bias_x="m/s^2", accel_bias_y="m/s^2", sigma_accel="m/s^2")
    notes = [f"drift = -C_b^n b_g with b_g at +1 sigma, heading (align's azimuth) {math.degrees(heading):g} deg",
             f"gyro turn-on bias {'removed by calibration' if calibrated_gyros else 'kept'}; change over "
             f"{window:g} s = sqrt(2) x slow-term Allan deviation",
             "accelerometer turn-on bias kept (indistinguishable from tilt at rest); platform x, y = body y, x"]
    return SystemInputs("align", model.name, values, sigmas, units, notes)


@renamed_keywords(window_s="window")
def vertical_inputs(model: ErrorModel, *, window: float = DEFAULT_WINDOW_S) -> SystemInputs:
    """``vertical`` (gyro vertical) inputs: the residual drifts of its two level axes and its accelerometer biases.

    The vertical's housing axes x, y take the IMU's body y, x (as align's platform: x, y, z = body y, x, -z).
    ``drift_x``, ``drift_y`` (rad/s): -b_g of those axes for the residual gyro bias at +1 sigma after a
    calibration ``window`` before use (its change over the window, sqrt(2) x the slow terms' Allan deviation);
    ``accel_bias_x``, ``accel_bias_y`` (m/s^2): the accelerometers' turn-on bias and its change, which nothing
    at rest removes (it is indistinguishable from tilt).

    Parameters
    ----------
    model : ErrorModel
        The IMU, SI.
    window : float
        Time between the gyro calibration and the run, s.

    Returns
    -------
    SystemInputs
        The four values, SI, and the same magnitudes as their 1-sigma spreads.
    """
    gyro = residual_bias(model.gyro, window, include_turn_on=False)
    accel = residual_bias(model.accel, window, include_turn_on=True)
    values = {"drift_x": -float(gyro[1]), "drift_y": -float(gyro[0]), "accel_bias_x": float(accel[1]),
              "accel_bias_y": float(accel[0])}
    sigmas = {name: abs(value) for name, value in values.items()}
    units = {"drift_x": "rad/s", "drift_y": "rad/s", "accel_bias_x": "m/s^2", "accel_bias_y": "m/s^2"}
    notes = [f"drift = -b_g at +1 sigma; gyro turn-on bias removed by calibration; change over {window:g} s = "
             "sqrt(2) x slow-term Allan deviation",
             "accelerometer turn-on bias kept (indistinguishable from tilt at rest); housing x, y = body y, x"]
    return SystemInputs("vertical", model.name, values, sigmas, units, notes)


def calibrate_inputs(model: ErrorModel) -> SystemInputs:
    """``calibrate`` (pulse drift calibration) inputs: the drifts to measure and the gyros' angle random walk.

    ``drift_x``, ``drift_y`` (rad/s) are the own drifts -b_g of the platform X
    (= body y) and Y (= body x) gyros for the 1-sigma turn-on bias: what the
    procedure estimates; ``angle_random_walk`` (rad/sqrt(s)) is the rms of
    their N.

    Parameters
    ----------
    model : ErrorModel
        The IMU, SI; only its gyro turn-on bias and random walk are used.

    Returns
    -------
    SystemInputs
        ``drift_x``, ``drift_y`` (rad/s), ``angle_random_walk`` (rad/sqrt(s)), and the drifts' 1-sigma spreads.
    """
    bias, walk = model.gyro.bias, model.gyro.random_walk
    values = {"drift_x": float(-bias[1]), "drift_y": float(-bias[0]), "angle_random_walk": _horizontal_rms(walk)}
    return SystemInputs("calibrate", model.name, values, {"drift_x": float(bias[1]), "drift_y": float(bias[0])},
                        {"drift_x": "rad/s", "drift_y": "rad/s", "angle_random_walk": "rad/s^0.5"},
                        ["drift = -b_g for the 1-sigma turn-on bias (calibration estimates it); "
                         "platform X, Y = body y, x"])


@renamed_keywords(step_s="step")
def north_inputs(model: ErrorModel, *, step: float) -> SystemInputs:
    """``north`` (ground gyrocompass) input: ``readout_noise``, the noise of one azimuth observation, rad.

    An angle obtained by integrating the rate over a sample step h carries the
    angle random walk N sqrt(h) and the angle quantisation Q (IEEE 952, white
    angle noise of standard deviation Q): noise = sqrt(Q^2 + N^2 h) (z gyro, the
    azimuth axis).

    Parameters
    ----------
    model : ErrorModel
        The IMU, SI; only the z gyro's quantisation Q (rad) and random walk N (rad/sqrt(s)) are used.
    step : float
        Sample step h of an azimuth observation, s (> 0; the ``north`` case's ``output_step``).

    Returns
    -------
    SystemInputs
        ``readout_noise``, rad, and the same value as its 1-sigma spread.
    """
    step = _check_window(step, "output_step")
    q, n = model.gyro.quantization[2], model.gyro.random_walk[2]
    noise = float(math.sqrt(q**2 + n**2 * step))
    return SystemInputs("north", model.name, {"readout_noise": noise}, {"readout_noise": noise},
                        {"readout_noise": "rad"}, [f"sqrt(Q^2 + N^2 h) of the z gyro at h = {step:g} s"])


@renamed_keywords(latitude_rad="latitude", window_s="window")
def errors_inputs(model: ErrorModel, *, latitude: float, window: float = DEFAULT_WINDOW_S) -> SystemInputs:
    """``errors`` (Schuler-loop navigation errors) inputs: each source's 1-sigma magnitude, SI, keyed by source.

    ``errors`` takes one source and its ``magnitude``; the caller picks the
    value of the source it runs.

    * ``drift`` (rad/s): residual horizontal gyro drift (rms of x and y, see :func:`residual_bias`);
    * ``accelerometer`` (m/s^2): horizontal accelerometer bias (rms of x and y, turn-on kept);
    * ``tilt`` (rad): the levelling error that bias leaves, accelerometer / g;
    * ``azimuth`` (rad): the gyrocompassing error sqrt((drift / (Omega cos L))^2 + (accelerometer tan L / g)^2)
      (the static limit of spec 06, independent east components);
    * ``velocity`` (m/s): 0, a start at rest knows its velocity.

    Parameters
    ----------
    model : ErrorModel
        The IMU, SI.
    latitude : float
        Latitude L of the static gyrocompassing limit, rad (within +/-89 deg).
    window : float
        Time between the gyro calibration and use (also the averaging window), s.

    Returns
    -------
    SystemInputs
        Source name -> 1-sigma magnitude in the units above, and the same as sigmas (velocity has none).
    """
    latitude = _check_latitude(latitude)
    gyro = residual_bias(model.gyro, window, include_turn_on=False)
    accel = residual_bias(model.accel, window, include_turn_on=True)
    drift, bias = _horizontal_rms(gyro), _horizontal_rms(accel)
    azimuth = math.hypot(drift / (EARTH_RATE * math.cos(latitude)),
                         bias * math.tan(latitude) / STANDARD_GRAVITY)
    values = {"tilt": bias / STANDARD_GRAVITY, "velocity": 0.0, "accelerometer": bias, "drift": drift,
              "azimuth": float(azimuth)}
    units = {"tilt": "rad", "velocity": "m/s", "accelerometer": "m/s^2", "drift": "rad/s", "azimuth": "rad"}
    return SystemInputs("errors", model.name, values, {k: v for k, v in values.items() if k != "velocity"}, units,
                        [f"latitude {math.degrees(latitude):g} deg, window {window:g} s",
                         "velocity 0: the run starts at rest"])
