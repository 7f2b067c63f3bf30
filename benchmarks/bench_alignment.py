"""Benchmark: Kalman fine alignment batched across records against a per-record loop.

1,000 simulated records of 300 s at 100 Hz (tactical-grade white noise and turn-on biases, level, at rest,
45 deg N), made in groups of ``GROUP`` records (288 MB of samples each; the whole set would be 1.4 GB and
is never held). Each group is aligned twice: once batched (every matrix step one ``matmul`` over the
records, the mechanisation one numba call for all of them) and once record by record. Printed: both
times, their ratio measured in this run, the largest difference between the two estimates (they are the
same computation: target 1e-9 rad, checked by the exit code), and the process's peak resident memory.
"""

from __future__ import annotations

import math
import resource
import sys
import time

import numpy as np

from schuler.alignment.comparison import simulated_batch
from schuler.alignment.data import StaticBatch
from schuler.alignment.kalman import align_kalman
from schuler.imu.error_model import ErrorModel, SensorErrors
from schuler.imu.spec import preset

RECORDS = 1000
GROUP = 200
DURATION_S = 300.0
DT = 0.01
LATITUDE = math.radians(45.0)
HEADING = math.radians(30.0)


def peak_memory_gb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 / 1e9  # ru_maxrss is in KiB on Linux


def model() -> ErrorModel:
    tactical = preset("tactical")
    return ErrorModel(gyro=SensorErrors(bias=tactical.gyro.bias, random_walk=tactical.gyro.random_walk),
                      accel=SensorErrors(bias=tactical.accel.bias, random_walk=tactical.accel.random_walk),
                      name="tactical biases and white noise")


def member(batch: StaticBatch, i: int) -> StaticBatch:
    return StaticBatch(batch.gyro_increment[i:i + 1], batch.accel_increment[i:i + 1], batch.sample_interval_s,
                       batch.latitude_rad, batch.gravity)


def main() -> int:
    errors = model()
    align_kalman(simulated_batch(errors, latitude=LATITUDE, heading=HEADING, duration=10.0,
                                 sample_interval=DT, members=2)[0], errors)   # numba compiled before timing
    batched = looped = simulating = 0.0
    difference = 0.0
    headings = []
    for first in range(0, RECORDS, GROUP):
        start = time.perf_counter()
        batch, _ = simulated_batch(errors, latitude=LATITUDE, heading=HEADING, duration=DURATION_S,
                                   sample_interval=DT, members=np.arange(first, first + GROUP), seed=1)
        simulating += time.perf_counter() - start
        start = time.perf_counter()
        together = align_kalman(batch, errors)
        batched += time.perf_counter() - start
        start = time.perf_counter()
        one_by_one = [align_kalman(member(batch, i), errors) for i in range(GROUP)]
        looped += time.perf_counter() - start
        alone = np.array([e.heading_rad[0] for e in one_by_one])
        difference = max(difference, float(np.abs(together.heading_rad - alone).max()))
        headings.append(together.heading_rad)
        del batch
    spread = float(np.std(np.concatenate(headings) - HEADING, ddof=1))
    print(f"Kalman fine alignment of {RECORDS:,} records of {DURATION_S:g} s at {1 / DT:g} Hz "
          f"(groups of {GROUP}; simulation {simulating:.1f} s, not counted)")
    print(f"  batched across records: {batched:8.2f} s ({1e3 * batched / RECORDS:.2f} ms per record)")
    print(f"  per-record loop:        {looped:8.2f} s ({1e3 * looped / RECORDS:.2f} ms per record)")
    print(f"  ratio loop / batched:   {looped / batched:8.1f}")
    print(f"  largest heading difference batched vs loop: {difference:.2e} rad (target 1e-9)")
    print(f"  heading spread over the records: {math.degrees(spread) * 60:.1f} arcmin")
    print(f"  peak resident memory: {peak_memory_gb():.2f} GB")
    return 0 if difference < 1e-9 else 1


if __name__ == "__main__":
    sys.exit(main())
