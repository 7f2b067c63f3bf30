"""GNSS epochs and the other aiding data: typed records, their simulation from a truth, outages.

A :class:`GnssRecord` holds positions (latitude, longitude rad, height m) with 1-sigma north/east/down (m) per
epoch, optionally NED velocities (m/s) with their 1-sigma; times as in the source (seconds since the start for
simulated data, seconds of week for files). Simulated epochs take the antenna's truth at the body lever arm from
:mod:`schuler.aided.epochs` (interpolated between IMU samples; the arm's equations are there).

Latency: a GNSS stamp t is late by ``latency`` s: the epoch stamped t holds the antenna's position (and velocity)
at t - latency. Noise: white, normal, drawn from :class:`~schuler.core.random.RandomStreams` at the address
(seed, stream, member, epoch index), the index counting the epochs of the schedule before outages remove any: a
member's draws depend on nothing else. ``streams=None`` gives the noise-free data (the sigmas are still stated).

Outages are (start_s, duration_s) pairs: an outage removes the epochs with start <= t < start + duration.
:func:`detect_outages` reads them back from a record as the gaps longer than twice its nominal (median) interval:
a gap between epochs t_a and t_b is the outage (t_a + interval, t_b - t_a - interval), so that a scheduled outage
and the one detected from its data agree.

Examples
--------
>>> schedule_outages(300.0, 60.0, every=400.0, end=1500.0)
((300.0, 60.0), (700.0, 60.0), (1100.0, 60.0))
>>> detect_outages(np.array([1.0, 2.0, 3.0, 7.0, 8.0]))
((4.0, 3.0),)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from schuler.aided.epochs import draws, epoch_schedule, offset_position, positive, truth_at, vector3
from schuler.core.earth import EARTH_RATE
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter, renamed_keywords

DEFAULT_POSITION_SIGMA_M = (0.5, 0.5, 1.0)
"""Default 1-sigma of simulated GNSS positions, north, east, down, m (a differential code solution)."""

@renamed_keywords(position_sigma_m="position_sigma", velocity_sigma_m_s="velocity_sigma")
def validate_epochs(t_s, position_sigma, velocity_sigma=None, *, name: str = "gnss", locate=None) -> None:
    """Refuse unsorted or repeated epoch times and NaN, zero or negative sigmas, naming the first bad epoch.

    Parameters
    ----------
    t_s : ndarray, shape (n,)
        Epoch times, s.
    position_sigma : ndarray, shape (n, 3)
        1-sigma north, east, down, m.
    velocity_sigma : ndarray, shape (n, 3), optional
        1-sigma of v_N, v_E, v_D, m/s.
    name : str
        The input's name in messages (an option or configuration key).
    locate : callable, optional
        Row index -> where it is ("line 12"); default "epoch k" (k counted from 1).

    Raises
    ------
    InvalidParameter
        One line naming the first offending epoch.
    """
    where = locate or (lambda row: f"epoch {row + 1}")
    t = np.asarray(t_s, dtype=float)
    if t.size == 0:
        raise InvalidParameter(name, "no epochs")
    if not np.all(np.isfinite(t)):
        raise InvalidParameter(name, f"{where(int(np.flatnonzero(~np.isfinite(t))[0]))}: time is not finite")
    steps = np.diff(t)
    if np.any(steps <= 0):
        row = int(np.flatnonzero(steps <= 0)[0]) + 1
        kind = "repeats the one before" if steps[row - 1] == 0 else "is earlier than the one before"
        raise InvalidParameter(name, f"{where(row)}: time {t[row]:.6f} s {kind} (times must increase strictly)")
    for label, sigma in (("position", position_sigma), ("velocity", velocity_sigma)):
        if sigma is None:
            continue
        bad = ~(np.asarray(sigma, dtype=float) > 0)  # NaN compares false: refused with zeros and negatives
        if np.any(bad):
            row, axis = np.argwhere(bad)[0]
            raise InvalidParameter(name, f"{where(int(row))}: {label} 1-sigma {('north', 'east', 'down')[axis]} "
                                         f"is {float(sigma[row, axis])!r} (must be finite and > 0)")


@dataclass(frozen=True, eq=False)
class GnssRecord:
    """GNSS epochs: positions with their 1-sigma, optionally NED velocities with theirs.

    Parameters
    ----------
    t_s : ndarray, shape (n,)
        Epoch times, s (strictly increasing; seconds of week for a file).
    latitude_rad, longitude_rad : ndarray, shape (n,)
        Antenna position, rad.
    height_m : ndarray, shape (n,)
        Antenna height above the ellipsoid, m.
    position_sigma_m : ndarray, shape (n, 3)
        1-sigma north, east, down of each epoch, m (> 0).
    velocity_ned_m_s : ndarray, shape (n, 3), optional
        Antenna velocity v_N, v_E, v_D, m/s.
    velocity_sigma_m_s : ndarray, shape (n, 3), optional
        1-sigma of the velocities, m/s (> 0); given exactly when the velocities are.
    source : str
        Where the epochs came from (a file name or "simulated").
    """

    t_s: np.ndarray
    latitude_rad: np.ndarray
    longitude_rad: np.ndarray
    height_m: np.ndarray
    position_sigma_m: np.ndarray
    velocity_ned_m_s: np.ndarray | None = None
    velocity_sigma_m_s: np.ndarray | None = None
    source: str = ""

    def __post_init__(self):
        t = np.asarray(self.t_s, dtype=float).reshape(-1)
        n = t.size
        object.__setattr__(self, "t_s", t)
        for key in ("latitude_rad", "longitude_rad", "height_m"):
            array = np.asarray(getattr(self, key), dtype=float).reshape(-1)
            if array.shape != (n,) or not np.all(np.isfinite(array)):
                raise InvalidParameter(key, f"must be {n} finite numbers (one per epoch)")
            object.__setattr__(self, key, array)
        if (self.velocity_ned_m_s is None) != (self.velocity_sigma_m_s is None):
            raise InvalidParameter("velocity_sigma_m_s", "velocities and their 1-sigma come together")
        for key in ("position_sigma_m", "velocity_ned_m_s", "velocity_sigma_m_s"):
            if getattr(self, key) is None:
                continue
            array = np.asarray(getattr(self, key), dtype=float)
            if array.shape != (n, 3):
                raise InvalidParameter(key, f"shape {array.shape} must be ({n}, 3)")
            object.__setattr__(self, key, array)
        if self.velocity_ned_m_s is not None and not np.all(np.isfinite(self.velocity_ned_m_s)):
            raise InvalidParameter("velocity_ned_m_s", "must be finite")
        if np.any(np.abs(self.latitude_rad) > math.pi / 2):
            raise InvalidParameter("latitude_rad", "must lie within +/-90 deg")
        validate_epochs(t, self.position_sigma_m, self.velocity_sigma_m_s, name="gnss")

    @property
    def epochs(self) -> int:
        """Number of epochs n."""
        return int(self.t_s.size)

    @property
    def has_velocity(self) -> bool:
        """Whether the epochs carry velocities."""
        return self.velocity_ned_m_s is not None

    @property
    def nominal_interval_s(self) -> float:
        """The median interval between epochs, s (NaN for a single epoch)."""
        return float(np.median(np.diff(self.t_s))) if self.epochs > 1 else math.nan

    def select(self, keep) -> GnssRecord:
        """The epochs where ``keep`` is true.

        Parameters
        ----------
        keep : sequence of bool, shape (n,)
            Which epochs to keep.

        Returns
        -------
        GnssRecord
        """
        keep = np.asarray(keep, dtype=bool)
        velocity, sigma = self.velocity_ned_m_s, self.velocity_sigma_m_s
        return replace(self, t_s=self.t_s[keep], latitude_rad=self.latitude_rad[keep],
                       longitude_rad=self.longitude_rad[keep], height_m=self.height_m[keep],
                       position_sigma_m=self.position_sigma_m[keep],
                       velocity_ned_m_s=None if velocity is None else velocity[keep],
                       velocity_sigma_m_s=None if sigma is None else sigma[keep])

    def without(self, outages) -> GnssRecord:
        """The record with the epochs inside the outages removed.

        Parameters
        ----------
        outages : sequence of (float, float)
            (start, duration) pairs, s, in the record's time base.

        Returns
        -------
        GnssRecord
        """
        return self.select(~in_outages(self.t_s, outages))

    def outages(self) -> tuple[tuple[float, float], ...]:
        """The gaps of this record longer than twice its nominal interval, as (start_s, duration_s) pairs."""
        return detect_outages(self.t_s)


def check_outages(outages) -> tuple[tuple[float, float], ...]:
    """Outages as (start_s, duration_s) float pairs, checked: finite, duration > 0, sorted, not overlapping.

    Parameters
    ----------
    outages : sequence of (float, float)
        (start, duration) pairs, s.

    Returns
    -------
    tuple of (float, float)
        The same pairs, sorted by start, s.

    Raises
    ------
    InvalidParameter
        Naming ``outages``.
    """
    pairs = []
    for item in outages:
        values = np.asarray(item, dtype=float).reshape(-1)
        if values.shape != (2,) or not np.all(np.isfinite(values)) or values[1] <= 0:
            raise InvalidParameter("outages", f"each outage is [start, duration] in s with duration > 0, got {item!r}")
        pairs.append((float(values[0]), float(values[1])))
    pairs.sort()
    for (start, duration), (next_start, _) in zip(pairs, pairs[1:]):
        if next_start < start + duration:
            raise InvalidParameter("outages", f"the outage at {next_start:g} s starts before the one at {start:g} s "
                                              f"ends ({start + duration:g} s)")
    return tuple(pairs)


def schedule_outages(start: float, duration: float, every: float | None = None,
                     end: float = math.inf) -> tuple[tuple[float, float], ...]:
    """Outages of ``duration`` from ``start``, repeated each ``every`` seconds while they start before ``end``.

    Parameters
    ----------
    start : float
        Start of the first outage, s.
    duration : float
        Length of each outage, s (> 0).
    every : float, optional
        Time from one outage's start to the next, s (> duration); None or 0: a single outage.
    end : float
        No outage starts at or after this time, s (the data's end).

    Returns
    -------
    tuple of (float, float)
        (start_s, duration_s) pairs.
    """
    if not math.isfinite(start):
        raise InvalidParameter("outage_start", f"must be finite, got {start!r}")
    duration = positive(duration, "outage_duration")
    if not every:
        return ((float(start), duration),) if start < end else ()
    every = positive(every, "outage_every")
    if every <= duration:
        raise InvalidParameter("outage_every", f"{every:g} s must exceed the outage duration {duration:g} s")
    if not math.isfinite(end):
        raise InvalidParameter("outage_every", "a repeated outage needs the data's end")
    count = max(0, math.ceil((end - start) / every - 1e-12))
    return tuple((float(start + k * every), duration) for k in range(count))



def scheduled_outages(case, end: float, default_start: float | None = None) -> tuple[tuple[float, float], ...]:
    """The outages a case schedules, before ``end``: its ``outages`` list, else ``outage_start`` repeated.

    Parameters
    ----------
    case : Mapping
        A validated case of ``schuler aided`` (SI: ``outages`` as (start, duration) pairs or None,
        ``outage_start`` (None: ``default_start``), ``outage_duration``, ``outage_every``, s).
    end : float
        The data's end, s: no outage starts at or after it.
    default_start : float, optional
        Start of the first outage when ``outage_start`` is not set, s (None: no outage).
    """
    if case["outages"] is not None:
        return tuple(pair for pair in case["outages"] if pair[0] < end)
    start = default_start if case["outage_start"] is None else case["outage_start"]
    if start is None or not case["outage_duration"] or start >= end:
        return ()
    return schedule_outages(start, case["outage_duration"], case["outage_every"], end=end)

def in_outages(t_s, outages) -> np.ndarray:
    """Whether each time falls inside an outage (start <= t < start + duration).

    Parameters
    ----------
    t_s : array_like, shape (n,)
        Times, s.
    outages : sequence of (float, float)
        (start, duration) pairs, s.

    Returns
    -------
    ndarray of bool, shape (n,)
    """
    t = np.asarray(t_s, dtype=float)
    inside = np.zeros(t.shape, dtype=bool)
    for start, duration in check_outages(outages):
        inside |= (t >= start) & (t < start + duration)
    return inside


@renamed_keywords(nominal_interval_s="nominal_interval")
def detect_outages(t_s, nominal_interval: float | None = None) -> tuple[tuple[float, float], ...]:
    """The gaps between epochs longer than twice the nominal interval, as (start_s, duration_s) outages.

    Parameters
    ----------
    t_s : array_like, shape (n,)
        Epoch times, s, increasing.
    nominal_interval : float, optional
        The interval between epochs, s; default the median interval.

    Returns
    -------
    tuple of (float, float)
        One (t_a + interval, t_b - t_a - interval) pair per gap from t_a to t_b, s.
    """
    t = np.asarray(t_s, dtype=float)
    if t.size < 2:
        return ()
    steps = np.diff(t)
    interval = float(np.median(steps)) if nominal_interval is None else positive(nominal_interval,
                                                                                     "nominal_interval_s")
    gaps = np.flatnonzero(steps > 2.0 * interval)
    return tuple((float(t[k] + interval), float(steps[k] - interval)) for k in gaps)


@dataclass(frozen=True, eq=False)
class GnssTruth:
    """The antenna's true position and velocity at the GNSS epochs, before noise and outages.

    Attributes
    ----------
    index : ndarray, shape (n,)
        Epoch numbers of the schedule (the addresses of the noise draws).
    t_s : ndarray, shape (n,)
        Stamps, s (the truth is that of ``t_s - latency_s``).
    position : ndarray, shape (n, 3)
        Antenna latitude, longitude (rad), height (m).
    velocity_ned_m_s : ndarray, shape (n, 3)
        Antenna velocity, m/s.
    latency_s : float
        Stamp delay, s.
    """

    index: np.ndarray
    t_s: np.ndarray
    position: np.ndarray
    velocity_ned_m_s: np.ndarray
    latency_s: float


def gnss_truth(trajectory, duration: float, *, imu_rate: float = 100.0, gnss_rate: float = 1.0,
               lever_arm=(0.0, 0.0, 0.0), latency: float = 0.0, time_offset: float = 0.0,
               earth_rate: float = EARTH_RATE) -> GnssTruth:
    """The antenna's truth at the GNSS epochs of a trajectory (computed once, shared by all members).

    Parameters
    ----------
    trajectory : Trajectory
        A trajectory of :mod:`schuler.navigate.trajectory`.
    duration : float
        s, a whole number of IMU intervals.
    imu_rate : float
        Rate of the truth's samples, Hz.
    gnss_rate : float
        Epoch rate, Hz.
    lever_arm : array_like, shape (3,)
        Antenna from the IMU in body axes (x forward, y right, z down), m.
    latency : float
        Stamp delay, s (>= 0).
    time_offset : float
        Stamp of epoch 0, s, in [0, 1 / gnss_rate).
    earth_rate : float
        Omega, rad/s.

    Returns
    -------
    GnssTruth
    """
    index, stamps = epoch_schedule(gnss_rate, duration, latency=latency, time_offset=time_offset)
    truth = truth_at(trajectory, duration, stamps - latency, imu_rate=imu_rate, earth_rate=earth_rate)
    position, velocity = truth.at_lever_arm(lever_arm)
    return GnssTruth(index, stamps, position, velocity, float(latency))


def gnss_measurements(truth: GnssTruth, *, position_sigma=DEFAULT_POSITION_SIGMA_M, velocity_sigma=None,
                      streams: RandomStreams | None = None, member: int = 0, outages=()) -> GnssRecord:
    """One member's GNSS record: the truth with white noise of the stated 1-sigma, outages removed.

    Parameters
    ----------
    truth : GnssTruth
        From :func:`gnss_truth`.
    position_sigma : array_like, shape (3,)
        1-sigma north, east, down, m (> 0).
    velocity_sigma : float or array_like of 3, optional
        1-sigma of v_N, v_E, v_D, m/s (> 0); None: positions only.
    streams : RandomStreams, optional
        The study's random numbers; None: no noise (the record still states the sigmas).
    member : int
        Member number, index >= 0.
    outages : sequence of (float, float)
        (start, duration) pairs, s: the epochs inside are removed.

    Returns
    -------
    GnssRecord
    """
    sigma = vector3(position_sigma, "position_sigma")
    vsigma = None if velocity_sigma is None else np.broadcast_to(np.asarray(velocity_sigma, dtype=float), (3,))
    for name, values in (("position_sigma", sigma), ("velocity_sigma", vsigma)):
        if values is not None and not np.all(values > 0):
            raise InvalidParameter(name, f"must be finite and > 0, got {values.tolist()}")
    n = truth.t_s.size
    position_noise = np.zeros((n, 3))
    velocity_noise = np.zeros((n, 3))
    if streams is not None and n:
        for axis, label in enumerate(("north", "east", "down")):
            position_noise[:, axis] = draws(streams, f"gnss/position_{label}", member, truth.index) * sigma[axis]
            if vsigma is not None:
                velocity_noise[:, axis] = draws(streams, f"gnss/velocity_{label}", member, truth.index) * vsigma[axis]
    p = offset_position(truth.position[:, 0], truth.position[:, 1], truth.position[:, 2], position_noise)
    record = GnssRecord(truth.t_s, p[:, 0], p[:, 1], p[:, 2], np.tile(sigma, (n, 1)),
                        None if vsigma is None else truth.velocity_ned_m_s + velocity_noise,
                        None if vsigma is None else np.tile(vsigma, (n, 1)), source="simulated")
    return record.without(outages)


def simulate_gnss(trajectory, duration: float, *, imu_rate: float = 100.0, gnss_rate: float = 1.0,
                  position_sigma=DEFAULT_POSITION_SIGMA_M, velocity_sigma=None, lever_arm=(0.0, 0.0, 0.0),
                  latency: float = 0.0, time_offset: float = 0.0, outages=(), streams: RandomStreams | None = None,
                  member: int = 0, earth_rate: float = EARTH_RATE) -> GnssRecord:
    """Simulated GNSS of a trajectory: :func:`gnss_truth` then :func:`gnss_measurements`.

    Parameters
    ----------
    trajectory : Trajectory
        A trajectory of :mod:`schuler.navigate.trajectory`.
    duration, latency, time_offset : float
        s (see :func:`gnss_truth`).
    imu_rate, gnss_rate : float
        Rates of the truth's samples and of the epochs, Hz.
    position_sigma, velocity_sigma, lever_arm : array_like
        m, m/s (None: positions only), m (see :func:`gnss_measurements`, :func:`gnss_truth`).
    outages : sequence of (float, float)
        (start, duration) pairs, s.
    streams : RandomStreams, optional
        None: no noise.
    member : int
        Member number, index.
    earth_rate : float
        Omega, rad/s.

    Returns
    -------
    GnssRecord

    Examples
    --------
    >>> from schuler.navigate.trajectory import Stationary
    >>> record = simulate_gnss(Stationary(latitude=0.5), 10.0, imu_rate=10.0, outages=[(3.0, 2.0)])
    >>> record.t_s.tolist(), record.outages()
    ([1.0, 2.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0], ((3.0, 2.0),))
    """
    truth = gnss_truth(trajectory, duration, imu_rate=imu_rate, gnss_rate=gnss_rate, lever_arm=lever_arm,
                       latency=latency, time_offset=time_offset, earth_rate=earth_rate)
    return gnss_measurements(truth, position_sigma=position_sigma, velocity_sigma=velocity_sigma, streams=streams,
                             member=member, outages=outages)
