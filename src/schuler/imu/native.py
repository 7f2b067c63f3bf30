"""The native record format: Parquet, one row group per chunk, metadata in the schema.

Columns ``t_s, gyro_x .. gyro_z, accel_x .. accel_z`` (float64), in the units
of ``kind`` (rates rad/s and m/s^2, or increments rad and m/s), body frame x
forward, y right, z down. The schema metadata key ``schuler.imu`` holds JSON:
format version, kind, sample interval, site, initial attitude, gravity, source.
Reading is chunked by row group, so files larger than memory stream; a writer
(:class:`ParquetRecordWriter`) appends chunks, so a simulation never holds the
whole record.

Examples
--------
>>> import tempfile, pathlib
>>> record = ImuRecord(time_s=[0.01, 0.02, 0.03], gyro=np.zeros((3, 3)), accel=np.ones((3, 3)),
...                    kind="rate", sample_interval_s=0.01, latitude_rad=0.5)
>>> path = write_parquet(record, pathlib.Path(tempfile.mkdtemp()) / "r.parquet")
>>> back = open_parquet(path).read()
>>> back.latitude_rad, back.samples, float(back.accel[2, 1])
(0.5, 3, 1.0)
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from schuler.exceptions import InvalidParameter, renamed_keywords
from schuler.imu.readers import ImuFileError, RecordSource
from schuler.imu.record import KINDS, ImuRecord

FORMAT_VERSION = 1
_COLUMNS = ("t_s", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")
_METADATA_KEY = b"schuler.imu"


def _schema(metadata: dict):
    import pyarrow as pa

    return pa.schema([(name, pa.float64()) for name in _COLUMNS],
                     metadata={_METADATA_KEY: json.dumps(metadata).encode()})


class ParquetRecordWriter:
    """Append chunks of samples to a native file; the file appears atomically on :meth:`close`.

    Parameters
    ----------
    path : str or Path
    kind : {"rate", "increment"}
    sample_interval_s : float
    **metadata
        ``latitude_rad``, ``longitude_rad``, ``height_m``, ``initial_attitude_rad``,
        ``gravity_m_s2``, ``source``.
    """

    @renamed_keywords(sample_interval_s="sample_interval")
    def __init__(self, path, kind: str, sample_interval: float, **metadata):
        import pyarrow.parquet as pq

        from schuler.io import atomic_path

        if kind not in KINDS:
            raise InvalidParameter("kind", f"{kind!r} must be one of {', '.join(KINDS)}")
        allowed = {"latitude_rad", "longitude_rad", "height_m", "initial_attitude_rad", "gravity_m_s2", "source"}
        if set(metadata) - allowed:
            raise InvalidParameter(sorted(set(metadata) - allowed)[0], "unknown record metadata")
        self._atomic = atomic_path(path)
        self._tmp = self._atomic.__enter__()
        header = {"version": FORMAT_VERSION, "kind": kind, "sample_interval_s": float(sample_interval), **metadata}
        self._schema = _schema(header)
        self._writer = pq.ParquetWriter(self._tmp, self._schema)
        self.path = Path(path)

    def write(self, time_s, gyro, accel) -> None:
        """Append ``time_s`` (n,), ``gyro`` (n, 3), ``accel`` (n, 3) as one row group.

        Parameters
        ----------
        time_s : array_like
            Time at the end of each sample interval, s, shape (n,).
        gyro : array_like
            Gyro samples, shape (n, 3), body axes x forward, y right, z down: rad/s (``kind="rate"``) or rad
            (``kind="increment"``).
        accel : array_like
            Accelerometer samples, shape (n, 3), body axes: m/s^2 (rate) or m/s (increment).
        """
        import pyarrow as pa

        gyro, accel = np.asarray(gyro, dtype=float), np.asarray(accel, dtype=float)
        arrays = [np.asarray(time_s, dtype=float), *gyro.T, *accel.T]
        self._writer.write_table(pa.Table.from_arrays([pa.array(np.ascontiguousarray(a)) for a in arrays],
                                                      schema=self._schema))

    def close(self) -> Path:
        """Finish the file and move it into place."""
        self._writer.close()
        self._atomic.__exit__(None, None, None)
        return self.path

    def __enter__(self):
        return self

    def __exit__(self, kind, value, traceback):
        if kind is None:
            self.close()
        else:
            self._writer.close()
            self._atomic.__exit__(kind, value, traceback)


def write_parquet(record: ImuRecord, path, rows_per_group: int = 1 << 20) -> Path:
    """Write a record in the native format; returns the path.

    Parameters
    ----------
    record : ImuRecord
        The samples and their metadata (kind, sample interval, site, attitude, gravity, source).
    path : str or Path
        Output file (appears atomically).
    rows_per_group : int
        Samples per Parquet row group, number of (the chunk a reader streams).

    Returns
    -------
    Path
        The file written.
    """
    with ParquetRecordWriter(path, record.kind, record.sample_interval_s, latitude_rad=record.latitude_rad,
                             longitude_rad=record.longitude_rad, height_m=record.height_m,
                             initial_attitude_rad=record.initial_attitude_rad, gravity_m_s2=record.gravity_m_s2,
                             source=record.source) as writer:
        for start in range(0, record.samples, rows_per_group):
            stop = start + rows_per_group
            writer.write(record.time_s[start:stop], record.gyro[start:stop], record.accel[start:stop])
    return Path(path)


def open_parquet(path) -> RecordSource:
    """Open a native file: metadata now, samples chunk by chunk.

    Parameters
    ----------
    path : str or Path
        A ``.parquet`` file written by :func:`write_parquet` or :class:`ParquetRecordWriter`.

    Returns
    -------
    RecordSource
        Kind, sample interval (s), exact sample count and site; chunks in SI, body axes.
    """
    import pyarrow.parquet as pq

    path = Path(path)
    try:
        handle = pq.ParquetFile(path)
    except Exception as error:  # pyarrow raises several types for a damaged or foreign file
        raise ImuFileError(path, f"not a Parquet file ({type(error).__name__}: {error})") from None
    raw = (handle.schema_arrow.metadata or {}).get(_METADATA_KEY)
    if raw is None:
        raise ImuFileError(path, "a Parquet file without schuler IMU metadata (write it with write_parquet)")
    header = json.loads(raw)
    if header.get("version") != FORMAT_VERSION:
        raise ImuFileError(path, f"format version {header.get('version')!r}; this reader knows {FORMAT_VERSION}")
    missing = [c for c in _COLUMNS if c not in handle.schema_arrow.names]
    if missing:
        raise ImuFileError(path, f"missing column {missing[0]!r}")
    metadata = {k: header.get(k) for k in ("latitude_rad", "longitude_rad", "height_m", "initial_attitude_rad",
                                           "gravity_m_s2")}
    metadata["first_data_line"] = 1

    def chunks(rows: int):
        row = 0
        for batch in handle.iter_batches(batch_size=rows, columns=list(_COLUMNS)):
            data = np.column_stack([batch.column(i).to_numpy(zero_copy_only=False) for i in range(len(_COLUMNS))])
            bad = ~np.isfinite(data)
            if bad.any():
                r, c = np.argwhere(bad)[0]
                raise ImuFileError(path, f"non-finite value in row {row + int(r) + 1}", column=int(c) + 1,
                                   column_name=_COLUMNS[c])
            row += data.shape[0]
            yield data[:, 0], data[:, 1:4], data[:, 4:7]

    return RecordSource(path=path, kind=header["kind"], sample_interval_s=header["sample_interval_s"],
                        estimated_samples=handle.metadata.num_rows, metadata=metadata, _chunks=chunks)
