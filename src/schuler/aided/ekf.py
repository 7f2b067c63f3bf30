"""The error-state extended Kalman filter around the strapdown INS, with closed-loop feedback.

:func:`run_filter` navigates a batch of N members with :mod:`schuler.navigate`'s own strapdown
step (:func:`schuler.navigate._loops.strapdown_chunk`: coning and sculling corrections, WGS-84
gravity and radii; no second mechanization), feeding it the IMU increments compensated with the
filter's current sensor-error estimates,

    dtheta_c = (dtheta - b_hat_g dt) / (1 + s_hat_g),   dv_c = (dv - b_hat_a dt) / (1 + s_hat_a),

so that the filter's bias and scale states are the residual errors (module
:mod:`schuler.aided.error_state`). Events happen in time order:

* every covariance step (``covariance_interval``, a whole number of IMU intervals) and at
  every measurement epoch, P is propagated exactly over the time since its last propagation
  (:func:`~schuler.aided.error_state.transition`: F held at the solution of the interval's
  start with the sensors' means over the interval; Van Loan's Q_d); a Gauss-Markov estimate
  b_hat decays by exp(-dt/T) over the same time, as the mean of the true process does;
* a measurement epoch between two IMU samples is reached by splitting that sample's increments
  in proportion to time (the rates taken constant over the sample), not by rounding it to a
  sample; the coning and sculling terms of the two parts are those of equal-rate halves, an
  error of second order in the increments;
* measurements come from sources (:mod:`schuler.aided.sources`: GNSS, and optionally zero
  velocity, zero rate, the vehicle's odometer and non-holonomic constraint, the barometer), each
  with its epochs; epochs of several sources closer than 1e-9 s are one event;
* at an epoch the residual of each measurement is formed from the solution (h_hat - z), gated
  and applied (:func:`~schuler.aided.kalman.update`, Joseph form; several sources at once:
  :func:`~schuler.aided.kalman.stacked_update`, each gated on its own); the estimated errors are fed
  back, r <- r - delta_r, v <- v - delta_v, q_bn <- q(psi) q_bn (C <- exp([psi x]) C, since
  C_hat = (I - [psi x]) C), b_hat <- b_hat + delta_b, s_hat <- s_hat + delta_s (the aiding
  states' estimates likewise), and the error state is reset to zero (P unchanged, first order).

References
----------
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*,
2nd ed., Artech House, 2013, ch. 14 (loosely coupled INS/GNSS, closed-loop correction).
E.-H. Shin, *Estimation Techniques for Low-Cost Inertial Navigation*, PhD thesis, University of
Calgary, 2005.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numba
import numpy as np

from schuler.aided import kalman, measurements
from schuler.aided.error_state import (
    ACCEL_BIAS,
    ACCEL_SCALE,
    ATTITUDE,
    GYRO_BIAS,
    GYRO_SCALE,
    POSITION,
    VELOCITY,
    FilterModel,
    NavigationPoint,
    transition,
)
from schuler.aided.gnss import GnssRecord
from schuler.aided.sources import Context, Source, SourceLog
from schuler.core.attitude import dcm_from_quaternion, quaternion_from_rotation_vector, quaternion_multiply
from schuler.core.earth import EARTH_RATE, radii_of_curvature
from schuler.exceptions import InvalidParameter, SimulationError
from schuler.memory import require
from schuler.navigate import _kernels
from schuler.navigate._loops import strapdown_chunk
from schuler.navigate.validity import domain_message

_NEVER = 2**62  # an output interval that never comes: the kernel stores nothing
_PARALLEL_STEPS = 200_000  # member-samples of a segment above which the mechanization runs on every core


@dataclass(frozen=True)
class _Epochs:
    """The members' GNSS epochs as arrays: one record shared by every member, or one record per member."""

    t: np.ndarray  # (k,)
    latitude: np.ndarray  # (N, k)
    longitude: np.ndarray
    height: np.ndarray
    sigma: np.ndarray  # (k, 3), shared
    velocity: np.ndarray | None  # (N, k, 3)
    velocity_sigma: np.ndarray | None  # (k, 3)

    @classmethod
    def of(cls, gnss: GnssRecord | Sequence[GnssRecord], members: int) -> _Epochs:
        records = [gnss] if isinstance(gnss, GnssRecord) else list(gnss)
        if len(records) not in (1, members):
            raise InvalidParameter("gnss", f"give one GNSS record or one per member ({members}), got {len(records)}")
        first = records[0]
        for record in records[1:]:
            if not np.array_equal(record.t_s, first.t_s) or not np.array_equal(record.position_sigma_m,
                                                                                 first.position_sigma_m):
                raise InvalidParameter("gnss", "the members' GNSS records must share their epochs and sigmas")
            if record.has_velocity != first.has_velocity:
                raise InvalidParameter("gnss", "either every member's GNSS record has velocities or none has")

        def rows(name):
            return np.broadcast_to(np.stack([getattr(r, name) for r in records]), (members,) + first.t_s.shape
                                   + np.shape(getattr(first, name))[1:])

        velocity = rows("velocity_ned_m_s") if first.has_velocity else None
        return cls(first.t_s, rows("latitude_rad"), rows("longitude_rad"), rows("height_m"), first.position_sigma_m,
                   velocity, first.velocity_sigma_m_s)


@dataclass(frozen=True)
class Start:
    """The initial navigation solution of every member and the filter's initial uncertainty.

    Parameters
    ----------
    latitude, longitude : ndarray, shape (N,)
        rad.
    height : ndarray, shape (N,)
        m.
    velocity : ndarray, shape (N, 3)
        NED, m/s.
    quaternion : ndarray, shape (N, 4)
        q_bn, scalar first.
    position_sigma : array_like, shape (3,)
        1-sigma of the initial position error, north, east, down, m.
    velocity_sigma : array_like, shape (3,)
        1-sigma of the initial velocity error, m/s.
    attitude_sigma : array_like, shape (3,)
        1-sigma of the initial psi, north, east, down, rad.
    """

    latitude: np.ndarray
    longitude: np.ndarray
    height: np.ndarray
    velocity: np.ndarray
    quaternion: np.ndarray
    position_sigma: np.ndarray
    velocity_sigma: np.ndarray
    attitude_sigma: np.ndarray

    @property
    def members(self) -> int:
        """N."""
        return int(np.atleast_1d(self.latitude).size)


@dataclass
class FilterRun:
    """The filter's solution, its covariance and its innovations (SI; leading axis: members).

    Attributes
    ----------
    t_s : ndarray, shape (n_out,)
        Output times (every ``output_every``-th IMU sample), s.
    solution : ndarray, shape (N, n_out, 10)
        Latitude, longitude (rad), height (m), v_N, v_E, v_D (m/s), q_bn (4).
    covariance_t_s : ndarray, shape (n_cov,)
        Times of the stored covariances (each covariance step and epoch, after any update), s.
    covariance : ndarray, shape (N, n_cov, n, n)
        P after each event, (state units)^2.
    sensor_estimates : ndarray, shape (N, n_cov, 12)
        b_hat_g (rad/s), b_hat_a (m/s^2), s_hat_g, s_hat_a at those times.
    epoch_t_s : ndarray, shape (k,)
        GNSS epochs processed, s.
    nis : ndarray, shape (N, k)
        Normalised innovation squared of each epoch's stacked measurement.
    accepted : ndarray of bool, shape (N, k)
        Whether each epoch passed the gate.
    residual : ndarray, shape (N, k, m)
        Residuals delta_z (m, then m/s for velocity).
    residual_sigma : ndarray, shape (N, k, m)
        Their predicted 1-sigma, sqrt(diag(S)).
    n_states : int
        Number of error states.
    sources : dict of str to SourceLog
        The other sources' epochs (``zupt``, ``zaru``, ``vehicle``, ``baro``), as the GNSS ones above.
    aiding_estimates : ndarray, shape (N, n_cov, e)
        The aiding states' estimates at the covariance times (odometer scale 1, barometer bias m; e may be 0).
    prior_covariance : ndarray, shape (N, n_cov, n, n), or None
        P before any update at each of those times (the initial P first), (state units)^2; kept for the smoother
        (``keep_for_smoother``), None otherwise.
    transition : ndarray, shape (N, n_cov, n, n), or None
        Phi from the previous stored time to each (the identity first and where no time passed), likewise.
    correction : ndarray, shape (N, n_cov, n), or None
        The estimated errors fed back at each of those times (zero where none), state units, likewise.
    """

    t_s: np.ndarray
    solution: np.ndarray
    covariance_t_s: np.ndarray
    covariance: np.ndarray
    sensor_estimates: np.ndarray
    epoch_t_s: np.ndarray
    nis: np.ndarray
    accepted: np.ndarray
    residual: np.ndarray
    residual_sigma: np.ndarray
    n_states: int = field(default=21)
    sources: dict = field(default_factory=dict)
    aiding_estimates: np.ndarray | None = None
    prior_covariance: np.ndarray | None = field(default=None, repr=False)
    transition: np.ndarray | None = field(default=None, repr=False)
    correction: np.ndarray | None = field(default=None, repr=False)

    @property
    def rejected(self) -> np.ndarray:
        """Epochs the gate rejected, every source, per member, shape (N,)."""
        return sum(self.rejected_by_source().values(), np.zeros(self.accepted.shape[0], dtype=int))

    def rejected_by_source(self) -> dict[str, np.ndarray]:
        """Epochs the gate rejected per source (``gnss`` first), per member, each shape (N,)."""
        return {"gnss": np.sum(~self.accepted, axis=-1), **{name: log.rejected for name, log in self.sources.items()}}


@dataclass
class _Accumulator:
    """Sums of the compensated increments since the covariance was last propagated."""

    members: int
    angle: np.ndarray = field(init=False)
    velocity: np.ndarray = field(init=False)
    elapsed: float = 0.0

    def __post_init__(self):
        self.reset()

    def reset(self):
        self.angle = np.zeros((self.members, 3))
        self.velocity = np.zeros((self.members, 3))
        self.elapsed = 0.0


class _Navigator:
    """The members' strapdown states, advanced through compensated increments (module docstring)."""

    def __init__(self, start: Start, increments: np.ndarray, dt: float, t0: float, output_every: int,
                 n_out: int, earth_rate: float, aiding_states: int = 0):
        n = start.members
        self.state = np.zeros((n, _kernels.STATE_SIZE))
        self.state[:, _kernels.LAT] = start.latitude
        self.state[:, _kernels.LON] = start.longitude
        self.state[:, _kernels.HGT] = start.height
        self.state[:, _kernels.SIN_LAT] = np.sin(start.latitude)
        self.state[:, _kernels.COS_LAT] = np.cos(start.latitude)
        self.state[:, _kernels.VEL:_kernels.VEL + 3] = start.velocity
        self.state[:, _kernels.VEL_PREV:_kernels.VEL_PREV + 3] = start.velocity
        self.state[:, _kernels.QUAT:_kernels.QUAT + 4] = start.quaternion
        self.increments = increments  # (n_samples, 6) shared or (N, n_samples, 6) per member
        self.dt, self.t0, self.earth_rate = dt, t0, earth_rate
        self.sample = 0  # the next sample to use
        self.used = 0.0  # the fraction of that sample already used
        self.output_every = output_every
        self.out = np.zeros((n, n_out + 1, _kernels.OUTPUT_SIZE))
        self.gyro_bias = np.zeros((n, 3))
        self.accel_bias = np.zeros((n, 3))
        self.gyro_scale = np.zeros((n, 3))
        self.accel_scale = np.zeros((n, 3))
        self.aiding = np.zeros((n, aiding_states))
        self.last_rate = np.zeros((n, 3))
        self._zeros_row = np.zeros((n, 12))
        self.fed_back: np.ndarray | None = None  # the sum of the corrections since it was last taken, when kept
        self._dummy_out = np.zeros((n, 1, _kernels.OUTPUT_SIZE))

    @property
    def time(self) -> float:
        return self.t0 + (self.sample + self.used) * self.dt

    def _compensated(self, first: int, stop: int, fraction: float) -> np.ndarray:
        raw = self.increments[..., first:stop, :]
        raw = np.broadcast_to(raw, (self.state.shape[0],) + raw.shape[-2:]) * fraction
        step = self.dt * fraction
        out = np.empty(raw.shape)
        out[..., :3] = (raw[..., :3] - self.gyro_bias[:, None, :] * step) / (1.0 + self.gyro_scale[:, None, :])
        out[..., 3:] = (raw[..., 3:] - self.accel_bias[:, None, :] * step) / (1.0 + self.accel_scale[:, None, :])
        return out

    def _step(self, first: int, stop: int, fraction: float, store: bool, accumulator: _Accumulator) -> None:
        compensated = self._compensated(first, stop, fraction)
        k = stop - first
        zeros = np.zeros((k, 6))
        vertical = np.zeros((k, 2))
        out, every = (self.out, self.output_every) if store else (self._dummy_out, _NEVER)
        threads = numba.get_num_threads()
        # a short segment is over before the worker threads have started: run it on this one
        numba.set_num_threads(threads if k * self.state.shape[0] >= _PARALLEL_STEPS else 1)
        try:
            self._mechanize(first, zeros, vertical, compensated, out, every, fraction)
        finally:
            numba.set_num_threads(threads)
        if self.state[:, _kernels.LEFT_AT].any():  # the kernel stopped a member outside the equations' domain
            members = self.state.shape[0]
            raise SimulationError(domain_message(self.state, np.arange(members), members if members > 1 else None,
                                                 self.dt, "free"))
        accumulator.angle += compensated[..., :3].sum(axis=1)
        accumulator.velocity += compensated[..., 3:].sum(axis=1)
        accumulator.elapsed += k * self.dt * fraction
        self.last_rate = compensated[:, -1, :3] / (self.dt * fraction)

    def _mechanize(self, first_sample, zeros, vertical, compensated, out, every, fraction) -> None:
        strapdown_chunk(self.dt * fraction, first_sample, zeros, vertical, self.state, self._zeros_row,
                        self._zeros_row, np.ascontiguousarray(compensated[..., :3]),
                        np.ascontiguousarray(compensated[..., 3:]), True, out, every, _kernels.FREE,
                        np.zeros(4), self.earth_rate, 1.0, 0.0, vertical, False)

    def advance_to(self, t: float, accumulator: _Accumulator) -> None:
        """Navigate every member up to time t (s), splitting the sample t falls in."""
        position = (t - self.t0) / self.dt  # in samples
        if position < self.sample + self.used - 1e-9:
            raise InvalidParameter("time", f"cannot go back to t = {t} s from {self.time} s")
        if self.used > 0.0:
            end = min(position - self.sample, 1.0)
            if end - self.used > 1e-12:
                self._step(self.sample, self.sample + 1, end - self.used, end >= 1.0 - 1e-12, accumulator)
            self.used = end
            if self.used >= 1.0 - 1e-12:
                self.sample, self.used = self.sample + 1, 0.0
            else:
                return
        whole = int(math.floor(position - self.sample + 1e-9))
        if whole > 0:
            self._step(self.sample, self.sample + whole, 1.0, True, accumulator)
            self.sample += whole
        rest = position - self.sample
        if rest > 1e-9:
            self._step(self.sample, self.sample + 1, rest, False, accumulator)
            self.used = rest

    def solution(self) -> measurements.Solution:
        st = self.state
        q = st[:, _kernels.QUAT:_kernels.QUAT + 4]
        return measurements.Solution(st[:, _kernels.LAT].copy(), st[:, _kernels.LON].copy(),
                                     st[:, _kernels.HGT].copy(), st[:, _kernels.VEL:_kernels.VEL + 3].copy(),
                                     dcm_from_quaternion(q), self.last_rate.copy())

    def point(self, accumulator: _Accumulator) -> NavigationPoint:
        sol = self.solution()
        elapsed = max(accumulator.elapsed, 1e-300)
        return NavigationPoint(sol.latitude, sol.height, sol.velocity, sol.body_to_ned,
                               accumulator.velocity / elapsed, accumulator.angle / elapsed)

    def correct(self, dx: np.ndarray, model: FilterModel) -> None:
        """Feed the estimated errors back into the solution and the sensor compensation."""
        if self.fed_back is not None:
            self.fed_back += dx
        st = self.state
        lat, h = st[:, _kernels.LAT], st[:, _kernels.HGT]
        R_N, R_E = radii_of_curvature(lat)
        dr = dx[:, POSITION]
        new_lat = lat - dr[:, 0] / (R_N + h)
        st[:, _kernels.LON] -= dr[:, 1] / ((R_E + h) * np.cos(lat))
        st[:, _kernels.HGT] = h + dr[:, 2]
        st[:, _kernels.LAT] = new_lat
        st[:, _kernels.SIN_LAT], st[:, _kernels.COS_LAT] = np.sin(new_lat), np.cos(new_lat)
        st[:, _kernels.VEL:_kernels.VEL + 3] -= dx[:, VELOCITY]
        st[:, _kernels.VEL_PREV:_kernels.VEL_PREV + 3] -= dx[:, VELOCITY]
        turn = quaternion_from_rotation_vector(dx[:, ATTITUDE])
        q = quaternion_multiply(turn, st[:, _kernels.QUAT:_kernels.QUAT + 4])
        st[:, _kernels.QUAT:_kernels.QUAT + 4] = q / np.linalg.norm(q, axis=-1, keepdims=True)
        self.gyro_bias += dx[:, GYRO_BIAS]
        self.accel_bias += dx[:, ACCEL_BIAS]
        if model.sensor_size == 21:
            self.gyro_scale += dx[:, GYRO_SCALE]
            self.accel_scale += dx[:, ACCEL_SCALE]
        self.aiding += dx[:, model.sensor_size:]

    def decay(self, model: FilterModel, elapsed: float) -> None:
        """Gauss-Markov estimates relax towards zero as the process's mean does."""
        targets = [self.gyro_bias, self.accel_bias] + ([self.gyro_scale, self.accel_scale]
                                                       if model.sensor_size == 21 else [])
        targets += [self.aiding[:, k:k + 1] for k in range(self.aiding.shape[1])]  # views: scaled in place
        for target, (_, process) in zip(targets, model.processes()):
            if process.decay_rate > 0:
                target *= math.exp(-process.decay_rate * elapsed)

    def estimates(self) -> np.ndarray:
        return np.concatenate([self.gyro_bias, self.accel_bias, self.gyro_scale, self.accel_scale], axis=1)

    def context(self, accumulator: _Accumulator, model: FilterModel) -> Context:
        """What the sources' residuals are formed from now (:class:`schuler.aided.sources.Context`)."""
        elapsed = accumulator.elapsed
        rate = accumulator.angle / elapsed if elapsed > 0 else self.last_rate
        aiding = {name: self.aiding[:, k - model.sensor_size] for name, k in model.aiding_states().items()}
        return Context(self.solution(), rate, elapsed if elapsed > 0 else self.dt, aiding)


def _gnss_source(epochs: _Epochs, lever_arm, velocity: bool, n: int, earth_rate: float) -> Source:
    """The GNSS fixes as a source: position, and velocity where used, stacked in that order."""

    def measure(epoch: int, context: Context):
        solution = context.solution
        residual, H = measurements.gnss_position(solution, lever_arm, epochs.latitude[:, epoch],
                                                 epochs.longitude[:, epoch], epochs.height[:, epoch], n)
        sigma = epochs.sigma[epoch]
        if velocity:
            assert epochs.velocity is not None and epochs.velocity_sigma is not None
            v_res, v_H = measurements.gnss_velocity(solution, lever_arm, epochs.velocity[:, epoch], n, earth_rate)
            residual = np.concatenate([residual, v_res], axis=1)
            H = np.concatenate([H, v_H], axis=1)
            sigma = np.concatenate([sigma, epochs.velocity_sigma[epoch]])
        return residual, H, np.diag(sigma**2)

    return Source("gnss", epochs.t, measure, 6 if velocity else 3)


def _groups(sources: Sequence[Source], t0: float, end: float) -> tuple[list[np.ndarray], list[list[tuple[int, int]]]]:
    """Each source's epochs inside (t0, end], and the events: (source, epoch) pairs less than 1e-9 s apart."""
    inside = [np.flatnonzero((source.t > t0) & (source.t <= end + 1e-9)) for source in sources]
    pairs = sorted(((float(source.t[j]), s, int(j)) for s, source in enumerate(sources) for j in inside[s]),
                   key=lambda e: e[0])
    groups: list[list[tuple[int, int]]] = []
    first = -math.inf
    for time, s, j in pairs:
        if time - first < 1e-9 and all(s != other for other, _ in groups[-1]):
            groups[-1].append((s, j))
        else:
            groups.append([(s, j)])
            first = time
    return inside, groups


def run_filter(increments: np.ndarray, interval: float, start: Start, model: FilterModel,
               gnss: GnssRecord | Sequence[GnssRecord], *,
               t0: float = 0.0, lever_arm=(0.0, 0.0, 0.0), covariance_interval: float = 1.0,
               use_velocity: bool = True, gate: float = kalman.DEFAULT_GATE, output_every: int = 1,
               initial_sensor_errors: np.ndarray | None = None, initial_sensor_sigma: np.ndarray | None = None,
               earth_rate: float = EARTH_RATE, sources: Sequence[Source] = (),
               keep_for_smoother: bool = False) -> FilterRun:
    """Filter a batch of members' IMU increments with GNSS fixes (module docstring).

    Parameters
    ----------
    increments : ndarray, shape (n, 6) or (N, n, 6)
        Measured dtheta (rad) and dv (m/s) of each IMU interval, body axes; row i ends at
        t0 + (i + 1) interval.
    interval : float
        IMU interval, s.
    start : Start
        Initial solutions (N members) and their 1-sigma.
    model : FilterModel
        The filter's sensor model (15 or 21 states).
    gnss : GnssRecord or sequence of GnssRecord
        The measurements (one record for every member, or one per member with the same epochs and sigmas; times on
        the IMU's time scale); epochs outside (t0, t0 + n interval] are skipped.
    t0 : float
        Time of the start, s.
    lever_arm : array_like, shape (3,)
        IMU to GNSS antenna, body axes, m.
    covariance_interval : float
        Covariance step, s (a whole number of IMU intervals, >= one).
    use_velocity : bool
        Whether GNSS velocities (if given) are used.
    gate : float
        Chi-square gate probability, a plain number in (0, 1] (1: no gate).
    output_every : int
        IMU samples per stored solution (1: every IMU epoch).
    initial_sensor_errors : ndarray, shape (12,) or (N, 12), optional
        Initial estimates b_g (rad/s), b_a (m/s^2), s_g, s_a compensated from the start (shared, or each member's).
    initial_sensor_sigma : ndarray, shape (6,) or (12,), optional
        1-sigma of the sensor-error states at the start (rad/s, m/s^2, then the scale factors, 1; the aiding
        states' follow from the model); default the model's
        (:meth:`~schuler.aided.error_state.FilterModel.initial_sigma`; KF-GINS's ``initbgstd`` ... differ).
    earth_rate : float
        Omega, rad/s.
    sources : sequence of Source
        Aiding besides GNSS (:mod:`schuler.aided.sources`), each named once, none named ``gnss``.
    keep_for_smoother : bool
        Whether to keep, at every stored covariance, the prior P, Phi and the correction fed back
        (:func:`schuler.aided.smoother.smooth` needs them; 2 n^2 + n more doubles per member and stored time).

    Returns
    -------
    FilterRun
    """
    increments = np.asarray(increments, dtype=float)
    n_samples = increments.shape[-2]
    members = start.members
    n = model.size
    steps = covariance_interval / interval
    if not (interval > 0 and steps >= 1 and abs(steps - round(steps)) < 1e-9):
        raise InvalidParameter("covariance_interval", f"must be a whole number (>= 1) of IMU intervals of "
                                                      f"{interval} s, got {covariance_interval} s")
    every_cov = int(round(steps))
    end = t0 + n_samples * interval
    epochs = _Epochs.of(gnss, members)
    velocity = use_velocity and epochs.velocity is not None
    names = [source.name for source in sources]
    if "gnss" in names or len(set(names)) < len(names):
        raise InvalidParameter("sources", f"each source once and none named gnss, got {names}")
    every_source = [_gnss_source(epochs, lever_arm, velocity, n, earth_rate), *sources]
    inside_of, groups = _groups(every_source, t0, end)
    n_cov = n_samples // every_cov + len(groups) + 1
    n_out = n_samples // output_every
    smoother_doubles = 2 * n * n + n if keep_for_smoother else 0
    logged = sum(kept.size * (2 + 2 * source.components) for source, kept in zip(every_source, inside_of))
    require(8.0 * members * (n_cov * (n * n + 12 + n - model.sensor_size + smoother_doubles)
                             + (n_out + 1) * _kernels.OUTPUT_SIZE + logged),
            "the filter's stored solution, covariances and innovations"
            + (" with the smoother's" if smoother_doubles else ""),
            "the duration, the members, the covariance interval, the output step or the aiding rates")
    logs = [SourceLog.empty(source.t[kept], members, source.components)
            for source, kept in zip(every_source, inside_of)]
    position_of = [{int(j): k for k, j in enumerate(kept)} for kept in inside_of]
    aiding_states = n - model.sensor_size
    navigator = _Navigator(start, increments, interval, t0, output_every, n_out, earth_rate, aiding_states)
    if initial_sensor_errors is not None:
        guess = np.asarray(initial_sensor_errors, dtype=float)
        navigator.gyro_bias[:], navigator.accel_bias[:] = guess[..., 0:3], guess[..., 3:6]
        navigator.gyro_scale[:], navigator.accel_scale[:] = guess[..., 6:9], guess[..., 9:12]
    sensor_sigma = model.initial_sigma()
    if initial_sensor_sigma is not None:
        sensor_sigma = np.concatenate([np.asarray(initial_sensor_sigma, float).reshape(-1),
                                       sensor_sigma[sensor_sigma.size - aiding_states:]])
    if sensor_sigma.shape != (n - 9,):
        given = sensor_sigma.size - aiding_states
        raise InvalidParameter("initial_sensor_sigma", f"needs {model.sensor_size - 9} values for "
                                                       f"{model.sensor_size} states, got {given}")
    sigma0 = np.concatenate([start.position_sigma, start.velocity_sigma, start.attitude_sigma, sensor_sigma])
    P = np.broadcast_to(np.diag(sigma0**2), (members, n, n)).copy()
    accumulator = _Accumulator(members)
    point = navigator.point(accumulator)
    cov_t, covs, estimates = [t0], [P.copy()], [navigator.estimates()]
    aiding_estimates = [navigator.aiding.copy()]
    identity = np.broadcast_to(np.eye(n), (members, n, n))
    if keep_for_smoother:
        navigator.fed_back = np.zeros((members, n))
        priors, transitions, corrections = [P.copy()], [identity], [np.zeros((members, n))]
    boundaries = t0 + np.arange(every_cov, n_samples + 1, every_cov) * interval
    events = sorted([(float(b), -1) for b in boundaries]
                    + [(float(every_source[group[0][0]].t[group[0][1]]), g) for g, group in enumerate(groups)],
                    key=lambda e: e[0])

    def propagate(P):
        elapsed = accumulator.elapsed
        if elapsed <= 0:
            return P, identity
        start_point = NavigationPoint(point.latitude, point.height, point.velocity, point.body_to_ned,
                                      accumulator.velocity / elapsed, accumulator.angle / elapsed)
        Phi, Q = transition(model, start_point, elapsed, earth_rate)
        navigator.decay(model, elapsed)
        return kalman.predict(P, Phi, Q), Phi

    previous = t0
    for index, (time, epoch) in enumerate(events):
        if epoch < 0 and index + 1 < len(events) and abs(events[index + 1][0] - time) < 1e-9:
            continue  # an epoch at the same time follows: propagate once, there
        Phi = identity
        if time - previous > 1e-12:
            navigator.advance_to(time, accumulator)
            P, Phi = propagate(P)
        previous = time
        if keep_for_smoother:
            priors.append(P.copy())
            transitions.append(np.broadcast_to(Phi, (members, n, n)))
        if epoch >= 0:
            context = navigator.context(accumulator, model)
            blocks = [every_source[s].measure(j, context) for s, j in groups[epoch]]
            if len(blocks) == 1:
                outcome = kalman.update(P, *blocks[0], gate)
                per_block = [outcome]
            else:
                outcome, per_block = kalman.stacked_update(P, blocks, gate)
            P = outcome.covariance
            navigator.correct(outcome.correction, model)
            for (s, j), block in zip(groups[epoch], per_block):
                log, k = logs[s], position_of[s][j]
                log.nis[:, k], log.accepted[:, k] = block.nis, block.accepted
                log.residual[:, k], log.residual_sigma[:, k] = block.residual, block.residual_sigma
        accumulator.reset()
        point = navigator.point(accumulator)
        cov_t.append(time)
        covs.append(P.copy())
        estimates.append(navigator.estimates())
        aiding_estimates.append(navigator.aiding.copy())
        if keep_for_smoother:
            assert navigator.fed_back is not None
            corrections.append(navigator.fed_back.copy())
            navigator.fed_back[:] = 0.0
    if navigator.time < end - 1e-9:
        navigator.advance_to(end, accumulator)
    out_t = t0 + np.arange(1, n_out + 1) * output_every * interval
    gnss_log = logs[0]
    run = FilterRun(out_t, navigator.out[:, 1:], np.asarray(cov_t), np.stack(covs, axis=1),
                    np.stack(estimates, axis=1), gnss_log.t_s, gnss_log.nis, gnss_log.accepted, gnss_log.residual,
                    gnss_log.residual_sigma, n, {source.name: log for source, log in zip(sources, logs[1:])},
                    np.stack(aiding_estimates, axis=1))
    if keep_for_smoother:
        run.prior_covariance, run.transition = np.stack(priors, axis=1), np.stack(transitions, axis=1)
        run.correction = np.stack(corrections, axis=1)
    return run
