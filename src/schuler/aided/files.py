"""What ``schuler aided run`` evaluates on files: a recording, its GNSS, optionally a reference and a configuration.

The inputs (parameters of :mod:`schuler.aided.evaluation`):

* ``record``: the IMU data. A file ending ``.csv``, ``.parquet`` or ``.imu`` is read as the IMU layer reads it
  (:func:`schuler.imu.files.read_record`: the project's CSV and Parquet, PSINS text); anything else is a KF-GINS
  text file of increments (:func:`schuler.aided.kfgins.read_imu`). Either way the accelerometer's median
  magnitude is checked against what the file should hold (:func:`~schuler.aided.kfgins.check_specific_force`):
  increments given where rates are expected, or the reverse, are refused.
* ``gnss_file``: KF-GINS GNSS text, 7 or 13 columns (:func:`~schuler.aided.kfgins.read_gnss`).
* ``reference``: KF-GINS navigation text (:func:`~schuler.aided.kfgins.read_navigation`), the truth the errors are
  computed against, interpolated linearly to the output times inside its span. Without it the error outputs
  are NaN (null in JSON) and the filter's 1-sigma remain.
* ``kf_gins_config``: a KF-GINS YAML configuration (:mod:`~schuler.aided.kfgins_configuration`). Its relative
  ``imupath`` and ``gnsspath`` are resolved against the YAML file's folder first, then against the working
  directory (KF-GINS itself uses only the working directory); ``outputpath`` is not used (``--out`` says where
  results go). ``record`` and ``gnss_file`` given beside it replace its paths.

With a configuration the filter is KF-GINS's model: GNSS position only, 21 states, its noise densities, every
bias and scale factor a first-order Gauss-Markov process of its ``gbstd`` ... ``asstd`` with the one ``corrtime``,
started at ``initgyrbias`` ... with ``initbgstd`` ... (:func:`kfgins_model`), the initial state ``initpos``,
``initvel``, ``initatt`` with ``initposstd``, ``initvelstd``, ``initattstd`` (taken as psi's north, east, down
1-sigma, as KF-GINS takes them), the antenna at ``antlever``, the IMU data between ``starttime`` and ``endtime``.
The options given beside it win: ``imu`` (the filter's IMU model from the IMU layer instead of ``imunoise``),
``lever_arm_x|y|z`` (each axis alone), ``aiding`` (GNSS velocity too, if the file has it), ``gnss_sigma_*``.
The covariance is propagated every ``covariance_interval`` (KF-GINS: at every IMU epoch).

Without a configuration the start is the reference at the IMU data's start (linearly interpolated), else the
record's own site and attitude (a PSINS or Parquet record, at rest); the 1-sigma of the start are those of a
simulated run (:data:`~schuler.aided.evaluation.START_SIGMA`), the IMU model that of ``imu``.

Times are as in the data (seconds of week): the outages are the GNSS gaps longer than twice the GNSS interval
(:func:`~schuler.aided.gnss.detect_outages`), and outages scheduled by the outage options, when given, remove
the epochs inside them first (their times also as in the data). ``gnss_sigma_north|east|down`` and
``gnss_velocity_sigma``, when given, replace the file's 1-sigma.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from schuler.aided import kfgins
from schuler.aided.ekf import Start
from schuler.aided.error_state import ErrorProcess, FilterModel
from schuler.aided.gnss import GnssRecord, detect_outages, scheduled_outages
from schuler.aided.kfgins_configuration import KfGinsConfiguration, read_configuration
from schuler.core.attitude import quaternion_from_euler
from schuler.exceptions import InvalidParameter
from schuler.imu.record import ImuRecord

FILE_PARAMETERS = ("record", "gnss_file", "reference", "kf_gins_config")
"""The parameters that make a case a run on files."""

IMU_LAYER_SUFFIXES = (".csv", ".parquet", ".imu")
"""Suffixes of IMU files read by the IMU layer; any other file is KF-GINS text."""

UNIFORM_TOLERANCE = 0.5
"""Largest departure of an IMU stamp from the uniform grid, in sample intervals."""


def is_file_case(case) -> bool:
    """Whether a case runs on files (any of :data:`FILE_PARAMETERS` set).

    Parameters
    ----------
    case : Case
        A validated case (text paths or None).
    """
    return any(case[name] is not None for name in FILE_PARAMETERS)


BYTES_PER_LINE = 120
"""Bytes of one line of a KF-GINS IMU file (seven numbers of 17 digits), for a work estimate before reading."""


def record_samples(case) -> int:
    """The IMU samples a case on files will filter, estimated from the file's size (0 if it cannot be found).

    Parameters
    ----------
    case : Case
        A validated case on files (paths as text).
    """
    path = case["record"]
    if path is None and case["kf_gins_config"] is not None:
        try:
            path = load_configuration(case["kf_gins_config"]).imu_path
        except InvalidParameter:
            return 0  # the run itself says what is wrong
    try:
        return Path(path).stat().st_size // BYTES_PER_LINE if path is not None else 0
    except OSError:
        return 0


def load_configuration(path) -> KfGinsConfiguration:
    """A KF-GINS configuration with its data paths resolved against its folder, then the working directory.

    Parameters
    ----------
    path : str or Path
        The YAML file.
    """
    path = Path(path)
    if not path.is_file():
        raise InvalidParameter("kf_gins_config", f"{path}: no such file")
    config = read_configuration(path)
    if config.imu_path.exists() and config.gnss_path.exists():
        return config
    # KF-GINS resolves against its working directory: a configuration written for that still runs
    here = read_configuration(path, base=Path.cwd())
    return replace(config, imu_path=config.imu_path if config.imu_path.exists() else here.imu_path,
                   gnss_path=config.gnss_path if config.gnss_path.exists() else here.gnss_path)


def read_imu_file(path, *, imu_rate: float | None = None, columns: int = 7, name: str = "record") -> ImuRecord:
    """The IMU data of a file as increments, checked (module docstring): the IMU layer's formats or KF-GINS text.

    Parameters
    ----------
    path : str or Path
        The file.
    imu_rate : float, optional
        The stated rate (``imudatarate``), Hz, checked against the stamps.
    columns : int
        Columns of a KF-GINS file (``imudatalen``), number of.
    name : str
        The option naming the file in messages.
    """
    path = Path(path)
    if path.suffix.lower() in IMU_LAYER_SUFFIXES:
        from schuler.imu.files import read_record

        if not path.is_file():
            raise InvalidParameter(name, f"{path}: no such file")
        record = read_record(path)
        kfgins.check_specific_force(record.accel, record.sample_interval_s, record.kind, name)
    else:
        record = kfgins.read_imu(path, imu_rate=imu_rate, columns=columns, name=name)
    t = record.time_s
    # the filter steps on a uniform grid: the mean interval over the span, and no stamp far off it
    interval = float((t[-1] - t[0]) / (t.size - 1))
    off = np.abs(t - (t[0] + np.arange(t.size) * interval))
    if off.max() > UNIFORM_TOLERANCE * interval:
        row = int(np.argmax(off))
        raise InvalidParameter(name, f"{path.name}: sample {row + 1} at {t[row]:.6f} s is {off[row] / interval:.3g} "
                                     "intervals off the uniform grid (a gap in the IMU data?)")
    return ImuRecord(time_s=t, gyro=record.gyro_increment_rad, accel=record.accel_increment_m_s, kind="increment",
                     sample_interval_s=interval, latitude_rad=record.latitude_rad, longitude_rad=record.longitude_rad,
                     height_m=record.height_m, initial_attitude_rad=record.initial_attitude_rad, source=str(path))


def kfgins_model(config: KfGinsConfiguration) -> tuple[FilterModel, np.ndarray, np.ndarray]:
    """KF-GINS's filter model of a configuration: the model, the initial sensor errors and their 1-sigma.

    Every bias and scale factor is first-order Gauss-Markov with the one ``corrtime`` (spec 07).

    Parameters
    ----------
    config : KfGinsConfiguration
        The configuration (SI).

    Returns
    -------
    model : FilterModel
        21 states.
    initial : ndarray, shape (12,)
        b_g (rad/s), b_a (m/s^2), s_g, s_a at the start.
    sigma : ndarray, shape (12,)
        Their 1-sigma, same units.
    """
    def gauss_markov(sigma):
        return ErrorProcess("gauss-markov", sigma, correlation_time=config.correlation_time_s)

    model = FilterModel(config.gyro_angle_random_walk_rad_sqrt_s, config.accel_velocity_random_walk_m_s_sqrt_s,
                        gauss_markov(config.gyro_bias_sigma_rad_s), gauss_markov(config.accel_bias_sigma_m_s2),
                        gauss_markov(config.gyro_scale_factor_sigma), gauss_markov(config.accel_scale_factor_sigma))
    initial = np.concatenate([config.initial_gyro_bias_rad_s, config.initial_accel_bias_m_s2,
                              config.initial_gyro_scale_factor, config.initial_accel_scale_factor])
    sigma = np.concatenate([config.initial_gyro_bias_sigma_rad_s, config.initial_accel_bias_sigma_m_s2,
                            config.initial_gyro_scale_factor_sigma, config.initial_accel_scale_factor_sigma])
    return model, initial, sigma


@dataclass(frozen=True, eq=False)
class FileInputs:
    """The data of a run on files, read and checked (SI; times as in the data).

    Attributes
    ----------
    t0_s : float
        Start of the first IMU interval used, s.
    interval_s : float
        IMU interval, s.
    increments : ndarray, shape (n, 6)
        dtheta (rad), dv (m/s) of the intervals used, body axes.
    gnss : GnssRecord
        The GNSS epochs used (scheduled outages removed, 1-sigma replaced where options say so).
    reference : NavigationRecord or None
        The truth, if given.
    configuration : KfGinsConfiguration or None
        The KF-GINS configuration, if given.
    outages : tuple of (float, float)
        The GNSS gaps inside the IMU span, (start, duration), s.
    """

    t0_s: float
    interval_s: float
    increments: np.ndarray
    gnss: GnssRecord
    reference: kfgins.NavigationRecord | None
    configuration: KfGinsConfiguration | None
    outages: tuple[tuple[float, float], ...]


def _span(imu: ImuRecord, config: KfGinsConfiguration | None) -> tuple[float, np.ndarray]:
    """(t0, rows): the IMU rows inside ``starttime`` .. ``endtime`` and the start of the first one's interval."""
    t = imu.time_s
    keep = np.ones(t.size, dtype=bool)
    if config is not None:
        keep &= t > config.start_time_s
        if config.end_time_s is not None:
            keep &= t <= config.end_time_s + 1e-9
    rows = np.flatnonzero(keep)
    if rows.size < 2:
        raise InvalidParameter("starttime", f"starttime .. endtime leaves {rows.size} IMU samples of "
                                            f"[{t[0]:.3f}, {t[-1]:.3f}] s")
    return float(t[rows[0]] - imu.sample_interval_s), rows


def _sigmas(gnss: GnssRecord, case) -> GnssRecord:
    """The GNSS record with the 1-sigma the options give in place of the file's."""
    position = gnss.position_sigma_m.copy()
    for axis, name in enumerate(("gnss_sigma_north", "gnss_sigma_east", "gnss_sigma_down")):
        if case[name] is not None:
            position[:, axis] = case[name]
    velocity = gnss.velocity_sigma_m_s
    if velocity is not None and case["gnss_velocity_sigma"] is not None:
        velocity = np.full_like(velocity, case["gnss_velocity_sigma"])
    return replace(gnss, position_sigma_m=position, velocity_sigma_m_s=velocity)




def read_inputs(case) -> FileInputs:
    """Read and check the files a case names (module docstring).

    Parameters
    ----------
    case : Case
        A validated case with at least one of :data:`FILE_PARAMETERS` set (paths as text).
    """
    config = load_configuration(case["kf_gins_config"]) if case["kf_gins_config"] is not None else None
    imu_path = case["record"] if case["record"] is not None else (config.imu_path if config else None)
    gnss_path = case["gnss_file"] if case["gnss_file"] is not None else (config.gnss_path if config else None)
    if imu_path is None:
        raise InvalidParameter("record", "give the IMU data: `record` FILE (or `kf_gins_config` with imupath)")
    if gnss_path is None:
        raise InvalidParameter("gnss_file", "give the GNSS data: `gnss_file` FILE (or `kf_gins_config` with "
                                            "gnsspath)")
    imu_name = "record" if case["record"] is not None else "imupath"
    imu = read_imu_file(imu_path, imu_rate=config.imu_rate_hz if config else None,
                        columns=config.imu_columns if config else 7, name=imu_name)
    gnss_name = "gnss_file" if case["gnss_file"] is not None else "gnsspath"
    gnss = _sigmas(kfgins.read_gnss(gnss_path, name=gnss_name), case)
    kfgins.check_overlap(imu, gnss, gnss_name)
    t0, rows = _span(imu, config)
    end = t0 + rows.size * imu.sample_interval_s
    scheduled = scheduled_outages(case, end)
    if scheduled:
        gnss = gnss.without(scheduled)
    inside = (gnss.t_s > t0) & (gnss.t_s <= end + 1e-9)
    if not inside.any():
        raise InvalidParameter(gnss_name, f"no GNSS epoch falls inside the IMU data used, [{t0:.3f}, {end:.3f}] s")
    outages = detect_outages(gnss.t_s[inside], gnss.nominal_interval_s) if inside.sum() > 1 else ()
    reference = kfgins.read_navigation(case["reference"]) if case["reference"] is not None else None
    if reference is not None and (reference.t_s[-1] < t0 or reference.t_s[0] > end):
        raise InvalidParameter("reference", f"its span [{reference.t_s[0]:.3f}, {reference.t_s[-1]:.3f}] s does not "
                                            f"overlap the IMU's [{t0:.3f}, {end:.3f}] s")
    increments = np.concatenate([imu.gyro[rows], imu.accel[rows]], axis=1)
    return FileInputs(t0, imu.sample_interval_s, increments, gnss, reference, config, outages)


def reference_at(reference: kfgins.NavigationRecord, t_s: np.ndarray):
    """The reference at times inside its span, linearly interpolated: (rows of ``t_s`` kept, lat, lon, h, v, q).

    Parameters
    ----------
    reference : NavigationRecord
        The truth (SI).
    t_s : ndarray, shape (n,)
        Times, s, increasing.

    Returns
    -------
    kept : ndarray of bool, shape (n,)
        Which times fall inside the reference's span.
    latitude, longitude, height, velocity, quaternion : ndarray
        At the kept times (rad, rad, m, m/s NED, q_bn).
    """
    ref_t = reference.t_s
    kept = (t_s >= ref_t[0] - 1e-9) & (t_s <= ref_t[-1] + 1e-9)
    t = t_s[kept]
    right = np.clip(np.searchsorted(ref_t, t), 1, ref_t.size - 1)
    left = right - 1
    span = ref_t[right] - ref_t[left]
    w = np.clip((t - ref_t[left]) / np.where(span > 0, span, 1.0), 0.0, 1.0)

    def lerp(values):
        weight = w.reshape(w.shape + (1,) * (values.ndim - 1))
        return values[left] * (1 - weight) + values[right] * weight

    q = quaternion_from_euler(*reference.attitude_rad.T)
    q_right = q[right] * np.sign(np.sum(q[left] * q[right], axis=-1, keepdims=True))  # the same hemisphere
    q_at = q[left] * (1 - w[:, None]) + q_right * w[:, None]
    q_at /= np.linalg.norm(q_at, axis=-1, keepdims=True)
    return kept, lerp(reference.latitude_rad), lerp(reference.longitude_rad), lerp(reference.height_m), \
        lerp(reference.velocity_ned_m_s), q_at


def start_of(inputs: FileInputs, sigma) -> Start:
    """The filter's start: the configuration's initial state, else the reference's, else the record's site at rest.

    Parameters
    ----------
    inputs : FileInputs
        The data read.
    sigma : tuple
        1-sigma of position (m), velocity (m/s), psi (rad, 3) where the configuration gives none.
    """
    config = inputs.configuration
    if config is not None:
        roll, pitch, yaw = config.initial_attitude_rad
        return Start(np.array([config.initial_position[0]]), np.array([config.initial_position[1]]),
                     np.array([config.initial_position[2]]), config.initial_velocity_m_s[None, :],
                     quaternion_from_euler(roll, pitch, yaw)[None, :], config.initial_position_sigma_m,
                     config.initial_velocity_sigma_m_s, config.initial_attitude_sigma_rad)
    position, velocity, attitude = sigma
    if inputs.reference is not None:
        kept, lat, lon, h, v, q = reference_at(inputs.reference, np.array([inputs.t0_s]))
        if not kept[0]:
            raise InvalidParameter("reference", f"does not reach back to the IMU data's start, {inputs.t0_s:.3f} s: "
                                                "the start is taken from it (or give `kf_gins_config`)")
        return Start(lat, lon, h, v, q, np.full(3, position), np.full(3, velocity), np.asarray(attitude))
    raise InvalidParameter("kf_gins_config", "a run on files needs its initial state: give `kf_gins_config` "
                                             "(initpos, initvel, initatt) or `reference` (its state at the start)")


def lever_arm_of(case, config: KfGinsConfiguration | None) -> tuple[float, float, float]:
    """The antenna lever arm, m: each axis from its option when given, else ``antlever``, else 0.

    Parameters
    ----------
    case : Case
        A validated case (``lever_arm_x|y|z`` in m or None).
    config : KfGinsConfiguration or None
        The configuration.
    """
    base = (0.0, 0.0, 0.0) if config is None else tuple(float(v) for v in config.antenna_lever_arm_m)
    return tuple(base[axis] if case[name] is None else float(case[name])  # type: ignore[return-value]
                 for axis, name in enumerate(("lever_arm_x", "lever_arm_y", "lever_arm_z")))

