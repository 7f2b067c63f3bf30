"""One entry point for IMU files, whatever their format: open, read, write.

The suffix decides the format: ``.imu`` is PSINS text
(:func:`~schuler.imu.readers.open_psins`), ``.parquet`` the native format
(:mod:`~schuler.imu.native`), anything else CSV
(:func:`~schuler.imu.readers.open_csv`, whose mapping options apply).
"""

from __future__ import annotations

from pathlib import Path

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
from schuler.imu.record import ImuRecord


def open_record(path, **options) -> RecordSource:
    """Open an IMU file by its suffix; keyword options go to :func:`~schuler.imu.readers.open_csv` (CSV only)."""
    path = Path(path)
    if not path.is_file():
        raise ImuFileError(path, "no such file")
    suffix = path.suffix.lower()
    if suffix in (".imu", ".parquet") and options:
        raise InvalidParameter(sorted(options)[0], f"applies to CSV files only, not {suffix}")
    if suffix == ".imu":
        return open_psins(path)
    if suffix == ".parquet":
        return open_parquet(path)
    return open_csv(path, **options)


def read_record(path, max_memory_bytes: int = DEFAULT_MAX_MEMORY_BYTES, **options) -> ImuRecord:
    """Read an IMU file into memory (see :func:`open_record`); refuses files over ``max_memory_bytes``."""
    return open_record(path, **options).read(max_memory_bytes)


def write_record(record: ImuRecord, path) -> Path:
    """Write a record: ``.parquet`` native, ``.csv`` the project's CSV (rates, SI)."""
    suffix = Path(path).suffix.lower()
    if suffix == ".parquet":
        return write_parquet(record, path)
    if suffix == ".csv":
        return write_csv(record, path)
    raise InvalidParameter("output", f"{Path(path).name}: write .parquet (native) or .csv")
