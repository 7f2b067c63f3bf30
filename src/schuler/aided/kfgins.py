"""KF-GINS's data: its text formats read and written in SI, and its YAML configuration read as it is.

Formats (spec 07; whitespace- or comma-separated text, ``#`` comment lines and blank lines skipped):

* IMU (:func:`read_imu`, :func:`write_imu`): seconds of week; dtheta x, y, z (rad); dv x, y, z (m/s); body axes
  front-right-down; each row the increment over the interval ending at its stamp. KF-GINS uses the first seven
  columns of ``imudatalen``; so does :func:`read_imu`.
* GNSS (:func:`read_gnss`, :func:`write_gnss`): seconds of week; latitude, longitude (deg); height (m); 1-sigma
  north, east, down (m) -- 7 columns; or 13: the same position, then v_N, v_E, v_D (m/s), the three position
  1-sigma (m) and the three velocity 1-sigma (m/s).
* Navigation, reference or result (:func:`read_navigation`, :func:`write_navigation`): GPS week; seconds of week;
  latitude, longitude (deg); height (m); v_N, v_E, v_D (m/s); roll, pitch, yaw (deg). Written with no header.

Records are SI with the times as in the file. Written precision (the round trip's): times 1e-9 s, latitude and
longitude 1e-12 deg (1e-7 m), heights, velocities and Euler angles 1e-9 (m, m/s, deg); IMU increments and all
1-sigma with 17 significant digits (exact). Reading uses pandas' C parser (a 300,000-line IMU file in about
0.5 s); only a file it refuses is read again line by line, to name the first bad line.

Bad input is one :class:`~schuler.exceptions.InvalidParameter` naming the file's option and line: a wrong
column count, text that is not a number (quoted, at most 80 characters), a value that is not finite, times
that repeat or go back, NaN, zero or negative 1-sigma, an IMU rate that disagrees with the stamps (by more
than :data:`RATE_TOLERANCE`), and specific force where increments are expected or the reverse
(:func:`check_specific_force`).

The YAML configuration is read by :mod:`schuler.aided.kfgins_configuration`.

Examples
--------
>>> import tempfile, pathlib
>>> path = pathlib.Path(tempfile.mkdtemp()) / "gnss.txt"
>>> _ = path.write_text("456300.0 30.5 114.5 20.0 0.01 0.01 0.02\\n456301.0 30.5 114.5 20.0 0.01 0.01 nan\\n")
>>> read_gnss(path)
Traceback (most recent call last):
...
schuler.exceptions.InvalidParameter: gnss_file: gnss.txt line 2: nan is not a finite number
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from schuler.aided.gnss import GnssRecord, validate_epochs
from schuler.core.earth import STANDARD_GRAVITY
from schuler.exceptions import InvalidParameter, renamed_keywords
from schuler.imu.record import ImuRecord

RATE_TOLERANCE = 0.01
"""Largest relative difference between the stated IMU rate's interval and the stamps' median interval."""

MAGNITUDE_FACTOR = 3.0
"""The median |specific force| must lie within this factor of g (of g dt for increments)."""

SECONDS_PER_WEEK = 604_800.0
"""Seconds in a GPS week: KF-GINS's largest end time."""

_EXCERPT = 80


def _excerpt(text: str) -> str:
    text = text.strip()
    return repr(text if len(text) <= _EXCERPT else text[:_EXCERPT - 3] + "...")


def _data_lines(raw: bytes):
    """(line number, text) of the data lines, comments from ``#`` removed: the lines the fast reader reads."""
    for number, line in enumerate(raw.decode("utf-8", errors="replace").splitlines(), start=1):
        text = line.split("#", 1)[0].strip()
        if text:
            yield number, text


def _diagnose(raw: bytes, path: Path, name: str, columns: tuple[int, ...]) -> InvalidParameter:
    """The one-line error of the first bad line of a file the fast reader refused."""
    expected = " or ".join(str(c) for c in columns)
    first: tuple[int, int] | None = None
    for number, text in _data_lines(raw):
        fields = text.replace(",", " ").split()
        for token in fields:
            try:
                value = float(token)
            except ValueError:
                return InvalidParameter(name, f"{path.name} line {number}: not a number: {_excerpt(token)} "
                                              f"in {_excerpt(text)}")
            if not math.isfinite(value):
                return InvalidParameter(name, f"{path.name} line {number}: {token} is not a finite number")
        if len(fields) not in columns:
            return InvalidParameter(name, f"{path.name} line {number}: {len(fields)} columns, expected {expected}")
        if first is None:
            first = (number, len(fields))
        elif len(fields) != first[1]:
            return InvalidParameter(name, f"{path.name} line {number}: {len(fields)} columns, line {first[0]} has "
                                          f"{first[1]} (every line needs the same)")
    return InvalidParameter(name, f"{path.name}: no data lines" if not any(True for _ in _data_lines(raw))
                            else f"{path.name}: cannot be read as {expected} numeric columns")


def _read_table(path, name: str, columns: tuple[int, ...]) -> tuple[np.ndarray, bytes]:
    """The numbers of a KF-GINS text file, shape (n, c) with c in ``columns``, all finite; and its bytes."""
    import pandas as pd

    path = Path(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise InvalidParameter(name, f"{path}: no such file") from None
    except OSError as error:
        raise InvalidParameter(name, f"{path}: cannot be read ({error.strerror})") from None
    text = raw.replace(b",", b" ") if b"," in raw else raw
    values = None
    try:
        values = pd.read_csv(io.BytesIO(text), sep=r"\s+", header=None, comment="#", dtype=np.float64,
                             engine="c").to_numpy()
    except (ValueError, pd.errors.ParserError, pd.errors.EmptyDataError):
        pass
    if values is None or values.ndim != 2 or values.shape[1] not in columns or not np.all(np.isfinite(values)):
        raise _diagnose(raw, path, name, columns)
    return values, raw


def _line_of(raw: bytes, row: int) -> int:
    """The line number of data row ``row`` (from 0) of a file."""
    for index, (number, _) in enumerate(_data_lines(raw)):
        if index == row:
            return number
    return -1


def _check_times(t: np.ndarray, raw: bytes, path: Path, name: str) -> None:
    steps = np.diff(t)
    if np.any(steps <= 0):
        row = int(np.flatnonzero(steps <= 0)[0]) + 1
        kind = "repeats the one before" if steps[row - 1] == 0 else "is earlier than the one before"
        raise InvalidParameter(name, f"{path.name} line {_line_of(raw, row)}: time {t[row]:.6f} s {kind} "
                                     "(times must increase strictly)")


@renamed_keywords(interval_s="interval")
def check_specific_force(values, interval: float, kind: str = "increment", name: str = "imu_file") -> None:
    """Refuse specific force given as increments where rates are expected, or the reverse (a magnitude check).

    The median of |value| over the samples must lie within a factor :data:`MAGNITUDE_FACTOR` of what ``kind``
    expects: g dt (m/s) for velocity increments over intervals dt, g (m/s^2) for specific force. A vehicle's
    specific force stays near g on the median; the wrong kind is off by 1/dt (200 times at 200 Hz).

    Parameters
    ----------
    values : array_like, shape (n, 3)
        Accelerometer columns: velocity increments, m/s, or specific force, m/s^2 (see ``kind``).
    interval : float
        Sample interval dt, s.
    kind : {"increment", "rate"}
        What the values should be.
    name : str
        The input's name in the message.

    Raises
    ------
    InvalidParameter
        Saying what was expected and what the median is.
    """
    expected = STANDARD_GRAVITY * (interval if kind == "increment" else 1.0)
    median = float(np.median(np.linalg.norm(np.asarray(values, dtype=float), axis=1)))
    ratio = median / expected
    if 1.0 / MAGNITUDE_FACTOR <= ratio <= MAGNITUDE_FACTOR:
        return
    if kind == "increment":
        what = f"velocity increments over {interval:g}-s intervals: median |dv| should be near g dt = " \
               f"{expected:.4g} m/s, it is {median:.4g} m/s"
        hint = " (specific force in m/s^2?)" if ratio > MAGNITUDE_FACTOR else ""
    else:
        what = f"specific force: median |f| should be near g = {expected:.4g} m/s^2, it is {median:.4g} m/s^2"
        hint = f" (velocity increments over {interval:g}-s intervals?)" if ratio < 1 / MAGNITUDE_FACTOR else ""
    raise InvalidParameter(name, f"expected {what}, {ratio:.3g} times that{hint}")


def read_imu(path, *, imu_rate: float | None = None, columns: int = 7, name: str = "imu_file") -> ImuRecord:
    """Read a KF-GINS IMU file (increments, body FRD) into an :class:`~schuler.imu.record.ImuRecord`.

    Parameters
    ----------
    path : str or Path
        The text file.
    imu_rate : float, optional
        The stated rate (KF-GINS's ``imudatarate``), Hz; checked against the stamps. Default: from the stamps.
    columns : int
        Columns per line (``imudatalen``, >= 7), number of; the first seven are read.
    name : str
        The option or key naming the file in messages.

    Returns
    -------
    ImuRecord
        ``kind="increment"``; ``time_s`` in seconds of week; ``sample_interval_s`` 1 / imu_rate.
    """
    if isinstance(columns, bool) or not isinstance(columns, int) or columns < 7:
        raise InvalidParameter("imudatalen", f"must be a whole number >= 7, got {columns!r}")
    values, raw = _read_table(path, name, (columns,))
    path = Path(path)
    if values.shape[0] < 2:
        raise InvalidParameter(name, f"{path.name}: {values.shape[0]} samples; at least 2 are needed")
    t = values[:, 0]
    _check_times(t, raw, path, name)
    median = float(np.median(np.diff(t)))
    if imu_rate is None:
        interval = median
    else:
        if not (math.isfinite(imu_rate) and imu_rate > 0):
            raise InvalidParameter("imudatarate", f"must be finite and > 0 Hz, got {imu_rate!r}")
        interval = 1.0 / imu_rate
        if abs(median - interval) > RATE_TOLERANCE * interval:
            raise InvalidParameter("imudatarate", f"{imu_rate:g} Hz disagrees with {path.name}'s stamps: their "
                                                  f"median interval is {median:.6g} s ({1.0 / median:.6g} Hz)")
    check_specific_force(values[:, 4:7], interval, "increment", name)
    return ImuRecord(time_s=t, gyro=values[:, 1:4], accel=values[:, 4:7], kind="increment",
                     sample_interval_s=interval, source=str(path))


def read_gnss(path, *, name: str = "gnss_file") -> GnssRecord:
    """Read a KF-GINS GNSS file of 7 or 13 columns.

    Parameters
    ----------
    path : str or Path
        The text file.
    name : str
        The option or key naming the file in messages.

    Returns
    -------
    GnssRecord
        Times in seconds of week, positions in rad and m, velocities (13 columns) in m/s.
    """
    values, raw = _read_table(path, name, (7, 13))
    path = Path(path)
    t = values[:, 0]
    position_sigma = values[:, 4:7] if values.shape[1] == 7 else values[:, 7:10]
    velocity = values[:, 4:7] if values.shape[1] == 13 else None
    velocity_sigma = values[:, 10:13] if values.shape[1] == 13 else None
    validate_epochs(t, position_sigma, velocity_sigma, name=name,
                    locate=lambda row: f"{path.name} line {_line_of(raw, row)}")
    if np.any(np.abs(values[:, 1]) > 90.0):
        row = int(np.flatnonzero(np.abs(values[:, 1]) > 90.0)[0])
        raise InvalidParameter(name, f"{path.name} line {_line_of(raw, row)}: latitude {values[row, 1]:g} deg "
                                     "is beyond +/-90 deg")
    return GnssRecord(t, np.radians(values[:, 1]), np.radians(values[:, 2]), values[:, 3], position_sigma, velocity,
                      velocity_sigma, source=str(path))


def check_overlap(imu: ImuRecord, gnss: GnssRecord, name: str = "gnss_file") -> None:
    """Refuse GNSS epochs that all fall outside the IMU's span.

    Parameters
    ----------
    imu : ImuRecord
        The IMU samples (stamps in s).
    gnss : GnssRecord
        The GNSS epochs (stamps in s, the same time base).
    name : str
        The option naming the GNSS data in messages.

    Raises
    ------
    InvalidParameter
        Stating both spans.
    """
    first, last = imu.time_s[0] - imu.sample_interval_s, imu.time_s[-1]
    if not np.any((gnss.t_s >= first) & (gnss.t_s <= last)):
        raise InvalidParameter(name, f"the GNSS span [{gnss.t_s[0]:.3f}, {gnss.t_s[-1]:.3f}] s does not overlap "
                                     f"the IMU's [{first:.3f}, {last:.3f}] s")


@dataclass(frozen=True, eq=False)
class NavigationRecord:
    """Navigation states in KF-GINS's reference/result layout, SI.

    Parameters
    ----------
    week : ndarray of int, shape (n,)
        GPS week, number of (KF-GINS writes 0 in its result).
    t_s : ndarray, shape (n,)
        Seconds of week, s.
    latitude_rad, longitude_rad : ndarray, shape (n,)
        rad.
    height_m : ndarray, shape (n,)
        m.
    velocity_ned_m_s : ndarray, shape (n, 3)
        v_N, v_E, v_D, m/s.
    attitude_rad : ndarray, shape (n, 3)
        Roll, pitch, yaw (heading), rad.
    """

    week: np.ndarray
    t_s: np.ndarray
    latitude_rad: np.ndarray
    longitude_rad: np.ndarray
    height_m: np.ndarray
    velocity_ned_m_s: np.ndarray
    attitude_rad: np.ndarray

    def __post_init__(self):
        n = np.asarray(self.t_s).size
        for key, shape in (("week", (n,)), ("t_s", (n,)), ("latitude_rad", (n,)), ("longitude_rad", (n,)),
                           ("height_m", (n,)), ("velocity_ned_m_s", (n, 3)), ("attitude_rad", (n, 3))):
            array = np.asarray(getattr(self, key), dtype=np.int64 if key == "week" else float)
            if array.shape != shape or not np.all(np.isfinite(array)):
                raise InvalidParameter(key, f"must be finite numbers of shape {shape}, got shape {array.shape}")
            object.__setattr__(self, key, array)


def read_navigation(path, *, name: str = "reference") -> NavigationRecord:
    """Read a KF-GINS navigation file (a reference, or KF-GINS's result): 11 columns.

    Parameters
    ----------
    path : str or Path
        The text file.
    name : str
        The option naming the file in messages.

    Returns
    -------
    NavigationRecord
    """
    values, raw = _read_table(path, name, (11,))
    if np.any(values[:, 0] != np.round(values[:, 0])):
        row = int(np.flatnonzero(values[:, 0] != np.round(values[:, 0]))[0])
        raise InvalidParameter(name, f"{Path(path).name} line {_line_of(raw, row)}: week {values[row, 0]!r} is not "
                                     "a whole number")
    _check_times(values[:, 0] * SECONDS_PER_WEEK + values[:, 1], raw, Path(path), name)
    return NavigationRecord(values[:, 0].astype(np.int64), values[:, 1], np.radians(values[:, 2]),
                            np.radians(values[:, 3]), values[:, 4], values[:, 5:8], np.radians(values[:, 8:11]))


def _write_table(path, columns: list[np.ndarray], formats: list[str], chunk: int = 65_536) -> Path:
    """Rows of ``columns`` in ``formats``, space-separated, no header; formatted a block at a time."""
    path = Path(path)
    table = np.column_stack(columns)
    row = " ".join(formats) + "\n"
    with path.open("w", encoding="utf-8", newline="\n") as handle:
        for start in range(0, table.shape[0], chunk):
            block = table[start:start + chunk]
            handle.write((row * block.shape[0]) % tuple(block.ravel().tolist()))
    return path


_EXACT = "%.17g"


def write_imu(path, record: ImuRecord) -> Path:
    """Write an IMU record in KF-GINS's 7-column format (increments; a rate record is converted).

    Parameters
    ----------
    path : str or Path
        The file to write.
    record : ImuRecord
        Samples in body FRD; its ``time_s`` is written as the seconds of week.

    Returns
    -------
    Path
    """
    return _write_table(path, [record.time_s, record.gyro_increment_rad, record.accel_increment_m_s],
                        ["%.9f"] + [_EXACT] * 6)


def write_gnss(path, record: GnssRecord) -> Path:
    """Write a GNSS record: 7 columns, or 13 when it carries velocities.

    Parameters
    ----------
    path : str or Path
        The file to write.
    record : GnssRecord
        Epochs; ``t_s`` is written as the seconds of week.

    Returns
    -------
    Path
    """
    position = [record.t_s, np.degrees(record.latitude_rad), np.degrees(record.longitude_rad), record.height_m]
    formats = ["%.9f", "%.12f", "%.12f", "%.9f"]
    if record.velocity_ned_m_s is None:
        return _write_table(path, position + [record.position_sigma_m], formats + [_EXACT] * 3)
    return _write_table(path, position + [record.velocity_ned_m_s, record.position_sigma_m,
                                          record.velocity_sigma_m_s], formats + ["%.9f"] * 3 + [_EXACT] * 6)


def write_navigation(path, record: NavigationRecord) -> Path:
    """Write navigation states as KF-GINS writes its result: 11 columns, no header.

    Parameters
    ----------
    path : str or Path
        The file to write.
    record : NavigationRecord
        The states, SI.

    Returns
    -------
    Path
    """
    return _write_table(path, [record.week, record.t_s, np.degrees(record.latitude_rad),
                               np.degrees(record.longitude_rad), record.height_m, record.velocity_ned_m_s,
                               np.degrees(record.attitude_rad)],
                        ["%d", "%.9f", "%.12f", "%.12f"] + ["%.9f"] * 7)

