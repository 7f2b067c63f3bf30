"""Benchmark: streaming Allan deviation (memory, speed against allantools) and error-model simulation throughput.

1. Allan deviation of 10^8 rate samples on one axis (white noise plus a rate
   random walk), generated chunk by chunk and never held: the process's peak
   resident memory is printed (target < 1.5 GB).
2. The same estimator against ``allantools.oadev`` on 10^7 samples held in
   memory, same lags: time ratio and largest relative difference (target 1e-12).
3. Simulation with every error term on (bias, scale factor, misalignment,
   g-sensitivity, Gauss-Markov, flicker sum, random walk, rate random walk,
   quantisation; the tactical preset's figures plus the rest), six axes at
   100 Hz: six-axis samples per second with two worker threads (target >= 2 M/s
   on 2 cores) and, from a single-threaded run, the share of time spent drawing
   random numbers.

The exit code checks what does not depend on the machine's load (memory and
agreement); speeds are printed beside their targets, measured in this run, with
the load average before and after and the simulation's CPU time: on a shared
machine the wall-clock rate falls with the load, the rate per CPU second far less.
"""

from __future__ import annotations

import os
import resource
import sys
import time
from dataclasses import replace

import allantools
import numpy as np

from schuler.core import random as addressed_random
from schuler.imu.allan import AllanAccumulator, allan_deviation, allan_lags
from schuler.imu.simulate import ImuSimulator, iter_simulation, static_truth
from schuler.imu.spec import preset

BIG = 10**8
MEDIUM = 10**7
CHUNK = 1 << 22
DT = 0.01


def peak_memory_gb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 / 1e9  # ru_maxrss is in KiB on Linux


def samples(rng, n: int, carry: float) -> tuple[np.ndarray, float]:
    walk = carry + 1e-6 * np.cumsum(rng.standard_normal(n))
    return 1e-3 * rng.standard_normal(n) + walk, float(walk[-1])


def bench_allan_big() -> tuple[float, float]:
    rng = np.random.default_rng(1)
    accumulator = AllanAccumulator(DT, allan_lags(BIG), channels=1)
    carry, start = 0.0, time.perf_counter()
    for _ in range(BIG // CHUNK + 1):
        n = min(CHUNK, BIG - accumulator.samples)
        if n <= 0:
            break
        chunk, carry = samples(rng, n, carry)
        accumulator.update(chunk)
    curve = accumulator.curves()[0]
    seconds = time.perf_counter() - start
    print(f"allan: {BIG:.0e} samples, {curve.tau_s.size} lags up to tau = {curve.tau_s[-1]:.4g} s, streamed in "
          f"chunks of {CHUNK:,}")
    print(f"  time (generation included)   : {seconds:8.1f} s")
    return seconds, peak_memory_gb()


def bench_allan_against_allantools() -> tuple[float, float]:
    y, _ = samples(np.random.default_rng(2), MEDIUM, 0.0)
    lags = allan_lags(MEDIUM)
    start = time.perf_counter()
    ours = allan_deviation(y, DT, lags=lags)
    ours_seconds = time.perf_counter() - start
    start = time.perf_counter()
    _, reference, _, _ = allantools.oadev(y, rate=1 / DT, data_type="freq", taus=lags * DT)
    reference_seconds = time.perf_counter() - start
    worst = float(np.max(np.abs(ours.adev / reference - 1.0)))
    print(f"allan vs allantools.oadev: {MEDIUM:.0e} samples, {lags.size} lags")
    print(f"  schuler (streamed, with confidence intervals): {ours_seconds:8.2f} s")
    print(f"  allantools.oadev                             : {reference_seconds:8.2f} s")
    print(f"  speed ratio                                  : {reference_seconds / ours_seconds:8.2f}x")
    print(f"  largest relative difference                  : {worst:.1e} (target <= 1e-12)")
    return worst, reference_seconds / ours_seconds


def every_term_model():
    model = preset("tactical")
    gyro = replace(model.gyro, gm_sigma=np.full(3, 1e-6), gm_correlation_time_s=np.full(3, 300.0),
                   rate_random_walk=np.full(3, 1e-8), quantization=np.full(3, 1e-6),
                   g_sensitivity=np.full((3, 3), 1e-6))
    accel = replace(model.accel, gm_sigma=np.full(3, 1e-4), gm_correlation_time_s=np.full(3, 300.0),
                    rate_random_walk=np.full(3, 1e-6), quantization=np.full(3, 1e-4))
    return replace(model, gyro=gyro, accel=accel, name="tactical, every term on")


def simulate(workers: int, members: int, length: int) -> tuple[float, float]:
    """Wall-clock and CPU seconds (all threads) of a simulation of ``members`` x ``length`` samples."""
    truth = static_truth(0.8, 0.3)
    simulator = ImuSimulator(every_term_model(), DT, true_gyro=truth[0], true_accel=truth[1], seed=7,
                             workers=workers)
    start, cpu = time.perf_counter(), time.process_time()
    for _ in iter_simulation(simulator, np.arange(members), length, member_chunk=members):
        pass
    return time.perf_counter() - start, time.process_time() - cpu


def bench_simulation() -> float:
    members, length = 8, 1 << 20
    simulate(1, 1, 1 << 16)  # compile and warm the kernels
    seconds, cpu_seconds = simulate(2, members, length)
    rate = members * length / seconds
    # the share of random-number generation, from a single-threaded run with the generator timed
    spent, drawn = [0.0], [0]
    originals = {name: getattr(addressed_random.RandomStreams, name) for name in ("normal_series", "normal_block")}

    def timed(original):
        def draw(self, *args, **kwargs):
            begin = time.perf_counter()
            values = original(self, *args, **kwargs)
            spent[0] += time.perf_counter() - begin
            drawn[0] += values.size
            return values
        return draw

    for name, original in originals.items():  # white noise by series, the slow processes by blocks
        setattr(addressed_random.RandomStreams, name, timed(original))
    try:
        single, _ = simulate(1, 2, length)
    finally:
        for name, original in originals.items():
            setattr(addressed_random.RandomStreams, name, original)
    streams = addressed_random.RandomStreams(3)
    begin = time.perf_counter()
    streams.normal_series("bench", [0], 0, 4 * length)
    normals = 4 * length / (time.perf_counter() - begin)
    per_sample = drawn[0] / (2 * length)
    print(f"simulation: {every_term_model().name}, {members} members x {length:,} samples x 6 axes at 100 Hz")
    print(f"  addressed normals, 1 thread  : {normals / 1e6:6.1f} M/s; the simulation draws {per_sample:.1f} per "
          f"six-axis sample, which bounds one thread to {normals / per_sample / 1e6:.2f} M six-axis samples/s")
    print(f"  2 workers                    : {seconds:8.2f} s = {rate / 1e6:6.2f} M six-axis samples/s "
          f"(target >= 2)")
    per_cpu = members * length / cpu_seconds
    print(f"  2 workers, CPU time          : {cpu_seconds:8.2f} s = {per_cpu / 1e6:6.2f} M six-axis samples per "
          f"CPU second (two free cores at most {2 * per_cpu / 1e6:.2f} M/s)")
    print(f"  1 worker                     : {2 * length / single / 1e6:6.2f} M six-axis samples/s; random numbers "
          f"{100 * spent[0] / single:.0f} % of the time")
    return rate


def main() -> int:
    start = time.perf_counter()
    print("load average (1, 5, 15 min) at the start: {:.2f}, {:.2f}, {:.2f} on {} cores".format(
        *os.getloadavg(), os.cpu_count()))
    _, memory = bench_allan_big()
    print(f"  peak resident memory         : {memory:8.2f} GB (target < 1.5 GB)")
    worst, _ = bench_allan_against_allantools()
    bench_simulation()
    print(f"total benchmark time: {time.perf_counter() - start:.0f} s")
    print("load average (1, 5, 15 min) at the end: {:.2f}, {:.2f}, {:.2f}".format(*os.getloadavg()))
    return 0 if memory < 1.5 and worst <= 1e-12 else 1


if __name__ == "__main__":
    sys.exit(main())
