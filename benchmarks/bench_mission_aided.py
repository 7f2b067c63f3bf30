"""Benchmark: the aided mission's covariance analysis, and the covariance against the filter's Monte Carlo.

* Covariance analysis of the 1-h tactical drive with 1-Hz GNSS and three 60-s outages
  (``examples/mission_tactical_gnss.toml``: 3600 covariance steps, 18 sources through the closed loop in one
  stack): wall and CPU time (target < 1 s, issue 28), against the same budget computed one source at a time
  (one analysis per source with every other switched off, the nominal filter rerun each time), measured in the
  same run; the two agree to rounding.
* Each aided example's ``--monte-carlo 1000`` (``schuler aided``'s filter on the nonlinear INS): its time
  (target < 4 min) and, at the end of every outage, the members' RMS horizontal error beside the covariance's
  1-sigma (target: within 10 %; the RMS of 1000 two-degree-of-freedom errors scatters by 1.6 %).

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_mission_aided.py``.
"""

from __future__ import annotations

import time
import tomllib
from pathlib import Path

from bench_mission import timed
from schuler.mission.aiding import aided_budget
from schuler.mission.setup import mission_setup
from schuler.study.scenario import load_scenario

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def one_at_a_time(setup, sources):
    """Each source's variance at every outage's end, one analysis per source (the others switched off)."""
    return {name: [o["horizontal_error_sigma_m"] ** 2 for o in
                   aided_budget(setup, disabled=tuple(s for s in sources if s != name)).outages]
            for name in sources}


def main() -> None:
    scenario = load_scenario(EXAMPLES / "mission_tactical_gnss.toml")
    setup = mission_setup(dict(scenario.definition().case(**scenario.given())))
    aided_budget(setup)  # warm-up
    budget, wall, cpu = timed(lambda: aided_budget(setup))
    sources = budget.budget.sources
    separate, base_wall, base_cpu = timed(lambda: one_at_a_time(setup, sources), repeat=1)
    worst = max(abs(separate[name][k] / (o["horizontal_error_sigma_m"] ** 2 * o["shares"][name]) - 1.0)
                for k, o in enumerate(budget.outages) for name in sources if o["shares"][name] > 1e-9)
    print(f"covariance analysis, 1-h tactical drive, {budget.budget.time.size - 1} steps, {len(sources)} sources, "
          f"{len(budget.outages)} outages: {wall:.3f} s wall, {cpu:.3f} s CPU (target < 1 s)")
    print(f"  one analysis per source: {base_wall:.2f} s wall, {base_cpu:.2f} s CPU; ratio {base_cpu / cpu:.1f}x "
          f"(CPU); the same shares to {worst:.1e}")
    for path in sorted(EXAMPLES.glob("mission_*_gnss.toml")):
        title = tomllib.loads(path.read_text())["title"]
        scenario = load_scenario(path)
        start = time.perf_counter()
        result = scenario.definition().run(**scenario.given(), monte_carlo=1000, seed=scenario.monte_carlo.seed)
        seconds = time.perf_counter() - start
        print(f"{path.name} ({title}): --monte-carlo 1000 in {seconds:.0f} s wall (target < 240 s)")
        for outage in result.to_dict()["monte_carlo"]["outages"]:
            ratio = outage["horizontal_error_end_rms_m"] / outage["horizontal_error_sigma_m"]
            print(f"  outage at {outage['start_s']:g} s for {outage['duration_s']:g} s: covariance "
                  f"{outage['horizontal_error_sigma_m']:.3f} m, Monte Carlo RMS at the end "
                  f"{outage['horizontal_error_end_rms_m']:.3f} m ({100 * (ratio - 1):+.1f} %), of the largest "
                  f"{outage['horizontal_error_max_rms_m']:.3f} m")


if __name__ == "__main__":
    main()
