"""The mission's batched evaluation: one covariance pass for many cases, the same numbers as one at a time."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.mission.api import SYSTEM
from schuler.mission.covariance import covariance_budget, covariance_budgets
from schuler.mission.evaluation import PARAMETERS
from schuler.mission.exponential import expm_stack
from schuler.mission.monte_carlo import final_horizontal_errors, run_members
from schuler.mission.setup import mission_setup


def setup_of(**values):
    case = PARAMETERS.case(values)
    return mission_setup({name: case[name] for name in PARAMETERS.names})


def test_the_stacked_exponential_is_scipys_to_rounding():
    rng = np.random.default_rng(4)
    # norms from 1e-3 (no squaring) to about 600 (a minute's step of the psi model: g dt), mixed in one stack
    matrices = rng.normal(size=(40, 13, 13)) * np.logspace(-4, 1.7, 40)[:, None, None]
    expected = np.array([scipy.linalg.expm(a) for a in matrices])
    scale = np.abs(expected).max(axis=(1, 2), keepdims=True)
    assert np.abs(expm_stack(matrices) - expected).max(axis=(1, 2), keepdims=True) / scale == \
        pytest.approx(0.0, abs=1e-12)


def test_the_covariance_analysis_makes_no_scipy_exponential(monkeypatch):
    # scipy's per-matrix LAPACK calls cost 10-40 times their arithmetic under OpenBLAS's threads on a busy
    # machine: the mission's thousands of small exponentials go through numpy's stacked solve instead
    def refuse(*args, **kwargs):
        raise AssertionError("scipy.linalg.expm called")

    monkeypatch.setattr(scipy.linalg, "expm", refuse)
    budget = covariance_budget(setup_of(imu="tactical", trajectory="flight", duration=2400.0))
    assert budget.sigma("horizontal_position")[-1] > 0


@pytest.mark.parametrize("batch_steps", [20_000, 80])  # one batch; batches of two 40-step missions
def test_a_batch_of_budgets_is_each_budget_alone(batch_steps, monkeypatch):
    from schuler.mission import covariance

    monkeypatch.setattr(covariance, "BATCH_STEPS", batch_steps)
    headings = np.radians([0.0, 75.0, 200.0])
    setups = [setup_of(imu="tactical", trajectory="flight", duration=2400.0, heading=h) for h in headings]
    setups.append(setup_of(imu="consumer", alignment="ground-gyrocompass", calibration="multi-position",
                           trajectory="great-circle", duration=2400.0, speed=20.0))
    for batched, setup in zip(covariance_budgets(setups), setups):
        alone = covariance_budget(setup)
        for channel in ("horizontal_position", "horizontal_velocity", "heading"):
            np.testing.assert_allclose(batched.sigma(channel), alone.sigma(channel), rtol=1e-12, atol=0)
        assert batched.shares() == pytest.approx(alone.shares(), rel=1e-10, abs=1e-15)


def test_a_batch_of_budgets_needs_one_step_grid():
    with pytest.raises(InvalidParameter, match="one duration, output step and vertical channel"):
        covariance_budgets([setup_of(duration=3600.0), setup_of(duration=7200.0)])


def test_members_of_different_imu_rates_each_fly_at_their_own():
    case = {"imu": "industrial", "alignment": "ground-gyrocompass", "trajectory": "stationary", "duration": 600.0}
    streams = RandomStreams(9)
    values = SYSTEM.evaluate_values({**case, "imu_rate": np.array([1.0, 4.0])}, members=np.array([3, 4]),
                                    random=streams)
    setup = setup_of(**case)
    for i, (member, rate) in enumerate(((3, 1.0), (4, 4.0))):
        alone = final_horizontal_errors(run_members(setup, np.array([member]), streams, rate,
                                                    output_step=setup.duration))[0]
        assert values["member_position_error_m"][i] == pytest.approx(alone, rel=1e-12)
    assert not math.isclose(values["member_position_error_m"][1],
                            final_horizontal_errors(run_members(setup, np.array([4]), streams, 1.0,
                                                                output_step=setup.duration))[0], rel_tol=1e-9)
