"""Benchmark: the aided INS's filter on the 25-min drive, against pyins, and its batched Monte Carlo.

Case (the aided-navigation targets): the default drive (:func:`schuler.navigate.drive.drive`,
1,500 s at 200 Hz: 300,000 IMU epochs), an IMU with constant biases, scale errors and white noise of
KF-GINS's example grade, 1-Hz GNSS positions and velocities with three 60-s outages, the 21-state
filter with its covariance propagated every second.

* schuler: :func:`schuler.aided.ekf.run_filter` on one member, CPU seconds of one core (target <= 2 s);
  the data (IMU synthesis, GNSS) are made before the clock starts.
* pyins 1.0.1 (``python-ins``, the benchmark-only extra): ``filters.run_feedback_filter`` on the first
  60 s of the same drive (its own IMU synthesis from the same truth; position fixes at 1 Hz, covariance
  step 1 s), CPU seconds per second of data, against schuler's on the whole drive. Skipped when absent.
* The Rauch-Tung-Striebel smoother (:func:`schuler.aided.smoother.smooth`) on the same drive: the filter run kept
  for it (``keep_for_smoother``) against the plain one, and the backward pass with the smoothed solution at every
  IMU epoch, CPU seconds and their ratios to the plain filter's; memory: the kept arrays and the smoother's peak
  (tracemalloc, numpy's allocations) beside their estimates before the run.
* Batched Monte Carlo: 100 members of a 300-s drive in one call against 10 single-member calls scaled to
  100 (members per CPU second; target >= 10x).
* The whole command on files: the same drive (tactical IMU, member 0) written in KF-GINS's formats with a
  KF-GINS configuration (:func:`schuler.aided.outputs.write_simulated_files`), then ``schuler aided run
  --kf-gins-config kf-gins.yaml --reference reference.nav --out DIR`` in a fresh process (reading the files,
  filtering, writing navigation.nav, navigation.csv, the error CSV and the figures), wall seconds of the second
  of two runs (the first compiles and caches the kernels; target <= 9 s), and its ratio to the filter-only wall
  time measured above.

Printed beside each figure: the load average (two shared cores move wall-clock times by up to 3x).
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

from schuler.aided.ekf import Start, run_filter
from schuler.aided.error_state import ErrorProcess, FilterModel
from schuler.aided.gnss import simulate_gnss
from schuler.aided.smoother import smooth, smoothed_bytes
from schuler.core.random import RandomStreams
from schuler.navigate.drive import drive
from schuler.navigate.truth import ideal_imu

RATE = 200.0
TARGET_SECONDS = 2.0
TARGET_COMMAND_SECONDS = 9.0
TARGET_BATCH_RATIO = 10.0
OUTAGES = ((400.0, 60.0), (800.0, 60.0), (1200.0, 60.0))
ARW, VRW = math.radians(0.003) / 60.0, 0.03 / 60.0  # KF-GINS's example: deg/sqrt(h), m/s/sqrt(h)
GYRO_BIAS, ACCEL_BIAS = math.radians(0.027) / 3600.0, 15e-5  # deg/h, 15 mGal
SCALE = 300e-6


def model() -> FilterModel:
    gm = dict(kind="gauss-markov", correlation_time=4 * 3600.0)
    return FilterModel(ARW, VRW, ErrorProcess(sigma=GYRO_BIAS, **gm), ErrorProcess(sigma=ACCEL_BIAS, **gm),
                       ErrorProcess(sigma=SCALE, **gm), ErrorProcess(sigma=SCALE, **gm))


def measured(ideal: np.ndarray, members: int, seed: int = 1) -> np.ndarray:
    """The ideal increments with per-member constant biases and scale errors and white noise."""
    rng = np.random.default_rng(seed)
    dt = 1.0 / RATE
    out = np.empty((members,) + ideal.shape)
    for axis, (bias, density) in enumerate(((GYRO_BIAS, ARW), (ACCEL_BIAS, VRW))):
        part = slice(3 * axis, 3 * axis + 3)
        b = rng.normal(size=(members, 1, 3)) * bias
        s = rng.normal(size=(members, 1, 3)) * SCALE
        out[..., part] = ideal[None, :, part] * (1 + s) + b * dt + rng.normal(size=out[..., part].shape) * density \
            * math.sqrt(dt)
    return out


def start(path, members: int) -> Start:
    v0, q0 = path.kinematics(np.array([0.0]))
    ones = np.ones(members)
    return Start(path.latitude * ones, path.longitude * ones, path.height * ones, np.repeat(v0, members, 0),
                 np.repeat(q0, members, 0), np.full(3, 1.0), np.full(3, 0.1), np.radians([0.1, 0.1, 1.0]))


def cpu(call):
    t0, c0 = time.perf_counter(), time.process_time()
    result = call()
    return result, time.perf_counter() - t0, time.process_time() - c0


def gnss(path, duration: float, members: int):
    streams = RandomStreams(3)
    return [simulate_gnss(path, duration, imu_rate=RATE, gnss_rate=1.0, position_sigma=(0.5, 0.5, 1.0),
                          velocity_sigma=(0.05, 0.05, 0.05), outages=OUTAGES, streams=streams, member=m)
            for m in range(members)]


def bench_pyins(path, imu, seconds: float) -> float | None:
    """CPU seconds of pyins's feedback filter per second of data, on the first ``seconds`` of the drive."""
    try:
        import pandas as pd
        from pyins import filters, measurements, sim, strapdown
    except ImportError:
        print("pyins: not installed (pip install python-ins==1.0.1, the 'bench' extra): comparison skipped")
        return None
    from schuler.core.attitude import euler_from_quaternion

    n = int(seconds * RATE)
    t = np.arange(n + 1) / RATE
    lla = np.column_stack([np.degrees(np.r_[path.latitude, imu.latitude_rad[:n]]),
                           np.degrees(np.r_[path.longitude, imu.longitude_rad[:n]]),
                           np.r_[path.height, imu.height_m[:n]]])
    v0, q0 = path.kinematics(np.array([0.0]))
    rph = np.degrees(euler_from_quaternion(np.vstack([q0, imu.quaternion[:n]])))
    velocity = np.vstack([v0, imu.velocity_ned_m_s[:n]])
    trajectory, imu_frame = sim.generate_imu(t, lla, rph, velocity, sensor_type="increment")
    increments = strapdown.compute_increments_from_imu(imu_frame, "increment")
    fixes = trajectory.iloc[:: int(RATE)][["lat", "lon", "alt"]]
    position = measurements.Position(pd.DataFrame(fixes), 0.5)
    initial = trajectory.iloc[0]
    filters.run_feedback_filter(initial, 1.0, 0.1, 0.1, 1.0, increments.iloc[: int(RATE)], measurements=[position],
                                time_step=1.0)  # numba compilation
    _, wall, spent = cpu(lambda: filters.run_feedback_filter(initial, 1.0, 0.1, 0.1, 1.0, increments,
                                                             measurements=[position], time_step=1.0))
    print(f"pyins 1.0.1 run_feedback_filter, {seconds:.0f} s of the drive: {wall:.2f} s wall, {spent:.2f} s CPU "
          f"({spent / seconds * 1e3:.1f} ms CPU per second of data)")
    return spent / seconds


def bench_smoother(path, data, fixes, filter_cpu: float) -> None:
    """The filter kept for the smoother and the smoother on one member of the whole drive: CPU and memory."""
    kept, _, kept_cpu = cpu(lambda: run_filter(data, 1.0 / RATE, start(path, 1), model(), fixes,
                                               keep_for_smoother=True))
    smoothed, _, smooth_cpu = cpu(lambda: smooth(kept))
    assert kept.prior_covariance is not None and kept.transition is not None and kept.correction is not None
    members, stored, n = kept.correction.shape
    held = kept.prior_covariance.nbytes + kept.transition.nbytes + kept.correction.nbytes
    tracemalloc.start()
    smooth(kept)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    estimate = smoothed_bytes(members, stored, kept.t_s.size, n)
    sigma = np.sqrt(smoothed.covariance[0, :, 0, 0] + smoothed.covariance[0, :, 1, 1]).max()
    print(f"smoother, the same drive ({stored:,} stored covariance times, {kept.t_s.size:,} IMU epochs): the filter "
          f"kept for it {kept_cpu:.2f} s CPU ({kept_cpu / filter_cpu:.2f}x the plain filter's {filter_cpu:.2f} s), "
          f"the backward pass with the smoothed solution {smooth_cpu:.2f} s CPU ({smooth_cpu / filter_cpu:.2f}x); "
          f"memory: the kept P-, Phi and corrections {held / 1e6:.1f} MB (estimated "
          f"{8.0 * stored * (2 * n * n + n) / 1e6:.1f} MB), the smoother's peak {peak / 1e6:.1f} MB (estimated "
          f"{estimate / 1e6:.1f} MB); largest smoothed horizontal 1-sigma {sigma:.2f} m")


def bench_command(filter_wall: float) -> None:
    """Wall seconds of ``schuler aided run --kf-gins-config ... --out DIR`` on the drive written to files."""
    from schuler.aided.outputs import write_simulated_files
    from schuler.registry import get_system

    case = get_system("aided").case(duration=1500.0, imu_rate=RATE, outage_start=400.0, outage_every=400.0)
    with tempfile.TemporaryDirectory() as folder:
        paths = write_simulated_files(case, Path(folder) / "data", week_start=456_300.0)
        command = [sys.executable, "-m", "schuler", "aided", "run", "--kf-gins-config", str(paths["configuration"]),
                   "--reference", str(paths["reference"]), "--json"]
        walls = []
        for attempt in range(2):  # the first compiles and caches the kernels
            out = Path(folder) / f"out{attempt}"
            t0 = time.perf_counter()
            subprocess.run([*command, "--out", str(out)], check=True, capture_output=True)
            walls.append(time.perf_counter() - t0)
        sizes = sum(p.stat().st_size for p in out.iterdir()) / 1e6
    wall = walls[-1]
    print(f"schuler aided run --kf-gins-config ... --out DIR (300,000 IMU epochs from files, {sizes:.0f} MB written):"
          f" {wall:.2f} s wall (first run {walls[0]:.2f} s; target <= {TARGET_COMMAND_SECONDS:g} s: "
          f"{'met' if wall <= TARGET_COMMAND_SECONDS else 'NOT met'}); {wall / filter_wall:.1f}x the filter alone "
          f"({filter_wall:.2f} s wall)")


def main() -> int:
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    print(f"load average {os.getloadavg()[0]:.1f}")
    path = drive()
    imu = ideal_imu(path, path.duration, RATE)
    ideal = np.concatenate([imu.angle_increment_rad, imu.velocity_increment_m_s], axis=1)
    data = measured(ideal, 1)[0]
    fixes = gnss(path, path.duration, 1)[0]
    run_filter(data[: int(10 * RATE)], 1.0 / RATE, start(path, 1), model(), fixes)  # compile and warm
    run, wall, spent = cpu(lambda: run_filter(data, 1.0 / RATE, start(path, 1), model(), fixes))
    ok = spent <= TARGET_SECONDS
    print(f"schuler, 1,500-s drive at 200 Hz ({len(data):,} IMU epochs, {fixes.epochs} GNSS epochs, 21 states, "
          f"three 60-s outages): {wall:.2f} s wall, {spent:.2f} s CPU (target <= {TARGET_SECONDS} s: "
          f"{'met' if ok else 'NOT met'}); {run.rejected[0]} epochs rejected")
    bench_smoother(path, data, fixes, spent)
    per_second = bench_pyins(path, imu, 60.0)
    if per_second is not None:
        print(f"ratio, CPU per second of data: pyins / schuler = {per_second / (spent / path.duration):.0f}x")
    members, duration = 100, 300.0
    short = drive(duration=duration)
    short_imu = ideal_imu(short, duration, RATE)
    short_ideal = np.concatenate([short_imu.angle_increment_rad, short_imu.velocity_increment_m_s], axis=1)
    batch_data = measured(short_ideal, members, seed=5)
    batch_fixes = gnss(short, duration, members)
    _, b_wall, b_cpu = cpu(lambda: run_filter(batch_data, 1.0 / RATE, start(short, members), model(), batch_fixes,
                                              output_every=int(RATE)))
    singles = 10
    _, s_wall, s_cpu = cpu(lambda: [run_filter(batch_data[m], 1.0 / RATE, start(short, 1), model(), batch_fixes[m],
                                               output_every=int(RATE)) for m in range(singles)])
    ratio = (s_cpu / singles * members) / b_cpu
    print(f"Monte Carlo, {members} members x {duration:.0f} s: batched {b_wall:.1f} s wall, {b_cpu:.1f} s CPU; "
          f"{singles} single runs {s_cpu:.1f} s CPU -> throughput ratio {ratio:.1f}x (target >= "
          f"{TARGET_BATCH_RATIO}x: {'met' if ratio >= TARGET_BATCH_RATIO else 'NOT met'})")
    print(f"load average {os.getloadavg()[0]:.1f}")
    bench_command(wall)
    print(f"load average {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
