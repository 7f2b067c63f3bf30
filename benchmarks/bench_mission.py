"""Benchmark: the mission study's covariance analysis and its nonlinear Monte Carlo.

* Covariance analysis of a 10-h cruise (navigation-grade IMU, 15-min Kalman alignment, 60-s steps,
  17 sources, every source's contribution at every step): wall and CPU time (target < 1 s, issue 18),
  against the same budget computed source by source with the navigate layer's per-run linear model
  (:func:`schuler.navigation_errors.three_d.propagate_along`, one call per constant source and a
  sampled Monte Carlo of the white noises being out of the question, the constant sources only),
  measured in the same run.
* Monte Carlo of the nonlinear INS (1-h great circle, 200 members, 2 Hz IMU, white noise on all six
  axes from the navigate layer's :class:`~schuler.navigate.errors.WhiteNoise`, the IMU layer's
  compiled streams): member-samples per second, and the noise's own rate.
* The four example missions' --monte-carlo 1000 time, estimated from the measured throughput
  (issue 18: each under 4 minutes on 2 cores).

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_mission.py``.
"""

from __future__ import annotations

import math
import time
import tomllib
from pathlib import Path

import numpy as np

from schuler.core.attitude import dcm_from_quaternion
from schuler.core.random import RandomStreams
from schuler.mission.coefficients import step_coefficients
from schuler.mission.covariance import covariance_budget
from schuler.mission.evaluation import PARAMETERS
from schuler.mission.monte_carlo import run_members, white_noise
from schuler.mission.setup import CONSTANT_SOURCES, mission_setup
from schuler.mission.stages import initial_state_map, sensor_inputs
from schuler.navigation_errors.three_d import propagate_along
from schuler.study.scenario import load_scenario

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def setup_of(**values):
    case = PARAMETERS.case(values)
    return mission_setup({name: case[name] for name in PARAMETERS.names})


def timed(function, repeat: int = 3):
    best_wall = best_cpu = math.inf
    result = None
    for _ in range(repeat):
        wall, cpu = time.perf_counter(), time.process_time()
        result = function()
        best_wall = min(best_wall, time.perf_counter() - wall)
        best_cpu = min(best_cpu, time.process_time() - cpu)
    return result, best_wall, best_cpu


def source_by_source(setup):
    """The constant sources' final horizontal variance, one propagate_along call per source."""
    trajectory = setup.trajectory()
    c = step_coefficients(trajectory, setup.latitude, setup.height, setup.duration, setup.output_step)
    start = dcm_from_quaternion(trajectory.kinematics(np.array([0.0]))[1])[0]
    x0 = initial_state_map(setup, start, 7) * setup.constant_sigmas[:, None]
    sigmas = setup.constant_sigmas
    inputs = sensor_inputs(c.body_to_ned, c.body_rate, c.body_specific_force) * sigmas[None, :, None]
    total = 0.0
    for j in range(len(CONSTANT_SOURCES)):
        x = propagate_along(c.time, c.latitude, c.height, c.velocity_ned, c.specific_force_ned, x0[j],
                            inputs[:, j, :])
        total += x[-1, 0] ** 2 + x[-1, 1] ** 2
    return total


def main() -> None:
    cruise = setup_of(imu="navigation", trajectory="great-circle", duration=36000.0, alignment_duration=900.0)
    covariance_budget(cruise)  # warm-up
    budget, wall, cpu = timed(lambda: covariance_budget(cruise))
    constant, base_wall, base_cpu = timed(lambda: source_by_source(cruise), repeat=1)
    mine = budget.horizontal()[-1][:len(CONSTANT_SOURCES)].sum()
    print(f"covariance analysis, 10-h cruise, {budget.time.size - 1} steps, {len(budget.sources)} sources: "
          f"{wall:.3f} s wall, {cpu:.3f} s CPU (target < 1 s)")
    print(f"  constant sources one propagate_along call each: {base_wall:.3f} s wall, {base_cpu:.3f} s CPU; "
          f"ratio {base_cpu / cpu:.1f}x (CPU); same variance to {abs(constant / mine - 1):.1e}")
    print(f"  final 1-sigma {budget.sigma('horizontal_position')[-1]:.1f} m")

    setup = setup_of(imu="tactical", trajectory="great-circle", duration=3600.0)
    members, rate = 200, 2.0
    samples = members * setup.duration * rate
    run_members(setup, np.arange(4), RandomStreams(0), rate)  # numba warm-up
    _, wall, cpu = timed(lambda: run_members(setup, np.arange(members), RandomStreams(0), rate), repeat=1)
    mission_rate = samples / cpu
    print(f"Monte Carlo, 1-h great circle, {members} members at {rate:g} Hz: "
          f"{samples / wall / 1e6:.2f} M member-samples/s wall, {mission_rate / 1e6:.2f} M/s CPU")
    noise = white_noise(setup, RandomStreams(0))
    _, noise_wall, noise_cpu = timed(lambda: noise.increments(np.arange(members), 0, int(setup.duration * rate),
                                                              1 / rate), repeat=1)
    print(f"  the noise alone: {samples / noise_cpu / 1e6:.2f} M member-samples/s CPU")
    for path in sorted(EXAMPLES.glob("mission_*.toml")):
        values = tomllib.loads(path.read_text())
        if values["parameters"].get("aiding"):
            continue  # the filter's Monte Carlo: benchmarks/bench_mission_aided.py
        scenario = load_scenario(path)
        given = scenario.given()
        duration = given.get("duration", 7200.0)
        imu_rate = given.get("imu_rate", 2.0)
        estimate = 1000 * duration * imu_rate / mission_rate
        print(f"  {path.name} ({values['title']}): --monte-carlo 1000 about {estimate:.0f} s CPU (target < 240 s)")


if __name__ == "__main__":
    main()
