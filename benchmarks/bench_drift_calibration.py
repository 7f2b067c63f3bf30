"""Benchmark: 10,000 Monte Carlo calibration procedures, vectorised vs a per-trial loop.

Both run the same simulation (:func:`run_procedure` with the typical error
budget, three-axis, two positions); the loop runs one member per call. The loop
is timed on a sample of trials and scaled to 10,000. Target: ratio >= 50.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

from schuler.drift_calibration.error_budget import TYPICAL
from schuler.drift_calibration.procedure import run_procedure
from schuler.drift_calibration.reproduction import default_stabilizer

TRIALS = 10_000
SAMPLE = 100
TARGET = 50.0


def main() -> int:
    import dataclasses

    stabilizer = dataclasses.replace(default_stabilizer(), loop_time_constant=TYPICAL.loop_time_constant)
    site = (math.radians(70.0), math.radians(80.0), math.radians(1.0) / 3600.0)
    rng = np.random.default_rng(0)
    start = time.perf_counter()
    for _ in range(0, TRIALS, 2000):
        run_procedure(stabilizer, *site, budget=TYPICAL, members=2000, rng=rng)
    vectorised = time.perf_counter() - start
    start = time.perf_counter()
    for _ in range(SAMPLE):
        run_procedure(stabilizer, *site, budget=TYPICAL, members=1, rng=rng)
    loop = (time.perf_counter() - start) * TRIALS / SAMPLE
    ratio = loop / vectorised
    print(f"vectorised: {vectorised:.2f} s for {TRIALS} procedures")
    print(f"per-trial loop: {loop:.1f} s (scaled from {SAMPLE} trials)")
    print(f"ratio: {ratio:.0f}x (target >= {TARGET:.0f}x)")
    return 0 if ratio >= TARGET else 1


if __name__ == "__main__":
    sys.exit(main())
