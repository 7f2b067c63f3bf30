"""Reading IMU files: the project's CSV (with a column/unit mapping for other layouts) and PSINS ``.imu``.

Every reader returns a :class:`RecordSource`: the file's metadata plus an
iterator over validated chunks of samples in SI, body frame x forward, y right,
z down. :meth:`RecordSource.read` gathers the chunks into an
:class:`~schuler.imu.record.ImuRecord` after estimating the memory it needs;
the Allan analysis streams the chunks instead, so a file larger than memory
can still be characterised.

Errors name the file, the line and the column (:class:`ImuFileError`): time
going backwards, gaps, irregular sampling, empty or non-numeric cells, columns
whose units are not those expected. Text encodings: UTF-8 (with or without a
byte-order mark) and UTF-16 with a byte-order mark are read; other 8-bit text is
read as Latin-1 (the numbers are ASCII in any case); anything else is refused
with one :class:`ImuFileError`, never a ``UnicodeDecodeError``.

The formats
-----------
CSV (the project's): a header ``t_s,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s,
accel_x_m_s2,accel_y_m_s2,accel_z_m_s2`` (any column order), rates in SI, time
at the end of each sample interval; lines starting with ``#`` before the header
are comments. Other layouts: ``columns`` maps each channel (``time``,
``gyro_x`` .. ``accel_z``) to the file's column name and ``units`` gives each
channel's unit ("deg/s", "g", "deg" or "m/s" for increments, "ms").

PSINS ``.imu`` (G. Yan's PSINS toolbox, ``imufile.m``): ``%`` comment lines,
then three header lines of six numbers: (pitch0, roll0, yaw0 in deg; VE0, VN0,
VU0 in m/s), (latitude0, longitude0 in deg, height0 in m, t0 in s, sampling
interval in ms, g in m/s^2), (gyro scale factors in arcsec per count,
accelerometer scale factors in ug*s per count); then one line per sample of six
integer counts of angle and velocity increments over the interval ending at
t_k = t0 + k dt (k = 1..n), optionally a seventh column of time dither in us.
The accelerometer scale is ug*s times **the g of the second header line**, not
9.80665. Axes X right, Y forward, Z up (converted here to x forward, y right,
z down); PSINS attitude is (pitch, roll, yaw) of the body in East-North-Up with
yaw positive towards west (heading = -yaw), Euler order yaw-pitch-roll.
"""

from __future__ import annotations

import difflib
import io
import math
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from schuler.exceptions import InvalidParameter, SchulerError, renamed_keywords
from schuler.imu.record import KINDS, ImuRecord, axes_matrix
from schuler.units import quoted

CHANNELS = ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")
"""The six sensor channels, body frame."""

CSV_HEADER = ("t_s", "gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s", "accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2")
"""Column names of the project's CSV format (rates, SI)."""

DEFAULT_MAX_MEMORY_BYTES = 2 * 1024**3
"""Largest in-memory record :meth:`RecordSource.read` builds without being asked for more."""

CHUNK_ROWS = 1 << 20
"""Rows per chunk when streaming a file."""

MAX_LINE_CHARACTERS = 1 << 16
"""Longest header or sample line read while opening a file; a longer one is refused, not loaded into memory."""

_BYTES_PER_SAMPLE = 7 * 8 * 3  # time + 6 channels as float64, with room for one copy while converting
_ARCSEC = math.pi / 180.0 / 3600.0


class ImuFileError(SchulerError):
    """A file cannot be read as an IMU record; says where (file, line, column) and why."""

    def __init__(self, path, message: str, line: int | None = None, column: int | None = None,
                 column_name: str | None = None):
        self.path, self.line, self.column = Path(path), line, column
        where = str(Path(path).name)
        if line is not None:
            where += f", line {line}"
        if column is not None:
            shown = column_name if not column_name or len(column_name) <= 40 else column_name[:40] + "..."
            where += f", column {column}" + (f" ({shown})" if shown else "")
        super().__init__(f"{where}: {message}")


@dataclass
class RecordSource:
    """An opened IMU file: metadata and validated SI chunks.

    Attributes
    ----------
    path : Path
    kind : {"rate", "increment"}
    sample_interval_s : float or None
        From the header, or None until the first chunk sets it (CSV).
    estimated_samples : int
        From the file size and the first lines (exact for the native format).
    metadata : dict
        ``latitude_rad``, ``longitude_rad``, ``height_m``, ``initial_attitude_rad``,
        ``gravity_m_s2`` where the file states them.
    """

    path: Path
    kind: str
    sample_interval_s: float | None
    estimated_samples: int
    _chunks: Callable[[int], Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]] = field(repr=False)
    metadata: dict = field(default_factory=dict)

    def chunks(self, rows: int = CHUNK_ROWS) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """Yield ``(time_s, gyro, accel)`` chunks of at most ``rows`` samples, checked for continuity.

        Parameters
        ----------
        rows : int
            Largest chunk, number of samples (>= 2).

        Yields
        ------
        time_s, gyro, accel : ndarray
            Times, s, shape (n,); gyro and accelerometer samples, shape (n, 3), body axes x forward, y right,
            z down, in the units of ``kind`` (rad/s and m/s^2, or rad and m/s).
        """
        if int(rows) < 2:
            raise InvalidParameter("rows", f"chunk size must be >= 2, got {rows!r}")
        checker = _TimeCheck(self.path, self.sample_interval_s, self.metadata.get("first_data_line", 2))
        for time_s, gyro, accel in self._chunks(int(rows)):
            checker.check(time_s)
            if self.sample_interval_s is None:
                self.sample_interval_s = checker.dt
            yield time_s, gyro, accel

    def interval_s(self) -> float:
        """The sample interval, s: stated by the file, or measured once the first chunk is read."""
        if self.sample_interval_s is None:
            raise ImuFileError(self.path, "the sample interval is measured from the samples: read a chunk first")
        return self.sample_interval_s

    def estimated_bytes(self) -> int:
        """Memory an in-memory :class:`ImuRecord` of this file needs while being built, bytes."""
        return int(self.estimated_samples * _BYTES_PER_SAMPLE)

    def read(self, max_memory_bytes: int = DEFAULT_MAX_MEMORY_BYTES) -> ImuRecord:
        """The whole file as an :class:`ImuRecord`, refused when it would need more than ``max_memory_bytes``.

        Parameters
        ----------
        max_memory_bytes : int
            Largest memory the record may need while being built, bytes (default 2 GiB).

        Returns
        -------
        ImuRecord
            Every sample, in the units of ``kind``, with the file's metadata.
        """
        needed = self.estimated_bytes()
        if needed > max_memory_bytes:
            raise ImuFileError(self.path, f"about {self.estimated_samples:,} samples need ~{needed / 1e9:.1f} GB in "
                               f"memory, above the {max_memory_bytes / 1e9:.1f} GB limit; analyse it in chunks "
                               "(the Allan analysis streams files) or raise max_memory_bytes")
        parts = list(self.chunks())
        if not parts:
            raise ImuFileError(self.path, "no samples")
        time_s, gyro, accel = (np.concatenate([p[i] for p in parts]) for i in range(3))
        if time_s.size < 2:
            raise ImuFileError(self.path, f"a record needs at least 2 samples, the file has {time_s.size}")
        keys = ("latitude_rad", "longitude_rad", "height_m", "initial_attitude_rad", "gravity_m_s2")
        return ImuRecord(time_s=time_s, gyro=gyro, accel=accel, kind=self.kind,
                         sample_interval_s=self.interval_s(), source=self.path.name,
                         **{k: self.metadata.get(k) for k in keys})


class _TimeCheck:
    """Time stamps must increase by one sample interval: names the line of the first that does not."""

    def __init__(self, path, dt: float | None, first_line: int):
        self.path, self.line = path, first_line
        self.dt: float | None = dt
        self.last: float | None = None

    def check(self, time_s: np.ndarray) -> None:
        if time_s.size == 0:
            return
        series = time_s if self.last is None else np.concatenate([[self.last], time_s])
        steps = np.diff(series)
        if self.dt is None:
            if steps.size == 0:
                raise ImuFileError(self.path, "the first chunk holds a single sample; the sample interval is unknown")
            self.dt = float(np.median(steps))
            if not self.dt > 0:
                raise ImuFileError(self.path, "time does not increase", line=self.line, column=1)
            # a regular chunk's span over its steps is exact to rounding; single differences of
            # time stamps written as decimals are not (0.02 - 0.01 = 0.009999999999999998...)
            span = float(series[-1] - series[0]) / steps.size
            if abs(span - self.dt) <= 1e-6 * self.dt:
                self.dt = span
        offset = self.line - (0 if self.last is None else 1)  # line of series[0]
        backwards = np.flatnonzero(steps <= 0)
        gaps = np.flatnonzero(steps > 1.5 * self.dt)
        irregular = np.flatnonzero((steps > 0) & (steps < 0.5 * self.dt))
        for bad, what in ((backwards, "time does not increase"), (gaps, "gap"), (irregular, "irregular sampling")):
            if bad.size:
                k = int(bad[0])
                detail = (f"{what}: t = {series[k + 1]:.9g} s after {series[k]:.9g} s "
                          f"(sample interval {self.dt:.6g} s)")
                if what == "gap":
                    detail += f", about {round(steps[k] / self.dt) - 1:,} samples missing"
                raise ImuFileError(self.path, detail, line=offset + k + 1, column=1)
        self.last = float(time_s[-1])
        self.line += time_s.size


def detect_encoding(path) -> str:
    """The text encoding to read ``path`` with: 'utf-8-sig', 'utf-16', 'utf-8' or 'latin-1'.

    Parameters
    ----------
    path : str or Path
        The text file; its first 64 KiB decide.

    Returns
    -------
    str
        A codec name for :func:`open`.

    Raises
    ------
    ImuFileError
        A file with NUL bytes and no UTF-16 byte-order mark (UTF-16 without a
        mark, UTF-32, or binary data).
    """
    path = Path(path)
    try:
        with open(path, "rb") as handle:
            head = handle.read(1 << 16)
    except OSError as error:
        raise ImuFileError(path, f"cannot open: {error.strerror or error}") from None
    if head.startswith(b"\xef\xbb\xbf"):
        return "utf-8-sig"
    if head.startswith((b"\xff\xfe", b"\xfe\xff")) and not head.startswith(b"\xff\xfe\x00\x00"):
        return "utf-16"
    if b"\x00" in head:
        raise ImuFileError(path, "not a text file in UTF-8, UTF-16 with a byte-order mark or Latin-1 "
                           "(NUL bytes found); convert it to UTF-8 text")
    try:
        head.decode("utf-8")
        return "utf-8"
    except UnicodeDecodeError as error:
        if error.start >= len(head) - 3:  # a character cut by the 64 KiB window
            return "utf-8"
        return "latin-1"


def _open_text(path, encoding: str):
    return open(path, encoding=encoding, errors="strict", newline="")


def _decode_guard(path, iterator):
    """Re-raise a decoding error met deep in a file as one ImuFileError."""
    try:
        yield from iterator
    except UnicodeDecodeError as error:
        raise ImuFileError(path, f"not valid text in the detected encoding ({error.reason} at byte "
                           f"{error.start} of a read block); convert the file to UTF-8") from None


def _bounded_lines(path: Path, handle) -> Iterator[str]:
    """The lines of an open text file, each read with a bound; a line over :data:`MAX_LINE_CHARACTERS` is refused."""
    for number, line in enumerate(iter(lambda: handle.readline(MAX_LINE_CHARACTERS + 1), ""), start=1):
        if len(line) > MAX_LINE_CHARACTERS and line[-1] not in "\r\n":
            raise ImuFileError(path, f"a line longer than {MAX_LINE_CHARACTERS:,} characters ({line[:40]!r}...); "
                               "an IMU file's header and sample lines are short", line=number)
        yield line


def _estimate_rows(path: Path, header_bytes: int, sample_lines: list[str]) -> int:
    size = os.path.getsize(path)
    if not sample_lines:
        return 0
    per_line = max(1.0, sum(len(line.encode("utf-8")) + 1 for line in sample_lines) / len(sample_lines))
    return int(math.ceil(max(0, size - header_bytes) / per_line))


def _read_numeric_chunks(path: Path, encoding: str, skip_lines: int, names, sep: str, rows: int, first_line: int):
    """pandas' C reader over the data lines, float64, with file/line/column in every error."""
    import pandas as pd

    options = dict(sep=sep, header=None, names=names, skiprows=skip_lines, chunksize=rows, encoding=encoding,
                   skip_blank_lines=False, engine="c")
    line = first_line
    try:
        for frame in pd.read_csv(path, **options):
            values = frame.to_numpy(dtype=float, na_value=np.nan) if frame.dtypes.map(
                lambda d: d.kind in "fiu").all() else _locate_text(path, frame, line)
            bad = ~np.isfinite(values)
            if bad.any():
                row, column = np.argwhere(bad)[0]
                raise ImuFileError(path, "empty or non-finite value", line=line + int(row), column=int(column) + 1,
                                   column_name=str(frame.columns[column]))
            yield values
            line += len(frame)
    except pd.errors.ParserError as error:
        raise ImuFileError(
            path, f"malformed line: {str(error).strip()} (lines counted from the file's start)") from None
    except UnicodeDecodeError as error:
        raise ImuFileError(path, f"not valid text in {encoding} ({error.reason}); convert the file to UTF-8") from None
    except pd.errors.EmptyDataError:
        return


def _locate_text(path, frame, first_line: int) -> np.ndarray:
    """A chunk with a non-numeric cell: name the first one."""
    import pandas as pd

    for column_index, column in enumerate(frame.columns):
        converted = pd.to_numeric(frame[column], errors="coerce")
        text = frame[column].notna() & converted.isna()
        if text.any():
            row = int(np.flatnonzero(text.to_numpy())[0])
            raise ImuFileError(path, f"not a number: {quoted(frame[column].iloc[row])}", line=first_line + row,
                               column=column_index + 1, column_name=str(column))
    return frame.apply(pd.to_numeric, errors="coerce").to_numpy(dtype=float)


def _unit_scale(unit: str, expected: str, channel: str) -> float:
    from schuler.units import parse_quantity

    return parse_quantity(f"1 {unit}", expected, name=f"units.{channel}")


@renamed_keywords(latitude_rad="latitude", longitude_rad="longitude", height_m="height")
def open_csv(path, *, columns: dict[str, str] | None = None, units: dict[str, str] | None = None,
             kind: str = "rate", axes: str = "FRD", delimiter: str = ",", check_units: bool = True,
             latitude: float | None = None, longitude: float | None = None,
             height: float | None = None) -> RecordSource:
    """Open a CSV file of IMU samples.

    Parameters
    ----------
    path : str or Path
    columns : dict, optional
        Channel (``time``, ``gyro_x`` .. ``accel_z``) -> the file's column name.
        Default: the project's header :data:`CSV_HEADER`.
    units : dict, optional
        Channel -> unit as text ("deg/s", "g", "deg", "m/s", "ms") or a pint unit. Defaults:
        s, rad/s and m/s^2 for rates, rad and m/s for increments.
    kind : {"rate", "increment"}
        What the sensor columns hold.
    axes : str
        Where the file's x, y, z axes point (see :func:`~schuler.imu.record.axes_matrix`), default "FRD".
    delimiter : str
    check_units : bool
        Refuse accelerometer rates whose mean magnitude is 0.5..1.5 while declared
        in m/s^2 (the file is almost surely in g).
    latitude, longitude, height : float, optional
        The site, which a CSV file does not carry: latitude and longitude in rad, height in m.

    Returns
    -------
    RecordSource
    """
    path = Path(path)
    if kind not in KINDS:
        raise InvalidParameter("kind", f"{kind!r} must be one of {', '.join(KINDS)}")
    rotation = axes_matrix(axes)
    encoding = detect_encoding(path)
    header, comment_lines, sample_lines, header_bytes = _csv_header(path, encoding)
    names = [name.strip() for name in header.split(delimiter)]
    mapping = _csv_mapping(path, names, columns, comment_lines + 1)
    scales = _csv_scales(units or {}, kind)
    order = [names.index(mapping[c]) for c in ("time", *CHANNELS)]
    estimated = _estimate_rows(path, header_bytes, sample_lines)
    first_line = comment_lines + 2

    def chunks(rows: int):
        checked = not check_units or kind != "rate"
        for values in _read_numeric_chunks(path, encoding, comment_lines + 1, names, delimiter, rows, first_line):
            values = values[:, order]
            time_s = values[:, 0] * scales["time"]
            gyro = values[:, 1:4] * np.array([scales[c] for c in CHANNELS[:3]])
            accel = values[:, 4:7] * np.array([scales[c] for c in CHANNELS[3:]])
            if not checked:
                _check_accel_units(path, accel, scales, mapping, names, first_line)
                checked = True
            yield time_s, gyro @ rotation.T, accel @ rotation.T

    return RecordSource(path=path, kind=kind, sample_interval_s=None, estimated_samples=estimated,
                        metadata={"latitude_rad": latitude, "longitude_rad": longitude, "height_m": height,
                                  "first_data_line": first_line},
                        _chunks=lambda rows: _decode_guard(path, chunks(rows)))


def _csv_header(path: Path, encoding: str):
    with _open_text(path, encoding) as handle:
        try:
            comments, header_bytes, header = 0, 0, None
            lines = _bounded_lines(path, handle)
            for line in lines:
                header_bytes += len(line.encode("utf-8"))
                if line.lstrip().startswith("#"):
                    comments += 1
                    continue
                header = line.strip()
                break
            sample = [line.rstrip("\r\n") for _, line in zip(range(1000), lines)]
        except UnicodeDecodeError as error:
            raise ImuFileError(
                path, f"not valid text in {encoding} ({error.reason}); convert the file to UTF-8") from None
    if not header:
        raise ImuFileError(path, "no header line (expected " + ",".join(CSV_HEADER) + ")")
    return header, comments, sample, header_bytes


def _csv_mapping(path: Path, names: list[str], columns: dict | None, header_line: int) -> dict[str, str]:
    if columns is not None:
        unknown = set(columns) - {"time", *CHANNELS}
        if unknown:
            raise InvalidParameter("columns", f"unknown channel {sorted(unknown)[0]!r}; channels are time, "
                                   + ", ".join(CHANNELS))
        mapping = {"time": "t_s", **dict(zip(CHANNELS, CSV_HEADER[1:]))}
        mapping.update(columns)
    else:
        mapping = {"time": "t_s", **dict(zip(CHANNELS, CSV_HEADER[1:]))}
    for channel, name in mapping.items():
        if name in names:
            continue
        prefix = "t_" if channel == "time" else channel + "_"
        same_channel = [(i, n) for i, n in enumerate(names) if n.startswith(prefix)]
        if same_channel and columns is None:
            index, found = same_channel[0]
            raise ImuFileError(path, f"wrong units: column {quoted(found)} where {quoted(name)} is expected (the "
                               "project's CSV holds SI rates); give a column/unit mapping for other units",
                               line=header_line, column=index + 1, column_name=found)
        close = difflib.get_close_matches(name, names, n=1)
        hint = f"; did you mean {quoted(close[0])}?" if close else f"; the header has {quoted(', '.join(names))}"
        raise ImuFileError(path, f"no column {quoted(name)} for {channel}{hint}", line=header_line)
    return mapping


def _csv_scales(units: dict[str, str], kind: str) -> dict[str, float]:
    unknown = set(units) - {"time", *CHANNELS}
    if unknown:
        raise InvalidParameter("units", f"unknown channel {sorted(unknown)[0]!r}; channels are time, gyro, accel, "
                               + ", ".join(CHANNELS))
    expected = {"time": "s", **{c: ("rad/s" if kind == "rate" else "rad") for c in CHANNELS[:3]},
                **{c: ("m/s^2" if kind == "rate" else "m/s") for c in CHANNELS[3:]}}
    return {channel: _unit_scale(units.get(channel, target), target, channel) for channel, target in expected.items()}


def _check_accel_units(path, accel, scales, mapping, names, first_line) -> None:
    if not np.isclose(scales["accel_x"], 1.0):
        return
    norm = float(np.linalg.norm(accel.mean(axis=0)))
    if 0.5 <= norm <= 1.5:
        raise ImuFileError(path, f"wrong units: the mean specific force is {norm:.3f} m/s^2, which looks like g; "
                           "give units={'accel_x': 'g', ...} (or check_units=False if it is right)",
                           line=first_line, column=names.index(mapping["accel_x"]) + 1,
                           column_name=mapping["accel_x"])


def open_psins(path) -> RecordSource:
    """Open a PSINS ``.imu`` text file (see the module notes for the format and frames).

    Parameters
    ----------
    path : str or Path
        The ``.imu`` file (three numeric header lines, then integer counts).

    Returns
    -------
    RecordSource
        Increments (rad, m/s) in x forward, y right, z down; metadata with the
        site, the nominal initial attitude (roll, pitch, heading in NED) and the
        file's g.
    """
    path = Path(path)
    encoding = detect_encoding(path)
    headers, skip, header_bytes, sample = _psins_header(path, encoding)
    (pitch, roll, yaw, *_), (lat, lon, height, t0, interval_ms, gravity), scale = headers
    if not (interval_ms > 0 and gravity > 0):
        raise ImuFileError(path, f"header: sampling interval {interval_ms} ms and g {gravity} must be > 0",
                           line=skip - 1)
    if not abs(lat) <= 90:
        raise ImuFileError(path, f"header: latitude {lat} deg is outside [-90, 90]", line=skip - 1, column=1)
    dt = interval_ms / 1000.0
    gyro_scale = np.asarray(scale[:3]) * _ARCSEC
    accel_scale = np.asarray(scale[3:]) * 1e-6 * gravity
    rotation = axes_matrix("RFU")
    columns = len(sample[0].split()) if sample else 6
    if columns not in (6, 7):
        raise ImuFileError(path, f"a data line has {columns} numbers; the format has 6 (or 7 with time dither)",
                           line=skip + 1)
    names = [f"{s}_{a}" for s in ("gyro", "accel") for a in "XYZ"] + (["dither_us"] if columns == 7 else [])

    def chunks(rows: int):
        start = 0
        for values in _read_numeric_chunks(path, encoding, skip, names, r"\s+", rows, skip + 1):
            k = np.arange(start + 1, start + values.shape[0] + 1)
            time_s = t0 + k * dt + (values[:, 6] * 1e-6 if columns == 7 else 0.0)
            start += values.shape[0]
            yield time_s, (values[:, 0:3] * gyro_scale) @ rotation.T, (values[:, 3:6] * accel_scale) @ rotation.T

    metadata = {"latitude_rad": math.radians(lat), "longitude_rad": math.radians(lon), "height_m": float(height),
                "gravity_m_s2": float(gravity), "first_data_line": skip + 1,
                "initial_attitude_rad": psins_attitude_to_ned(pitch, roll, yaw)}
    return RecordSource(path=path, kind="increment", sample_interval_s=dt,
                        estimated_samples=_estimate_rows(path, header_bytes, sample), metadata=metadata,
                        _chunks=lambda rows: _decode_guard(path, chunks(rows)))


def _psins_header(path: Path, encoding: str):
    headers: list[list[float]] = []
    line_number, header_bytes = 0, 0
    with _open_text(path, encoding) as handle:
        try:
            lines = _bounded_lines(path, handle)
            for line in lines:
                line_number += 1
                header_bytes += len(line.encode("utf-8"))
                text = line.strip()
                if not text or text.startswith("%"):
                    continue
                try:
                    numbers = [float(v) for v in text.split()]
                except ValueError:
                    raise ImuFileError(path, f"header line {len(headers) + 1} is not numeric: {quoted(text)}",
                                       line=line_number) from None
                if len(numbers) != 6 or not all(math.isfinite(v) for v in numbers):
                    raise ImuFileError(path, f"header line {len(headers) + 1} must hold 6 finite numbers, "
                                       f"it holds {len(numbers)}", line=line_number)
                headers.append(numbers)
                if len(headers) == 3:
                    break
            sample = [line.rstrip("\r\n") for _, line in zip(range(1000), lines)]
        except UnicodeDecodeError as error:
            raise ImuFileError(
                path, f"not valid text in {encoding} ({error.reason}); convert the file to UTF-8") from None
    if len(headers) < 3:
        raise ImuFileError(path, f"a PSINS file has 3 numeric header lines, found {len(headers)}")
    return headers, line_number, header_bytes, sample


def psins_attitude_to_ned(pitch_deg: float, roll_deg: float, yaw_deg: float) -> tuple[float, float, float]:
    """PSINS (pitch, roll, yaw) of an X-right/Y-forward/Z-up body in ENU -> (roll, pitch, heading) in NED, rad.

    PSINS builds C_b^n = Rz(yaw) Rx(pitch) Ry(roll) (ENU, yaw positive towards
    west). The same physical attitude of the x-forward/y-right/z-down body in
    NED is ``T C_b^n P^T`` with T the ENU -> NED swap and P :func:`axes_matrix`
    ("RFU"), read back as aerospace roll, pitch, heading (Euler z-y-x).

    Parameters
    ----------
    pitch_deg, roll_deg, yaw_deg : float
        PSINS attitude of the file's first header line, deg (yaw positive towards west).

    Returns
    -------
    roll, pitch, heading : float
        Attitude of the x-forward/y-right/z-down body in NED, rad; heading in [0, 2 pi).

    Examples
    --------
    >>> [round(math.degrees(a), 6) for a in psins_attitude_to_ned(0.0, 0.0, -90.6)]
    [0.0, 0.0, 90.6]
    """
    from scipy.spatial.transform import Rotation

    c_enu = Rotation.from_euler("ZXY", [yaw_deg, pitch_deg, roll_deg], degrees=True).as_matrix()
    enu_to_ned = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
    c_ned = enu_to_ned @ c_enu @ axes_matrix("RFU").T
    heading, pitch, roll = Rotation.from_matrix(c_ned).as_euler("ZYX")
    return (float(roll), float(pitch), float(heading % (2 * math.pi)))


def write_csv(record: ImuRecord, path) -> Path:
    """Write a record in the project's CSV format (rates, SI), atomically.

    Parameters
    ----------
    record : ImuRecord
        The samples (increments are written as rates).
    path : str or Path
        Output file.

    Returns
    -------
    Path
        The file written.
    """
    from schuler.io import atomic_path

    data = np.column_stack([record.time_s, record.gyro_rate_rad_s, record.accel_m_s2])
    buffer = io.StringIO()
    np.savetxt(buffer, data, delimiter=",", header=",".join(CSV_HEADER), comments="", fmt="%.17g")
    with atomic_path(path) as tmp:
        tmp.write_text(buffer.getvalue(), encoding="utf-8")
    return Path(path)
