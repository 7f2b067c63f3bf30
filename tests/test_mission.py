"""The mission study: budget invariants, stage closed forms, covariance against the nonlinear Monte Carlo."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.core.attitude import dcm_from_quaternion
from schuler.core.earth import EARTH_RATE
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.mission.covariance import covariance_budget
from schuler.mission.evaluation import PARAMETERS
from schuler.mission.monte_carlo import final_horizontal_errors, initial_errors, member_draws, run_members
from schuler.mission.reproduction import reproduce
from schuler.mission.setup import CONSTANT_SOURCES, mission_setup
from schuler.navigate.mechanization import navigate
from schuler.units import from_unit


def setup_of(**values):
    case = PARAMETERS.case(values)
    return mission_setup({name: case[name] for name in PARAMETERS.names})


MISSIONS = {
    "kalman-cruise": {"imu": "tactical", "trajectory": "great-circle", "duration": 3600.0},
    "gyrocompass-stationary": {"imu": "navigation", "alignment": "gyrocompass", "trajectory": "stationary",
                               "duration": 7200.0, "alignment_duration": 900.0},
    "ground-flight": {"imu": "industrial", "alignment": "ground-gyrocompass", "calibration": "multi-position",
                      "trajectory": "flight", "duration": 1800.0, "initial_position_error": 10.0},
}


@pytest.mark.parametrize("name", MISSIONS)
def test_shares_add_up_to_the_total(name):
    budget = covariance_budget(setup_of(**MISSIONS[name]))
    for index in (1, budget.time.size // 2, -1):
        assert sum(budget.shares(index).values()) == pytest.approx(1.0, abs=1e-12)
    # the shares are of the total the budget reports: the sum of the variances is sigma^2
    assert budget.horizontal()[-1].sum() == pytest.approx(budget.sigma("horizontal_position")[-1] ** 2, rel=1e-12)


@pytest.mark.parametrize("name", MISSIONS)
def test_switching_off_a_source_removes_exactly_its_share(name):
    setup = setup_of(**MISSIONS[name])
    budget = covariance_budget(setup)
    total = budget.horizontal()[-1].sum()
    shares = budget.shares()
    for source in sorted(shares, key=lambda s: -shares[s])[:3]:
        without = covariance_budget(setup, disabled=(source,)).horizontal()[-1].sum()
        # linear dynamics, independent sources: exact up to rounding
        assert 1.0 - without / total == pytest.approx(shares[source], rel=1e-9, abs=1e-12)


def test_the_stage_closed_forms_and_invariants_reproduce():
    reproduction = reproduce()
    assert reproduction.failures == []
    assert len(reproduction.rows) == 5


def test_a_gyro_bias_acts_through_the_heading_it_leaves_and_during_navigation():
    # one source: the east gyro bias of a level vehicle heading north is the y gyro; after a Kalman alignment
    # the heading error it leaves and its drift cancel in the psi equation's east line (equilibrium), so at rest
    # psi_E stays put and the north error it makes is only the 24-h mode's: far less than without the alignment
    setup = setup_of(imu="navigation", trajectory="stationary", heading=0.0, duration=4 * 3600.0)
    with_alignment = covariance_budget(setup)
    i = with_alignment.sources.index("gyro_bias_y")
    through_both = with_alignment.horizontal()[-1, i]
    x0 = with_alignment.initial_state[i]
    sigma = setup.constant_sigmas[CONSTANT_SOURCES.index("gyro_bias_y")]
    # psi_D = -epsilon_E / (Omega cos L), epsilon_E = -b_y: the closed form (Groves 2013, Sec. 5.6.2)
    assert x0[-1] == pytest.approx(sigma / (EARTH_RATE * math.cos(setup.latitude)), rel=1e-12)
    free = covariance_budget(setup_of(imu="navigation", trajectory="stationary", heading=0.0,
                                      duration=4 * 3600.0, alignment="ground-gyrocompass",
                                      north_reference_error=0.0))
    assert through_both < 0.05 * free.horizontal()[-1, i]


def test_calibration_residuals_follow_their_closed_forms():
    pulse = setup_of(imu="tactical", calibration="pulse", calibration_duration=600.0, trajectory="stationary",
                     duration=3600.0)
    gyro = pulse.error_model.gyro
    floor = np.hypot(0.0034 * gyro.bias, gyro.random_walk / math.sqrt(600.0))
    assert np.all(pulse.gyro_bias_sigma() >= floor)
    assert np.all(pulse.gyro_bias_sigma() <= np.hypot(floor, 2 * gyro.bias_instability))
    multi = setup_of(imu="tactical", calibration="multi-position", calibration_duration=600.0,
                     trajectory="stationary", duration=3600.0)
    # the multi-position test removes the accelerometer turn-on bias (1 mg) down to its noise and slow terms
    assert np.all(multi.accel_bias_sigma() < 0.1 * pulse.accel_bias_sigma())
    assert np.allclose(multi.accel_scale_factor_sigma(),
                       multi.error_model.accel.random_walk / (9.80665 * math.sqrt(600.0)), rtol=1e-12)


def test_the_monte_carlo_starts_from_the_attitude_error_the_covariance_assumes():
    setup = setup_of(imu="tactical", trajectory="great-circle", duration=600.0, heading=math.radians(30.0))
    trajectory = setup.trajectory()
    q0 = trajectory.kinematics(np.array([0.0]))[1][0]
    members = np.arange(6)
    _, x0 = member_draws(setup, members, RandomStreams(3), 7, dcm_from_quaternion(q0))
    result = navigate(trajectory, 60.0, imu_rate=1.0, output_step=60.0,
                      initial_errors=initial_errors(x0, setup, q0), member_ids=members)
    phi0 = result.attitude_error_rad[:, 0]
    # psi = phi - delta_theta with no position error: phi0 is the drawn psi0 to second order (tilts of mrad)
    assert np.allclose(phi0, x0[:, -3:], rtol=0.0, atol=1e-3 * np.abs(x0[:, -3:]).max())


def test_members_do_not_depend_on_chunking():
    setup = setup_of(imu="industrial", trajectory="stationary", duration=600.0)
    streams = RandomStreams(5)
    whole = final_horizontal_errors(run_members(setup, np.arange(4), streams, 1.0))
    parts = np.concatenate([final_horizontal_errors(run_members(setup, np.arange(i, i + 2), streams, 1.0))
                            for i in (0, 2)])
    assert np.array_equal(whole, parts)


def test_covariance_agrees_with_the_nonlinear_monte_carlo_short():
    # a cheap variant of the slow three-mission check: 400 members, navigation grade, 2-h stationary.
    # The RMS over 400 members of a 2-D error has a relative standard error of about 1/sqrt(4 * 400) = 2.5 %;
    # 10 % is four of them
    setup = setup_of(imu="navigation", trajectory="stationary", duration=7200.0, alignment_duration=900.0)
    sigma = covariance_budget(setup).sigma("horizontal_position")[-1]
    errors = final_horizontal_errors(run_members(setup, np.arange(400), RandomStreams(11), 1.0))
    assert math.sqrt(np.mean(errors**2)) == pytest.approx(sigma, rel=0.10)


LONG_MISSIONS = {
    "stationary-24h": {"imu": "navigation", "trajectory": "stationary", "duration": 86400.0,
                       "alignment_duration": 900.0, "output_step": 600.0, "imu_rate": 0.5},
    "flight-2h": {"imu": "navigation", "trajectory": "flight", "duration": 7200.0, "alignment_duration": 900.0,
                  "imu_rate": 1.0},
    "cruise-10h": {"imu": "navigation", "trajectory": "great-circle", "duration": 36000.0, "alignment_duration": 900.0,
                   "output_step": 600.0, "imu_rate": 0.5},
}
"""The issue's three missions; reduced IMU rates (exact for the noise increments, ample for the smooth paths)."""


@pytest.mark.slow
@pytest.mark.parametrize("name", LONG_MISSIONS)
def test_covariance_agrees_with_the_nonlinear_monte_carlo(name):
    # the budget's acceptance: final 1-sigma within 10 % at 1,000 members (sampling error of the RMS about 1.6 %)
    values = dict(LONG_MISSIONS[name])
    rate = values.pop("imu_rate")
    setup = setup_of(**values)
    sigma = covariance_budget(setup).sigma("horizontal_position")[-1]
    errors = np.concatenate([final_horizontal_errors(run_members(setup, np.arange(i, i + 250), RandomStreams(7), rate,
                                                                 output_step=setup.duration))
                             for i in range(0, 1000, 250)])
    assert math.sqrt(np.mean(errors**2)) == pytest.approx(sigma, rel=0.10)


def test_bad_stage_choices_are_refused_by_name():
    with pytest.raises(InvalidParameter, match="alignment_duration"):
        covariance_budget(setup_of(alignment="gyrocompass", alignment_duration=20.0, latitude=math.radians(60.0),
                                   gyrocompass_time_constant=600.0))
    with pytest.raises(InvalidParameter, match="duration"):
        setup_of(trajectory="flight", duration=600.0).trajectory()
    with pytest.raises(InvalidParameter, match="output_step"):
        covariance_budget(setup_of(duration=3601.0, output_step=60.0))


def test_a_better_gyro_buys_more_than_a_longer_alignment_for_a_tactical_flight():
    base = {"trajectory": "flight", "duration": 7200.0}
    tactical = covariance_budget(setup_of(imu="tactical", **base)).sigma("horizontal_position")[-1]
    longer = covariance_budget(setup_of(imu="tactical", alignment_duration=1800.0, **base))
    navigation = covariance_budget(setup_of(imu="navigation", **base)).sigma("horizontal_position")[-1]
    assert navigation < longer.sigma("horizontal_position")[-1] < tactical
    assert from_unit(1.0, "arcmin") > 0


def test_sensor_inputs_map_unit_sources_through_the_attitude():
    from schuler.mission.stages import sensor_inputs

    # heading 90 deg: body x points east, y south, z down
    body_to_ned = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    rate, force = np.array([2.0, 3.0, 5.0]), np.array([0.0, 0.0, -9.8])
    inputs = sensor_inputs(body_to_ned, rate, force)
    assert inputs.shape == (len(CONSTANT_SOURCES), 6)
    row = dict(zip(CONSTANT_SOURCES, inputs))
    np.testing.assert_array_equal(row["gyro_bias_x"], [0, 0, 0, 0.0, -1.0, 0.0])          # epsilon = -C b_g
    np.testing.assert_array_equal(row["accel_bias_y"], [-1.0, 0.0, 0.0, 0, 0, 0])         # nabla = C b_a
    np.testing.assert_array_equal(row["gyro_scale_factor_y"], [0, 0, 0, 3.0, 0.0, 0.0])   # -C diag(omega) k
    np.testing.assert_array_equal(row["accel_scale_factor_z"], [0.0, 0.0, -9.8, 0, 0, 0])  # C diag(f) k
    np.testing.assert_array_equal(row["north_reference"], np.zeros(6))
