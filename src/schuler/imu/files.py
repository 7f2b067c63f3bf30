"""One entry point for IMU files, whatever their format: open, read, write.

The suffix decides the format: ``.imu`` is PSINS text
(:func:`~schuler.imu.readers.open_psins`), ``.parquet`` the native format
(:mod:`~schuler.imu.native`), anything else CSV
(:func:`~schuler.imu.readers.open_csv`, whose mapping options apply).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from schuler.exceptions import InvalidParameter
from schuler.imu.native import open_parquet, write_parquet
from schuler.imu.readers import (
    DEFAULT_MAX_MEMORY_BYTES,
    ImuFileError,
    RecordSource,
    open_csv,
    open_psins,
    write_csv,
)
from schuler.imu.record import ImuInfo, ImuRecord, info_from_means


def open_record(path, **options) -> RecordSource:
    """Open an IMU file by its suffix; keyword options go to :func:`~schuler.imu.readers.open_csv` (CSV only).

    Parameters
    ----------
    path : str or Path
        The file: ``.imu`` (PSINS), ``.parquet`` (native) or anything else (CSV).
    **options
        Keywords of :func:`~schuler.imu.readers.open_csv` (column mapping, units, kind, axes, site in rad and m);
        in ``units``, ``gyro`` and ``accel`` stand for their three axes (``{"gyro": "deg/s"}``); refused for
        ``.imu`` and ``.parquet``.

    Returns
    -------
    RecordSource
        The opened file: metadata and an iterator over its chunks, nothing read yet beyond the header.
    """
    path = Path(path)
    if not path.exists():
        raise ImuFileError(path, "no such file")
    if path.is_dir():
        raise ImuFileError(path, "is a folder, not an IMU file")
    if not path.is_file():
        raise ImuFileError(path, "not a regular file (a device, pipe or socket); give an IMU file")
    suffix = path.suffix.lower()
    if suffix in (".imu", ".parquet") and options:
        raise InvalidParameter(sorted(options)[0], f"applies to CSV files only, not {suffix}")
    if suffix == ".imu":
        return open_psins(path)
    if suffix == ".parquet":
        return open_parquet(path)
    if options.get("units"):
        # "gyro" and "accel" stand for their three axes
        options["units"] = {name: unit for key, unit in options["units"].items()
                            for name in ([f"{key}_{axis}" for axis in "xyz"] if key in ("gyro", "accel") else [key])}
    return open_csv(path, **options)


def read_record(path, max_memory_bytes: int = DEFAULT_MAX_MEMORY_BYTES, **options) -> ImuRecord:
    """Read an IMU file into memory (see :func:`open_record`); refuses files over ``max_memory_bytes``.

    Parameters
    ----------
    path : str or Path
        The file (any format of :func:`open_record`).
    max_memory_bytes : int
        Largest memory the record may need while being built, bytes (default 2 GiB).
    **options
        Keywords of :func:`~schuler.imu.readers.open_csv` (CSV only).

    Returns
    -------
    ImuRecord
        The whole record, rates in SI, body axes x forward, y right, z down.
    """
    return open_record(path, **options).read(max_memory_bytes)


def file_info(path, **options) -> ImuInfo:
    """What an IMU file holds (:class:`~schuler.imu.record.ImuInfo`), streamed: memory bounded by a chunk.

    Every chunk is read and checked (time steps, finite values), so a damaged
    line is reported wherever it is; ``options`` as for :func:`open_record`.

    Parameters
    ----------
    path : str or Path
        The file (any format of :func:`open_record`).
    **options
        Keywords of :func:`~schuler.imu.readers.open_csv` (CSV only).

    Returns
    -------
    ImuInfo
        Samples, kind, sample interval (s), mean gyro rate (rad/s) and specific force (m/s^2), body axes, and the
        site the file states.
    """
    source = open_record(path, **options)
    samples, gyro, accel = 0, np.zeros(3), np.zeros(3)
    for _, g, a in source.chunks():
        samples += g.shape[0]
        gyro += g.sum(axis=0)
        accel += a.sum(axis=0)
    if samples < 2:
        raise ImuFileError(source.path, f"a record needs at least 2 samples, the file has {samples}")
    scale = samples * (source.interval_s() if source.kind == "increment" else 1.0)
    keys = ("latitude_rad", "longitude_rad", "height_m", "initial_attitude_rad", "gravity_m_s2")
    return info_from_means(source.path.name, samples, source.kind, source.interval_s(), gyro / scale,
                           accel / scale, **{k: source.metadata.get(k) for k in keys})


def write_record(record: ImuRecord, path) -> Path:
    """Write a record: ``.parquet`` native, ``.csv`` the project's CSV (rates, SI).

    Parameters
    ----------
    record : ImuRecord
        The samples to write.
    path : str or Path
        Output file; its suffix (``.parquet`` or ``.csv``) chooses the format.

    Returns
    -------
    Path
        The file written.
    """
    suffix = Path(path).suffix.lower()
    if suffix == ".parquet":
        return write_parquet(record, path)
    if suffix == ".csv":
        return write_csv(record, path)
    raise InvalidParameter("output", f"{Path(path).name}: write .parquet (native) or .csv")
