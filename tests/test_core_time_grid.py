"""One time-grid rule: the core's ``time_grid``, its invariants, and every system's output times following it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler import get_system
from schuler.core.geometry import GRID_TOLERANCE, grid_points, time_grid, time_grids
from schuler.exceptions import InvalidParameter

# a whole number of steps, within the tolerance of one (moved onto the duration), off by more, and mid-step
OFFSETS = st.sampled_from([0.0, 1e-10, -1e-10, 1e-12, -5e-10, 2e-9, -2e-9, 0.5, 0.999, 1e-6])


@st.composite
def grids(draw):
    """(duration, step) pairs, half of them within a few 1e-9 steps of a whole number of steps."""
    step = draw(st.floats(1e-3, 1e4))
    if draw(st.booleans()):
        duration = step * (draw(st.integers(2, 100_000)) + draw(OFFSETS))
    else:
        duration = step * draw(st.floats(1.0, 1e5))
    return duration, step


def _check_rule(duration: float, step: float, t: np.ndarray) -> None:
    assert t[0] == 0.0 and t[-1] == duration
    assert np.all(np.diff(t) > 0.0)
    # every point but the last is k step, rounded once: the steps before the last are `step` up to that rounding
    np.testing.assert_array_equal(t[:-1], step * np.arange(t.size - 1))
    last = t[-1] - t[-2]
    # the last step is at most one step, or longer by the 1e-9 step a duration on a step may be moved by (plus the
    # rounding of duration / step and of the subtraction)
    assert 0.0 < last <= step * (1.0 + GRID_TOLERANCE) + 8.0 * np.spacing(duration)


@settings(max_examples=400, deadline=None)
@given(grids())
def test_time_grid_invariants(grid):
    duration, step = grid
    t = time_grid(duration, step)
    _check_rule(duration, step, t)
    ratio = duration / step
    if abs(ratio - round(ratio)) <= 0.5 * GRID_TOLERANCE:    # well within the tolerance: ends on that step
        assert t.size == round(ratio) + 1
    elif abs(ratio - round(ratio)) >= 2.0 * GRID_TOLERANCE:  # well beyond it: a shorter last step
        assert t.size == math.floor(ratio) + 2 and t[-1] - t[-2] < step
    assert grid_points(duration, step) == t.size


@settings(max_examples=100, deadline=None)
@given(st.lists(grids(), min_size=1, max_size=5))
def test_grid_points_and_time_grids_agree_with_time_grid(cases):
    durations, steps = (np.array(values) for values in zip(*cases))
    # keep the padded batch small: at most 10,000 points per case
    steps = np.maximum(steps, durations / 9_999.0)
    counts = grid_points(durations, steps)
    time, valid = time_grids(durations, steps)
    for k in range(len(cases)):
        single = time_grid(durations[k], steps[k])
        assert counts[k] == single.size == valid[k].sum()
        np.testing.assert_array_equal(time[k][valid[k]], single)


def test_grid_points_is_sized_before_it_is_refused():
    # an absurd grid is counted (a float), so that a memory check can refuse it; max_points refuses it here
    assert grid_points(1e12, 1e-6) == pytest.approx(1e18 + 1.0)
    with pytest.raises(InvalidParameter, match=r"^output_step: .*at most 1,000"):
        grid_points(np.array([10.0, 1e6]), 1.0, names=("duration", "output_step"), max_points=1000)


# ----------------------------------------------------- every system's output times follow the rule

STEP = 10.0
DURATIONS = {
    "on a step": 600.0,
    "1e-10 step beyond one": 600.0 + 1e-10 * STEP,
    "1e-10 step short of one": 600.0 - 1e-10 * STEP,
    "mid-step": 605.0,
}
"""(duration, step) pairs: 60 whole steps; within 1e-9 step of them (the last point moved onto the duration);
a shorter last step of half a step."""

RUNS = {
    "errors": ("errors_run_drift", {"source": "drift"}),
    "vertical": ("vertical_timeseries", {}),
    "align": ("align_time_history", {}),
}
"""The systems with a time grid of their own once, and the histories a run keeps on it."""


@pytest.mark.parametrize("system", list(RUNS))
@pytest.mark.parametrize("where", list(DURATIONS))
def test_every_system_samples_on_the_core_time_grid(system, where):
    stem, values = RUNS[system]
    duration = DURATIONS[where]
    result = get_system(system).run(duration=duration, output_step=STEP, **values)
    np.testing.assert_array_equal(result.histories[stem].time, time_grid(duration, STEP))
    assert result.histories[stem].time[-1] == duration


@pytest.mark.parametrize("system", list(RUNS))
def test_every_system_names_its_own_step_when_it_refuses_a_grid(system):
    with pytest.raises(InvalidParameter, match="longer than the duration") as error:
        get_system(system).run(duration=100.0, output_step=200.0, **RUNS[system][1])
    assert error.value.name == "output_step"
