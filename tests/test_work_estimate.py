"""Long work is estimated before it starts, and refused past the time budget unless asked.

Every registered system declares ``member_seconds`` (declared work times a
measured rate); ``run`` and a sweep's plan multiply it by the members or cases
and refuse, in one line naming the estimate and the options to change, what
would take longer than the budget (10 min, ``SCHULER_TIME_BUDGET``) unless
``--no-time-limit`` is given. A system without its own estimate is held to the
pace its Monte Carlo's chunks show.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
import pytest

from schuler.contract import Cases
from schuler.memory import (
    DEFAULT_TIME_BUDGET,
    TimeBudgetExceeded,
    format_seconds,
    no_time_limit,
    parse_seconds,
    require_time,
    time_budget,
)
from schuler.registry import SYSTEM_MODULES, get_system
from schuler.study.plan import plan_sweep
from schuler.study.scenario import parse_scenario

LONG_RUNS = [
    ("north", {"monte_carlo": 1_000_000_000}, "`monte_carlo`"),
    ("navigate", {"duration": 864_000.0, "imu_rate": 100_000.0}, "`imu_rate`"),
    ("navigate", {"monte_carlo": 100_000}, "`monte_carlo`"),
    ("mission", {"monte_carlo": 1_000_000}, "`monte_carlo`"),
]
"""Runs that took over 90 s with neither a refusal nor an estimate, and an option the refusal must name."""


@pytest.mark.parametrize(("system", "values", "option"), LONG_RUNS)
def test_long_runs_are_refused_with_the_estimate_in_well_under_a_second(system, values, option):
    chosen = get_system(system)
    started = time.perf_counter()
    with pytest.raises(TimeBudgetExceeded) as caught:
        chosen.run(**values)
    seconds = time.perf_counter() - started
    message = str(caught.value)
    assert "would take about" in message and "more than the time budget of 10 min" in message
    assert option in message and "`no_time_limit`" in message and "\n" not in message
    assert seconds < 0.5


def test_a_scenario_of_a_billion_cases_is_refused_by_its_plan_and_by_run():
    scenario = parse_scenario('system = "north"\n[monte_carlo]\ncases = 1000000000\n'
                              '[monte_carlo.uniform]\nlatitude = ["10 deg", "60 deg"]\n')
    started = time.perf_counter()
    with pytest.raises(TimeBudgetExceeded, match="^this sweep of 1000000000 cases would take about"):
        plan_sweep(scenario, get_system("north"))
    with pytest.raises(TimeBudgetExceeded, match="with 1000000000 Monte Carlo members would take about"):
        get_system("north").run(monte_carlo=1_000_000_000, draw=scenario.draw, **scenario.values)
    assert time.perf_counter() - started < 1.0


def test_the_refusal_is_one_line_with_exit_code_2_and_the_option_lifts_it(run_cli, monkeypatch):
    outcome = run_cli("north", "run", "--monte-carlo", "1000000000")
    assert outcome.code == 2
    assert outcome.stderr.count("\n") == 1 and "would take about 22.7 days" in outcome.stderr
    monkeypatch.setenv("SCHULER_TIME_BUDGET", "1e-9 s")
    assert run_cli("errors", "run", "--duration", "60").code == 2
    lifted = run_cli("errors", "run", "--duration", "60", "--no-time-limit", "--json")
    assert lifted.code == 0, lifted.stderr


def test_a_sweep_shows_its_estimate_and_is_refused_past_the_budget(tmp_path, run_cli, monkeypatch):
    scenario = tmp_path / "north.toml"
    scenario.write_text('system = "north"\n[parameters]\nduration = "100 s"\n')
    plan = plan_sweep(parse_scenario(scenario.read_text()), get_system("north"),
                      ["latitude=10:60:10"])
    # 6 cases of 1.3 ms + 101 samples x 3.3 us each (the rates declared in ground_gyrocompass.api)
    assert plan.estimated_seconds == pytest.approx(6 * (1.3e-3 + 3.3e-6 * 101), rel=1e-6)
    monkeypatch.setenv("SCHULER_TIME_BUDGET", "0.001 s")
    refused = run_cli("sweep", scenario, "--param", "latitude=10:60:10", "--out", tmp_path / "out")
    assert refused.code == 2 and "this sweep of 6 cases would take about" in refused.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("name", list(SYSTEM_MODULES))
def test_every_system_declares_an_estimate_that_grows_with_its_work(name):
    system = get_system(name)
    assert system.member_seconds is not None
    case = system.case()
    single = system.work_seconds(case, 0)
    assert single is not None and 0.0 < single < DEFAULT_TIME_BUDGET
    assert system.work_seconds(case, 1000) == pytest.approx(single / 4 * 1004, rel=1e-12)
    longer = {p.name: p for p in system.parameters}.get("duration")
    if longer is not None and longer.maximum is not None and name not in ("errors", "calibrate"):
        # a longer run is more work (errors and calibrate take their time from the grid, not the duration)
        stretched = system.case(duration=float(longer.maximum) * (1 if longer.unit == "s" else 1))
        assert system.work_seconds(stretched, 0) > single


def test_estimates_are_within_a_factor_of_ten_of_the_measured_time():
    navigate = get_system("navigate")
    values = {"duration": 600.0, "imu_rate": 100.0}
    case = navigate.case(**values)
    batch = Cases.from_case(case, 2)
    navigate.evaluate(batch)  # compiled once, as in any run after the first chunk
    batch = Cases.from_case(case, 10)
    started = time.perf_counter()
    navigate.evaluate(batch)
    measured = (time.perf_counter() - started) / 10
    # the rate was measured at 3.2-4.3 ms per member for this case on a quiet machine and 26 ms under a load of 5
    assert navigate.member_seconds(case) / 10 < measured < 10 * navigate.member_seconds(case)


def test_a_system_without_an_estimate_is_refused_on_its_measured_pace(monkeypatch):
    align = get_system("align")

    def slow(cases, histories=False):
        time.sleep(0.02)
        return align.evaluate(cases, histories=histories)

    undeclared = dataclasses.replace(align, member_seconds=None, member_bytes=lambda case: 2**40, evaluate=slow)
    monkeypatch.setenv("SCHULER_TIME_BUDGET", "2 s")
    started = time.perf_counter()
    with pytest.raises(TimeBudgetExceeded, match=r"align Monte Carlo \(100000 members; pace measured\)"):
        undeclared.run(monte_carlo=100_000, duration=600.0)
    # one member per chunk (2**40 bytes each): refused after the second chunk, not after 100,000 x 20 ms
    assert time.perf_counter() - started < 5.0
    assert undeclared.work_seconds(undeclared.case(), 10) is None
    summary = undeclared.run(monte_carlo=3, duration=600.0).monte_carlo
    assert summary.members == 3


def test_the_budget_comes_from_the_environment_and_the_option(monkeypatch):
    monkeypatch.delenv("SCHULER_TIME_BUDGET", raising=False)
    assert time_budget() == DEFAULT_TIME_BUDGET == 600.0
    monkeypatch.setenv("SCHULER_TIME_BUDGET", "2 h")
    assert time_budget() == 7200.0
    with no_time_limit():
        assert time_budget() == math.inf
        require_time(1e30, "anything", "nothing")
    assert time_budget() == 7200.0
    with no_time_limit(False):
        with pytest.raises(TimeBudgetExceeded, match="^this run would take about 3.17e\\+04 years, more than the "
                                                     "time budget of 2 h; change --monte-carlo, or add"):
            require_time(1e12, "this run", "--monte-carlo")
    monkeypatch.setenv("SCHULER_TIME_BUDGET", "soon")
    with pytest.raises(Exception, match="SCHULER_TIME_BUDGET: cannot read 'soon'"):
        time_budget()


@pytest.mark.parametrize(("text", "seconds"), [("90", 90.0), ("90 s", 90.0), ("10 min", 600.0), ("1.5 h", 5400.0),
                                               ("2 days", 172800.0), ("1e3", 1000.0), ("none", math.inf)])
def test_durations_are_read_as_people_write_them(text, seconds):
    assert parse_seconds(text) == seconds


@pytest.mark.parametrize(("seconds", "text"), [(5.0, "5 s"), (95.0, "1.58 min"), (600.0, "10 min"),
                                               (7200.0, "2 h"), (1.5e7, "174 days"), (1e9, "31.7 years")])
def test_estimates_are_shown_in_readable_units(seconds, text):
    assert format_seconds(seconds) == text


def test_the_progress_label_carries_the_estimate(monkeypatch, run_cli):
    import schuler.cli.systems as systems

    labels = []
    original = systems.progress_reporter

    def recording(label, enabled=True):
        labels.append(label)
        return original(label, enabled)

    monkeypatch.setattr(systems, "progress_reporter", recording)
    outcome = run_cli("calibrate", "run", "--monte-carlo", "20")
    assert outcome.code == 0, outcome.stderr
    expected = get_system("calibrate").work_seconds(get_system("calibrate").case(), 20)
    assert labels == [f"calibrate Monte Carlo (estimate {format_seconds(expected)})"]
    assert np.isclose(expected, 4e-5 * 4 * 24, rtol=1e-12)
