"""Benchmark: north by variable-projection least squares against the source's grid search,
and the Monte Carlo of that estimator.

On one record (the source's experiment, source 004: 0..200 s every 1 s, simulated
by numerical integration) the 4-unknown identification is timed three ways:

* lsq: variable projection from the default start (no grid);
* (a) the source's procedure: three grid stages (the printed boxes, 568,008 cells),
  one numerical integration of eqs. (1)-(2) per cell; a random sample of cells is
  timed and the time scaled to all cells;
* (b) the same three stages with the vectorised closed form (Gram-matrix misfit).

The Monte Carlo (:func:`schuler.ground_gyrocompass.monte_carlo.monte_carlo`) fits
every noisy record with the production estimator from its default start; it is
timed against a plain loop of ``identify()`` over the same records (what a user's
script would do), and its failure rates are printed for the source's case, a short
noisy window, and nominal values 30 % / 20 % off.

Targets: lsq at least 10,000x faster than (a) and 20x faster than (b); lsq alpha0
error <= 1e-9 rad on the noise-free record; the Monte Carlo no slower than the
loop of identify() with 4 unknowns (0.9x, for timing noise) and at least 5x faster
with 2 (one QR for all records). Exits non-zero if a target is missed.
Run: python benchmarks/bench_ground_gyrocompass.py
"""

from __future__ import annotations

import sys
import time

import numpy as np

from schuler.core.geometry import ARCSEC, time_grid
from schuler.ground_gyrocompass import motion
from schuler.ground_gyrocompass.estimate import identify
from schuler.ground_gyrocompass.grid import axis, misfit_cells_ode, refine, source_boxes
from schuler.ground_gyrocompass.monte_carlo import monte_carlo
from schuler.ground_gyrocompass.observations import observe
from schuler.ground_gyrocompass.reproduction import source_b, source_record

SAMPLE_CELLS = 40
REPEATS = 5
ROUNDS = 6
MC_MEMBERS = 200


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
    failures += monte_carlo_section(b)
    for failure in failures:
        print(f"MISSED: {failure}")
    return 1 if failures else 0


def monte_carlo_section(b: float) -> list[str]:
    """Time the Monte Carlo against a loop of identify() on the same records; print its failure rates."""
    truth = {"alpha0": motion.SOURCE_ALPHA0, "alpha0_dot": motion.SOURCE_ALPHA0_DOT,
             "decay_rate": motion.SOURCE_LAMBDA, "coefficient": b}
    instrument = {"hm": motion.SOURCE_HM, "inertia": motion.SOURCE_INERTIA, "omega_h": motion.SOURCE_OMEGA_H}
    duration, noise = 120.0, 5 * ARCSEC
    time_s = time_grid(duration, 1.0)
    angle = motion.closed_form(time_s, truth["alpha0"], truth["alpha0_dot"], motion.SOURCE_LAMBDA, b)
    failures = []
    print(f"\nMonte Carlo: {MC_MEMBERS} records of {duration:g} s, noise 5 arcsec, production estimator")
    for unknowns, target in ((4, 0.9), (2, 5.0)):
        # the Monte Carlo's records for seed 0 are these: the same generator, the same observation model
        records = observe(np.broadcast_to(angle, (MC_MEMBERS, time_s.size)), truth["alpha0"], noise,
                          rng=np.random.default_rng(0))

        def loop(records=records, unknowns=unknowns):
            return [identify(time_s, record, unknowns, decay_rate=motion.SOURCE_LAMBDA, **instrument)
                    for record in records]

        def study(unknowns=unknowns):
            return monte_carlo(truth, [duration], [noise], members=MC_MEMBERS, unknowns=unknowns, seed=0)

        loop_times, study_times = [], []
        for _ in range(3):
            loop_times.append(best_time(loop, repeats=1)[0])
            t_study, result = best_time(study, repeats=1)
            study_times.append(t_study)
        t_loop, t_study = min(loop_times), min(study_times)
        estimates = np.array([estimate.alpha0_rad for estimate in loop()])
        loop_std = float(np.std(estimates - truth["alpha0"], ddof=1)) / ARCSEC
        ratio = t_loop / t_study
        print(f"  {unknowns} unknowns: monte_carlo {t_study * 1e3 / MC_MEMBERS:6.2f} ms per record, "
              f"loop of identify() {t_loop * 1e3 / MC_MEMBERS:6.2f} ms per record: ratio {ratio:5.2f}x "
              f"(target >= {target:g}x); north std {result.std_error_rad[0, 0] / ARCSEC:.4f} arcsec "
              f"(loop {loop_std:.4f}, predicted {result.predicted_std_rad[0, 0] / ARCSEC:.4f})")
        if ratio < target:
            failures.append(f"Monte Carlo with {unknowns} unknowns below {target:g}x the loop of identify()")
    print("  failure rates (1 - converged, and converged but off by more than 5 predicted sigma), 4 unknowns:")
    cases = [
        ("source case, 200 s, 1 arcsec", [200.0], [1 * ARCSEC], None),
        ("source case, 200 s, 10 arcsec", [200.0], [10 * ARCSEC], None),
        ("short window, 60 s, 10 arcsec", [60.0], [10 * ARCSEC], None),
        ("60 s, 10 arcsec, nominal lambda +30 %, B -20 %", [60.0], [10 * ARCSEC],
         {"decay_rate": 1.3 * motion.SOURCE_LAMBDA, "coefficient": 0.8 * b}),
    ]
    for label, durations, noises, nominal in cases:
        result = monte_carlo(truth, durations, noises, members=1000, unknowns=4, seed=1, nominal=nominal)
        print(f"    {label:48s} not converged {1 - result.converged_fraction[0, 0]:.3%}, "
              f"gross errors {result.gross_error_fraction[0, 0]:.3%} of 1000")
    return failures


if __name__ == "__main__":
    sys.exit(main())
