"""The ``schuler imu`` commands beyond ``run`` and ``reproduce``: ``info``, ``allan`` and ``simulate``.

Each is a function of validated SI values (and the file paths) returning a
typed result; :data:`ACTIONS` declares them for the command line.

* ``info FILE``: what a file holds (:class:`~schuler.imu.record.ImuInfo`), streamed
  chunk by chunk, so any size is read in bounded memory; every line is checked.
* ``allan FILE``: Allan curves and IEEE 952 terms of the six channels
  (:func:`~schuler.imu.analysis.allan_deviation`, the same from Python), streamed.
* ``simulate -o FILE``: a record of a grade or spec file at rest; ``.parquet``
  is written window by window (memory bounded), ``.csv`` in memory after an
  estimate; either appears atomically.

CSV files: the project's header (rates, SI) unless ``--columns`` maps each
channel to the file's column and ``--units`` gives their units
(``--units gyro=deg/s,accel=g,time=ms``; ``gyro`` and ``accel`` stand for
their three axes), ``--kind increment`` for angle and velocity increments,
``--axes`` where the file's axes point (``RFU``: x right, y forward, z up).
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

from schuler.contract import Action, Argument
from schuler.exceptions import InvalidParameter
from schuler.imu.analysis import PER_OCTAVE, allan_deviation
from schuler.imu.evaluation import PARAMETERS, imu_of, sample_interval
from schuler.imu.files import file_info, write_record
from schuler.imu.instrument import resolve_model
from schuler.imu.record import KINDS, ImuInfo
from schuler.imu.results import AllanResult
from schuler.imu.run_results import SimulationResult
from schuler.imu.simulate import simulate_record, write_simulation
from schuler.memory import require
from schuler.params import Parameter, ParameterSet
from schuler.units import quoted

CSV_BYTES_PER_SAMPLE = 600
"""Memory a simulated record written as CSV holds per sample: the simulation, the table and its text, bytes."""

PARQUET_BYTES_PER_SAMPLE = 56
"""Disk a native file takes per sample: seven float64 columns, bytes (before compression)."""

CSV_FILE_BYTES_PER_SAMPLE = 180
"""Disk a CSV file takes per sample: seven numbers of 17 significant digits and their separators, bytes."""

FILE_ARGUMENT = Argument("file", "IMU file: the project's CSV (or any CSV with --columns and --units), PSINS .imu, "
                                 "or .parquet")

CSV_OPTIONS = (
    Parameter("kind", "", None, "CSV only: what the sensor columns hold (not set: rate).", choices=KINDS,
              kind="choice"),
    Parameter("axes", "", None, "CSV only: where the file's x, y, z axes point, three of F B R L D U (not set: FRD).",
              kind="text"),
    Parameter("columns", "", None, "CSV only: the file's column of each channel, e.g. 'time=t,gyro_x=wx,gyro_y=wy,"
              "gyro_z=wz,accel_x=ax,accel_y=ay,accel_z=az' (not set: the project's header).", kind="text"),
    Parameter("units", "", None, "CSV only: units of the columns, e.g. 'gyro=deg/s,accel=g,time=ms' (gyro and accel "
              "set their three axes; not set: s, rad/s, m/s^2).", kind="text"),
    Parameter("latitude", "deg", None, "CSV only: site latitude (a CSV file does not carry it).", minimum=-90,
              maximum=90),
)

INFO_PARAMETERS = ParameterSet(CSV_OPTIONS, owner="imu info")
ALLAN_PARAMETERS = ParameterSet((*CSV_OPTIONS, PER_OCTAVE), owner="imu allan")
SIMULATE_PARAMETERS = PARAMETERS + ParameterSet((Parameter(
    "seed", "", 0, "Seed of the record's random numbers.", minimum=0, kind="integer"),))


_PAIR_EXAMPLES = {"columns": "time=t,gyro_x=wx,accel_x=ax", "units": "gyro=deg/s,accel=g"}
"""What each channel=value option's message suggests."""


def _pairs(text: str, name: str) -> dict[str, str]:
    pairs = {}
    for part in (p.strip() for p in text.split(",")):
        key, equals, value = part.partition("=")
        if not equals or not key.strip() or not value.strip():
            raise InvalidParameter(name, f"{quoted(part)} is not channel=value; write e.g. '{_PAIR_EXAMPLES[name]}'")
        pairs[key.strip()] = value.strip()
    return pairs


def csv_options(file: Path, kind=None, axes=None, columns=None, units=None, latitude=None) -> dict:
    """The keyword options of :func:`~schuler.imu.readers.open_csv` the user set; refused for other formats.

    Parameters
    ----------
    file : Path
        The IMU file; its suffix decides whether CSV options apply (``.imu`` and ``.parquet`` state their own
        layout).
    kind : {"rate", "increment"}, optional
        CSV only: what the sensor columns hold (not set: rate).
    axes : str, optional
        CSV only: where the file's x, y, z axes point, three letters of F B R L D U (not set: FRD).
    columns : str, optional
        CSV only: ``channel=column`` pairs separated by commas, e.g. ``time=t,gyro_x=wx`` (not set: the
        project's header).
    units : str, optional
        CSV only: ``channel=unit`` pairs separated by commas, e.g. ``gyro=deg/s,accel=g,time=ms``; ``gyro`` and
        ``accel`` set their three axes (not set: s, rad/s, m/s^2).
    latitude : float, optional
        CSV only: site latitude, rad (a CSV file does not carry it).

    Returns
    -------
    dict
        ``open_csv`` keywords: ``kind``, ``axes``, ``columns`` and ``units`` (dicts by channel) and
        ``latitude``, only those the user set.
    """
    given = [name for name, value in (("kind", kind), ("axes", axes), ("columns", columns), ("units", units),
                                      ("latitude", latitude)) if value not in (None, "")]
    suffix = Path(file).suffix.lower()
    if given and suffix in (".imu", ".parquet"):
        raise InvalidParameter(given[0], f"applies to CSV files only; {Path(file).name} is {suffix} and states its "
                               "own layout")
    options: dict = {}
    if kind is not None:
        options["kind"] = kind
    if axes:
        options["axes"] = axes
    if columns:
        options["columns"] = _pairs(columns, "columns")
    if units:
        options["units"] = _pairs(units, "units")
    if latitude is not None:
        options["latitude"] = latitude
    return options


def info(file: Path, **options) -> ImuInfo:
    """What an IMU file holds: samples, rate, duration, mean rates (body x forward, y right, z down), site.

    Parameters
    ----------
    file : Path
        The IMU file: the project's CSV (or any CSV with ``columns`` and ``units``), PSINS ``.imu`` or
        ``.parquet``.
    **options
        The CSV options of :func:`csv_options` (``kind``, ``axes``, ``columns``, ``units``, ``latitude`` in rad).

    Returns
    -------
    ImuInfo
        Samples, sample interval, duration, mean gyro rates (rad/s) and specific forces (m/s^2), site.
    """
    return file_info(file, **csv_options(file, **options))


def allan(file: Path, per_octave: int = 2, **options) -> AllanResult:
    """``schuler imu allan FILE``: :func:`~schuler.imu.analysis.allan_deviation` of a file, its options parsed.

    Parameters
    ----------
    file : Path
        The IMU file (any format of :func:`info`).
    per_octave : int
        Averaging times per octave of tau, number of (1 to 16).
    **options
        The CSV options of :func:`csv_options` (``kind``, ``axes``, ``columns``, ``units``, ``latitude`` in rad).

    Returns
    -------
    AllanResult
        Curves, terms and grade of the six channels.
    """
    return allan_deviation(file, per_octave=per_octave, **csv_options(file, **options))


def simulate(output: Path, imu=None, duration=3600.0, imu_rate=100.0, output_step=None,
             latitude=math.radians(45.0), azimuth=0.0, seed: int = 0) -> SimulationResult:
    """Simulate a record of a grade or spec file at rest into ``output`` (.parquet streamed, .csv in memory).

    Parameters
    ----------
    output : Path
        File to write: ``.parquet`` (native, written window by window) or ``.csv`` (the project's format).
    imu : str, optional
        The simulated IMU: a grade (:data:`~schuler.imu.spec.GRADES`), a TOML spec file or a recording whose
        identified noise terms are simulated (not set: tactical).
    duration : float
        Length of the record, s (rounded to whole samples).
    imu_rate : float
        Sample rate, Hz (used when ``output_step`` is not set).
    output_step : float, optional
        Sample interval dt, s (instead of ``imu_rate``).
    latitude : float
        Site latitude, rad.
    azimuth : float
        Heading of the body x axis, clockwise from north, rad.
    seed : int
        Seed of the record's random numbers.

    Returns
    -------
    SimulationResult
        The file written, model, samples, duration (s), sample interval (s), seed, site (rad) and file size
        (bytes).
    """
    output = Path(output)
    suffix = output.suffix.lower()
    if suffix not in (".parquet", ".csv"):
        raise InvalidParameter("output", f"{output.name}: write .parquet (native, streamed) or .csv")
    model = resolve_model(imu_of(imu))
    dt = sample_interval(imu_rate, output_step)
    samples = int(round(duration / dt))
    if samples < 2:
        raise InvalidParameter("duration", f"{duration:g} s at {dt:g} s per sample gives fewer than 2 samples")
    folder = output.resolve().parent
    folder.mkdir(parents=True, exist_ok=True)
    needed_disk = samples * (PARQUET_BYTES_PER_SAMPLE if suffix == ".parquet" else CSV_FILE_BYTES_PER_SAMPLE)
    free = shutil.disk_usage(folder).free
    if needed_disk > free:
        raise InvalidParameter("duration", f"the file would take about {needed_disk / 1e9:.3g} GB, more than the "
                               f"{free / 1e9:.3g} GB free in {folder}")
    site = {"latitude": latitude, "heading": azimuth}
    if suffix == ".parquet":
        write_simulation(output, model, duration=samples * dt, sample_interval=dt, seed=seed, **site)
    else:
        require(samples * CSV_BYTES_PER_SAMPLE, "this CSV file", "`duration` or `imu_rate` (or write .parquet, which "
                                                                 "streams)")
        record = simulate_record(model, duration=samples * dt, sample_interval=dt, seed=seed,
                                 max_memory_bytes=samples * CSV_BYTES_PER_SAMPLE, **site)
        write_record(record, output)
    return SimulationResult(path=str(output), model=model.name, model_source=model.source, samples=samples,
                            duration_s=samples * dt, sample_interval_s=dt, seed=seed, latitude_rad=latitude,
                            azimuth_rad=azimuth, file_size_bytes=output.stat().st_size, files=[output])


ACTIONS = (
    Action("info", "What an IMU file holds: samples, rate, duration, mean rates and site.\n\n"
                   "Mean rates are body-frame, x forward, y right, z down; at rest they show the Earth rate and "
                   "-g on z. The file is read chunk by chunk (any size) and every line is checked.",
           info, INFO_PARAMETERS, arguments=(FILE_ARGUMENT,)),
    Action("allan", "Allan deviation and IEEE 952 noise terms of the six channels of an IMU file.\n\n"
                    "Overlapping Allan deviation with confidence intervals, the terms N, B, K, Q, R by weighted "
                    "least squares (unresolved ones as upper bounds), and the grade the gyro curves belong to. "
                    "--out writes the figures and the curves (CSV).",
           allan, ALLAN_PARAMETERS, arguments=(FILE_ARGUMENT,)),
    Action("simulate", "Simulate a record of an IMU at rest from a grade or a TOML spec file.\n\n"
                       "Body frame x forward, y right, z down, level, heading --azimuth; rates in SI. .parquet is "
                       "written window by window (any length); .csv is built in memory.",
           simulate, SIMULATE_PARAMETERS,
           output_file="Output file: .parquet (native, streamed) or .csv (the project's format)."),
)
"""The IMU system's own commands."""
