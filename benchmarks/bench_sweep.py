"""Sweep throughput: 10^6 cases of the gyrocompassing steady-state accuracy.

A latitude grid (0..79 deg, 80 points) times 12,500 Monte Carlo draws of the
residual drifts and accelerometer errors = 10^6 cases, in chunks of 50,000:

1. in-process (vectorised ``System.sweep`` per chunk): cases per second,
   end to end (evaluation, chunk files, gathering into results.parquet);
2. a Dask LocalCluster of 2 worker processes, same sweep: time ratio to the
   in-process run (without and with the cluster's start-up), and the results
   must be identical.

On a 2-core machine the Dask run cannot be faster: the evaluation is already
vectorised (one core does a chunk in a fraction of a second), while Dask adds
worker start-up, pickling each chunk's 50,000-row result back to the client,
and the client still writes every chunk. The ratio is printed as measured;
Dask pays off when the per-case work is heavy (simulated runs) or the cluster
spans several machines.

Targets (exit 1 when missed): in-process at least 100,000 cases/s end to end;
identical results on both executors; peak memory of this process bounded
(under 1.5 GB for 10^6 cases; chunks are streamed, never held together).
Pass ``--cases N`` to scale (N a multiple of 80).
"""

from __future__ import annotations

import argparse
import resource
import sys
import tempfile
import time
import warnings
from pathlib import Path

import pandas as pd

from schuler.gyrocompassing.case import GyrocompassingAccuracyWarning
from schuler.study.scenario import parse_scenario
from schuler.study.sweep import run_sweep

# the grid reaches 80 deg latitude on purpose: the accuracy warning is expected there
warnings.simplefilter("ignore", GyrocompassingAccuracyWarning)

SCENARIO = """\
system = "align"
[parameters]
drift_east = "0 deg/h"
time_constant = "300 s"
damping = 0.707
[monte_carlo]
seed = 1
[monte_carlo.normal]
drift_east = "0.01 deg/h"
drift_north = "0.01 deg/h"
accel_error_x = "1e-4 g"
accel_error_y = "1e-4 g"
"""

TARGET_CASES_PER_SECOND = 100_000
MEMORY_LIMIT_MB = 1500
LATITUDES = 80


def peak_memory_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def timed(label: str, scenario, folder: Path, draws: int, **options):
    began = time.perf_counter()
    summary = run_sweep(
        scenario,
        folder,
        (f"latitude=0:{LATITUDES - 1}:1",),
        draws,
        chunk_size=50_000,
        write_csv=False,
        plots=False,
        progress=False,
        **options,
    )
    seconds = time.perf_counter() - began
    print(f"{label:>28}: {summary.cases:,} cases in {seconds:6.2f} s = {summary.cases / seconds:12,.0f} cases/s")
    return seconds, summary


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=1_000_000)
    args = parser.parse_args()
    draws = max(1, args.cases // LATITUDES)
    scenario = parse_scenario(SCENARIO, source="bench_sweep")
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        inprocess, summary = timed("in-process", scenario, tmp / "inprocess", draws)
        rate = summary.cases / inprocess
        memory = peak_memory_mb()
        print(f"{'peak memory (this process)':>28}: {memory:,.0f} MB")
        from distributed import LocalCluster

        began = time.perf_counter()
        with LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=50
        ) as cluster:
            startup = time.perf_counter() - began
            print(f"{'LocalCluster start-up':>28}: {startup:6.2f} s")
            dask_seconds, _ = timed(
                "Dask LocalCluster, 2 workers", scenario, tmp / "dask", draws, scheduler=cluster.scheduler_address
            )
        ratio = dask_seconds / inprocess
        with_startup = (dask_seconds + startup) / inprocess
        print(f"{'Dask / in-process time':>28}: {ratio:.2f} (with start-up {with_startup:.2f})", end="")
        if ratio < 0.8:
            print("  (Dask is faster)")
        else:
            print("  (no gain: transfer and scheduling overhead match the compute saved on these cores)")
        same = pd.read_parquet(tmp / "dask" / "results.parquet").equals(
            pd.read_parquet(tmp / "inprocess" / "results.parquet")
        )
        print(f"{'identical results':>28}: {same}")
    if rate < TARGET_CASES_PER_SECOND:
        failures.append(f"in-process {rate:,.0f} cases/s < {TARGET_CASES_PER_SECOND:,}")
    if not same:
        failures.append("Dask results differ from the in-process results")
    if memory > MEMORY_LIMIT_MB:
        failures.append(f"peak memory {memory:,.0f} MB > {MEMORY_LIMIT_MB} MB")
    for failure in failures:
        print(f"FAILED: {failure}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
