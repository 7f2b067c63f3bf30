"""Replaying a recorded IMU file through the INS: ``--record FILE``.

A recording (the project's CSV, a PSINS ``.imu`` file, or native Parquet, read
by :func:`schuler.imu.files.read_record`) is taken as a **static vehicle**: its
angle and velocity increments (body x forward, y right, z down) are integrated
by the strapdown computer instead of the ideal IMU of a synthetic truth, and the
errors (computed - true) are against a **stationary truth** at the recording's
site and initial attitude. Whatever the record holds besides the Earth rate and
gravity at that site and attitude (biases, noise, disturbances, a wrong stated
attitude) shows up as navigation error.

The site and attitude come from the record's metadata when it states them; the
options ``latitude``, ``longitude``, ``height`` and ``heading`` win when given.
Without a stated latitude (a CSV file carries none) ``latitude`` is needed;
without a stated attitude, ``heading`` is needed and the record is taken as
level (roll = pitch = 0). Longitude and height default to 0 as for the synthetic
trajectories. The duration is the record's, cut to whole output steps, or a
shorter ``duration``; the IMU rate is the record's.

``imu`` is the sensor error model only (a grade or a spec file): a recording
given there is refused with a message naming ``record``.

Examples
--------
>>> is_recording("tactical"), is_recording("spec.toml")
(False, False)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from schuler.exceptions import InvalidParameter, SchulerError
from schuler.imu.files import read_record
from schuler.imu.record import ImuRecord
from schuler.imu.spec import GRADES
from schuler.memory import budget
from schuler.navigate.mechanization import output_interval
from schuler.navigate.trajectory import Stationary

RECORD_SUFFIXES = (".csv", ".imu", ".parquet")
"""Suffixes of recorded IMU files (:func:`schuler.imu.files.open_record` reads any other as CSV too)."""

_RELATIVE = 1e-9
"""Relative tolerance when comparing a rate or a duration with the record's."""


@dataclass(frozen=True)
class Replay:
    """A recording ready to navigate: where it stood, how long, at what rate, and its increments.

    Parameters
    ----------
    trajectory : Stationary
        The stationary truth (site and initial attitude).
    duration : float
        s, a whole number of output steps within the record.
    imu_rate : float
        The record's sample rate, Hz.
    increments : ndarray, shape (n, 6)
        (dtheta, dv) of the record's first n = duration x rate intervals, rad and m/s, body axes.
    source : str
        The file's name.
    """

    trajectory: Stationary
    duration: float
    imu_rate: float
    increments: np.ndarray
    source: str


def is_recording(text: str) -> bool:
    """Whether ``text`` names a recorded IMU file (an existing file that is neither a grade nor SPEC.toml).

    Parameters
    ----------
    text : str
        A grade, a spec file or a recording's path (no unit).
    """
    path = Path(text)
    return text not in GRADES and path.suffix.lower() != ".toml" and path.is_file()


def read_recording(text: str) -> ImuRecord:
    """The record of ``--record FILE``, in memory within the run's budget; errors name ``record``.

    Parameters
    ----------
    text : str
        Path of the recorded IMU file (CSV, PSINS ``.imu`` or Parquet).

    Returns
    -------
    ImuRecord
        The record, SI.
    """
    try:
        return read_record(text, max_memory_bytes=budget() // 4)
    except SchulerError as error:
        raise InvalidParameter("record", f"{Path(text).name}: {error}") from None


def increments(record: ImuRecord) -> np.ndarray:
    """The record's (dtheta, dv) per interval, shape (n, 6), rad and m/s, body x forward, y right, z down.

    Parameters
    ----------
    record : ImuRecord
        A recorded IMU file in memory (SI increments).
    """
    return np.concatenate([record.gyro_increment_rad, record.accel_increment_m_s], axis=1)


def _site(record: ImuRecord, case) -> Stationary:
    name = Path(record.source).name or "the record"
    latitude = case["latitude"] if case["latitude"] is not None else record.latitude_rad
    if latitude is None:
        raise InvalidParameter("record", f"{name} states no latitude: give `latitude` (the site of the recording)")
    attitude = record.initial_attitude_rad
    if attitude is None:
        if case["heading"] is None:
            raise InvalidParameter("record", f"{name} states no initial attitude: give `heading` (the record is then "
                                          "taken as level)")
        attitude = (0.0, 0.0, case["heading"])
    roll, pitch, heading = attitude
    if case["heading"] is not None:
        heading = case["heading"]
    longitude = case["longitude"] if case["longitude"] is not None else record.longitude_rad
    height = case["height"] if case["height"] is not None else record.height_m
    return Stationary(latitude=latitude, longitude=longitude or 0.0, height=height or 0.0, roll=roll, pitch=pitch,
                      heading=heading)


def replay(text: str, case) -> Replay:
    """The recording ``--record text`` with the options of ``case`` applied and checked.

    Parameters
    ----------
    text : str
        Path of the recorded IMU file.
    case : Case
        A validated case of the ``navigate`` parameters (SI values): its
        ``latitude``, ``longitude``, ``height`` and ``heading`` override the record's,
        its ``duration`` shortens it, its ``output_step`` cuts it to whole steps.

    Returns
    -------
    Replay
        The stationary truth, the duration (s), the record's rate (Hz) and its increments.

    Raises
    ------
    InvalidParameter
        A trajectory other than stationary or a speed (``trajectory``, ``speed``); a rate other than
        the record's (``imu_rate``); a duration longer than the record (``duration``); a record
        without the site or attitude and no option giving it (``record``).
    """
    if case["trajectory"].strip() != "stationary":
        raise InvalidParameter("trajectory", "a recording is replayed as a static vehicle: use the stationary "
                                             "trajectory with `record` FILE")
    if case["speed"]:
        raise InvalidParameter("speed", "a recording is replayed as a static vehicle (at rest)")
    record = read_recording(text)
    rate = 1.0 / record.sample_interval_s
    if case["imu_rate"] is not None and not math.isclose(case["imu_rate"], rate, rel_tol=_RELATIVE):
        raise InvalidParameter("imu_rate", f"{case['imu_rate']:g} Hz differs from the recording's {rate:g} Hz; "
                                           "leave `imu_rate` out")
    every = output_interval(case["output_step"], rate)
    step = every / rate
    if case["duration"] is None:
        duration = (record.samples // every) * step
        if duration <= 0:
            raise InvalidParameter("output_step", f"{case['output_step']:g} s is longer than the recording "
                                                  f"({record.duration_s:g} s)")
    elif case["duration"] > record.duration_s * (1 + _RELATIVE):
        raise InvalidParameter("duration", f"{case['duration']:g} s is longer than the recording "
                                           f"({record.duration_s:g} s); give at most that")
    else:
        duration = case["duration"]
    samples = round(duration * rate)
    return Replay(_site(record, case), float(duration), rate, increments(record)[:samples],
                  Path(record.source).name or Path(text).name)
