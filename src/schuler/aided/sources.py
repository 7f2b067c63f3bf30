"""Measurement sources of the aided INS: epoch times and a function giving residual, H and R at each.

:func:`schuler.aided.ekf.run_filter` treats GNSS and every other aiding the same way: it propagates the
solution and P to each epoch of each source, and there forms the source's residual delta_z = h(x_hat) - z, its
H and R (:mod:`schuler.aided.measurements`) from the solution, gates and applies them; epochs of several
sources at one time are one stacked update (:func:`schuler.aided.kalman.stacked_update`). A source is

* its ``name`` (the per-source counts of rejected epochs are keyed by it),
* its epoch times ``t`` (s, the IMU's time scale, sorted),
* ``measure(j, context)``: the residual (N, m), H ([N,] m, n) and R ([N,] m, m) of epoch j, from the
  :class:`schuler.aided.sources.Context` (the solution, the compensated gyros' mean since the last event
  and the aiding states' estimates).

Stops (zero velocity and zero rate) come from given intervals or from the IMU
(:func:`schuler.aided.sources.detect_stops`: a windowed variance test of specific force and angular rate).

References
----------
I. Skog, P. Handel, J.-O. Nilsson and J. Rantakokko, "Zero-velocity detection -- an algorithm evaluation",
*IEEE Transactions on Biomedical Engineering* 57(11), 2010 (the moving-variance detector, their Eq. 7 with
the rate term of Eq. 8 added).
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed.,
Artech House, 2013, Sec. 15.3.2 and 16.2.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from schuler.aided import measurements
from schuler.aided.error_state import FilterModel
from schuler.core.earth import EARTH_RATE
from schuler.exceptions import InvalidParameter

STOP_WINDOW_S = 1.0
"""Window of the stop detector, s: long enough to average the noise, shorter than a stop."""

STOP_THRESHOLD = 2.0
"""Threshold of the stop detector on its statistic divided by its mean at rest (6 (W - 1) / W): a window whose
variances of specific force and rate exceed twice their noise's is moving."""


@dataclass(frozen=True)
class Context:
    """What a source's residual is formed from at an epoch (SI; leading axis: members).

    Parameters
    ----------
    solution : Solution
        The navigation solution at the epoch (:class:`schuler.aided.measurements.Solution`).
    mean_rate : ndarray, shape (N, 3)
        The compensated gyros' mean since the last event, rad/s.
    window : float
        The time that mean covers, s.
    aiding : dict of str to ndarray
        The estimates of the aiding states (``odometer_scale``, 1; ``barometer_bias``, m), each (N,).
    """

    solution: measurements.Solution
    mean_rate: np.ndarray
    window: float
    aiding: dict


Measure = Callable[[int, Context], tuple[np.ndarray, np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class Source:
    """One aiding source: its name, its epochs and its measurement (module docstring).

    Parameters
    ----------
    name : str
        ``gnss``, ``zupt``, ``zaru``, ``vehicle`` (NHC and/or odometer) or ``baro``.
    t : ndarray, shape (k,)
        Epoch times, s, sorted.
    measure : callable
        ``measure(j, context) -> (residual (N, m), H ([N,] m, n), R ([N,] m, m))`` in measurement units.
    components : int
        m, the residual's length.
    """

    name: str
    t: np.ndarray
    measure: Measure
    components: int


@dataclass
class SourceLog:
    """One source's epochs as processed (leading axis: members).

    Attributes
    ----------
    t_s : ndarray, shape (k,)
        Epochs processed, s.
    nis : ndarray, shape (N, k)
        NIS of each epoch's residual on its own S block, dimensionless.
    accepted : ndarray of bool, shape (N, k)
        Whether the gate passed it.
    residual : ndarray, shape (N, k, m)
        delta_z, measurement units.
    residual_sigma : ndarray, shape (N, k, m)
        sqrt(diag(S)), measurement units.
    """

    t_s: np.ndarray
    nis: np.ndarray
    accepted: np.ndarray
    residual: np.ndarray
    residual_sigma: np.ndarray

    @classmethod
    def empty(cls, t_s: np.ndarray, members: int, components: int) -> SourceLog:
        """A log of k epochs, zero until filled.

        Parameters
        ----------
        t_s : ndarray, shape (k,)
            Epoch times, s.
        members : int
            N, number of.
        components : int
            m, number of.
        """
        k = t_s.size
        return cls(t_s, np.zeros((members, k)), np.zeros((members, k), dtype=bool), np.zeros((members, k, components)),
                   np.zeros((members, k, components)))

    @property
    def rejected(self) -> np.ndarray:
        """Epochs the gate rejected, per member, shape (N,)."""
        return np.sum(~self.accepted, axis=-1)


def _sigma(value, name: str) -> float:
    number = float(value)
    if not (math.isfinite(number) and number > 0):
        raise InvalidParameter(name, f"must be finite and > 0, got {value!r}")
    return number


def stop_epochs(intervals: Sequence[tuple[float, float]], rate: float) -> np.ndarray:
    """Epoch times k / rate inside the stops (start < t <= end), s, sorted.

    Parameters
    ----------
    intervals : sequence of (float, float)
        The stops' (start, end) times, s.
    rate : float
        Update rate during a stop, Hz.
    """
    rate = _sigma(rate, "zupt_rate")
    times = [np.arange(math.floor(start * rate) + 1, math.floor(end * rate + 1e-9) + 1) / rate
             for start, end in intervals if end > start]
    return np.unique(np.concatenate(times)) if times else np.zeros(0)


def zero_velocity_source(times: np.ndarray, sigma: float, model: FilterModel) -> Source:
    """Zero-velocity updates at the given epochs (:func:`schuler.aided.measurements.zero_velocity`).

    Parameters
    ----------
    times : ndarray, shape (k,)
        Epochs at stops, s.
    sigma : float
        1-sigma of the residual velocity at a stop (vibration, rocking), m/s.
    model : FilterModel
        The filter's states.
    """
    R = np.eye(3) * _sigma(sigma, "zupt_sigma") ** 2

    def measure(j: int, context: Context):
        residual, H = measurements.zero_velocity(context.solution, model)
        return residual, H, R

    return Source("zupt", np.asarray(times, dtype=float), measure, 3)


def zero_rate_source(times: np.ndarray, sigma: float, model: FilterModel, earth_rate: float = EARTH_RATE) -> Source:
    """Zero-angular-rate updates at the given epochs (:func:`schuler.aided.measurements.zero_rate`).

    The residual uses the compensated gyros' mean over the time since the filter's last event, so its R is
    sigma^2 + N_g^2 / window per axis (N_g: the filter's angle random walk).

    Parameters
    ----------
    times : ndarray, shape (k,)
        Epochs at stops, s.
    sigma : float
        1-sigma of the residual rate at a stop (rocking), rad/s.
    model : FilterModel
        The filter's states and angle random walk.
    earth_rate : float
        Omega, rad/s.
    """
    variance = _sigma(sigma, "zaru_sigma") ** 2
    walk = np.asarray(model.angle_random_walk) ** 2

    def measure(j: int, context: Context):
        residual, H = measurements.zero_rate(context.solution, context.mean_rate, model, earth_rate)
        return residual, H, np.diag(variance + walk / max(context.window, 1e-300))

    return Source("zaru", np.asarray(times, dtype=float), measure, 3)


def vehicle_source(times: np.ndarray, speed: np.ndarray | None, model: FilterModel, *, lever_arm=(0.0, 0.0, 0.0),
                   mounting: np.ndarray = np.eye(3), speed_sigma: float = 0.05, constraint_sigma: float = 0.1,
                   constraint: bool = True, earth_rate: float = EARTH_RATE) -> Source:
    """The odometer and/or the non-holonomic constraint (:func:`schuler.aided.measurements.vehicle`).

    Parameters
    ----------
    times : ndarray, shape (k,)
        Epochs, s.
    speed : ndarray, shape ([N,] k), or None
        Measured odometer speeds, m/s; None: the constraint alone.
    model : FilterModel
        The filter's states (an ``odometer_scale`` state is compensated and estimated).
    lever_arm : array_like, shape (3,)
        IMU to the wheel's contact point, body axes, m.
    mounting : ndarray, shape (3, 3)
        C_b^v (:func:`schuler.aided.measurements.mounting_matrix`), plain numbers.
    speed_sigma : float
        1-sigma of the odometer speed, m/s.
    constraint_sigma : float
        1-sigma of the lateral and vertical wheel velocities (skid, suspension), m/s.
    constraint : bool
        Whether the constraint rows are used.
    earth_rate : float
        Omega, rad/s.
    """
    rows = ([0] if speed is not None else []) + ([1, 2] if constraint else [])
    if not rows:
        raise InvalidParameter("aiding", "the vehicle source needs the odometer or the constraint")
    variances = {0: _sigma(speed_sigma, "odometer_sigma") ** 2, 1: _sigma(constraint_sigma, "nhc_sigma") ** 2}
    R = np.diag([variances[min(row, 1)] for row in rows])
    speeds = None if speed is None else np.atleast_2d(np.asarray(speed, dtype=float))
    arm, C_bv = np.asarray(lever_arm, dtype=float), np.asarray(mounting, dtype=float)

    def measure(j: int, context: Context):
        value = 0.0 if speeds is None else speeds[:, j]
        scale = context.aiding.get("odometer_scale", 0.0)
        residual, H = measurements.vehicle(context.solution, arm, C_bv, value, model, rows=rows,
                                           odometer_scale=scale, earth_rate=earth_rate)
        return residual, H, R

    return Source("vehicle", np.asarray(times, dtype=float), measure, len(rows))


def barometer_source(times: np.ndarray, height: np.ndarray, sigma: float, model: FilterModel) -> Source:
    """Barometric heights (:func:`schuler.aided.measurements.barometer`).

    Parameters
    ----------
    times : ndarray, shape (k,)
        Epochs, s.
    height : ndarray, shape ([N,] k)
        Measured heights, m.
    sigma : float
        1-sigma of the white noise, m.
    model : FilterModel
        The filter's states (a ``barometer_bias`` state is compensated and estimated).
    """
    heights = np.atleast_2d(np.asarray(height, dtype=float))
    R = np.eye(1) * _sigma(sigma, "baro_sigma") ** 2

    def measure(j: int, context: Context):
        residual, H = measurements.barometer(context.solution, heights[:, j], model,
                                             context.aiding.get("barometer_bias", 0.0))
        return residual, H, R

    return Source("baro", np.asarray(times, dtype=float), measure, 1)


def detect_stops(increments: np.ndarray, interval: float, gyro_sigma: float, accel_sigma: float, *,
                 window: float = STOP_WINDOW_S, threshold: float = STOP_THRESHOLD) -> list[tuple[float, float]]:
    """Stops of one IMU record from the moving variance of its specific force and angular rate.

    Over each window of W samples the statistic (Skog et al. 2010, Eq. 7 and 8)

        T = (1/W) sum_k ( |f_k - mean f|^2 / sigma_a^2 + |omega_k - mean omega|^2 / sigma_g^2 )

    is 6 (W - 1) / W on average at rest whatever the biases are; a window is stationary if T is below
    ``threshold`` times that. Runs of stationary windows are the stops, each (start of its first window, end of
    its last). A vehicle moving straight at a constant speed without vibration (a simulated cruise) has the
    specific force and rate of a stop to within the Coriolis and transport-rate terms, so the test marks it
    still: give the stops as intervals on such data.

    Parameters
    ----------
    increments : ndarray, shape (n, 6)
        dtheta (rad) and dv (m/s) of each IMU interval.
    interval : float
        IMU interval, s.
    gyro_sigma : float
        1-sigma of one sample's rate noise, rad/s (N_g / sqrt(interval)).
    accel_sigma : float
        1-sigma of one sample's specific-force noise, m/s^2 (N_a / sqrt(interval)).
    window : float
        Window, s (at least two samples).
    threshold : float
        Threshold on T over its mean at rest, dimensionless (> 1).

    Returns
    -------
    list of (float, float)
        The stops' (start, end) times from the record's start, s.
    """
    samples = int(round(_sigma(window, "stop_window") / _sigma(interval, "interval")))
    if samples < 2 or not threshold > 1:
        raise InvalidParameter("stop_window", f"needs two samples and a threshold > 1, got {samples} and {threshold}")
    data = np.asarray(increments, dtype=float) / interval
    blocks = data.shape[0] // samples
    if blocks == 0:
        return []
    windows = data[:blocks * samples].reshape(blocks, samples, 6)
    spread = windows - windows.mean(axis=1, keepdims=True)
    statistic = (np.sum(spread[..., 3:] ** 2, axis=(1, 2)) / _sigma(accel_sigma, "accel_sigma") ** 2
                 + np.sum(spread[..., :3] ** 2, axis=(1, 2)) / _sigma(gyro_sigma, "gyro_sigma") ** 2) / samples
    still = statistic < threshold * 6.0 * (samples - 1) / samples
    edges = np.diff(np.concatenate([[0], still.astype(int), [0]]))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    span = samples * interval
    return [(float(a * span), float(b * span)) for a, b in zip(starts, ends)]
