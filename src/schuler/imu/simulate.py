"""Simulated IMU records from an error model: N members x T samples, in windows, independent of the cut.

Every random number is addressed through :class:`~schuler.core.random.RandomStreams`
by (seed, stream, member, index): stream ``"gyro_x/white"`` sample k of member m is
the same number whichever windows of time and groups of members the work is cut
into, and the recursive terms carry their state from window to window in the
kernels of :mod:`~schuler.imu._kernels`, so a record simulated in pieces equals
the record simulated at once, bit for bit.

Slow processes on a coarse grid
-------------------------------
A Gauss-Markov bias with a correlation time of minutes, each term of the flicker
sum and the rate random walk change little from one sample to the next; drawing
a random number per sample for each would cost most of the time. Each such
process is generated exactly (its exact discretisation) on a coarse grid of
step D dt and interpolated linearly in between. The interpolation leaves out a
Brownian-bridge part of variance q D dt / 6 (q the process's diffusion, 2 sigma^2 / T
or K^2), which acts like white noise of PSD ~ q (D dt)^2 / 6; D is the largest power
of two for which this is below 1e-3 of the white-noise PSD N^2 (and D dt <= T / 2, two
grid points per correlation time; D <= :data:`~schuler.core.random.BLOCK`). With no
white noise (N = 0) the grid is the sample grid (D = 1) and the simulation is exact.

The grids of one channel nest (powers of two), so the processes are summed on
them and refined to the samples once per channel (:func:`schuler.imu._kernels.slow_block`),
not interpolated one by one. Their random numbers come from one stream per
channel, ``"gyro_x/slow"``, block by block (:meth:`~schuler.core.random.RandomStreams.normal_block`):
block b holds, process after process, the BLOCK / D innovations of the grid points
in samples (b BLOCK, (b + 1) BLOCK] (block 0 first holds each process's initial
value), so the samples of block b draw exactly the numbers they need, addressed
by (seed, stream, member, b, position), whatever the windows.

Examples
--------
>>> from schuler.imu.spec import preset
>>> record = simulate_record(preset("tactical"), duration=10.0, sample_interval=0.01, seed=1,
...                          latitude=0.6)
>>> record.samples, record.kind
(1000, 'rate')
>>> bool(abs(record.accel_m_s2[:, 2].mean() + 9.80) < 0.05)   # specific force z ~ -g (z down)
True
"""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from schuler.core.earth import EARTH_RATE, normal_gravity
from schuler.core.random import BLOCK, RandomStreams
from schuler.exceptions import InvalidParameter, renamed_keywords
from schuler.imu import _kernels
from schuler.imu.error_model import ErrorModel, SensorErrors, flicker_terms
from schuler.imu.record import ImuRecord

INTERPOLATION_TOLERANCE = 1e-3
"""Largest share of the white-noise PSD the coarse-grid interpolation may leave out."""

WINDOW = 1 << 18
"""Samples per window when streaming."""

DEFAULT_MAX_MEMORY_BYTES = 2 * 1024**3
"""Largest in-memory simulation (members x samples x 6 x 8 bytes) built without being asked for more."""

_AXES = "xyz"
_NO_OFFSET = np.zeros(1)


@renamed_keywords(latitude_rad="latitude", heading_rad="heading", gravity_m_s2="gravity")
def static_truth(latitude: float, heading: float = 0.0, gravity: float | None = None):
    """True gyro and accelerometer inputs of a level IMU at rest, body x forward, y right, z down.

    Parameters
    ----------
    latitude : float
        Geodetic latitude L, rad.
    heading : float
        Heading psi of the x axis, clockwise from north, rad.
    gravity : float, optional
        g (default: WGS-84 normal gravity at L).

    Returns
    -------
    gyro, accel : ndarray (3,)
        omega_b = Omega [cos L cos psi, -cos L sin psi, -sin L] (rad/s) and f_b = [0, 0, -g] (m/s^2).
    """
    if not abs(latitude) <= math.pi / 2:
        raise InvalidParameter("latitude", f"{latitude!r} rad must be within [-pi/2, pi/2]")
    g = float(normal_gravity(latitude)) if gravity is None else float(gravity)
    c, s = math.cos(latitude), math.sin(latitude)
    gyro = EARTH_RATE * np.array([c * math.cos(heading), -c * math.sin(heading), -s])
    return gyro, np.array([0.0, 0.0, -g])


@dataclass(frozen=True)
class _SlowTerms:
    """A channel's slow processes, x_{i+1} = phi x_i + drive w_i from x_0 = sigma w_0, on grids of 2**level samples."""

    names: tuple[str, ...]
    phis: np.ndarray
    drives: np.ndarray
    sigmas: np.ndarray
    levels: np.ndarray

    def normals(self, block: int) -> int:
        """How many normals block ``block`` of the channel's slow stream holds."""
        return int(np.sum(BLOCK >> self.levels)) + (self.levels.size if block == 0 else 0)


def _coarse_level(diffusion: float, white_density: float, dt: float, correlation_time: float | None) -> int:
    """log2 of the grid step D: the largest power of two within the interpolation and correlation limits."""
    if white_density <= 0 or diffusion <= 0:
        return 0
    step = white_density * math.sqrt(6.0 * INTERPOLATION_TOLERANCE / diffusion) / dt
    if correlation_time is not None:
        step = min(step, correlation_time / (2.0 * dt))
    return min(max(0, int(math.floor(math.log2(max(step, 1.0))))), BLOCK.bit_length() - 1)


def _slow_terms(errors: SensorErrors, axis: int, dt: float) -> _SlowTerms:
    white = errors.random_walk[axis]
    terms = []
    if errors.gm_sigma[axis] > 0:
        terms.append(("gm", errors.gm_sigma[axis], errors.gm_correlation_time_s[axis]))
    if errors.bias_instability[axis] > 0:
        flicker = flicker_terms(errors.bias_instability[axis], errors.flicker_tau_range_s)
        terms += [(f"flicker{j}", sigma, time) for j, (sigma, time) in enumerate(zip(*flicker))]
    rows = []
    for name, sigma, time in terms:
        level = _coarse_level(2 * sigma**2 / time, white, dt, time)
        interval = (1 << level) * dt
        rows.append((name, math.exp(-interval / time), sigma * math.sqrt(-math.expm1(-2 * interval / time)), sigma,
                     level))
    k = errors.rate_random_walk[axis]
    if k > 0:
        level = _coarse_level(k**2, white, dt, None)
        rows.append(("rate_random_walk", 1.0, k * math.sqrt((1 << level) * dt), 0.0, level))
    names, phis, drives, sigmas, levels = zip(*rows) if rows else ((), (), (), (), ())
    return _SlowTerms(names, np.array(phis, dtype=float), np.array(drives, dtype=float), np.array(sigmas, dtype=float),
                      np.array(levels, dtype=np.int64))


@dataclass
class _SlowState:
    """A channel's slow processes at the start of the next block, and the block a window ended inside."""

    left: np.ndarray
    kept: tuple[int, np.ndarray] | None = None  # (block number, its summed slow processes), for the next window


@dataclass
class _MemberState:
    """Where one member's simulation stands: next sample, slow processes per channel, quantiser residuals."""

    next_sample: int = 0
    slow: dict = field(default_factory=dict)  # channel -> _SlowState
    residual: dict = field(default_factory=dict)  # channel -> quantiser residual


class ImuSimulator:
    """Simulates members of one error model; windows of each member must come in time order for speed.

    Parameters
    ----------
    model : ErrorModel
    sample_interval_s : float
        dt, s.
    true_gyro_rad_s, true_accel_m_s2 : ndarray, shape (3,) or (n, 3)
        True inputs, body frame (constant, or one row per sample from sample 0).
    seed : int
        Study seed of the addressed random numbers.
    workers : int
        Threads over members (the random generator and the kernels release the GIL).

    Notes
    -----
    Member m draws its constant errors (bias, scale factor, misalignment,
    g-sensitivity) from streams ``"gyro/bias"`` ... at member index m, its white
    noise from ``"gyro_x/white"`` ... at sample index k and its slow processes
    from ``"gyro_x/slow"`` ... by blocks of samples (module docstring). A window
    that does not continue the member's last one is recomputed from sample 0,
    so any cut gives the same numbers.
    """

    @renamed_keywords(sample_interval_s="sample_interval", true_gyro_rad_s="true_gyro", true_accel_m_s2="true_accel")
    def __init__(self, model: ErrorModel, sample_interval: float, *, true_gyro=(0.0, 0.0, 0.0),
                 true_accel=(0.0, 0.0, 0.0), seed: int = 0, workers: int = 1):
        dt = float(sample_interval)
        if not (math.isfinite(dt) and dt > 0):
            raise InvalidParameter("sample_interval", f"must be finite and > 0 s, got {sample_interval!r}")
        self.model, self.dt, self.workers = model, dt, max(1, int(workers))
        self.streams = RandomStreams(seed)
        self.true_gyro = self._truth(true_gyro, "true_gyro_rad_s")
        self.true_accel = self._truth(true_accel, "true_accel_m_s2")
        self._sensors = {"gyro": model.gyro, "accel": model.accel}
        self._slow_terms = {f"{s}_{a}": _slow_terms(e, i, dt) for s, e in self._sensors.items()
                            for i, a in enumerate(_AXES)}
        self._states: dict[int, _MemberState] = {}

    @staticmethod
    def _truth(values, name: str) -> np.ndarray:
        array = np.asarray(values, dtype=float)
        if array.shape != (3,) and (array.ndim != 2 or array.shape[1] != 3):
            raise InvalidParameter(name, f"shape {array.shape} must be (3,) or (n, 3)")
        if not np.all(np.isfinite(array)):
            raise InvalidParameter(name, "must be finite")
        return array

    def coarse_steps(self) -> dict[str, int]:
        """Coarse-grid step D (in samples) of every slow process, by name (``"gyro_x/flicker3"``)."""
        return {f"{channel}/{name}": 1 << int(level) for channel, terms in self._slow_terms.items()
                for name, level in zip(terms.names, terms.levels)}

    def member_state_bytes(self) -> int:
        """Largest memory a member's carried state holds between windows, bytes (a block of slow sums per channel)."""
        return sum(BLOCK * 8 for terms in self._slow_terms.values() if terms.levels.size)

    def constants(self, members) -> dict[str, np.ndarray]:
        """Each member's constant errors: ``gyro_bias`` (m, 3), ``gyro_matrix`` (m, 3, 3) = I + S + M, ``gyro_g`` ...

        Parameters
        ----------
        members : ndarray of int
            Member numbers (the addresses of their draws).
        """
        members = np.asarray(members, dtype=np.int64).reshape(-1)
        out = {}
        for sensor, errors in self._sensors.items():
            out[f"{sensor}_bias"] = self.streams.normal(f"{sensor}/bias", members, 3) * errors.bias
            scale = self.streams.normal(f"{sensor}/scale_factor", members, 3) * errors.scale_factor
            misalignment = self.streams.normal(f"{sensor}/misalignment", members, 9).reshape(-1, 3, 3)
            matrix = np.eye(3) + misalignment * errors.misalignment
            matrix[:, np.arange(3), np.arange(3)] = 1.0 + scale
            out[f"{sensor}_matrix"] = matrix
            g_entries = self.streams.normal(f"{sensor}/g_sensitivity", members, 9).reshape(-1, 3, 3)
            out[f"{sensor}_g"] = g_entries * errors.g_sensitivity
        return out

    def _true_window(self, truth: np.ndarray, start: int, stop: int) -> np.ndarray:
        if truth.ndim == 1:
            return np.broadcast_to(truth, (stop - start, 3))
        if stop > truth.shape[0]:
            raise InvalidParameter("samples", f"the true inputs cover {truth.shape[0]:,} samples, asked up to {stop:,}")
        return truth[start:stop]

    def _add_slow(self, member: int, state: _MemberState, channel: str, start: int, stop: int,
                  values: np.ndarray) -> None:
        """Add the channel's slow processes over samples start .. stop-1 to ``values``, block by block."""
        terms = self._slow_terms[channel]
        slow = state.slow.setdefault(channel, _SlowState(left=np.zeros(terms.levels.size)))
        for block in range(start // BLOCK, (stop - 1) // BLOCK + 1):
            origin = block * BLOCK
            lo, hi = max(start, origin) - origin, min(stop, origin + BLOCK) - origin
            destination = values[origin + lo - start:origin + hi - start]
            if slow.kept is not None and slow.kept[0] == block:
                destination += slow.kept[1][lo:hi]
                continue
            # windows continue each other (_member_window replays otherwise), so this block is the next one
            keep = hi < BLOCK  # the next window starts inside this block: keep its sums
            target = np.zeros(BLOCK) if keep else destination
            normals = self.streams.normal_block(f"{channel}/slow", member, block, terms.normals(block))
            _kernels.slow_block(normals, terms.phis, terms.drives, terms.sigmas, terms.levels, BLOCK, block == 0,
                                slow.left, np.empty(2 * BLOCK + 17), target, 0 if keep else lo)
            slow.kept = (block, target) if keep else None
            if keep:
                destination += target[lo:hi]

    def forget(self, members) -> None:
        """Drop the carried state of ``members`` (their next window replays from sample 0).

        Parameters
        ----------
        members : ndarray of int
            Member numbers.
        """
        for member in np.asarray(members, dtype=np.int64).reshape(-1):
            self._states.pop(int(member), None)

    def _member_window(self, member: int, start: int, stop: int, constants: dict, row: int,
                       out: tuple[np.ndarray, np.ndarray], as_errors: bool) -> None:
        state = self._states.get(member)
        if state is None or state.next_sample != start:
            state = _MemberState()
            for begin in range(0, start, WINDOW):  # replay from the start: results never depend on the cut
                end = min(start, begin + WINDOW)
                scratch = np.empty((end - begin, 3))
                self._fill(member, state, begin, end, constants, row, (scratch, scratch), False)
        self._fill(member, state, start, stop, constants, row, out, as_errors)
        self._states[member] = state

    def _deterministic(self, sensor: str, constants: dict, row: int, start: int, stop: int):
        """(I + S + M) u + b (+ G f for gyros): a 3-vector for constant inputs, else (3, L)."""
        truth = self.true_gyro if sensor == "gyro" else self.true_accel
        matrix, bias = constants[f"{sensor}_matrix"][row], constants[f"{sensor}_bias"][row]
        with_g = sensor == "gyro" and np.any(self.model.gyro.g_sensitivity)
        if truth.ndim == 1 and self.true_accel.ndim == 1:
            value = matrix @ truth + bias
            return value + constants["gyro_g"][row] @ self.true_accel if with_g else value
        value = matrix @ self._true_window(truth, start, stop).T + bias[:, None]
        if with_g:
            value = value + constants["gyro_g"][row] @ self._true_window(self.true_accel, start, stop).T
        return value

    def _fill(self, member: int, state: _MemberState, start: int, stop: int, constants: dict, row: int,
              out: tuple[np.ndarray, np.ndarray], as_errors: bool) -> None:
        """Samples start .. stop-1 of one member into ``out`` = (gyro, accel), each of shape (stop - start, 3)."""
        for s_index, (sensor, errors) in enumerate(self._sensors.items()):
            deterministic = self._deterministic(sensor, constants, row, start, stop)
            truth = self.true_gyro if sensor == "gyro" else self.true_accel
            for axis in range(3):
                channel = f"{sensor}_{_AXES[axis]}"
                density = errors.random_walk[axis]
                if density > 0:
                    values = self.streams.normal_series(f"{channel}/white", [member], start, stop)[0]
                    values *= density / math.sqrt(self.dt)
                    values += deterministic[axis]
                else:
                    values = np.empty(stop - start)
                    values[:] = deterministic[axis]
                if self._slow_terms[channel].levels.size:
                    self._add_slow(member, state, channel, start, stop, values)
                quantum = errors.quantization[axis] * math.sqrt(12.0)
                if quantum > 0:
                    if channel not in state.residual:
                        phase = self.streams.uniform(f"{channel}/quantization_phase", [member])[0]
                        state.residual[channel] = phase * quantum
                    values *= self.dt
                    state.residual[channel] = _kernels.quantize(values, quantum, state.residual[channel])
                    values /= self.dt
                if not as_errors:
                    _kernels.store(values, _NO_OFFSET, 1.0, out[s_index][:, axis])
                else:  # (rate - true) dt while the channel is in cache
                    true_axis = truth[axis:axis + 1] if truth.ndim == 1 else truth[start:stop, axis]
                    _kernels.store(values, np.ascontiguousarray(true_axis), self.dt, out[s_index][:, axis])
        state.next_sample = stop

    def window(self, members, start: int, stop: int, *, as_errors: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Rates of ``members`` over samples ``start .. stop-1``: gyro (m, L, 3) rad/s, accel (m, L, 3) m/s^2.

        Sample k is the mean over (k dt, (k + 1) dt]. With quantisation, rate = whole quanta / dt.
        Both arrays are new and C-contiguous.

        Parameters
        ----------
        members : ndarray of int
            Member numbers.
        start, stop : int
            Sample index range.
        as_errors : bool
            Return the increment errors (rate - true input) dt instead, rad and m/s.

        """
        members = np.asarray(members, dtype=np.int64).reshape(-1)
        start, stop = int(start), int(stop)
        if start < 0 or stop <= start:
            raise InvalidParameter("samples", f"window [{start}, {stop}) must satisfy 0 <= start < stop")
        if members.size and members.min() < 0:
            raise InvalidParameter("members", "member numbers must be >= 0")
        constants = self.constants(members)
        gyro, accel = np.empty((members.size, stop - start, 3)), np.empty((members.size, stop - start, 3))
        jobs = [(int(m), start, stop, constants, row, (gyro[row], accel[row]), as_errors)
                for row, m in enumerate(members)]
        if self.workers > 1 and len(jobs) > 1:
            with ThreadPoolExecutor(self.workers) as pool:
                list(pool.map(lambda job: self._member_window(*job), jobs))
        else:
            for job in jobs:
                self._member_window(*job)
        return gyro, accel


def _check_size(members: int, samples: int, max_memory_bytes: int) -> None:
    needed = members * samples * 6 * 8 * 2
    if needed > max_memory_bytes:
        raise InvalidParameter("samples", f"{members:,} members x {samples:,} samples need ~{needed / 1e9:.1f} GB, "
                               f"above the {max_memory_bytes / 1e9:.1f} GB limit; stream with iter_simulation or "
                               "write_simulation")


def _sample_count(duration_s: float, dt: float) -> int:
    if not (math.isfinite(duration_s) and duration_s > 0):
        raise InvalidParameter("duration", f"must be finite and > 0 s, got {duration_s!r}")
    samples = int(round(duration_s / dt))
    if samples < 2:
        raise InvalidParameter("duration", f"{duration_s:g} s at {dt:g} s per sample gives fewer than 2 samples")
    return samples


def iter_simulation(simulator: ImuSimulator, members, samples: int, window: int = WINDOW, member_chunk: int = 8):
    """Yield ``(members, start, gyro, accel)`` windows covering ``samples`` samples of ``members``, bounded memory.

    Parameters
    ----------
    simulator : ImuSimulator
        The simulator (error model, dt, seed).
    members : ndarray of int
        Member numbers.
    samples : int
        Number of samples per member.
    window : int
        Number of samples per window.
    member_chunk : int
        Number of members simulated at once.
    """
    members = np.asarray(members, dtype=np.int64).reshape(-1)
    for first in range(0, members.size, member_chunk):
        group = members[first:first + member_chunk]
        for start in range(0, samples, window):
            stop = min(samples, start + window)
            gyro, accel = simulator.window(group, start, stop)
            yield group, start, gyro, accel
        simulator.forget(group)


@renamed_keywords(sample_interval_s="sample_interval", true_gyro_rad_s="true_gyro", true_accel_m_s2="true_accel")
def simulate_members(model: ErrorModel, *, samples: int, sample_interval: float, members=1, seed: int = 0,
                     true_gyro=(0.0, 0.0, 0.0), true_accel=(0.0, 0.0, 0.0), workers: int = 1,
                     max_memory_bytes: int = DEFAULT_MAX_MEMORY_BYTES) -> tuple[np.ndarray, np.ndarray]:
    """All samples of several members in memory: gyro and accel rates, each (members, samples, 3).

    ``members`` is a count (members 0 .. n-1) or a sequence of member numbers.

    Parameters
    ----------
    model : ErrorModel
        Sensor errors (SI).
    samples : int
        Number of samples per member.
    sample_interval : float
        dt, s.
    members : int or sequence of int
        A count (members 0 .. n-1) or the member numbers.
    seed : int
        Seed of the random streams.
    true_gyro : tuple of float
        True angular rate in body axes, rad/s.
    true_accel : tuple of float
        True specific force in body axes, m/s^2.
    workers : int
        Number of threads.
    max_memory_bytes : int
        Largest result allocated, bytes (larger requests are refused).

    """
    ids = np.arange(members) if np.ndim(members) == 0 else np.asarray(members, dtype=np.int64)
    _check_size(ids.size, int(samples), max_memory_bytes)
    simulator = ImuSimulator(model, sample_interval, true_gyro=true_gyro,
                             true_accel=true_accel, seed=seed, workers=workers)
    gyro = np.empty((ids.size, int(samples), 3))
    accel = np.empty_like(gyro)
    for _, start, g, a in iter_simulation(simulator, ids, int(samples), member_chunk=max(1, ids.size)):
        gyro[:, start:start + g.shape[1]] = g
        accel[:, start:start + g.shape[1]] = a
    return gyro, accel


@renamed_keywords(duration_s="duration", sample_interval_s="sample_interval", latitude_rad="latitude",
                  heading_rad="heading")
def simulate_record(model: ErrorModel, *, duration: float, sample_interval: float, seed: int = 0, member: int = 0,
                    latitude: float = math.radians(45.0), heading: float = 0.0, kind: str = "rate",
                    max_memory_bytes: int = DEFAULT_MAX_MEMORY_BYTES) -> ImuRecord:
    """One member's record of a level IMU at rest (:func:`static_truth`), as an :class:`ImuRecord`.

    Parameters
    ----------
    model : ErrorModel
        Sensor errors (SI): the member's constant errors are drawn from it, its random processes simulated.
    duration : float
        Length of the record, s.
    sample_interval : float
        Sample interval dt, s.
    seed : int
        Study seed of the addressed random numbers, plain number >= 0.
    member : int
        Member number, index >= 0: with the seed, the address of the random numbers.
    latitude : float
        Geodetic latitude L of the site, rad.
    heading : float
        Heading of the body x axis, clockwise from north, rad.
    kind : {"rate", "increment"}
        What a sample holds: the mean rate over dt (rad/s, m/s^2) or its increment (rad, m/s).
    max_memory_bytes : int
        Largest record allocated, bytes (larger requests are refused).

    Returns
    -------
    ImuRecord
        Samples at t = dt, 2 dt, ..., body axes x forward, y right, z down.
    """
    dt = float(sample_interval)
    samples = _sample_count(duration, dt)
    gyro_true, accel_true = static_truth(latitude, heading)
    gyro, accel = simulate_members(model, samples=samples, sample_interval=dt, members=[member], seed=seed,
                                   true_gyro=gyro_true, true_accel=accel_true,
                                   max_memory_bytes=max_memory_bytes)
    scale = dt if kind == "increment" else 1.0
    return ImuRecord(time_s=dt * np.arange(1, samples + 1), gyro=gyro[0] * scale, accel=accel[0] * scale, kind=kind,
                     sample_interval_s=dt, latitude_rad=latitude, initial_attitude_rad=(0.0, 0.0, heading),
                     source=f"simulated {model.name}, seed {seed}, member {member}")


@renamed_keywords(duration_s="duration", sample_interval_s="sample_interval", latitude_rad="latitude",
                  heading_rad="heading")
def write_simulation(path, model: ErrorModel, *, duration: float, sample_interval: float, seed: int = 0,
                     member: int = 0, latitude: float = math.radians(45.0), heading: float = 0.0,
                     workers: int = 1):
    """Simulate one member at rest straight into a native (Parquet) file, window by window; returns the path.

    Parameters
    ----------
    path : str or Path
        The Parquet file.
    model : ErrorModel
        Sensor errors (SI).
    duration : float
        Length of the record, s.
    sample_interval : float
        Sample interval dt, s.
    seed : int
        Study seed of the addressed random numbers, plain number >= 0.
    member : int
        Member number, index >= 0: with the seed, the address of the random numbers.
    latitude : float
        Geodetic latitude L of the site, rad.
    heading : float
        Heading of the body x axis, clockwise from north, rad.
    workers : int
        Threads over members, number of.

    Returns
    -------
    Path
        The file written: rates (rad/s, m/s^2), body axes x forward, y right, z down, the same samples as
        :func:`simulate_record`.
    """
    from schuler.imu.native import ParquetRecordWriter

    dt = float(sample_interval)
    samples = _sample_count(duration, dt)
    gyro_true, accel_true = static_truth(latitude, heading)
    simulator = ImuSimulator(model, dt, true_gyro=gyro_true, true_accel=accel_true, seed=seed,
                             workers=workers)
    with ParquetRecordWriter(path, "rate", dt, latitude_rad=latitude, initial_attitude_rad=(0.0, 0.0, heading),
                             source=f"simulated {model.name}, seed {seed}, member {member}") as writer:
        for _, start, gyro, accel in iter_simulation(simulator, [member], samples):
            writer.write(dt * np.arange(start + 1, start + gyro.shape[1] + 1), gyro[0], accel[0])
    return writer.path
