"""What the alignment methods read: a batch of static records as increments, and what each method returns.

:class:`StaticBatch` holds m records of n samples each (``(m, n, 3)`` angle
increments, rad, and velocity increments, m/s, body x forward / y right / z
down) taken at one site; one :class:`~schuler.imu.record.ImuRecord` is a batch of
one. :class:`MethodEstimate` is one method's answer for every record of a
batch: final roll, pitch, heading (rad, aerospace, NED), the method's own
1-sigma where it has one, and the histories on a common time grid.

Examples
--------
>>> import numpy as np
>>> batch = StaticBatch(np.zeros((2, 100, 3)), np.zeros((2, 100, 3)), sample_interval_s=0.01,
...                     latitude_rad=0.6)
>>> batch.members, batch.samples, batch.duration_s
(2, 100, 1.0)
>>> batch.history_indices(0.25)
array([ 25,  50,  75, 100])
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from schuler.core.attitude import wrap_angle
from schuler.core.earth import normal_gravity
from schuler.exceptions import InvalidParameter, renamed_keywords
from schuler.imu.record import ImuRecord
from schuler.results import Result

BYTES_PER_SAMPLE = 6 * 8
"""Bytes of one six-axis sample of one record in a batch (float64)."""


@dataclass
class StaticBatch:
    """m static records at one site, as increments over each sample interval.

    Parameters
    ----------
    gyro_increment : ndarray (m, n, 3)
        Angle increments, rad, body axes.
    accel_increment : ndarray (m, n, 3)
        Velocity increments (specific force integrated over dt), m/s, body axes.
    sample_interval_s : float
        dt, s.
    latitude_rad : float
        Site latitude L, rad.
    gravity_m_s2 : float, optional
        g at the site (default: WGS-84 normal gravity at L).
    """

    gyro_increment: np.ndarray
    accel_increment: np.ndarray
    sample_interval_s: float
    latitude_rad: float
    gravity_m_s2: float | None = None

    def __post_init__(self):
        self.gyro_increment = np.asarray(self.gyro_increment, dtype=float)
        self.accel_increment = np.asarray(self.accel_increment, dtype=float)
        if self.gyro_increment.ndim != 3 or self.gyro_increment.shape[2] != 3:
            raise InvalidParameter("gyro_increment", f"shape {self.gyro_increment.shape} must be (members, samples, 3)")
        if self.accel_increment.shape != self.gyro_increment.shape:
            raise InvalidParameter("accel_increment", f"shape {self.accel_increment.shape} must equal the gyro's "
                                   f"{self.gyro_increment.shape}")
        if self.samples < 2:
            raise InvalidParameter("duration", f"an alignment needs at least 2 samples, got {self.samples}")
        dt = float(self.sample_interval_s)
        if not (math.isfinite(dt) and dt > 0):
            raise InvalidParameter("sample_interval_s", f"must be finite and > 0, got {self.sample_interval_s!r}")
        self.sample_interval_s = dt
        if not (math.isfinite(self.latitude_rad) and abs(self.latitude_rad) <= math.pi / 2):
            raise InvalidParameter("latitude", f"{self.latitude_rad!r} rad must be within [-pi/2, pi/2]")
        if self.gravity_m_s2 is not None and not (math.isfinite(self.gravity_m_s2) and self.gravity_m_s2 > 0):
            raise InvalidParameter("gravity", f"must be finite and > 0 m/s^2, got {self.gravity_m_s2!r}")
        for name in ("gyro_increment", "accel_increment"):
            if not np.all(np.isfinite(getattr(self, name))):
                raise InvalidParameter(name, "holds NaN or infinite samples")

    @classmethod
    @renamed_keywords(latitude_rad="latitude", start_s="start", duration_s="duration")
    def from_record(cls, record: ImuRecord, *, latitude: float | None = None, start: float = 0.0,
                    duration: float | None = None) -> StaticBatch:
        """The window [start, start + duration) of a record as a batch of one.

        Parameters
        ----------
        record : ImuRecord
            The recording at rest (increments, body axes).
        latitude : float, optional
            Site latitude L, rad (default: the record's).
        start : float
            Start of the window, s from the record's first sample.
        duration : float, optional
            Length of the window, s (default: to the record's end).

        Returns
        -------
        StaticBatch
            One member; gravity the record's, if it states one.

        Raises
        ------
        InvalidParameter
            No latitude (neither in the record nor given), or a window outside the record.
        """
        latitude = record.latitude_rad if latitude is None else latitude
        if latitude is None:
            raise InvalidParameter("latitude", f"{record.source or 'the record'} states no site latitude; give one")
        first, stop = window_indices(record.samples, record.sample_interval_s, start, duration)
        return cls(record.gyro_increment_rad[None, first:stop], record.accel_increment_m_s[None, first:stop],
                   record.sample_interval_s, float(latitude), record.gravity_m_s2)

    @property
    def gravity(self) -> float:
        """g at the site, m/s^2 (the one given, or WGS-84 normal gravity at the latitude)."""
        return float(normal_gravity(self.latitude_rad)) if self.gravity_m_s2 is None else float(self.gravity_m_s2)

    @property
    def members(self) -> int:
        return int(self.gyro_increment.shape[0])

    @property
    def samples(self) -> int:
        return int(self.gyro_increment.shape[1])

    @property
    def duration_s(self) -> float:
        return round(self.samples * self.sample_interval_s, 12)

    def head(self, duration_s: float) -> StaticBatch:
        """The first ``duration_s`` seconds (at least 2 samples, at most all), as a batch (views, no copy).

        Parameters
        ----------
        duration_s : float
            Length kept from the start, s (rounded to whole samples).

        Returns
        -------
        StaticBatch
            The same members, site and sample interval.
        """
        samples = max(2, min(self.samples, int(round(duration_s / self.sample_interval_s))))
        return StaticBatch(self.gyro_increment[:, :samples], self.accel_increment[:, :samples],
                           self.sample_interval_s, self.latitude_rad, self.gravity_m_s2)

    def history_indices(self, step_s: float) -> np.ndarray:
        """Sample counts (1-based ends) at which histories are reported: every ``step_s``, and the last sample.

        Parameters
        ----------
        step_s : float
            Step of the histories, s (rounded to whole samples, at least one).

        Returns
        -------
        ndarray of int, shape (K,)
            Number of samples up to each reported time, increasing, ending with :attr:`samples`.
        """
        stride = max(1, int(round(step_s / self.sample_interval_s)))
        ends = np.arange(stride, self.samples + 1, stride)
        if ends.size == 0 or ends[-1] != self.samples:
            ends = np.append(ends, self.samples)
        return ends



@renamed_keywords(start_s="start", duration_s="duration")
def window_indices(samples: int, dt: float, start: float, duration: float | None) -> tuple[int, int]:
    """Sample range [first, stop) of the window [start, start + duration) of a record of ``samples`` samples.

    Parameters
    ----------
    samples : int
        Number of samples in the record.
    dt : float
        Sample interval, s.
    start : float
        Start of the window, s from the record's first sample (rounded to a whole sample).
    duration : float or None
        Length of the window, s (None: to the record's end).

    Returns
    -------
    first, stop : int
        Index of the window's first sample and one past its last.

    Raises
    ------
    InvalidParameter
        A start outside the record, a window past its end or one of fewer than 2 samples.
    """
    total = samples * dt
    if not (math.isfinite(start) and 0 <= start < total):
        raise InvalidParameter("start", f"{start:g} s must be within the record's [0, {total:g}) s")
    first = int(round(start / dt))
    if duration is None:
        return first, samples
    if not (math.isfinite(duration) and duration > 0):
        raise InvalidParameter("duration", f"must be finite and > 0 s, got {duration!r}")
    stop = first + int(round(duration / dt))
    if stop > samples:
        raise InvalidParameter("duration", f"{start:g} s + {duration:g} s runs past the record's end "
                               f"({total:g} s)")
    if stop - first < 2:
        raise InvalidParameter("duration", f"{duration:g} s holds fewer than 2 samples")
    return first, stop


@dataclass
class MethodEstimate(Result):
    """One method's attitude for every record of a batch (arrays of length 1 for a single record).

    Attributes
    ----------
    method : str
        ``coarse``, ``inertial_frame``, ``kalman`` or ``gyrocompass``.
    roll_rad, pitch_rad, heading_rad : ndarray (m,)
        Final attitude, aerospace angles (heading in (-pi, pi]).
    sigma_rad : ndarray (m, 3) or None
        The method's own 1-sigma of roll, pitch, heading (None: the method states none).
    time_s : ndarray (K,)
        Times of the histories, s from the window's start.
    roll_history_rad, pitch_history_rad, heading_history_rad : ndarray (m, K)
        The attitude the method would give if stopped at each time.
    sigma_history_rad : ndarray (m, K, 3) or None
        Its 1-sigma over time, where it has one.
    """

    method: str
    roll_rad: np.ndarray
    pitch_rad: np.ndarray
    heading_rad: np.ndarray
    sigma_rad: np.ndarray | None
    time_s: np.ndarray
    roll_history_rad: np.ndarray
    pitch_history_rad: np.ndarray
    heading_history_rad: np.ndarray
    sigma_history_rad: np.ndarray | None = None

    units: ClassVar[dict[str, str]] = {"time_s": "s"}

    def to_dataframe(self):
        """The histories, one row per record and time: ``record``, ``t_s``, roll, pitch, heading (and 1-sigma), rad."""
        import pandas as pd

        records, n_time = np.shape(self.heading_history_rad)
        frame = pd.DataFrame({"record": np.repeat(np.arange(records), n_time), "t_s": np.tile(self.time_s, records),
                              "roll_rad": np.ravel(self.roll_history_rad),
                              "pitch_rad": np.ravel(self.pitch_history_rad),
                              "heading_rad": np.ravel(self.heading_history_rad)})
        if self.sigma_history_rad is not None:
            sigma = np.reshape(self.sigma_history_rad, (-1, 3))
            for column, name in enumerate(("roll", "pitch", "heading")):
                frame[f"{name}_sigma_rad"] = sigma[:, column]
        return frame

    def render(self):
        """The final attitude of each record in deg and its 1-sigma in arcmin."""
        from rich.table import Table

        table = Table(title=f"{self.method}: final attitude ({np.size(self.time_s)} times, "
                            f"{float(np.max(self.time_s, initial=0.0)):g} s)")
        table.add_column("record", justify="right")
        for name in ("roll (deg)", "pitch (deg)", "heading (deg)", "1-sigma r, p, h (arcmin)"):
            table.add_column(name, justify="right")
        for record in range(np.size(self.heading_rad)):
            angles = [f"{math.degrees(float(np.ravel(a)[record])):.4f}"
                      for a in (self.roll_rad, self.pitch_rad, self.heading_rad)]
            sigma = "-" if self.sigma_rad is None else ", ".join(
                f"{math.degrees(float(v)) * 60:.3g}" for v in np.reshape(self.sigma_rad, (-1, 3))[record])
            table.add_row(str(record), *angles, sigma)
        return table


@renamed_keywords(time_s="time")
def convergence_time(time, history, final, band) -> np.ndarray:
    """The first time after which ``history`` stays within ``band`` of ``final`` (per record), s.

    Parameters
    ----------
    time : ndarray (K,)
        Times of the history, s.
    history : ndarray (m, K)
        Angles, rad (differences are wrapped).
    final : ndarray (m,)
        Final angle of each record, rad.
    band : float or ndarray (m,)
        Half-width, rad.

    Returns
    -------
    ndarray (m,)
        Convergence time of each record, s (the last time when the history never settles).
    """
    outside = np.abs(wrap_angle(np.asarray(history) - np.asarray(final)[:, None])) > np.asarray(band).reshape(-1, 1)
    last = np.where(outside.any(axis=1), outside.shape[1] - 1 - np.argmax(outside[:, ::-1], axis=1), -1)
    return np.where(last + 1 < time.size, time[np.minimum(last + 1, time.size - 1)], time[-1])
