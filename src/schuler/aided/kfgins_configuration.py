"""KF-GINS's YAML configuration read as KF-GINS reads it, into a frozen configuration in SI.

Every key KF-GINS's ``loadConfig`` and ``main`` read (:data:`CONFIGURATION_KEYS`, :data:`NOISE_KEYS`), in its
units: degrees, deg/h, mGal (1 mGal = 1e-5 m/s^2), ppm, deg/sqrt(h), m/s/sqrt(h), hours. All are mandatory but
``initbgstd``, ``initbastd``, ``initsgstd`` and ``initsastd``, which default (as in KF-GINS) to the bias and
scale-factor instabilities ``gbstd``, ``abstd``, ``gsstd``, ``asstd``. Unknown keys are refused with the closest
known key; a key given twice, wrong lengths and types are refused naming the key. KF-GINS takes any negative
``endtime`` as "to the end" and needs integers for ``imudatalen`` and ``imudatarate``; so does this reader.

KF-GINS resolves relative paths against its working directory; here they are relative to the YAML file's
folder unless ``base`` says otherwise (KF-GINS's own example, ``./dataset/...`` beside ``dataset/kf-gins.yaml``,
needs ``base`` set to the folder it is run from).

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> _ = (folder / "kf-gins.yaml").write_text(example_configuration())
>>> config = read_configuration(folder / "kf-gins.yaml")
>>> round(float(np.degrees(config.initial_position[0])), 6), config.imu_rate_hz, config.end_time_s
(30.5, 200.0, None)
>>> _ = (folder / "bad.yaml").write_text(example_configuration().replace("initpos:", "initpso:"))
>>> read_configuration(folder / "bad.yaml")
Traceback (most recent call last):
...
schuler.exceptions.InvalidParameter: initpso: unknown key; did you mean 'initpos'?
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from schuler.aided.epochs import LARGEST_LEVER_ARM_M
from schuler.aided.kfgins import SECONDS_PER_WEEK
from schuler.exceptions import InvalidParameter

MGAL = 1e-5
"""One milligal, m/s^2."""

PPM = 1e-6
"""One part per million."""



_DEG = math.pi / 180.0
_VECTOR_KEYS = {
    # key: (field, factor to SI, unit in the file, may it be negative)
    "initvel": ("initial_velocity_m_s", 1.0, "m/s", True),
    "initatt": ("initial_attitude_rad", _DEG, "deg", True),
    "initgyrbias": ("initial_gyro_bias_rad_s", _DEG / 3600.0, "deg/h", True),
    "initaccbias": ("initial_accel_bias_m_s2", MGAL, "mGal", True),
    "initgyrscale": ("initial_gyro_scale_factor", PPM, "ppm", True),
    "initaccscale": ("initial_accel_scale_factor", PPM, "ppm", True),
    "initposstd": ("initial_position_sigma_m", 1.0, "m", False),
    "initvelstd": ("initial_velocity_sigma_m_s", 1.0, "m/s", False),
    "initattstd": ("initial_attitude_sigma_rad", _DEG, "deg", False),
    "initbgstd": ("initial_gyro_bias_sigma_rad_s", _DEG / 3600.0, "deg/h", False),
    "initbastd": ("initial_accel_bias_sigma_m_s2", MGAL, "mGal", False),
    "initsgstd": ("initial_gyro_scale_factor_sigma", PPM, "ppm", False),
    "initsastd": ("initial_accel_scale_factor_sigma", PPM, "ppm", False),
    "antlever": ("antenna_lever_arm_m", 1.0, "m", True),
}
_NOISE_KEYS = {
    "arw": ("gyro_angle_random_walk_rad_sqrt_s", _DEG / 60.0, "deg/sqrt(h)", False),
    "vrw": ("accel_velocity_random_walk_m_s_sqrt_s", 1.0 / 60.0, "m/s/sqrt(h)", False),
    "gbstd": ("gyro_bias_sigma_rad_s", _DEG / 3600.0, "deg/h", False),
    "abstd": ("accel_bias_sigma_m_s2", MGAL, "mGal", False),
    "gsstd": ("gyro_scale_factor_sigma", PPM, "ppm", False),
    "asstd": ("accel_scale_factor_sigma", PPM, "ppm", False),
}
_OPTIONAL = {"initbgstd": "gbstd", "initbastd": "abstd", "initsgstd": "gsstd", "initsastd": "asstd"}
_SCALAR_KEYS = ("imupath", "gnsspath", "outputpath", "imudatalen", "imudatarate", "starttime", "endtime", "initpos")
CONFIGURATION_KEYS = (*_SCALAR_KEYS, *_VECTOR_KEYS, "imunoise")
"""The top-level keys KF-GINS reads; ``imunoise`` holds arw, vrw, gbstd, abstd, gsstd, asstd and corrtime.
All are mandatory but initbgstd, initbastd, initsgstd and initsastd (default: gbstd, abstd, gsstd, asstd)."""
NOISE_KEYS = (*_NOISE_KEYS, "corrtime")
"""The keys of ``imunoise``, all mandatory."""


@dataclass(frozen=True, eq=False)
class KfGinsConfiguration:
    """A KF-GINS configuration in SI (arrays of 3 are read-only; axes: NED for the state, body FRD for the IMU).

    Attributes
    ----------
    source : Path
        The YAML file.
    imu_path, gnss_path, output_path : Path
        ``imupath``, ``gnsspath``, ``outputpath``, resolved against the folder given to the reader.
    imu_columns : int
        ``imudatalen``: columns of the IMU file (>= 7; the first seven are used).
    imu_rate_hz : float
        ``imudatarate``, Hz.
    start_time_s : float
        ``starttime``, seconds of week.
    end_time_s : float or None
        ``endtime``, seconds of week; None for a negative value (to the end of the IMU file).
    initial_position : ndarray
        ``initpos``: latitude, longitude (rad), height (m).
    initial_velocity_m_s, initial_attitude_rad : ndarray
        ``initvel`` (v_N, v_E, v_D, m/s); ``initatt`` (roll, pitch, yaw, rad).
    initial_gyro_bias_rad_s, initial_accel_bias_m_s2 : ndarray
        ``initgyrbias`` (rad/s), ``initaccbias`` (m/s^2).
    initial_gyro_scale_factor, initial_accel_scale_factor : ndarray
        ``initgyrscale``, ``initaccscale``, dimensionless.
    initial_position_sigma_m, initial_velocity_sigma_m_s, initial_attitude_sigma_rad : ndarray
        ``initposstd`` (north, east, down, m), ``initvelstd`` (m/s), ``initattstd`` (roll, pitch, yaw, rad).
    initial_gyro_bias_sigma_rad_s, initial_accel_bias_sigma_m_s2 : ndarray
        ``initbgstd`` (rad/s), ``initbastd`` (m/s^2); default the bias instabilities below.
    initial_gyro_scale_factor_sigma, initial_accel_scale_factor_sigma : ndarray
        ``initsgstd``, ``initsastd``, dimensionless; default the scale-factor instabilities below.
    gyro_angle_random_walk_rad_sqrt_s, accel_velocity_random_walk_m_s_sqrt_s : ndarray
        ``imunoise.arw`` (rad/sqrt(s)), ``imunoise.vrw`` (m/s/sqrt(s)).
    gyro_bias_sigma_rad_s, accel_bias_sigma_m_s2 : ndarray
        ``imunoise.gbstd`` (rad/s), ``imunoise.abstd`` (m/s^2): steady 1-sigma of the Gauss-Markov biases.
    gyro_scale_factor_sigma, accel_scale_factor_sigma : ndarray
        ``imunoise.gsstd``, ``imunoise.asstd``, dimensionless: steady 1-sigma of the Gauss-Markov scale factors.
    correlation_time_s : float
        ``imunoise.corrtime``, s: of the biases and scale factors alike.
    antenna_lever_arm_m : ndarray
        ``antlever``: the GNSS antenna from the IMU, body x forward, y right, z down, m.
    """

    source: Path
    imu_path: Path
    gnss_path: Path
    output_path: Path
    imu_columns: int
    imu_rate_hz: float
    start_time_s: float
    end_time_s: float | None
    initial_position: np.ndarray
    initial_velocity_m_s: np.ndarray
    initial_attitude_rad: np.ndarray
    initial_gyro_bias_rad_s: np.ndarray
    initial_accel_bias_m_s2: np.ndarray
    initial_gyro_scale_factor: np.ndarray
    initial_accel_scale_factor: np.ndarray
    initial_position_sigma_m: np.ndarray
    initial_velocity_sigma_m_s: np.ndarray
    initial_attitude_sigma_rad: np.ndarray
    initial_gyro_bias_sigma_rad_s: np.ndarray
    initial_accel_bias_sigma_m_s2: np.ndarray
    initial_gyro_scale_factor_sigma: np.ndarray
    initial_accel_scale_factor_sigma: np.ndarray
    gyro_angle_random_walk_rad_sqrt_s: np.ndarray
    accel_velocity_random_walk_m_s_sqrt_s: np.ndarray
    gyro_bias_sigma_rad_s: np.ndarray
    accel_bias_sigma_m_s2: np.ndarray
    gyro_scale_factor_sigma: np.ndarray
    accel_scale_factor_sigma: np.ndarray
    correlation_time_s: float
    antenna_lever_arm_m: np.ndarray


def _number(key: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InvalidParameter(key, f"must be a finite number, got {value!r}")
    return float(value)


def _triple(key: str, value, unit: str, signed: bool = True) -> np.ndarray:
    if not isinstance(value, list) or len(value) != 3:
        raise InvalidParameter(key, f"must be a list of 3 numbers in {unit}, got {value!r}")
    array = np.array([_number(key, v) for v in value])
    if not signed and np.any(array < 0):
        raise InvalidParameter(key, f"standard deviations must be >= 0, got {value!r}")
    return array


def _refuse_unknown(mapping: dict, allowed, where: str = "") -> None:
    for key in mapping:
        if key not in allowed:
            close = difflib.get_close_matches(str(key), list(allowed), n=1)
            hint = f"did you mean '{close[0]}'?" if close else f"allowed: {', '.join(allowed)}"
            raise InvalidParameter(f"{where}{key}", f"unknown key; {hint}")


def _load_yaml(path: Path) -> dict:
    import yaml

    class _UniqueKeys(yaml.SafeLoader):
        """A safe loader refusing a key given twice (PyYAML keeps the last silently)."""

    def mapping(loader, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = loader.construct_object(key_node, deep=deep)
            if key in seen:
                raise InvalidParameter(str(key), f"given twice in {path.name} (line {key_node.start_mark.line + 1})")
            seen.add(key)
        return loader.construct_mapping(node, deep)

    _UniqueKeys.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, mapping)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise InvalidParameter("kf_gins_config", f"{path}: cannot be read ({error})") from None
    try:
        data = yaml.load(text, Loader=_UniqueKeys)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" line {mark.line + 1}" if mark is not None else ""
        raise InvalidParameter("kf_gins_config", f"{path.name}{where}: not valid YAML "
                                                 f"({getattr(error, 'problem', None) or error})") from None
    if not isinstance(data, dict):
        raise InvalidParameter("kf_gins_config", f"{path.name}: must be a mapping of KF-GINS's keys")
    return data


def _whole(key: str, value, smallest: int) -> int:
    number = _number(key, value)
    if number != round(number) or number < smallest:
        raise InvalidParameter(key, f"must be a whole number >= {smallest} (KF-GINS reads an integer), got {value!r}")
    return int(number)


def read_configuration(path, *, base=None) -> KfGinsConfiguration:
    """Read a KF-GINS YAML configuration as KF-GINS reads it, into SI.

    Parameters
    ----------
    path : str or Path
        The YAML file.
    base : str or Path, optional
        Folder against which relative paths are resolved; default the YAML file's folder (KF-GINS itself uses
        its working directory: pass ``Path.cwd()`` to run a configuration written for that).

    Returns
    -------
    KfGinsConfiguration

    Raises
    ------
    InvalidParameter
        One line naming the key: unknown (with the closest known key), missing, of the wrong type or length,
        out of range; or the file is not valid YAML.
    """
    path = Path(path)
    data = _load_yaml(path)
    _refuse_unknown(data, CONFIGURATION_KEYS)
    missing = [key for key in CONFIGURATION_KEYS if key not in data and key not in _OPTIONAL]
    if missing:
        raise InvalidParameter(missing[0], f"missing from {path.name} (KF-GINS needs "
                                           f"{', '.join(missing)})")
    noise = data["imunoise"]
    if not isinstance(noise, dict):
        raise InvalidParameter("imunoise", f"must be a mapping of {', '.join(NOISE_KEYS)}")
    _refuse_unknown(noise, NOISE_KEYS, "imunoise.")
    if missing := [key for key in NOISE_KEYS if key not in noise]:
        raise InvalidParameter(f"imunoise.{missing[0]}", f"missing from {path.name}")
    folder = path.parent if base is None else Path(base)
    paths = {}
    for key in ("imupath", "gnsspath", "outputpath"):
        if not isinstance(data[key], str) or not data[key].strip():
            raise InvalidParameter(key, f"must be a path (text), got {data[key]!r}")
        paths[key] = (folder / data[key].strip()).resolve()
    fields = {}
    for key, (name, factor, unit, signed) in _NOISE_KEYS.items():
        fields[name] = _triple(f"imunoise.{key}", noise[key], unit, signed) * factor
    for key, (name, factor, unit, signed) in _VECTOR_KEYS.items():
        value = data.get(key, noise.get(_OPTIONAL.get(key, "")))
        fields[name] = _triple(key, value, unit, signed) * factor
    correlation_time = _number("imunoise.corrtime", noise["corrtime"])
    if correlation_time <= 0:
        raise InvalidParameter("imunoise.corrtime", f"must be > 0 h, got {noise['corrtime']!r}")
    position = _triple("initpos", data["initpos"], "deg, deg, m")
    if abs(position[0]) > 90.0:
        raise InvalidParameter("initpos", f"latitude {position[0]:g} deg is beyond +/-90 deg")
    if np.linalg.norm(fields["antenna_lever_arm_m"]) > LARGEST_LEVER_ARM_M:
        raise InvalidParameter("antlever", f"{data['antlever']} is longer than {LARGEST_LEVER_ARM_M:g} m: KF-GINS "
                                           "reads metres (is it in cm or mm?)")
    start, end = _number("starttime", data["starttime"]), _number("endtime", data["endtime"])
    if not 0.0 <= start <= SECONDS_PER_WEEK or end > SECONDS_PER_WEEK or (end >= 0 and end < start):
        raise InvalidParameter("starttime", f"starttime {start:g} s and endtime {end:g} s must satisfy 0 <= "
                               f"starttime <= endtime <= {SECONDS_PER_WEEK:g} s (endtime negative: to the end)")
    for array in fields.values():
        array.setflags(write=False)
    initial_position = np.array([math.radians(position[0]), math.radians(position[1]), position[2]])
    initial_position.setflags(write=False)
    return KfGinsConfiguration(
        source=path, imu_path=paths["imupath"], gnss_path=paths["gnsspath"], output_path=paths["outputpath"],
        imu_columns=_whole("imudatalen", data["imudatalen"], 7),
        imu_rate_hz=float(_whole("imudatarate", data["imudatarate"], 1)),
        start_time_s=start, end_time_s=None if end < 0 else end, initial_position=initial_position,
        correlation_time_s=correlation_time * 3600.0, **fields)


def example_configuration(imu_path: str = "imu.txt", gnss_path: str = "gnss.txt", output_path: str = "results") -> str:
    """The text of a complete KF-GINS configuration: a tactical-grade IMU at 200 Hz on the default drive.

    Parameters
    ----------
    imu_path, gnss_path, output_path : str
        The paths written for ``imupath``, ``gnsspath``, ``outputpath``.

    Returns
    -------
    str
        YAML text with every key KF-GINS reads, commented with its unit.
    """
    return f"""\
# A KF-GINS configuration: data files, processing interval, initial state, IMU noise, antenna lever arm.
imupath: "{imu_path}"        # IMU increments, 7 columns
gnsspath: "{gnss_path}"      # GNSS positions, 7 or 13 columns
outputpath: "{output_path}"  # folder of the results
imudatalen: 7                # columns of the IMU file
imudatarate: 200             # Hz
starttime: 0                 # seconds of week
endtime: -1                  # seconds of week; -1: to the end of the IMU file

initpos: [30.5, 114.5, 20.0]     # latitude deg, longitude deg, height m
initvel: [0.0, 0.0, 0.0]         # north, east, down, m/s
initatt: [0.0, 0.0, 0.0]         # roll, pitch, yaw, deg

initgyrbias: [0.0, 0.0, 0.0]     # deg/h, body forward, right, down
initaccbias: [0.0, 0.0, 0.0]     # mGal
initgyrscale: [0.0, 0.0, 0.0]    # ppm
initaccscale: [0.0, 0.0, 0.0]    # ppm

initposstd: [0.1, 0.1, 0.2]      # north, east, down, m
initvelstd: [0.05, 0.05, 0.05]   # m/s
initattstd: [0.05, 0.05, 0.5]    # roll, pitch, yaw, deg
initbgstd: [1.0, 1.0, 1.0]       # deg/h (default: imunoise gbstd)
initbastd: [100.0, 100.0, 100.0] # mGal (default: imunoise abstd)

imunoise:
  arw: [0.1, 0.1, 0.1]           # deg/sqrt(h)
  vrw: [0.1, 0.1, 0.1]           # m/s/sqrt(h)
  gbstd: [1.0, 1.0, 1.0]         # deg/h
  abstd: [100.0, 100.0, 100.0]   # mGal
  gsstd: [500.0, 500.0, 500.0]   # ppm
  asstd: [500.0, 500.0, 500.0]   # ppm
  corrtime: 1.0                  # h

antlever: [0.5, 0.0, -1.0]       # forward, right, down, m
"""
