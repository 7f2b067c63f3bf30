"""Benchmark: the nonlinear INS against pyins, one trajectory end to end, and batched Monte Carlo throughput.

Case (the issue's): a vehicle at rest at 45 deg for 3 h, IMU at 100 Hz (1,080,000 samples), vertical
channel held, with the same initial errors (north 10 m, east -5 m; 0.1 and -0.05 m/s; roll 1e-4 rad,
pitch -5e-5 rad, heading 1e-3 rad) and body-axis biases (gyro 1e-8, -2e-8, 5e-9 rad/s; accelerometer
1e-4, -2e-4, 0 m/s^2) in both.

* schuler, end to end: trajectory, truth and ideal IMU by inverse mechanization (streamed), strapdown
  integration and the errors at 1-s output (:func:`schuler.navigate.mechanization.navigate`).
* pyins 1.0.1 (``python-ins``, a benchmark-only extra), end to end: ``sim.generate_imu`` (increments),
  biases added, ``strapdown.compute_increments_from_imu``, ``Integrator.integrate``,
  ``transform.compute_state_difference``; and without its IMU synthesis (integration and errors only).
  Both warmed up first (numba compilation excluded). Skipped, with a message, when pyins is absent.
* Agreement of every error channel at the common 1-s times: max |schuler - pyins| / max |schuler|
  (target <= 1e-4), and each library's own floor (the same run without errors).
* Batched Monte Carlo: N members with per-member constant errors (initial errors, biases, scale
  factors, misalignments drawn from RandomStreams), 1 h at 100 Hz, in member-samples per second (target
  >= 10 M/s); the same through the noise interface with a source of zeros (its own cost) and with white
  sensor noise from RandomStreams (the generator's cost on top).
* Monte Carlo through the system (``schuler navigate run --imu GRADE --monte-carlo N``: the contract's
  ``evaluate`` on members drawing the IMU layer's full error model, constant errors and noise from
  :mod:`schuler.imu.simulate`), 1 h at 100 Hz (target >= 5 M member-samples per CPU second), with the share of the
  time spent generating the noise and the normals it draws per member-sample (one per channel for white
  noise, one per grid point of each slow process: 14.4 for the tactical grade); the tactical grade (white
  noise and flicker over 1 s to 1000 s, eleven Gauss-Markov terms per axis) and a model of its white
  noise alone (6.0).

* Normals per second on one core: :meth:`~schuler.core.random.RandomStreams.normal_series` (a ziggurat over
  counter hashes, compiled) against numpy's default generator (PCG64) and SFC64 drawing the same count in the
  same run (target >= 150 M/s per core).

Throughputs are printed from wall time and from CPU time (the machine is shared: CPU time shows the
work, wall time what a user waits, with the load average beside it); ratios use the same clock on both
sides. ``--only-imu-monte-carlo`` runs the last two parts alone.

Targets: end-to-end ratio >= 10 (pyins measured 0.38-0.41 M samples/s here), agreement <= 1e-4,
batched >= 10 M member-samples/s, with the IMU layer's full noise >= 5 M member-samples per CPU second (2.1 M
with numpy's generators), normals >= 150 M/s per core.
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

from schuler.contract import Cases
from schuler.core.random import RandomStreams
from schuler.imu.simulate import ImuSimulator
from schuler.navigate import imu_noise
from schuler.navigate.api import SYSTEM
from schuler.navigate.errors import ConstantSensorErrors, InitialErrors, WhiteNoise
from schuler.navigate.mechanization import estimate_memory, navigate
from schuler.navigate.trajectory import Stationary

LATITUDE_DEG = 45.0
HOURS = 3.0
IMU_RATE = 100.0
OUTPUT_STEP = 1.0
INITIAL = {"north": 10.0, "east": -5.0, "velocity_north": 0.1, "velocity_east": -0.05, "roll": 1e-4,
           "pitch": -5e-5, "heading": 1e-3}
GYRO_BIAS = np.array([1e-8, -2e-8, 5e-9])
ACCEL_BIAS = np.array([1e-4, -2e-4, 0.0])
MEMBERS = 128
MONTE_CARLO_HOURS = 1.0
TARGET_RATIO = 10.0
TARGET_AGREEMENT = 1e-4
TARGET_BATCH = 10e6
TARGET_NOISY = 5e6
"""Member-samples per CPU second of the Monte Carlo with the tactical grade's full noise model."""
TARGET_NORMALS = 150e6
"""Standard normals per second on one core."""
NORMALS_MEMBERS, NORMALS_SAMPLES = 64, 1 << 18
NOISY_MEMBERS = 42
"""Members of the Monte Carlo with the IMU layer's noise: two runs of 21 (one random-number block per window)."""
WHITE_ONLY = """name = "tactical white noise alone"
[gyro]
random_walk = "0.125 deg/sqrt(h)"
[accel]
random_walk = "0.065 ft/s/sqrt(h)"
"""

CHANNELS = {  # schuler name: (pyins column, factor to SI)
    "position_error_north_m": ("north", 1.0),
    "position_error_east_m": ("east", 1.0),
    "velocity_error_north_m_s": ("VN", 1.0),
    "velocity_error_east_m_s": ("VE", 1.0),
    "roll_error_rad": ("roll", math.pi / 180),
    "pitch_error_rad": ("pitch", math.pi / 180),
    "heading_error_rad": ("heading", math.pi / 180),
}


def timed(function):
    """(result, wall seconds, CPU seconds) of one call."""
    wall, cpu = time.perf_counter(), time.process_time()
    result = function()
    return result, time.perf_counter() - wall, time.process_time() - cpu


def peak_memory(function) -> float:
    """Peak of numpy/Python allocations during one call, MiB (tracemalloc)."""
    tracemalloc.start()
    function()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak / 2**20


def run_schuler(hours: float, errors: bool = True):
    initial = InitialErrors(position_error_north=INITIAL["north"], position_error_east=INITIAL["east"],
                            velocity_error_north=INITIAL["velocity_north"],
                            velocity_error_east=INITIAL["velocity_east"], roll_error=INITIAL["roll"],
                            pitch_error=INITIAL["pitch"], heading_error=INITIAL["heading"]) if errors else None
    sensors = ConstantSensorErrors(gyro_bias=GYRO_BIAS, accel_bias=ACCEL_BIAS) if errors else None
    return navigate(Stationary(latitude=math.radians(LATITUDE_DEG)), hours * 3600.0, imu_rate=IMU_RATE,
                    output_step=OUTPUT_STEP, initial_errors=initial, sensor_errors=sensors)


def run_pyins(hours: float, errors: bool = True, imu=None):
    """pyins end to end; returns (errors DataFrame, IMU synthesis seconds wall, CPU) for reuse."""
    from pyins import sim, strapdown, transform

    dt = 1.0 / IMU_RATE
    t = np.arange(0.0, hours * 3600.0 + dt / 2, dt)
    synthesis = (0.0, 0.0)
    if imu is None:
        lla = np.tile([LATITUDE_DEG, 0.0, 0.0], (t.size, 1))
        wall, cpu = time.perf_counter(), time.process_time()
        imu = sim.generate_imu(t, lla, np.zeros((t.size, 3)), np.zeros((t.size, 3)), sensor_type="increment")
        synthesis = (time.perf_counter() - wall, time.process_time() - cpu)
    trajectory, readings = imu
    readings = readings.copy()
    if errors:
        readings[["gyro_x", "gyro_y", "gyro_z"]] += GYRO_BIAS * dt
        readings[["accel_x", "accel_y", "accel_z"]] += ACCEL_BIAS * dt
    increments = strapdown.compute_increments_from_imu(readings, "increment")
    start = trajectory.iloc[0]
    if errors:
        error = sim.generate_pva_error(0.0, 0.0, 0.0, 0.0)
        error[["north", "east", "down"]] = [INITIAL["north"], INITIAL["east"], 0.0]
        error[["VN", "VE", "VD"]] = [INITIAL["velocity_north"], INITIAL["velocity_east"], 0.0]
        error[["roll", "pitch", "heading"]] = np.degrees([INITIAL["roll"], INITIAL["pitch"], INITIAL["heading"]])
        start = sim.perturb_pva(start, error)
    integrator = strapdown.Integrator(start, with_altitude=False)
    computed = integrator.integrate(increments)
    return transform.compute_state_difference(computed, trajectory), imu, synthesis


def agreement(ours, theirs) -> dict[str, float]:
    """max |schuler - pyins| / max |schuler| per channel at the common output times."""
    step = round(OUTPUT_STEP * IMU_RATE)
    out = {}
    for name, (column, factor) in CHANNELS.items():
        mine = ours.channel(name)
        other = theirs[column].to_numpy()[::step][: mine.size] * factor
        out[name] = float(np.abs(mine - other).max() / np.abs(mine).max())
    return out


def batch_errors(members: int):
    streams = RandomStreams(2024)
    ids = np.arange(members)

    def normal(stream, scale, size=None):
        return streams.normal(stream, ids, size) * scale

    misalignment = normal("misalignment", 1e-4, 9).reshape(members, 3, 3) * (1 - np.eye(3))
    initial = InitialErrors(position_error_north=normal("north", 10.0), position_error_east=normal("east", 10.0),
                            velocity_error_north=normal("vn", 0.1), velocity_error_east=normal("ve", 0.1),
                            roll_error=normal("roll", 1e-4), pitch_error=normal("pitch", 1e-4),
                            heading_error=normal("heading", 1e-3))
    sensors = ConstantSensorErrors(gyro_bias=normal("gyro_bias", 1e-8, 3), accel_bias=normal("accel_bias", 1e-4, 3),
                           gyro_scale_factor=normal("gyro_scale", 1e-5, 3),
                           accel_scale_factor=normal("accel_scale", 1e-4, 3),
                           gyro_misalignment=misalignment, accel_misalignment=misalignment)
    return initial, sensors


class ZeroNoise:
    """A noise source of zeros: what the noise interface itself costs (allocation, copy, kernel reads)."""

    def increments(self, members, start, stop, dt):
        return np.zeros((len(members), stop - start, 3)), np.zeros((len(members), stop - start, 3))


def run_batch(members: int, hours: float, noise=None):
    initial, sensors = batch_errors(members)
    return navigate(Stationary(latitude=math.radians(LATITUDE_DEG)), hours * 3600.0, imu_rate=IMU_RATE,
                    output_step=60.0, initial_errors=initial, sensor_errors=sensors, noise=noise,
                    member_ids=np.arange(members))


def imu_monte_carlo(imu: str, members: int, hours: float) -> tuple[float, float, float, float]:
    """The system's evaluate on Monte Carlo members drawing the model ``imu``: (wall, CPU, noise wall, noise CPU) s.

    The noise's share is measured by timing :class:`~schuler.navigate.imu_noise.ImuNoise` while the system runs.
    """
    spent = {"wall": 0.0, "cpu": 0.0}
    original = imu_noise.ImuNoise

    class TimedNoise(original):
        def increments(self, members, start, stop, dt):
            wall, cpu = time.perf_counter(), time.process_time()
            try:
                return super().increments(members, start, stop, dt)
            finally:
                spent["wall"] += time.perf_counter() - wall
                spent["cpu"] += time.process_time() - cpu

    case = SYSTEM.case(imu=imu, duration=hours * 3600.0, imu_rate=IMU_RATE, output_step=60.0)
    cases = Cases.from_case(case, members, random=RandomStreams(1))
    imu_noise.ImuNoise = TimedNoise
    try:
        _, wall, cpu = timed(lambda: SYSTEM.evaluate(cases))
    finally:
        imu_noise.ImuNoise = original
    return wall, cpu, spent["wall"], spent["cpu"]


def normals_per_sample(model, interval: float) -> float:
    """Random numbers the IMU layer draws per member-sample: white noise per channel, one per grid point."""
    steps = np.array(list(ImuSimulator(imu_noise.noise_model(model), interval).coarse_steps().values()), dtype=float)
    white = sum(int(np.count_nonzero(sensor.random_walk)) for sensor in (model.gyro, model.accel))
    return white + float(np.sum(1.0 / steps))


def normals_per_core() -> float:
    """Print the normals drawn per second on one core by the streams and by numpy's generators; returns ours."""
    count = NORMALS_MEMBERS * NORMALS_SAMPLES
    streams = RandomStreams(1)
    draws = {"schuler (RandomStreams.normal_series)":
             lambda: streams.normal_series("bench", np.arange(NORMALS_MEMBERS), 0, NORMALS_SAMPLES)}
    for name, bit_generator in (("numpy PCG64 (default_rng)", np.random.PCG64), ("numpy SFC64", np.random.SFC64)):
        generator = np.random.Generator(bit_generator(1))
        draws[name] = lambda generator=generator: generator.standard_normal((NORMALS_MEMBERS, NORMALS_SAMPLES))
    rates = {}
    for name, draw in draws.items():
        draw()  # each warmed up alike (compilation, the first touch of the memory)
        rates[name] = count / min(timed(draw)[2] for _ in range(3))
    baseline = rates["numpy PCG64 (default_rng)"]
    print(f"standard normals, {count:,} per draw, one core (CPU time; target >= {TARGET_NORMALS / 1e6:g} M/s): "
          + "; ".join(f"{name} {rate / 1e6:.0f} M/s ({rate / baseline:.2f}x PCG64)" for name, rate in rates.items()))
    return rates["schuler (RandomStreams.normal_series)"]


def noisy_monte_carlo() -> float:
    """Print the Monte Carlo throughput with the IMU layer's noise; returns the full grade's rate per CPU second."""
    samples = NOISY_MEMBERS * round(MONTE_CARLO_HOURS * 3600 * IMU_RATE)
    imu_monte_carlo("tactical", 2, 1.0 / 60.0)  # compile and warm up (one output step)
    print("load average (1, 5, 15 min) before the Monte Carlo with noise: {:.2f}, {:.2f}, {:.2f} on {} cores".format(
        *os.getloadavg(), os.cpu_count()))
    with tempfile.TemporaryDirectory() as folder:
        white = Path(folder) / "white.toml"
        white.write_text(WHITE_ONLY)
        rates = {}
        for label, imu in (("the tactical grade's full model", "tactical"), ("its white noise alone", str(white))):
            wall, cpu, noise_wall, noise_cpu = imu_monte_carlo(imu, NOISY_MEMBERS, MONTE_CARLO_HOURS)
            model = imu_noise.load_error_model(imu)
            slow = imu_noise.slow_processes(model, 1.0 / IMU_RATE)
            member = SYSTEM.member_bytes(SYSTEM.case(imu=imu, duration=MONTE_CARLO_HOURS * 3600.0,
                                                     output_step=60.0)) / 2**20
            rates[imu] = samples / cpu
            print(f"Monte Carlo through the system with {label} ({slow} slow processes per member): "
                  f"{NOISY_MEMBERS} members x {MONTE_CARLO_HOURS:g} h at {IMU_RATE:g} Hz in {wall:.2f} s wall, "
                  f"{cpu:.2f} s CPU: {samples / wall / 1e6:.2f} M member-samples/s wall, {samples / cpu / 1e6:.2f} M/s "
                  f"per CPU (target >= {TARGET_NOISY / 1e6:g} M/s); noise generation (schuler.imu.simulate) "
                  f"{noise_wall / wall:.0%} of the wall time, {noise_cpu / cpu:.0%} of the CPU time, "
                  f"{normals_per_sample(model, 1.0 / IMU_RATE):.1f} normals per member-sample; "
                  f"planned memory {member:.1f} MiB per member")
    print("load average after: {:.2f}, {:.2f}, {:.2f}".format(*os.getloadavg()))
    return rates["tactical"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only-imu-monte-carlo", action="store_true",
                        help="only the Monte Carlo through the system with the IMU layer's noise")
    if parser.parse_args(argv).only_imu_monte_carlo:
        return 0 if normals_per_core() >= TARGET_NORMALS and noisy_monte_carlo() >= TARGET_NOISY else 1
    samples = round(HOURS * 3600 * IMU_RATE)
    run_schuler(0.01)  # compile (cached after the first run) and warm up
    result, wall, cpu = timed(lambda: run_schuler(HOURS))
    floor = run_schuler(HOURS, errors=False)
    print(f"schuler: {HOURS:g} h at {IMU_RATE:g} Hz ({samples:,} samples) end to end in {wall:.2f} s wall, "
          f"{cpu:.2f} s CPU: {samples / wall / 1e6:.2f} M samples/s wall, {samples / cpu / 1e6:.2f} M/s CPU; "
          f"peak allocation {peak_memory(lambda: run_schuler(HOURS)):.0f} MiB")
    ok = True
    try:
        import pyins  # noqa: F401 - presence check
    except ImportError:
        print("pyins: not installed (pip install python-ins==1.0.1, the 'bench' extra): comparison skipped")
    else:
        run_pyins(0.01)  # numba compilation of pyins's integrator
        (theirs, imu, synthesis), p_wall, p_cpu = timed(lambda: run_pyins(HOURS))
        (_, _, _), i_wall, i_cpu = timed(lambda: run_pyins(HOURS, imu=imu))
        pyins_floor = run_pyins(HOURS, errors=False, imu=imu)[0]
        print(f"pyins: end to end {p_wall:.2f} s wall, {p_cpu:.2f} s CPU ({samples / p_wall / 1e6:.3f} M samples/s "
              f"wall; IMU synthesis {synthesis[0]:.2f} s); without synthesis {i_wall:.2f} s wall, {i_cpu:.2f} s CPU "
              f"({samples / i_wall / 1e6:.3f} M samples/s)")
        ratio, ratio_cpu = p_wall / wall, p_cpu / cpu
        print(f"ratio, end to end: {ratio:.1f}x wall, {ratio_cpu:.1f}x CPU; against pyins without its IMU "
              f"synthesis: {i_wall / wall:.1f}x wall, {i_cpu / cpu:.1f}x CPU (target >= {TARGET_RATIO:g}x)")
        agree = agreement(result, theirs)
        print("agreement, max |schuler - pyins| / max |schuler| (target <= 1e-4); floors: max |error| without "
              "errors, schuler / pyins:")
        for name, value in agree.items():
            column, factor = CHANNELS[name]
            print(f"  {name:26s} {value:.1e}   (max {np.abs(result.channel(name)).max():.4g}; floors "
                  f"{np.abs(floor.channel(name)).max():.1e} / {np.abs(pyins_floor[column]).max() * factor:.1e})")
        ok = ratio >= TARGET_RATIO and max(agree.values()) <= TARGET_AGREEMENT

    batch_samples = MEMBERS * round(MONTE_CARLO_HOURS * 3600 * IMU_RATE)
    run_batch(4, 1.0 / 60.0)  # compile and warm up
    _, b_wall, b_cpu = timed(lambda: run_batch(MEMBERS, MONTE_CARLO_HOURS))
    estimate = estimate_memory(MEMBERS, round(MONTE_CARLO_HOURS * 60) + 1, 65_536, False) / 2**20
    print(f"batch: {MEMBERS} members x {MONTE_CARLO_HOURS:g} h at {IMU_RATE:g} Hz with per-member constant errors in "
          f"{b_wall:.2f} s wall, {b_cpu:.2f} s CPU: {batch_samples / b_wall / 1e6:.1f} M member-samples/s wall, "
          f"{batch_samples / b_cpu / 1e6:.1f} M/s per CPU (target >= {TARGET_BATCH / 1e6:g} M/s); "
          f"planned memory {estimate:.1f} MiB, peak allocation "
          f"{peak_memory(lambda: run_batch(MEMBERS, MONTE_CARLO_HOURS)):.0f} MiB")
    noisy_members = MEMBERS // 4
    noisy_samples = noisy_members * round(MONTE_CARLO_HOURS * 3600 * IMU_RATE)
    for label, source in (("the noise interface alone (a source returning zeros)", ZeroNoise()),
                          ("white noise (RandomStreams.normal_series)",
                           WhiteNoise(angle_random_walk=2.9e-6, velocity_random_walk=1e-4, seed=7))):
        _, n_wall, n_cpu = timed(lambda source=source: run_batch(noisy_members, MONTE_CARLO_HOURS, source))
        print(f"batch with {label}: {noisy_members} members in {n_wall:.2f} s wall: "
              f"{noisy_samples / n_wall / 1e6:.2f} M member-samples/s wall, "
              f"{noisy_samples / n_cpu / 1e6:.2f} M/s per CPU")
    normals_rate = normals_per_core()
    noisy_rate = noisy_monte_carlo()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak resident memory of the whole benchmark (pyins's frames included): {peak:.0f} MiB")
    ok = ok and batch_samples / b_wall >= TARGET_BATCH and noisy_rate >= TARGET_NOISY and normals_rate >= TARGET_NORMALS
    print("PASS" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
