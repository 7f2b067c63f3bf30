"""Realistic observation records: sampling, window, read-out noise, quantisation, CSV files.

A record holds sample times ``t_s`` (s, since the rotor's release) and the observed
coordinate ``alpha_rad`` (rad): alpha - alpha0 for the source's relative reading
(eq. (10)), or alpha + c for absolute readings with an unknown offset c. Simulated
records are sampled on the core's time grid (:func:`~schuler.core.geometry.time_grid`).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from schuler.exceptions import InvalidParameter

COLUMNS = ("t_s", "alpha_rad")


def observe(angle, alpha0, noise=0.0, quantisation=0.0, reading="relative", offset=0.0, rng=None):
    """What the read-out gives for a true azimuth history, rad.

    Parameters
    ----------
    angle : ndarray (..., n)
        True azimuth alpha(t_k), rad (members along leading axes).
    alpha0 : float or ndarray
        True initial angle, rad (subtracted for the relative reading).
    noise : float
        Standard deviation of white Gaussian read-out noise, rad (>= 0).
    quantisation : float
        Read-out resolution, rad (0: none); readings are rounded to whole steps.
    reading : {"relative", "absolute"}
    offset : float
        Constant offset c of absolute readings, rad.
    rng : numpy.random.Generator, optional
        Needed when ``noise`` > 0.

    Examples
    --------
    >>> observe(np.array([0.02, 0.021]), 0.02, quantisation=1e-4)
    array([0. , 0.001])
    """
    if not (math.isfinite(noise) and noise >= 0.0):
        raise InvalidParameter("noise", f"{noise:g} rad: must be >= 0")
    if not (math.isfinite(quantisation) and quantisation >= 0.0):
        raise InvalidParameter("quantisation", f"{quantisation:g} rad: must be >= 0")
    angle = np.asarray(angle, dtype=float)
    base = np.asarray(alpha0, dtype=float)[..., None] if np.ndim(alpha0) else alpha0
    observed = angle - base if reading == "relative" else angle + offset
    if noise > 0.0:
        observed = observed + noise * rng.standard_normal(observed.shape)
    if quantisation > 0.0:
        observed = quantisation * np.round(observed / quantisation)
    return observed


def write_record(path, time, observed) -> Path:
    """Write a record as CSV with columns ``t_s``, ``alpha_rad`` (atomically).

    Parameters
    ----------
    path : str or Path
        The CSV file.
    time : ndarray
        Sample times, s.
    observed : ndarray
        Observed coordinate, rad.
    """
    import pandas as pd

    from schuler.io import write_dataframe_csv

    frame = pd.DataFrame({COLUMNS[0]: np.asarray(time, dtype=float), COLUMNS[1]: np.asarray(observed, dtype=float)})
    return write_dataframe_csv(frame, path)


def read_record(path):
    """Read and validate a CSV record; returns (time s, observed rad) arrays.

    The file must be UTF-8 text; a byte-order mark (spreadsheets' "CSV UTF-8") is
    accepted.

    Parameters
    ----------
    path : str or Path
        The CSV file (columns ``t_s``, ``alpha_rad``).

    Raises
    ------
    InvalidParameter
        Named after the file and line: a missing file, text that is not UTF-8 (or
        not text at all), missing columns, an empty or non-numeric or non-finite
        value, a negative time, a time not after the previous one, or no samples.
    """
    path = Path(path)
    if not path.is_file():
        raise InvalidParameter(str(path), "no such file")
    with path.open("rb") as handle:
        head = handle.read(4096)
    if b"\x00" in head:  # UTF-16 text (one NUL per ASCII character) or a binary file
        raise InvalidParameter(str(path), "not UTF-8 text (binary, or UTF-16); save the record as CSV (UTF-8)")
    try:
        return _read_rows(path)
    except UnicodeDecodeError:
        raise InvalidParameter(str(path), "not UTF-8 text; save the record as CSV (UTF-8)") from None
    except csv.Error as error:  # NUL bytes, an endless field: a binary file
        raise InvalidParameter(str(path), f"not a CSV text file ({error})") from None


def _read_rows(path: Path):
    times: list[float] = []
    angles: list[float] = []
    with path.open(newline="", encoding="utf-8-sig") as handle:
        reader = csv.reader(handle)
        header = next(reader, None)
        if header is None:
            raise InvalidParameter(str(path), "empty file (expected columns t_s, alpha_rad)")
        header = [name.strip() for name in header]
        missing = [name for name in COLUMNS if name not in header]
        if missing:
            raise InvalidParameter(f"{path} line 1", f"missing column(s) {', '.join(missing)}; found {header}")
        it, ia = header.index(COLUMNS[0]), header.index(COLUMNS[1])
        for line, row in enumerate(reader, start=2):
            if not row or all(not cell.strip() for cell in row):
                continue
            values = []
            for column, index in ((COLUMNS[0], it), (COLUMNS[1], ia)):
                text = row[index].strip() if index < len(row) else ""
                if not text:
                    raise InvalidParameter(f"{path} line {line}", f"missing {column}")
                try:
                    value = float(text)
                except ValueError:
                    raise InvalidParameter(f"{path} line {line}", f"{column} {text!r} is not a number") from None
                if not math.isfinite(value):
                    raise InvalidParameter(f"{path} line {line}", f"{column} is {text} (not a finite number)")
                values.append(value)
            if values[0] < 0.0:
                raise InvalidParameter(f"{path} line {line}", f"t_s {values[0]:g} is before the release (t < 0)")
            if times and values[0] <= times[-1]:
                raise InvalidParameter(
                    f"{path} line {line}",
                    f"t_s {values[0]:g} is not after the previous time {times[-1]:g} (times must increase)",
                )
            times.append(values[0])
            angles.append(values[1])
    if not times:
        raise InvalidParameter(str(path), "no samples")
    return np.array(times), np.array(angles)
