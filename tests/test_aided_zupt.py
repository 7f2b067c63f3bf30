"""Zero-velocity and zero-rate updates: H against h, the stop detector on the drive, a consumer IMU at a stop."""

import numpy as np
import pytest

from aided_measurement_helpers import assert_first_order, model, truth
from schuler.aided import measurements, sources
from schuler.aided.ekf import Start, run_filter
from schuler.aided.error_state import filter_model
from schuler.aided.gnss import GnssRecord
from schuler.core.earth import radii_of_curvature
from schuler.core.random import RandomStreams
from schuler.imu.simulate import ImuSimulator
from schuler.imu.spec import preset
from schuler.navigate.drive import drive
from schuler.navigate.truth import ideal_imu


def test_zero_rate_h_matches_its_residual_to_first_order():
    """Attitude, gyro bias and gyro scale columns of the zero-rate H against central differences of h."""
    filter_model_ = model(scale=True)
    true = truth(4, seed=3)
    ned_to_body = np.swapaxes(true.body_to_ned, 1, 2)
    omega_ie = np.stack([7.292115e-5 * np.cos(true.latitude), 0 * true.latitude,
                         -7.292115e-5 * np.sin(true.latitude)], axis=-1)
    still = measurements.Solution(true.latitude, true.longitude, true.height, np.zeros((4, 3)), true.body_to_ned,
                                  np.einsum("nij,nj->ni", ned_to_body, omega_ie))
    residual, H = measurements.zero_rate(still, still.angular_rate, filter_model_)
    assert np.allclose(residual, 0.0, atol=1e-18)  # the true rate at rest is the Earth's

    def h(solution, dx):
        return measurements.zero_rate(solution, solution.angular_rate, filter_model_)[0]

    scales = np.array([1.0] * 3 + [0.1] * 3 + [1e-3] * 3 + [1e-5] * 3 + [1e-3] * 3 + [1e-3] * 6)
    assert_first_order(h, still, H, filter_model_.size, scales)


def test_zero_velocity_residual_is_the_velocity_and_h_selects_it():
    filter_model_ = model(scale=False)
    true = truth(2)
    residual, H = measurements.zero_velocity(true, filter_model_)
    assert np.array_equal(residual, true.velocity)
    assert np.array_equal(np.einsum("nij,nj->ni", H, np.arange(15.0)[None].repeat(2, 0)), np.tile([3.0, 4, 5], (2, 1)))


def test_detector_finds_every_stop_of_the_drive():
    """A tactical IMU on the drive: each of the four 25-s stops holds a detected stop covering >= 90 % of it, and
    the speed changes and turns are never taken for stops (a vibration-free cruise is: see detect_stops)."""
    path = drive(duration=900.0)
    ideal = ideal_imu(path, 900.0, 100.0)
    dt = ideal.interval_s
    error_model = preset("tactical")
    simulator = ImuSimulator(error_model, dt, true_gyro=ideal.angle_increment_rad / dt,
                             true_accel=ideal.velocity_increment_m_s / dt, seed=4)
    gyro, accel = simulator.window(np.array([0]), 0, ideal.t_s.size)
    increments = np.concatenate([gyro, accel], axis=-1)[0] * dt
    found = sources.detect_stops(increments, dt, error_model.gyro.random_walk[0] / np.sqrt(dt),
                                 error_model.accel.random_walk[0] / np.sqrt(dt))
    for start, end in path.stationary_intervals():
        cover = max(min(end, b) - max(start, a) for a, b in found)
        assert cover >= 0.9 * (end - start), (start, end, found)
    speed = np.linalg.norm(path.kinematics(ideal.t_s)[0], axis=1)
    acceleration = np.abs(np.gradient(speed, dt))
    for a, b in found:
        inside = (ideal.t_s > a) & (ideal.t_s <= b)
        assert acceleration[inside].max() < 0.05  # m/s^2: no speed change inside a detected stop


def _consumer_at_the_first_stop(zupt: bool):
    """A consumer IMU standing for the drive's first 25 s, no GNSS: horizontal error at the end, m, of 4 members."""
    path = drive()
    duration = 24.0
    ideal = ideal_imu(path, duration, 100.0)
    dt = ideal.interval_s
    error_model = preset("consumer")
    simulator = ImuSimulator(error_model, dt, true_gyro=ideal.angle_increment_rad / dt,
                             true_accel=ideal.velocity_increment_m_s / dt, seed=RandomStreams(21).seed)
    members = np.arange(4)
    gyro, accel = simulator.window(members, 0, ideal.t_s.size)
    increments = np.concatenate([gyro, accel], axis=-1) * dt
    v0, q0 = path.kinematics(np.array([0.0]))
    ones = np.ones(4)
    start = Start(path.latitude * ones, path.longitude * ones, path.height * ones, np.repeat(v0, 4, 0),
                  np.repeat(q0, 4, 0), np.full(3, 1.0), np.full(3, 0.1), np.radians([1.0, 1.0, 5.0]))
    later = GnssRecord(np.array([duration + 10.0]), np.array([path.latitude]), np.array([path.longitude]),
                       np.array([path.height]), np.ones((1, 3)))  # after the end: no GNSS epoch is used
    fm = filter_model(error_model)
    extra = []
    if zupt:
        times = sources.stop_epochs([(0.0, duration)], 10.0)
        extra = [sources.zero_velocity_source(times, 0.01, fm), sources.zero_rate_source(times, 1e-4, fm)]
    run = run_filter(increments, dt, start, fm, later, sources=extra, output_every=100)
    R_N, R_E = radii_of_curvature(path.latitude)
    north = (run.solution[:, -1, 0] - ideal.latitude_rad[-1]) * R_N
    east = (run.solution[:, -1, 1] - ideal.longitude_rad[-1]) * R_E * np.cos(path.latitude)
    return np.hypot(north, east), run


def test_zupt_keeps_a_consumer_imus_drift_bounded_at_a_stop():
    """Measured (seed 21, 4 members, 24 s): free inertial 639 to 1,477 m; with ZUPT and ZARU at 10 Hz 0.5 to 1.1 mm."""
    free, _ = _consumer_at_the_first_stop(False)
    bounded, run = _consumer_at_the_first_stop(True)
    assert free.min() > 300.0
    assert bounded.max() < 0.01
    assert run.rejected_by_source()["zupt"].sum() == 0


@pytest.mark.slow
def test_stops_given_one_by_one_equal_the_drives_own_and_a_false_one_is_refused_by_the_gate(run_cli):
    from schuler.registry import get_system

    aided = get_system("aided")
    common = dict(duration=400.0, outage_start=250.0, aiding="gnss-position,gnss-velocity,zupt,zaru", seed=5)
    own = drive(duration=400.0).stationary_intervals()  # the simulated case is the drive from its own start
    listed = aided.run(stop_intervals=[[start, end - start] for start, end in own], **common)
    given = aided.run(**common)
    assert listed.outages == given.outages
    assert listed.rejected_by_source == given.rejected_by_source
    # a "stop" at road speed: every zero-velocity update there (10 Hz, 5 s) fails the gate
    moving = aided.run(stop_intervals=[[195.0, 5.0]], **common)  # at 20 m/s
    assert moving.rejected_by_source["zupt"] == 50
    out = run_cli("aided", "run", "--stop-intervals", "0:20", "--stops-from", "imu")
    assert out.code == 2 and "cannot be combined" in out.stderr
