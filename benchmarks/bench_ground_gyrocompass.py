"""Benchmark: north by variable-projection least squares against the source's grid search.

On one record (the source's experiment, source 004: 0..200 s every 1 s, simulated
by numerical integration) the 4-unknown identification is timed three ways:

* lsq: variable projection from the default start (no grid);
* (a) the source's procedure: three grid stages (the printed boxes, 568,008 cells),
  one numerical integration of eqs. (1)-(2) per cell; a random sample of cells is
  timed and the time scaled to all cells;
* (b) the same three stages with the vectorised closed form (Gram-matrix misfit).

Targets: lsq at least 10,000x faster than (a) and 20x faster than (b); lsq alpha0
error <= 1e-9 rad on the noise-free record. Exits non-zero if a target is missed.
Run: python benchmarks/bench_ground_gyrocompass.py
"""

from __future__ import annotations

import sys
import time

import numpy as np

from schuler.ground_gyrocompass import motion
from schuler.ground_gyrocompass.grid import axis, misfit_cells_ode, refine, source_boxes
from schuler.ground_gyrocompass.identification import identify
from schuler.ground_gyrocompass.reproduction import source_b, source_record

SAMPLE_CELLS = 40
REPEATS = 5
ROUNDS = 6


def best_time(function, repeats=REPEATS):
    """Smallest wall time of ``repeats`` calls (s) and the last result."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return min(times), result


def main() -> int:
    time_s, observed = source_record()
    b = source_b()
    boxes = source_boxes(4, motion.SOURCE_INERTIA, motion.SOURCE_OMEGA_H)

    def lsq():
        return identify(
            time_s, observed, 4, decay_rate=motion.SOURCE_LAMBDA, hm=motion.SOURCE_HM,
            inertia=motion.SOURCE_INERTIA, omega_h=motion.SOURCE_OMEGA_H,
        )

    def grid():
        return refine(time_s, observed, boxes, motion.SOURCE_LAMBDA, b)

    # interleaved, best of many: the machine is shared, and the minimum of repeated
    # runs is the least disturbed measure of each method's own cost
    lsq_times, grid_times = [], []
    for _ in range(ROUNDS):
        t_round, stages = best_time(grid, repeats=1)
        grid_times.append(t_round)
        t_round, estimate = best_time(lsq, repeats=REPEATS)
        lsq_times.append(t_round)
    t_lsq, t_grid = min(lsq_times), min(grid_times)
    lsq_error = abs(estimate.alpha0_rad - motion.SOURCE_ALPHA0)
    grid_error = abs(stages[-1].best["alpha0"] - motion.SOURCE_ALPHA0)
    total_cells = sum(stage.cells for stage in stages)

    # the source's procedure: one ODE integration per cell, timed on a random sample of cells
    rng = np.random.default_rng(0)
    sample = []
    for stage_box in boxes:
        axes = [axis(*stage_box[name]) for name in ("alpha0", "alpha0_dot", "decay_rate", "coefficient")]
        for _ in range(SAMPLE_CELLS // len(boxes) + 1):
            sample.append([rng.choice(values) for values in axes])
    sample = np.array(sample)
    start = time.perf_counter()
    misfit_cells_ode(time_s, observed, sample)
    per_cell = (time.perf_counter() - start) / len(sample)
    t_ode = per_cell * total_cells

    ratio_ode = t_ode / t_lsq
    ratio_grid = t_grid / t_lsq
    print("4 unknowns on the source's record (201 samples, 0..200 s)")
    print(f"  lsq (variable projection): {t_lsq * 1e3:9.2f} ms   {estimate.nfev} model evaluations   "
          f"alpha0 error {lsq_error:.2e} rad")
    print(f"  (a) grid, ODE per cell   : {t_ode:9.1f} s    {total_cells} cells at {per_cell * 1e3:.2f} ms "
          f"(sample of {len(sample)})   alpha0 error {grid_error:.2e} rad (same cells as (b))")
    print(f"  (b) grid, vectorised     : {t_grid * 1e3:9.1f} ms   {total_cells} cells   "
          f"alpha0 error {grid_error:.2e} rad")
    print("  note: the true alpha0 = 3.69 pi/540 lies on the source's third-stage grid, hence the grid's zero error;")
    print("        off the grid its error is up to half a third-stage step, 2.9e-5 rad.")
    print(f"  ratio (a) / lsq: {ratio_ode:12.0f}x   (target >= 10000x)")
    print(f"  ratio (b) / lsq: {ratio_grid:12.1f}x   (target >= 20x)")
    failures = []
    if ratio_ode < 10_000:
        failures.append("ODE grid ratio below 10,000x")
    if ratio_grid < 20:
        failures.append("vectorised grid ratio below 20x")
    if lsq_error > 1e-9:
        failures.append("lsq alpha0 error above 1e-9 rad")
    for failure in failures:
        print(f"MISSED: {failure}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
