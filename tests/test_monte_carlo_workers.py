"""A run's Monte Carlo spread over worker processes: the same members, summarised in the same order."""

from __future__ import annotations

import numpy as np
import pytest

from schuler.cases import monte_carlo
from schuler.core.random import RandomStreams
from schuler.drift_calibration.api import SYSTEM
from schuler.study.executors import make_executor


class Reversed:
    """An executor that finishes its tasks in the reverse of their order (as worker processes may)."""

    workers = 2

    def map(self, function, tasks):
        return reversed([function(task) for task in tasks])


def assert_same_statistics(got: dict, expected: dict) -> None:
    assert got.keys() == expected.keys()
    for key, value in expected.items():
        if value is None:
            assert got[key] is None, key
        else:
            assert got[key] == pytest.approx(value, rel=1e-9, abs=1e-15), key


def draw_azimuth(numbers):
    return {"azimuth": np.radians(10.0) * (numbers % 7)}


@pytest.mark.parametrize("draw", [None, draw_azimuth], ids=["system's terms", "drawn parameter"])
def test_chunks_finished_in_any_order_give_the_statistics_of_the_chunks_in_order(draw):
    case = SYSTEM.case(mode="single-axis", positions=3, loop_time_constant=0.002)
    summaries = [monte_carlo(SYSTEM.evaluate, SYSTEM.outputs, case, 97, RandomStreams(4), chunk=10, draw=draw,
                             executor=executor) for executor in (None, Reversed())]
    assert summaries[0].statistics == summaries[1].statistics
    for name, values in summaries[0].samples.items():
        np.testing.assert_array_equal(summaries[1].samples[name], values)


def test_worker_processes_give_the_members_of_this_process():
    case = SYSTEM.case(mode="single-axis", positions=3, loop_time_constant=0.002)
    executor = make_executor(workers=2)
    try:
        parallel = SYSTEM.monte_carlo(case, 120, RandomStreams(5), executor=executor)
    finally:
        executor.close()
    alone = SYSTEM.monte_carlo(case, 120, RandomStreams(5))
    assert parallel.members == alone.members == 120
    for name, values in alone.samples.items():
        # the members' values are the same; the chunks differ (two per worker), so the statistics merge at rounding
        np.testing.assert_allclose(parallel.samples[name], values, rtol=1e-12, atol=0)
        assert_same_statistics(parallel.statistics[name].to_dict(), alone.statistics[name].to_dict())


def test_the_time_estimate_shares_the_members_among_the_cores(monkeypatch):
    monkeypatch.setattr("os.sched_getaffinity", lambda pid: {0, 1}, raising=False)
    case = SYSTEM.case()
    if SYSTEM.work_seconds(case, 100) is None:
        pytest.skip("drift calibration declares no time per member")
    one, two, eight = (SYSTEM.work_seconds(case, 100, workers=w) for w in (1, 2, 8))
    full = SYSTEM.work_seconds(case, 0)
    assert two - full == pytest.approx((one - full) / 2, rel=1e-12)
    assert eight == pytest.approx(two, rel=1e-12)  # two cores: more workers than that share them


def test_workers_on_the_command_line(run_cli):
    options = ("calibrate", "run", "--mode", "single-axis", "--positions", "3", "--monte-carlo", "60", "--json")
    alone, parallel = run_cli(*options), run_cli(*options, "--workers", "2")
    assert alone.code == 0 and parallel.code == 0, parallel.stderr
    statistics = [outcome.json()["monte_carlo"]["statistics"] for outcome in (alone, parallel)]
    assert statistics[0].keys() == statistics[1].keys()
    for name, values in statistics[0].items():
        assert_same_statistics(statistics[1][name], values)
    refused = run_cli(*options, "--workers", "0")
    assert refused.code == 2 and "--workers" in refused.stderr
