"""Benchmark and reference: schuler's aided filter against KF-GINS (the C++ reference) on the same data.

The data: the default drive (:func:`schuler.navigate.drive.drive`, 1,500 s at 200 Hz: 300,000 IMU epochs), an IMU
whose errors are those a KF-GINS configuration states (:data:`NOISE`, a tactical grade: angle and velocity random
walks, Gauss-Markov biases of the stated 1-sigma and correlation time, constant scale-factor errors of the stated
1-sigma; simulated by :class:`schuler.imu.simulate.ImuSimulator`), 1-Hz RTK-like GNSS positions at KF-GINS's
example lever arm with three 60-s outages, all written in KF-GINS's own formats (:mod:`schuler.aided.kfgins`) with
a configuration in its own YAML (seconds of week from :data:`WEEK_START`).

Both tools run on those files:

* KF-GINS, the executable named by the environment variable ``SCHULER_KFGINS`` (built from i2Nav-WHU/KF-GINS
  outside this project), as a child process: wall and CPU seconds of the child;
* schuler, in-process and as its command would: the configuration, the IMU and GNSS files read, KF-GINS's model
  (GNSS position only, 21 states, ``corrtime`` on the biases and scale factors alike, no gate, as KF-GINS) filtered
  by :func:`schuler.aided.ekf.run_filter` with its covariance step of 1 s, and the navigation written in KF-GINS's
  result format at every IMU epoch; wall and CPU seconds of this process (kernels compiled before the clock).

Against the truth, for each: the horizontal position RMS, the largest horizontal error in each outage and the
heading RMS (KF-GINS's result read with :func:`schuler.aided.kfgins.read_navigation`). Without ``SCHULER_KFGINS``
the comparison is skipped (say so and exit 0). Printed beside the timings: the load average (two shared cores
move wall-clock times by up to 3x).

Run: ``SCHULER_KFGINS=/path/to/KF-GINS python benchmarks/bench_aided_kfgins.py [--duration S] [--seed K]``.

Measured (seed 1, load average 14 on two cores; KF-GINS built Release, -O3, with Debian's Eigen 3.4, yaml-cpp
0.7 and abseil 20220623): horizontal RMS 0.505 m (KF-GINS 0.492 m), outages 1.14, 4.32, 3.98 m (1.25, 4.04,
4.03 m), heading RMS 0.0466 deg (0.0466 deg); KF-GINS 5.0 s CPU, schuler 2.6 s CPU for the whole (1.4 s the
filter). Over seeds 1-6 schuler's horizontal RMS is 0.98-1.03 times KF-GINS's and each outage's largest error
0.91-1.07 times. The difference is schuler's Gauss-Markov estimates relaxing towards zero between updates (as the
mean of the modelled process does); KF-GINS keeps its fed-back biases and scale factors constant: without that
decay and with a 0.1-s covariance step schuler gives KF-GINS's figures within 0.1 %.
"""

from __future__ import annotations

import os

# one BLAS thread, set before numpy loads it: on two shared cores a threaded BLAS makes each of the filter's small
# matrix exponentials ~10x slower (spinning threads)
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import math
import resource
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from schuler.aided.ekf import Start, run_filter
from schuler.aided.error_state import ErrorProcess, FilterModel
from schuler.aided.gnss import simulate_gnss
from schuler.aided.kfgins import (
    NavigationRecord,
    read_gnss,
    read_imu,
    read_navigation,
    write_gnss,
    write_imu,
    write_navigation,
)
from schuler.aided.kfgins_configuration import KfGinsConfiguration, read_configuration
from schuler.core.attitude import euler_from_quaternion, quaternion_from_euler, wrap_angle
from schuler.core.earth import radii_of_curvature
from schuler.core.random import RandomStreams
from schuler.imu.error_model import ErrorModel, SensorErrors
from schuler.imu.record import ImuRecord
from schuler.imu.simulate import ImuSimulator
from schuler.navigate.drive import drive
from schuler.navigate.truth import ideal_imu

ENVIRONMENT = "SCHULER_KFGINS"
"""The environment variable naming the KF-GINS executable."""

RATE = 200.0
"""IMU rate, Hz."""

WEEK_START = 456300.0
"""Seconds of week at the drive's start (KF-GINS's example data start there)."""

OUTAGES = ((400.0, 60.0), (800.0, 60.0), (1200.0, 60.0))
"""GNSS outages of the 1,500-s drive, (start, duration) s from the drive's start."""

NOISE = {"arw": 0.1, "vrw": 0.1, "gbstd": 1.0, "abstd": 100.0, "gsstd": 500.0, "asstd": 500.0, "corrtime": 1.0}
"""The IMU's errors in KF-GINS's units: deg/sqrt(h), m/s/sqrt(h), deg/h, mGal, ppm, ppm, h (a tactical grade)."""

GNSS_SIGMA = (0.02, 0.02, 0.05)
"""GNSS position 1-sigma north, east, down, m (RTK-like, as KF-GINS's example data)."""

LEVER_ARM = (0.136, -0.301, -0.184)
"""IMU to GNSS antenna, body forward, right, down, m (KF-GINS's example ``antlever``)."""

INITIAL_SIGMA = ((0.1, 0.1, 0.2), (0.05, 0.05, 0.05), (0.05, 0.05, 0.5))
"""``initposstd`` (m), ``initvelstd`` (m/s), ``initattstd`` (deg) of the configuration."""

COVARIANCE_INTERVAL = 1.0
"""schuler's covariance step, s (KF-GINS propagates its covariance at every IMU epoch)."""

_DEG = math.pi / 180.0


@dataclass(frozen=True)
class Case:
    """A simulated drive written in KF-GINS's formats, with its truth at every IMU epoch.

    Attributes
    ----------
    folder : Path
        Where the files are.
    configuration : Path
        The KF-GINS YAML.
    t_s : ndarray, shape (n,)
        Truth times (the IMU stamps), seconds of week.
    latitude, longitude, height : ndarray, shape (n,)
        True position, rad, rad, m.
    attitude : ndarray, shape (n, 3)
        True roll, pitch, heading, rad.
    outages : tuple of (float, float)
        The outages in seconds of week, (start, duration) s.
    """

    folder: Path
    configuration: Path
    t_s: np.ndarray
    latitude: np.ndarray
    longitude: np.ndarray
    height: np.ndarray
    attitude: np.ndarray
    outages: tuple[tuple[float, float], ...]


@dataclass(frozen=True)
class Accuracy:
    """One tool's errors against the truth (computed - true).

    Attributes
    ----------
    horizontal_rms_m : float
        RMS of the horizontal position error over every output epoch, m.
    outage_max_m : tuple of float
        Largest horizontal error inside each outage, m.
    heading_rms_rad : float
        RMS of the heading error, rad.
    epochs : int
        Output epochs compared, number of.
    """

    horizontal_rms_m: float
    outage_max_m: tuple[float, ...]
    heading_rms_rad: float
    epochs: int


def error_model() -> ErrorModel:
    """The IMU's errors of :data:`NOISE` in SI, for the IMU layer's simulator.

    Returns
    -------
    ErrorModel
        White noise, Gauss-Markov biases (steady 1-sigma, correlation time) and constant scale factors.
    """
    corr = NOISE["corrtime"] * 3600.0
    gyro = SensorErrors(random_walk=NOISE["arw"] * _DEG / 60.0, gm_sigma=NOISE["gbstd"] * _DEG / 3600.0,
                        gm_correlation_time_s=corr, scale_factor=NOISE["gsstd"] * 1e-6)
    accel = SensorErrors(random_walk=NOISE["vrw"] / 60.0, gm_sigma=NOISE["abstd"] * 1e-5,
                         gm_correlation_time_s=corr, scale_factor=NOISE["asstd"] * 1e-6)
    return ErrorModel(gyro, accel, name="KF-GINS tactical", source="benchmarks/bench_aided_kfgins.py")


def _triple(values) -> str:
    return "[" + ", ".join(f"{v:.12g}" for v in values) + "]"


def configuration_text(imu_path: Path, gnss_path: Path, output_path: Path, start_s: float, position, velocity,
                       attitude) -> str:
    """A KF-GINS configuration in KF-GINS's own YAML: every key it reads, in its units.

    Parameters
    ----------
    imu_path, gnss_path, output_path : Path
        The data files and the output folder (written absolute: KF-GINS resolves against its working directory).
    start_s : float
        ``starttime``, seconds of week (the first IMU stamp: KF-GINS propagates from the sample after it).
    position : sequence of float
        Latitude, longitude (rad), height (m) at ``start_s``.
    velocity : sequence of float
        v_N, v_E, v_D at ``start_s``, m/s.
    attitude : sequence of float
        Roll, pitch, heading at ``start_s``, rad.

    Returns
    -------
    str
    """
    position_sigma, velocity_sigma, attitude_sigma = INITIAL_SIGMA
    heading = math.degrees(attitude[2]) % 360.0
    return f"""\
# KF-GINS configuration of schuler's benchmark drive (benchmarks/bench_aided_kfgins.py)
imupath: "{imu_path}"
gnsspath: "{gnss_path}"
outputpath: "{output_path}"
imudatalen: 7
imudatarate: {RATE:.0f}
starttime: {start_s:.9f}
endtime: -1

initpos: [{math.degrees(position[0]):.12f}, {math.degrees(position[1]):.12f}, {position[2]:.9f}]  # deg, deg, m
initvel: {_triple(velocity)}  # m/s
initatt: [{math.degrees(attitude[0]):.12f}, {math.degrees(attitude[1]):.12f}, {heading:.12f}]  # deg

initgyrbias: [0, 0, 0]    # deg/h
initaccbias: [0, 0, 0]    # mGal
initgyrscale: [0, 0, 0]   # ppm
initaccscale: [0, 0, 0]   # ppm

initposstd: {_triple(position_sigma)}   # m
initvelstd: {_triple(velocity_sigma)}   # m/s
initattstd: {_triple(attitude_sigma)}   # deg

imunoise:
  arw: {_triple([NOISE["arw"]] * 3)}      # deg/sqrt(h)
  vrw: {_triple([NOISE["vrw"]] * 3)}      # m/s/sqrt(h)
  gbstd: {_triple([NOISE["gbstd"]] * 3)}    # deg/h
  abstd: {_triple([NOISE["abstd"]] * 3)}    # mGal
  gsstd: {_triple([NOISE["gsstd"]] * 3)}    # ppm
  asstd: {_triple([NOISE["asstd"]] * 3)}    # ppm
  corrtime: {NOISE["corrtime"]:g}           # h

antlever: {_triple(LEVER_ARM)}   # m, forward, right, down
"""


def write_case(folder, duration: float = 1500.0, outages=OUTAGES, seed: int = 1) -> Case:
    """Simulate the drive and write its IMU, GNSS, truth and configuration in KF-GINS's formats.

    Parameters
    ----------
    folder : str or Path
        Folder of the files (``imu.txt``, ``gnss.txt``, ``truth.nav``, ``kf-gins.yaml``, ``kfgins/``).
    duration : float
        Length of the drive, s (>= 300).
    outages : sequence of (float, float)
        GNSS outages, (start, duration) s from the drive's start.
    seed : int
        Seed of the IMU errors and the GNSS noise, number.

    Returns
    -------
    Case
    """
    folder = Path(folder)
    (folder / "kfgins").mkdir(parents=True, exist_ok=True)
    path = drive(duration=duration)
    truth = ideal_imu(path, duration, RATE)
    dt = truth.interval_s
    simulator = ImuSimulator(error_model(), dt, true_gyro=truth.angle_increment_rad / dt,
                             true_accel=truth.velocity_increment_m_s / dt, seed=seed)
    gyro, accel = simulator.window(np.array([0]), 0, truth.t_s.size)
    t = WEEK_START + truth.t_s
    imu = ImuRecord(time_s=t, gyro=gyro[0] * dt, accel=accel[0] * dt, kind="increment", sample_interval_s=dt,
                    source="simulated drive")
    write_imu(folder / "imu.txt", imu)
    gnss = simulate_gnss(path, duration, imu_rate=RATE, gnss_rate=1.0, position_sigma=GNSS_SIGMA,
                         lever_arm=LEVER_ARM, outages=outages, streams=RandomStreams(seed), member=0)
    write_gnss(folder / "gnss.txt", replace(gnss, t_s=WEEK_START + gnss.t_s))
    attitude = euler_from_quaternion(truth.quaternion)
    write_navigation(folder / "truth.nav", NavigationRecord(np.zeros(t.size, dtype=np.int64), t, truth.latitude_rad,
                                                            truth.longitude_rad, truth.height_m,
                                                            truth.velocity_ned_m_s, attitude))
    position = (truth.latitude_rad[0], truth.longitude_rad[0], truth.height_m[0])
    text = configuration_text(folder / "imu.txt", folder / "gnss.txt", folder / "kfgins", float(t[0]), position,
                              truth.velocity_ned_m_s[0], attitude[0])
    (folder / "kf-gins.yaml").write_text(text, encoding="utf-8")
    return Case(folder, folder / "kf-gins.yaml", t, truth.latitude_rad, truth.longitude_rad, truth.height_m,
                attitude, tuple((WEEK_START + s, d) for s, d in outages))


def accuracy(case: Case, t_s, latitude, longitude, attitude) -> Accuracy:
    """Errors of a navigation solution against the case's truth at the solution's epochs.

    Parameters
    ----------
    case : Case
        The truth.
    t_s : array_like, shape (n,)
        Epochs of the solution, seconds of week (IMU stamps).
    latitude, longitude : array_like, shape (n,)
        Its position, rad.
    attitude : array_like, shape (n, 3)
        Its roll, pitch, heading, rad.

    Returns
    -------
    Accuracy
    """
    t_s = np.asarray(t_s, dtype=float)
    rows = np.rint((t_s - case.t_s[0]) * RATE).astype(np.int64)
    if rows.min() < 0 or rows.max() >= case.t_s.size or np.max(np.abs(case.t_s[rows] - t_s)) > 1e-6:
        raise ValueError("the solution's epochs are not the truth's")
    lat0, h = case.latitude[rows], case.height[rows]
    R_N, R_E = radii_of_curvature(lat0)
    north = (np.asarray(latitude) - lat0) * (R_N + h)
    east = wrap_angle(np.asarray(longitude) - case.longitude[rows]) * (R_E + h) * np.cos(lat0)
    horizontal = np.hypot(north, east)
    heading = wrap_angle(np.asarray(attitude)[:, 2] - case.attitude[rows, 2])
    worst = tuple(float(horizontal[(t_s > s) & (t_s <= s + d + 1e-9)].max()) for s, d in case.outages)
    return Accuracy(float(np.sqrt(np.mean(horizontal**2))), worst, float(np.sqrt(np.mean(heading**2))), t_s.size)


def _child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_kfgins(executable, case: Case) -> tuple[NavigationRecord, float, float]:
    """Run KF-GINS on the case's configuration; its result read back.

    Parameters
    ----------
    executable : str or Path
        The KF-GINS executable.
    case : Case
        The files.

    Returns
    -------
    navigation : NavigationRecord
        KF-GINS's ``KF_GINS_Navresult.nav``.
    wall, cpu : float
        Seconds of the child process (wall; user + system CPU).
    """
    cpu0, wall0 = _child_cpu(), time.perf_counter()
    done = subprocess.run([str(executable), str(case.configuration)], cwd=case.folder, capture_output=True,
                          text=True, check=False)
    wall, cpu = time.perf_counter() - wall0, _child_cpu() - cpu0
    if done.returncode != 0:
        raise RuntimeError(f"KF-GINS failed ({done.returncode}): {done.stdout[-500:]} {done.stderr[-500:]}")
    return read_navigation(case.folder / "kfgins" / "KF_GINS_Navresult.nav"), wall, cpu


def kfgins_model(config: KfGinsConfiguration) -> FilterModel:
    """KF-GINS's filter model of a configuration: 21 states, every sensor error Gauss-Markov with ``corrtime``.

    KF-GINS starts each sensor-error state at ``initbgstd`` ... (default the steady 1-sigma ``gbstd`` ...);
    :class:`~schuler.aided.error_state.ErrorProcess` has one 1-sigma for both, so the two must agree.

    Parameters
    ----------
    config : KfGinsConfiguration
        The configuration (SI).

    Returns
    -------
    FilterModel
    """
    pairs = ((config.gyro_bias_sigma_rad_s, config.initial_gyro_bias_sigma_rad_s),
             (config.accel_bias_sigma_m_s2, config.initial_accel_bias_sigma_m_s2),
             (config.gyro_scale_factor_sigma, config.initial_gyro_scale_factor_sigma),
             (config.accel_scale_factor_sigma, config.initial_accel_scale_factor_sigma))
    if any(not np.array_equal(steady, initial) for steady, initial in pairs):
        raise ValueError("initbgstd, initbastd, initsgstd, initsastd must equal gbstd, abstd, gsstd, asstd here")
    processes = [ErrorProcess("gauss-markov", steady, correlation_time=config.correlation_time_s)
                 for steady, _ in pairs]
    return FilterModel(config.gyro_angle_random_walk_rad_sqrt_s, config.accel_velocity_random_walk_m_s_sqrt_s,
                       *processes)


def run_schuler(case: Case, covariance_interval: float = COVARIANCE_INTERVAL):
    """schuler on the case's files, as its command would: read, filter with KF-GINS's model, write the result.

    Parameters
    ----------
    case : Case
        The files.
    covariance_interval : float
        Covariance step, s.

    Returns
    -------
    navigation : NavigationRecord
        The filter's solution at every IMU epoch after ``starttime`` (also written to ``schuler.nav``).
    wall, cpu, filter_cpu : float
        Seconds: wall and CPU of the whole (read, filter, write), CPU of the filter alone.
    """
    wall0, cpu0 = time.perf_counter(), time.process_time()
    config = read_configuration(case.configuration)
    imu = read_imu(config.imu_path, imu_rate=config.imu_rate_hz, columns=config.imu_columns)
    gnss = read_gnss(config.gnss_path)
    after = imu.time_s > config.start_time_s + 1e-9  # KF-GINS propagates from the sample after starttime
    increments = np.concatenate([imu.gyro_increment_rad, imu.accel_increment_m_s], axis=1)[after]
    lat, lon, h = config.initial_position
    roll, pitch, heading = config.initial_attitude_rad
    start = Start(np.array([lat]), np.array([lon]), np.array([h]), config.initial_velocity_m_s[None, :],
                  quaternion_from_euler(roll, pitch, heading)[None, :], config.initial_position_sigma_m,
                  config.initial_velocity_sigma_m_s, config.initial_attitude_sigma_rad)
    initial = np.concatenate([config.initial_gyro_bias_rad_s, config.initial_accel_bias_m_s2,
                              config.initial_gyro_scale_factor, config.initial_accel_scale_factor])
    filter_cpu0 = time.process_time()
    run = run_filter(increments, imu.sample_interval_s, start, kfgins_model(config), gnss, t0=config.start_time_s,
                     lever_arm=config.antenna_lever_arm_m, covariance_interval=covariance_interval,
                     use_velocity=False, gate=1.0, initial_sensor_errors=initial)
    filter_cpu = time.process_time() - filter_cpu0
    solution = run.solution[0]
    t = imu.time_s[after]
    attitude = euler_from_quaternion(solution[:, 6:10])
    navigation = NavigationRecord(np.zeros(t.size, dtype=np.int64), t, solution[:, 0], solution[:, 1],
                                  solution[:, 2], solution[:, 3:6], attitude)
    write_navigation(case.folder / "schuler.nav", navigation)
    return navigation, time.perf_counter() - wall0, time.process_time() - cpu0, filter_cpu


def warm_up(folder) -> None:
    """Compile and cache schuler's kernels on a short drive, so the clock measures the work.

    Parameters
    ----------
    folder : str or Path
        A scratch folder.
    """
    run_schuler(write_case(folder, duration=300.0, outages=((100.0, 30.0),)))


def _of(navigation: NavigationRecord, case: Case) -> Accuracy:
    return accuracy(case, navigation.t_s, navigation.latitude_rad, navigation.longitude_rad,
                    navigation.attitude_rad)


def compare(executable, folder, duration: float = 1500.0, outages=OUTAGES, seed: int = 1):
    """Both tools on one simulated drive: their accuracies and timings.

    Parameters
    ----------
    executable : str or Path
        The KF-GINS executable.
    folder : str or Path
        Where the files are written.
    duration : float
        Length of the drive, s.
    outages : sequence of (float, float)
        (start, duration) s from the drive's start.
    seed : int
        Seed of the simulated errors, number.

    Returns
    -------
    dict
        ``kfgins`` and ``schuler``: (Accuracy, wall s, CPU s); ``schuler_filter_cpu_s``; ``case``.
    """
    case = write_case(folder, duration, outages, seed)
    kf_nav, kf_wall, kf_cpu = run_kfgins(executable, case)
    nav, wall, cpu, filter_cpu = run_schuler(case)
    return {"kfgins": (_of(kf_nav, case), kf_wall, kf_cpu), "schuler": (_of(nav, case), wall, cpu),
            "schuler_filter_cpu_s": filter_cpu, "case": case}


def _row(name: str, result) -> str:
    acc, wall, cpu = result
    outages = "  ".join(f"{m:7.3f}" for m in acc.outage_max_m)
    return (f"{name:<8} {acc.horizontal_rms_m:10.4f}  {outages}  {math.degrees(acc.heading_rms_rad):10.5f}  "
            f"{wall:7.2f}  {cpu:7.2f}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=1500.0, help="length of the drive, s (>= 300)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the simulated errors")
    args = parser.parse_args(argv)
    executable = os.environ.get(ENVIRONMENT)
    if not executable:
        print(f"KF-GINS comparison skipped: set {ENVIRONMENT} to the KF-GINS executable")
        return 0
    if not Path(executable).is_file():
        print(f"KF-GINS comparison skipped: {ENVIRONMENT}={executable} is not a file")
        return 0
    outages = tuple((s, d) for s, d in OUTAGES if s + d <= args.duration) or ((args.duration / 3, 30.0),)
    with tempfile.TemporaryDirectory(prefix="schuler-kfgins-") as scratch:
        print(f"load average {os.getloadavg()[0]:.1f}")
        warm_up(Path(scratch) / "warm")
        result = compare(executable, Path(scratch) / "case", args.duration, outages, args.seed)
    epochs = result["kfgins"][0].epochs
    print(f"drive {args.duration:.0f} s at {RATE:.0f} Hz ({epochs:,} IMU epochs), 1-Hz GNSS (sigma "
          f"{GNSS_SIGMA} m), outages {outages} s; IMU {NOISE}")
    head = "  ".join(f"out{i + 1} max" for i in range(len(outages)))
    print(f"{'tool':<8} {'horiz RMS':>10}  {head}  {'head RMS':>10}  {'wall s':>7}  {'CPU s':>7}")
    units = "  ".join(f"{'m':>7}" for _ in outages)
    print(f"{'':<8} {'m':>10}  {units}  {'deg':>10}")
    print(_row("KF-GINS", result["kfgins"]))
    print(_row("schuler", result["schuler"]))
    kf, sc = result["kfgins"][0], result["schuler"][0]
    ratios = "  ".join(f"{b / a:7.3f}" for a, b in zip(kf.outage_max_m, sc.outage_max_m))
    print(f"{'ratio':<8} {sc.horizontal_rms_m / kf.horizontal_rms_m:10.3f}  {ratios}  "
          f"{sc.heading_rms_rad / kf.heading_rms_rad:10.3f}  {result['schuler'][1] / result['kfgins'][1]:7.3f}  "
          f"{result['schuler'][2] / result['kfgins'][2]:7.3f}   (schuler / KF-GINS)")
    print(f"schuler's filter alone: {result['schuler_filter_cpu_s']:.2f} s CPU (covariance step "
          f"{COVARIANCE_INTERVAL:g} s; KF-GINS: every IMU epoch)")
    print(f"load average {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
