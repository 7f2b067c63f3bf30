"""``schuler sweep --workers 2`` against the same sweep in-process: the pool must not be slower.

The sweep is the gyrocompassing example's (``examples/align_gyrocompassing.toml``,
simulated 2 h at 1 s steps): a latitude grid 0..80 deg times ``--monte-carlo``
draws, in chunks of 2,000 cases, run as a user runs it (``python -m schuler sweep``
in a subprocess, plots included). It is timed twice per environment:

1. as given (``make bench`` sets ``OPENBLAS_NUM_THREADS=1``);
2. without any ``*_NUM_THREADS`` variable, as most users run it: each process
   then starts a BLAS thread per core, which on a 2-core machine made two workers
   six times slower than none before the workers were given their share of the
   cores.

Printed per environment: wall-clock seconds and CPU seconds (this process's
children) of each run, the ratio workers / in-process, and whether the two
results.parquet are identical. Targets (exit 1 when missed): the ratio at most
``MAX_RATIO`` in both environments, identical results. The machine's load average
is printed beside: on a machine shared with other work, the wall-clock times
follow the share of the cores the runs get. ``--draws N`` scales the sweep.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "align_gyrocompassing.toml"
MAX_RATIO = 1.0


def children_cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def timed_sweep(out_dir: Path, draws: int, workers: int, env: dict) -> tuple[float, float]:
    """Wall-clock and CPU seconds of one ``schuler sweep`` (CPU: the command and its worker processes)."""
    command = [sys.executable, "-m", "schuler", "sweep", str(EXAMPLE), "--param", "latitude=0:80:1",
               "--monte-carlo", str(draws), "--chunk-size", "2000", "--workers", str(workers), "--out", str(out_dir),
               "--no-csv", "--no-progress", "--json"]
    cpu, began = children_cpu_s(), time.perf_counter()
    subprocess.run(command, env=env, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - began, children_cpu_s() - cpu


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=1000, help="Monte Carlo draws per latitude (81 latitudes)")
    args = parser.parse_args()
    given = dict(os.environ)
    environments = {"as given": given,
                    "no thread settings": {k: v for k, v in given.items() if not k.endswith("_NUM_THREADS")}}
    print(f"sweep: 81 latitudes x {args.draws} draws = {81 * args.draws:,} cases; "
          f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        for label, env in environments.items():
            runs = {}
            for workers in (1, 2):
                out_dir = Path(tmp) / f"{label.replace(' ', '-')}-{workers}"
                runs[workers] = timed_sweep(out_dir, args.draws, workers, env)
                wall, cpu = runs[workers]
                name = "in-process" if workers == 1 else "--workers 2"
                print(f"{label:>20}, {name:>11}: {wall:7.2f} s wall, {cpu:7.2f} s CPU")
            ratio = runs[2][0] / runs[1][0]
            same = pd.read_parquet(Path(tmp) / f"{label.replace(' ', '-')}-1" / "results.parquet").equals(
                pd.read_parquet(Path(tmp) / f"{label.replace(' ', '-')}-2" / "results.parquet"))
            print(f"{label:>20}: workers / in-process = {ratio:.2f} (wall clock); identical results: {same}")
            if ratio > MAX_RATIO:
                failures.append(f"{label}: --workers 2 took {ratio:.2f} times the in-process time")
            if not same:
                failures.append(f"{label}: the results of --workers 2 differ from the in-process ones")
    for failure in failures:
        print(f"FAILED: {failure}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
