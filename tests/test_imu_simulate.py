"""Simulation: the same numbers for any cut in members or time, the constant errors, the static truth."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.imu.error_model import ErrorModel, SensorErrors
from schuler.imu.files import read_record
from schuler.imu.simulate import ImuSimulator, iter_simulation, simulate_members, static_truth, write_simulation
from schuler.imu.spec import preset


def every_term_model():
    """All terms on, with small correlation times so that short records exercise every process."""
    gyro = SensorErrors(bias=1e-5, bias_instability=2e-6, flicker_tau_range_s=(0.5, 50.0), gm_sigma=3e-6,
                        gm_correlation_time_s=5.0, random_walk=5e-5, rate_random_walk=1e-6, quantization=2e-6,
                        scale_factor=1e-4, misalignment=1e-3, g_sensitivity=1e-6)
    accel = SensorErrors(bias=1e-3, bias_instability=5e-4, flicker_tau_range_s=(0.5, 50.0), gm_sigma=1e-4,
                         gm_correlation_time_s=2.0, random_walk=1e-3, rate_random_walk=1e-5, quantization=1e-4,
                         scale_factor=3e-4, misalignment=5e-4)
    return ErrorModel(gyro=gyro, accel=accel, name="every term")


TRUTH = static_truth(math.radians(50.0), math.radians(30.0))


@pytest.fixture(scope="module")
def whole():
    return simulate_members(every_term_model(), samples=9000, sample_interval_s=0.01, members=[0, 1, 2, 5], seed=11,
                            true_gyro_rad_s=TRUTH[0], true_accel_m_s2=TRUTH[1])


@settings(max_examples=5, deadline=None)
@given(window=st.integers(min_value=700, max_value=9000), member_chunk=st.integers(min_value=1, max_value=4))
def test_any_cut_in_time_and_members_gives_the_same_samples(whole, window, member_chunk):
    simulator = ImuSimulator(every_term_model(), 0.01, true_gyro_rad_s=TRUTH[0], true_accel_m_s2=TRUTH[1], seed=11)
    gyro, accel = np.empty_like(whole[0]), np.empty_like(whole[1])
    members = np.array([0, 1, 2, 5])
    for group, start, g, a in iter_simulation(simulator, members, 9000, window=window, member_chunk=member_chunk):
        rows = np.searchsorted(members, group)
        gyro[rows, start:start + g.shape[1]] = g
        accel[rows, start:start + g.shape[1]] = a
    assert np.array_equal(gyro, whole[0]) and np.array_equal(accel, whole[1])


def test_windows_out_of_order_and_threads_give_the_same_samples(whole):
    simulator = ImuSimulator(every_term_model(), 0.01, true_gyro_rad_s=TRUTH[0], true_accel_m_s2=TRUTH[1], seed=11,
                             workers=2)
    late, _ = simulator.window([5, 0], 6000, 9000)
    early, _ = simulator.window([5, 0], 0, 6000)
    assert np.array_equal(late[0], whole[0][3, 6000:]) and np.array_equal(early[1], whole[0][0, :6000])


def test_members_and_seeds_differ(whole):
    other, _ = simulate_members(every_term_model(), samples=100, sample_interval_s=0.01, members=[0], seed=12,
                                true_gyro_rad_s=TRUTH[0], true_accel_m_s2=TRUTH[1])
    assert not np.array_equal(whole[0][0, :100], whole[0][1, :100])
    assert not np.array_equal(whole[0][0, :100], other[0])


def test_quantised_increments_are_whole_steps(whole):
    step = 2e-6 * math.sqrt(12.0)
    counts = whole[0] * 0.01 / step
    assert np.allclose(counts, np.round(counts), atol=1e-6)


def test_static_truth_is_earth_rate_and_gravity_in_the_body_frame():
    gyro, accel = static_truth(math.radians(50.0), math.radians(90.0), gravity_m_s2=9.81)
    omega = 7.292115e-5
    # heading 90 deg: x points east (no north rate), y points south (-Omega cos L), z down (-Omega sin L)
    assert gyro == pytest.approx([0.0, -omega * math.cos(math.radians(50)), -omega * math.sin(math.radians(50))],
                                 abs=1e-15)
    assert accel == pytest.approx([0.0, 0.0, -9.81])


def test_constants_are_drawn_per_member_with_the_model_sigmas():
    model = ErrorModel(gyro=SensorErrors(bias=2e-5, scale_factor=1e-4, misalignment=1e-3, g_sensitivity=1e-6))
    constants = ImuSimulator(model, 0.01, seed=3).constants(np.arange(20_000))
    # 60,000 draws: sample std within 1 % (3 x 1/sqrt(2 x 60,000)) of the model's 1-sigma
    assert constants["gyro_bias"].std() == pytest.approx(2e-5, rel=0.01)
    diagonal = np.diagonal(constants["gyro_matrix"], axis1=1, axis2=2) - 1.0
    assert diagonal.std() == pytest.approx(1e-4, rel=0.01)
    off = constants["gyro_matrix"][:, ~np.eye(3, dtype=bool)]
    assert off.std() == pytest.approx(1e-3, rel=0.01)
    assert constants["gyro_g"].std() == pytest.approx(1e-6, rel=0.01)


def test_deterministic_errors_follow_the_measurement_equation():
    model = ErrorModel(gyro=SensorErrors(bias=1e-5, scale_factor=1e-3, misalignment=1e-3, g_sensitivity=1e-5))
    simulator = ImuSimulator(model, 0.01, true_gyro_rad_s=TRUTH[0], true_accel_m_s2=TRUTH[1], seed=5)
    gyro, accel = simulator.window([7], 0, 10)
    c = simulator.constants([7])
    expected = c["gyro_matrix"][0] @ TRUTH[0] + c["gyro_bias"][0] + c["gyro_g"][0] @ TRUTH[1]
    assert gyro[0] == pytest.approx(np.tile(expected, (10, 1)), rel=1e-12)
    assert accel[0] == pytest.approx(np.tile(TRUTH[1], (10, 1)))


def test_time_varying_truth_and_its_length():
    truth = np.column_stack([np.linspace(0, 1, 50), np.zeros(50), np.zeros(50)])
    simulator = ImuSimulator(ErrorModel(), 0.1, true_gyro_rad_s=truth, seed=0)
    gyro, _ = simulator.window([0], 10, 20)
    assert gyro[0, :, 0] == pytest.approx(truth[10:20, 0])
    with pytest.raises(InvalidParameter, match="cover 50 samples"):
        simulator.window([0], 40, 60)


def test_slow_processes_use_a_coarse_grid_only_under_white_noise():
    steps = ImuSimulator(preset("tactical"), 0.01).coarse_steps()
    assert max(steps.values()) > 100 and min(steps.values()) >= 1
    quiet = ErrorModel(gyro=SensorErrors(gm_sigma=1e-6, gm_correlation_time_s=100.0))
    assert set(ImuSimulator(quiet, 0.01).coarse_steps().values()) == {1}


def test_memory_is_estimated_before_allocating():
    with pytest.raises(InvalidParameter, match="GB, above"):
        simulate_members(preset("tactical"), samples=10**9, sample_interval_s=0.01, members=100)


def test_streamed_file_equals_the_in_memory_record(tmp_path):
    from schuler.imu.simulate import simulate_record

    path = write_simulation(tmp_path / "s.parquet", preset("industrial"), duration_s=30.0, sample_interval_s=0.01,
                            seed=4)
    record = simulate_record(preset("industrial"), duration_s=30.0, sample_interval_s=0.01, seed=4)
    streamed = read_record(path)
    assert np.array_equal(streamed.gyro, record.gyro) and np.array_equal(streamed.time_s, record.time_s)


def test_normal_series_is_independent_of_the_window():
    streams = RandomStreams(5)
    whole = streams.normal_series("a", [2, 9], 0, 20_000)
    for start, stop in [(0, 1), (4095, 4097), (8191, 19_999), (12_345, 20_000)]:
        assert np.array_equal(streams.normal_series("a", [9, 2], start, stop), whole[::-1, start:stop])
    # standard normal: mean and std of 40,000 draws within 4 standard errors
    assert abs(whole.mean()) < 4 / math.sqrt(whole.size) and abs(whole.std() - 1) < 4 / math.sqrt(2 * whole.size)
