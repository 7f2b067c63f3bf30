"""The IMU layer's error models inside the nonlinear INS: each member's constant errors and its noise.

An :class:`~schuler.imu.error_model.ErrorModel` (a grade preset or a spec file,
:mod:`schuler.imu.spec`) enters :func:`~schuler.navigate.mechanization.navigate`
in two parts, body axes (the platform's own axes in the platform mode):

* the **constant errors** of a member, turn-on bias b, scale factors S and
  misalignment M, become its :class:`~schuler.navigate.errors.ConstantSensorErrors`
  rows, which the time loops apply exactly to the true increments whatever
  the trajectory does (measured = (I + S + M) true + b dt);
* the **random processes**, white noise N, flicker B, Gauss-Markov, rate random
  walk K, quantisation Q, and the g-sensitivity G f, come through
  :class:`ImuNoise`, a :class:`~schuler.navigate.errors.SensorNoise` simulated by
  :class:`schuler.imu.simulate.ImuSimulator`.

Draws are the IMU layer's own: member m of seed s takes its constants from the
streams ``gyro/bias``, ``gyro/scale_factor``, ``gyro/misalignment``,
``gyro/g_sensitivity`` ... at address m, and its noise from ``gyro_x/white``,
``gyro_x/slow`` ... (:class:`~schuler.core.random.RandomStreams`), so a
member's sensors are those ``schuler.imu.simulate`` gives that member, and no
result depends on how the members are chunked. The nominal case (no random
streams) takes every constant error at +1 sigma, the representative case of
:mod:`schuler.imu.system_inputs`, and no noise.

G f and the quantiser act on the true input, which the noise interface does
not see: the simulator runs on the sensors' true rate and specific force at the
start (:func:`initial_inputs`), exact at rest and along a great circle (level,
constant speed), an approximation of G f through a profile's manoeuvres.

Examples
--------
>>> from schuler.imu.spec import preset
>>> constants = representative_constants(preset("tactical"), 2, np.array([0.0, 0.0, -9.8]))
>>> round(float(constants.gyro_bias[0, 0] / 4.84813681109536e-06), 6)   # 1 deg/h at +1 sigma
1.0
>>> drawn = drawn_constants(preset("tactical"), seed=3, members=np.arange(4))
>>> drawn.gyro_bias.shape, bool(np.all(drawn.gyro_misalignment[:, 0, 0] == 0.0))
((4, 3), True)
"""

from __future__ import annotations

import os
from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np

from schuler.exceptions import InvalidParameter, ScenarioError
from schuler.imu.error_model import ErrorModel, SensorErrors
from schuler.imu.simulate import ImuSimulator
from schuler.imu.spec import GRADES, load_spec_file, preset
from schuler.navigate.truth import TruthGenerator

_RANDOM_TERMS = ("random_walk", "bias_instability", "gm_sigma", "rate_random_walk", "quantization")

def load_error_model(text: str) -> ErrorModel:
    """The error model of ``--imu``: a grade preset or a TOML spec file (:mod:`schuler.imu.spec`).

    Parameters
    ----------
    text : str
        A grade name (navigation, tactical, industrial, consumer) or the path of a spec file SPEC.toml.

    Returns
    -------
    ErrorModel
        The model, SI.

    Raises
    ------
    InvalidParameter
        Naming ``imu``: neither a grade nor a readable spec file, or a figure of the file is wrong.

    Examples
    --------
    >>> load_error_model("tactical").name
    'tactical grade (ring-laser gyro IMU)'
    >>> load_error_model("tactcal")
    Traceback (most recent call last):
    ...
    schuler.exceptions.InvalidParameter: imu: 'tactcal' is neither a grade (navigation, tactical, industrial,
    consumer) nor a spec file SPEC.toml
    """
    if text in GRADES:
        return preset(text)
    path = Path(text)
    if path.suffix.lower() != ".toml":
        raise InvalidParameter("imu", f"{text!r} is neither a grade ({', '.join(GRADES)}) nor a spec file SPEC.toml")
    try:
        return load_spec_file(path)
    except ScenarioError as error:
        raise InvalidParameter("imu", str(error)) from None
    except InvalidParameter as error:
        raise InvalidParameter("imu", str(error)) from None


def noise_model(model: ErrorModel) -> ErrorModel:
    """The model without its constant errors b, S, M (those go to the time loops): what :class:`ImuNoise` simulates.

    Parameters
    ----------
    model : ErrorModel
        The full error model.

    Returns
    -------
    ErrorModel
        A copy with zero bias, scale factors and misalignment for both triads.
    """
    def without(errors: SensorErrors) -> SensorErrors:
        return replace(errors, bias=np.zeros(3), scale_factor=np.zeros(3), misalignment=np.zeros((3, 3)))

    return replace(model, gyro=without(model.gyro), accel=without(model.accel))


def has_noise(model: ErrorModel) -> bool:
    """Whether the model has random processes or a g-sensitivity (anything :class:`ImuNoise` adds).

    Parameters
    ----------
    model : ErrorModel
        The error model.
    """
    return any(np.any(getattr(sensor, name)) for sensor in (model.gyro, model.accel) for name in _RANDOM_TERMS) \
        or bool(np.any(model.gyro.g_sensitivity))


def slow_processes(model: ErrorModel, interval: float) -> int:
    """How many slow processes (Gauss-Markov, flicker terms, rate random walk) the simulator carries per member.

    Parameters
    ----------
    model : ErrorModel
        The full error model (its noise part, :func:`noise_model`, is simulated).
    interval : float
        IMU sample interval dt, s.

    Returns
    -------
    int
        Number of slow processes per member.
    """
    return len(ImuSimulator(noise_model(model), interval).coarse_steps())


def state_bytes(model: ErrorModel, interval: float) -> int:
    """Memory the simulator may carry per member from one window to the next, bytes.

    Parameters
    ----------
    model : ErrorModel
        The full error model (its noise part is simulated).
    interval : float
        IMU interval dt, s.
    """
    return ImuSimulator(noise_model(model), interval).member_state_bytes()


@dataclass(frozen=True)
class MemberConstants:
    """Constant sensor errors of N members, SI, body axes (as :class:`~schuler.navigate.errors.ConstantSensorErrors`).

    ``gyro_bias`` includes G f0 where the noise source does not add it (the nominal case).
    """

    gyro_bias: np.ndarray
    accel_bias: np.ndarray
    gyro_scale_factor: np.ndarray
    accel_scale_factor: np.ndarray
    gyro_misalignment: np.ndarray
    accel_misalignment: np.ndarray

    def as_dict(self) -> dict[str, np.ndarray]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


def _split(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """I + S + M -> (S as (N, 3), M with a zero diagonal)."""
    diagonal = np.diagonal(matrix, axis1=-2, axis2=-1)
    return diagonal - 1.0, matrix - diagonal[..., None] * np.eye(3)


def drawn_constants(model: ErrorModel, seed: int, members) -> MemberConstants:
    """Members' constant errors b, S, M drawn as :meth:`schuler.imu.simulate.ImuSimulator.constants` draws them.

    G is drawn by the same streams inside :class:`ImuNoise`, which adds G f.

    Parameters
    ----------
    model : ErrorModel
        The error model whose 1-sigma constant errors are drawn.
    seed : int
        Study seed of the addressed random streams.
    members : array_like of int
        Global member numbers, shape (N,): the addresses of the draws.

    Returns
    -------
    MemberConstants
        Biases (rad/s, m/s^2), scale factors (dimensionless) and misalignments (rad), body axes, one row per member.
    """
    drawn = ImuSimulator(model, 1.0, seed=seed).constants(members)
    gyro_scale, gyro_misalignment = _split(drawn["gyro_matrix"])
    accel_scale, accel_misalignment = _split(drawn["accel_matrix"])
    return MemberConstants(drawn["gyro_bias"], drawn["accel_bias"], gyro_scale, accel_scale, gyro_misalignment,
                           accel_misalignment)


def _plus_one_sigma(errors: SensorErrors, members: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    misalignment = errors.misalignment * (1.0 - np.eye(3))
    return (np.tile(errors.bias, (members, 1)), np.tile(errors.scale_factor, (members, 1)),
            np.tile(misalignment, (members, 1, 1)))


def representative_constants(model: ErrorModel, members: int, specific_force) -> MemberConstants:
    """Every constant error at +1 sigma (each bias, scale factor, misalignment and G entry), the same for all.

    Parameters
    ----------
    model : ErrorModel
        The error model whose 1-sigma constant errors are taken.
    members : int
        Batch size N, number of members (all get the same errors).
    specific_force : array_like, shape (3,)
        f0, m/s^2, the sensors' true specific force: G f0 joins the gyro bias.
    """
    gyro_bias, gyro_scale, gyro_misalignment = _plus_one_sigma(model.gyro, members)
    accel_bias, accel_scale, accel_misalignment = _plus_one_sigma(model.accel, members)
    gyro_bias = gyro_bias + model.gyro.g_sensitivity @ np.asarray(specific_force, dtype=float)
    return MemberConstants(gyro_bias, accel_bias, gyro_scale, accel_scale, gyro_misalignment, accel_misalignment)


def initial_inputs(generator: TruthGenerator, mode: str) -> tuple[np.ndarray, np.ndarray]:
    """The sensors' true angular rate (rad/s) and specific force (m/s^2) over the first IMU interval.

    Body axes for the strapdown; for the platform the NED frame's rate and the NED
    specific force (the platform is level and north-pointing to first order).

    Parameters
    ----------
    generator : TruthGenerator
        The run's truth (its first IMU interval is generated).
    mode : {"strapdown", "platform"}
        The mechanization: body axes or the NED frame.

    Returns
    -------
    rate, specific_force : ndarray
        True angular rate, rad/s, and specific force, m/s^2, each of shape (3,).
    """
    first = next(generator.chunks(1))
    increments = first.nav_increments[0] if mode == "platform" else first.increments[0]
    return increments[:3] / generator.dt, increments[3:] / generator.dt


class ImuNoise:
    """The random processes of an error model as a :class:`~schuler.navigate.errors.SensorNoise`.

    Parameters
    ----------
    model : ErrorModel
        The full model; its constant errors b, S, M are left to the time loops.
    seed : int
        Study seed of the addressed streams.
    interval : float
        IMU interval dt, s.
    true_rate, true_specific_force : array_like, shape (3,)
        The sensors' true inputs the simulator runs on (:func:`initial_inputs`): the
        increment errors are (simulated - true) dt.
    workers : int, optional
        Threads over members (default: the CPUs, at most 4).

    Notes
    -----
    Windows of a member must follow each other in time (as ``navigate`` asks for
    them); the simulator carries each member's slow processes and quantiser
    residual from one window to the next.
    """

    def __init__(self, model: ErrorModel, seed: int, interval: float, true_rate, true_specific_force,
                 workers: int | None = None):
        self.interval = float(interval)
        self.true_rate = np.asarray(true_rate, dtype=float)
        self.true_specific_force = np.asarray(true_specific_force, dtype=float)
        self._simulator = ImuSimulator(noise_model(model), self.interval, true_gyro=self.true_rate,
                                       true_accel=self.true_specific_force, seed=seed,
                                       workers=workers or min(4, os.cpu_count() or 1))

    def increments(self, members, start: int, stop: int, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """The errors (simulated - true) dt of the increments of IMU intervals ``start .. stop - 1``.

        Parameters
        ----------
        members : array_like of int
            Global member numbers, shape (M,).
        start : int
            Index of the first IMU interval (global); a member's windows must follow each other.
        stop : int
            Index one past the last IMU interval (global).
        dt : float
            IMU sample interval, s; must equal the ``interval`` the noise was set up for.

        Returns
        -------
        gyro, accel : ndarray
            Errors added to the angle increments (rad) and the velocity
            increments (m/s), sensor axes x, y, z, each of shape (M, stop - start, 3).
        """
        if not np.isclose(dt, self.interval, rtol=1e-12, atol=0.0):
            raise InvalidParameter("imu_rate", f"the noise was set up for {1 / self.interval:g} Hz, "
                                               f"asked for {1 / dt:g} Hz")
        return self._simulator.window(members, start, stop, as_errors=True)  # C-contiguous, as the loops read
