"""Benchmark: a 48-hour gyro-vertical simulation at 1-s output, and its stick/slip friction run.

Case: the source's worked example (60 deg, 10 m/s due west, R = 6.4e6 m) moving
along its great circle for 48 h, output every second (172,801 samples).

* Model run: :meth:`GyroVertical.simulate` (DOP853, rtol 1e-10, dense output
  evaluated on the 1-s grid). Printed: wall time, steps, right-hand-side
  evaluations.
* Baseline, same run: a naive solve_ivp (RK45, same tolerances, ``max_step`` =
  the 1-s output step, ``t_eval`` the grid), timed over 6 h and scaled to 48 h.
* Agreement of the two over the 6 h (velocity error), to show the speed costs no
  accuracy.
* Friction: 48 h of (30) at 1-s output with event-driven stick/slip switching.

Targets: model run < 5 s, ratio >= 10, agreement <= 1e-6 m/s, friction run < 10 s
with fewer than 150 evaluations per switch.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

from schuler.core.earth import DROZDOVICH
from schuler.gyro_vertical.friction import simulate_friction
from schuler.gyro_vertical.model import ATOL_TILT, ATOL_VELOCITY, RTOL, GyroVertical
from schuler.gyro_vertical.trajectory import GreatCircleTrajectory

HOURS = 48.0
BASELINE_HOURS = 6.0
TARGET_TIME = 5.0
TARGET_RATIO = 10.0
TARGET_AGREEMENT = 1e-6
TARGET_FRICTION_TIME = 10.0


def naive(model: GyroVertical, grid: np.ndarray) -> np.ndarray:
    """Velocity error y by RK45 forced to 1-s steps, kinematics evaluated at every call."""
    path = model.trajectory

    def rhs(t, x):
        return model.derivative(t, x, path.kinematics(t))

    atol = np.array([ATOL_TILT, ATOL_TILT, ATOL_VELOCITY, ATOL_VELOCITY])
    solution = solve_ivp(rhs, (grid[0], grid[-1]), model.initial_state(), method="RK45", t_eval=grid,
                         max_step=1.0, rtol=RTOL, atol=atol)
    return solution.y[3] - path.kinematics(grid).v_y


def main() -> int:
    path = GreatCircleTrajectory.from_source(math.radians(60.0), 10.0, radius=DROZDOVICH.radius,
                                             rate=DROZDOVICH.rate)
    model = GyroVertical(path, DROZDOVICH.gravity)
    grid = np.arange(0.0, HOURS * 3600 + 0.5, 1.0)

    start = time.perf_counter()
    response = model.simulate(grid)
    elapsed = time.perf_counter() - start
    print(f"model: {HOURS:g} h at 1-s output ({grid.size} samples) in {elapsed:.2f} s; "
          f"{response.method}: {response.n_steps} steps, {response.nfev} evaluations")

    short = grid[grid <= BASELINE_HOURS * 3600]
    start = time.perf_counter()
    baseline_error = naive(model, short)
    baseline = (time.perf_counter() - start) * HOURS / BASELINE_HOURS
    ratio = baseline / elapsed
    agreement = float(np.max(np.abs(baseline_error - response.velocity_error_y[: short.size])))
    print(f"baseline (RK45, max_step 1 s): {baseline:.1f} s (scaled from {BASELINE_HOURS:g} h)")
    print(f"ratio: {ratio:.0f}x (target >= {TARGET_RATIO:.0f}x); agreement {agreement:.1e} m/s "
          f"(target <= {TARGET_AGREEMENT:.0e})")

    q = 0.01 / DROZDOVICH.radius
    start = time.perf_counter()
    friction = simulate_friction((q, q), grid, initial_tilt=(0.0, math.radians(0.2 / 3600)),
                                 gravity=DROZDOVICH.gravity, radius=DROZDOVICH.radius)
    friction_time = time.perf_counter() - start
    switches = len(friction.switch_times) - 1
    per_switch = friction.nfev / max(switches, 1)
    print(f"friction: {HOURS:g} h at 1-s output in {friction_time:.2f} s; {switches} stick/slip switches, "
          f"{friction.nfev} evaluations ({per_switch:.0f} per switch)")

    ok = (elapsed < TARGET_TIME and ratio >= TARGET_RATIO and agreement <= TARGET_AGREEMENT
          and friction_time < TARGET_FRICTION_TIME and per_switch < 150)
    print("PASS" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
