"""Self-alignment at rest: each method against exact attitudes, the static limits, and schuler align's steady state.

Noise-free records are built from the true inputs (:func:`schuler.imu.simulate.static_truth`, or a
tilted body's C^T omega and C^T f), so every method must return the attitude to rounding; constant
biases must move it by the static limits of spec 06 ("Alignment at rest").
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.alignment.coarse import align_coarse
from schuler.alignment.data import StaticBatch, convergence_time
from schuler.alignment.gyrocompass import align_gyrocompass, settling_time
from schuler.alignment.inertial import align_inertial, net_rotation
from schuler.alignment.kalman import KalmanTuning, align_kalman
from schuler.alignment.limits import (
    accuracy_limit,
    gyrocompass_error_model,
    gyrocompass_noise,
    gyrocompass_steady_state,
    heading_random_walk,
    kpi_equivalent_inputs,
    static_errors,
)
from schuler.core.attitude import dcm_from_euler, euler_from_dcm, triad, wrap_angle
from schuler.core.earth import earth_rate_ned
from schuler.core.gyrocompass_design import loop_gains
from schuler.exceptions import InvalidParameter, NotObservable
from schuler.gyrocompassing.analytic import full_steady_state, steady_state
from schuler.imu.error_model import ErrorModel, SensorErrors
from schuler.imu.spec import preset

DEG_H = math.radians(1.0) / 3600.0
G = 9.80665


def static_batch(latitude, roll, pitch, heading, *, seconds=300.0, dt=0.01, gyro_bias=(0, 0, 0), accel_bias=(0, 0, 0)):
    """A noise-free record of a body at rest with the given attitude and constant biases (measured - true)."""
    C = dcm_from_euler(roll, pitch, heading)
    gyro = C.T @ earth_rate_ned(latitude) + np.asarray(gyro_bias, dtype=float)
    accel = C.T @ np.array([0.0, 0.0, -G]) + np.asarray(accel_bias, dtype=float)
    n = int(round(seconds / dt))
    return StaticBatch(np.tile(gyro * dt, (1, n, 1)), np.tile(accel * dt, (1, n, 1)), dt, latitude, G)


SIMPLE = ErrorModel(gyro=SensorErrors(bias=np.full(3, 0.01 * DEG_H),
                                      random_walk=np.full(3, 0.002 * math.radians(1) / 60)),
                    accel=SensorErrors(bias=np.full(3, 25e-6 * G), random_walk=np.full(3, 10e-6 * G)), name="test")


@settings(max_examples=60, deadline=None)
@given(st.floats(-3.0, 3.0), st.floats(-1.5, 1.5), st.floats(-3.1, 3.1))
def test_euler_round_trip(roll, pitch, heading):
    C = dcm_from_euler(roll, pitch, heading)
    assert np.allclose(C @ C.T, np.eye(3), atol=1e-12)
    r, p, h = euler_from_dcm(C)
    assert np.allclose(dcm_from_euler(r, p, h), C, atol=1e-12)   # the same rotation (angles unique up to gimbal lock)


@settings(max_examples=40, deadline=None)
@given(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5), st.floats(-3.1, 3.1))
def test_triad_recovers_any_rotation(roll, pitch, heading):
    C = dcm_from_euler(roll, pitch, heading)
    a, b = np.array([0.3, -1.0, 2.0]), np.array([1.0, 0.5, -0.2])
    assert np.allclose(triad(C.T @ a, C.T @ b, a, b), C, atol=1e-12)


@pytest.mark.parametrize("attitude_deg", [(0, 0, 0), (2, -3, 30), (-5, 1, -120), (0.5, 0.5, 179.5)])
@pytest.mark.parametrize("align", [align_coarse, align_inertial], ids=["coarse", "inertial_frame"])
def test_noise_free_records_give_the_attitude(attitude_deg, align):
    roll, pitch, heading = np.radians(attitude_deg)
    estimate = align(static_batch(math.radians(40.0), roll, pitch, heading))
    # tolerance: rounding of 30,000 increments and, for the inertial frame, the coning/sculling algorithm: 1e-9 rad
    assert estimate.roll_rad[0] == pytest.approx(roll, abs=1e-9)
    assert estimate.pitch_rad[0] == pytest.approx(pitch, abs=1e-9)
    assert wrap_angle(estimate.heading_rad[0] - heading) == pytest.approx(0.0, abs=1e-9)


def bias_case(heading_deg=30.0, vertical=0.05):
    gyro_bias = np.array([0.02, -0.03, vertical]) * DEG_H
    accel_bias = np.array([1e-4, -2e-4, 3e-4]) * G
    return math.radians(45.0), math.radians(heading_deg), gyro_bias, accel_bias


@pytest.mark.parametrize("heading_deg", [0.0, 30.0, 135.0, -100.0])
def test_coarse_alignment_errors_are_the_static_limits(heading_deg):
    latitude, heading, gyro_bias, accel_bias = bias_case(heading_deg)
    estimate = align_coarse(static_batch(latitude, 0.0, 0.0, heading, gyro_bias=gyro_bias, accel_bias=accel_bias))
    roll, pitch, psi = static_errors(latitude, heading, gyro_bias, accel_bias, G)
    # spec 06: roll = -b_ay/g, pitch = b_ax/g, heading = -b_gE/(Omega cos L) + b_aE tan L/g, first order: the
    # z bias changes the sensed g by b_az/g = 3e-4 (so 1e-3 relative); the north bias scales the heading error
    # by 1 - b_gN/(Omega cos L), 3e-3 here (so 5e-3 relative)
    assert estimate.roll_rad[0] == pytest.approx(roll, rel=1e-3)
    assert estimate.pitch_rad[0] == pytest.approx(pitch, rel=1e-3)
    assert wrap_angle(estimate.heading_rad[0] - heading) == pytest.approx(psi, rel=5e-3)
    assert roll == pytest.approx(-accel_bias[1] / G) and pitch == pytest.approx(accel_bias[0] / G)


@pytest.mark.parametrize("align", [align_inertial, lambda b: align_kalman(b, SIMPLE),
                                   lambda b: align_gyrocompass(b, time_constant=30.0, damping=0.8)],
                         ids=["inertial_frame", "kalman", "gyrocompass"])
def test_every_method_sees_the_same_static_limit(align):
    """Biases at rest are indistinguishable from attitude: no method removes them (spec 06).

    Without a vertical gyro bias: that one turns the heading during the window, each method its own way
    (:func:`test_vertical_gyro_bias_turns_the_inertial_frame_heading`).
    """
    latitude, heading, gyro_bias, accel_bias = bias_case(vertical=0.0)
    estimate = align(static_batch(latitude, 0.0, 0.0, heading, gyro_bias=gyro_bias, accel_bias=accel_bias))
    roll, pitch, psi = static_errors(latitude, heading, gyro_bias, accel_bias, G)
    # the gyrocompass adds its loop terms c_gamma b_gD/(c_a Omega cos L) - tan L b_gN/c_gamma (< 1 % here); the
    # Kalman filter ends within its own sigma of the static limit: 1 % of the heading error allowed for all
    assert wrap_angle(estimate.heading_rad[0] - heading) == pytest.approx(psi, rel=0.01)
    if estimate.method == "inertial_frame":   # the north tilt drifts by phi_N = -(3/4) b_gN T to the window's end
        north = math.cos(heading) * gyro_bias[0] - math.sin(heading) * gyro_bias[1]
        roll += math.cos(heading) * 0.75 * north * 300.0      # roll = -(cos psi phi_N + sin psi phi_E)
        pitch -= math.sin(heading) * 0.75 * north * 300.0     # pitch = sin psi phi_N - cos psi phi_E
    # second order and the east tilt the inertial frame leaves: 5 % of the level error
    assert estimate.roll_rad[0] == pytest.approx(roll, rel=0.05)
    assert estimate.pitch_rad[0] == pytest.approx(pitch, rel=0.05)


def test_vertical_gyro_bias_turns_the_inertial_frame_heading():
    """The inertial-frame estimate of C_b^n(0) rests on the middle of the window; carried to its end by the gyros
    it turns with the vertical bias: heading error + b_gD T / 2 (in accuracy_limit's bias part)."""
    latitude, heading = math.radians(45.0), math.radians(30.0)
    vertical = np.array([0.0, 0.0, 0.5]) * DEG_H
    estimate = align_inertial(static_batch(latitude, 0.0, 0.0, heading, gyro_bias=vertical))
    # second order: the tilt left by the turn, < 1e-3 relative
    assert wrap_angle(estimate.heading_rad[0] - heading) == pytest.approx(vertical[2] * 300.0 / 2.0, rel=1e-3)


@pytest.mark.parametrize("fraction", [0.1, 0.4, 0.6, 0.9])
def test_inertial_frame_tilt_impulse_responses(fraction):
    """A gyro angle step a at time u T moves the final level by k(u) a (heading 0): roll from the x gyro
    k = 2u | 1, pitch from the y gyro k = -u | 3u - 2 (before | after u = 1/2).

    These kernels give accuracy_limit's tilt noise (var 2T/3 north, T/6 east) and bias drift ((3/4) b T north,
    0 east).
    """
    latitude, amplitude = math.radians(45.0), 1e-4
    clean = static_batch(latitude, 0.0, 0.0, 0.0, seconds=300.0, dt=0.1)
    k = int(fraction * clean.samples)
    roll_kernel = 2 * fraction if fraction < 0.5 else 1.0
    pitch_kernel = -fraction if fraction < 0.5 else 3 * fraction - 2
    cases = ((0, roll_kernel, lambda e: e.roll_rad[0]), (1, pitch_kernel, lambda e: e.pitch_rad[0]))
    for axis, expected, read in cases:
        gyro = clean.gyro_increment.copy()
        gyro[0, k, axis] += amplitude
        estimate = align_inertial(StaticBatch(gyro, clean.accel_increment, 0.1, latitude, G))
        # the step lands at the end of sample k (u off by 1/n) and second-order terms: 0.01 in k
        assert read(estimate) / amplitude == pytest.approx(expected, abs=0.01)


def test_kalman_covariance_keeps_the_unobservable_bias_floor():
    """The heading 1-sigma cannot fall below sigma_bE / (Omega cos L): bias and heading are one observable."""
    latitude, heading = math.radians(45.0), math.radians(30.0)
    estimate = align_kalman(static_batch(latitude, 0.0, 0.0, heading, seconds=600.0, dt=0.05), SIMPLE)
    floor = accuracy_limit("kalman", SIMPLE, latitude=latitude, heading=heading, duration=600.0)
    assert estimate.sigma_rad[0, 2] >= 0.999 * floor.heading_bias_rad
    assert estimate.sigma_rad[0, 2] == pytest.approx(floor.heading_rad, rel=0.05)
    assert estimate.sigma_rad[0, 0] == pytest.approx(floor.roll_rad, rel=0.02)
    # the history shrinks: a filter that only grows its covariance would pass the floor test
    assert estimate.sigma_history_rad[0, 0, 2] > 2.0 * estimate.sigma_history_rad[0, -1, 2]


def test_gyrocompass_loop_settles_at_its_linear_steady_state():
    latitude, heading = math.radians(40.0), math.radians(30.0)
    gyro_bias, accel_bias = np.array([0.03, -0.07, 0.05]) * DEG_H * 0.1, np.array([2e-4, -1e-4, 3e-4]) * G
    batch = static_batch(latitude, 0.0, 0.0, heading, seconds=600.0, gyro_bias=gyro_bias, accel_bias=accel_bias)
    estimate = align_gyrocompass(batch, time_constant=30.0, damping=0.8)
    C = dcm_from_euler(0.0, 0.0, heading)
    c_gamma, c_a = loop_gains(latitude, 30.0, 0.8)
    phi = gyrocompass_steady_state(latitude, c_gamma, c_a, C @ gyro_bias, C @ accel_bias, G)
    # the nonlinear loop differs from the linear model by second-order terms (error ~4e-4 rad): 0.1 %
    assert wrap_angle(estimate.heading_rad[0] - heading) == pytest.approx(-phi[2], rel=1e-3)
    c, s = math.cos(heading), math.sin(heading)
    assert estimate.roll_rad[0] == pytest.approx(-(c * phi[0] + s * phi[1]), rel=1e-2)
    assert estimate.pitch_rad[0] == pytest.approx(s * phi[0] - c * phi[1], rel=1e-2)
    assert settling_time(30.0, 0.8) == pytest.approx(187.5)


@pytest.mark.parametrize("latitude_deg", [10.0, 50.45, 70.0])
def test_loop_steady_state_is_system_4s_full_model(latitude_deg):
    """KPI manual (1.18) with drift = -C b_g, eps_beta = -b_aN/g, eps_alpha = b_aE/g: the same numbers."""
    latitude = math.radians(latitude_deg)
    c_gamma, c_a = loop_gains(latitude, 30.0, 0.8)
    gyro_ned, accel_ned = np.array([0.2, -0.4, 0.3]) * DEG_H, np.array([1e-4, 2e-4, 0.0]) * G
    phi = gyrocompass_steady_state(latitude, float(c_gamma), float(c_a), gyro_ned, accel_ned, G)
    kpi = kpi_equivalent_inputs(gyro_ned, accel_ned, G)
    delta, beta, alpha = full_steady_state(latitude, c_gamma, c_a, **kpi)
    assert -phi[2] == pytest.approx(float(delta), rel=1e-12)      # heading error = delta
    assert -phi[1] == pytest.approx(float(beta), rel=1e-12) and -phi[0] == pytest.approx(float(alpha), rel=1e-12)


def test_static_heading_limit_is_the_gyro_term_of_1_21():
    """(1.21): delta_y = drift_east / (U cos phi) + c_gamma drift_up / (c_a U cos phi); the static limit's gyro term
    is its first part, the loop adds the second (with drift = -C b_g, drift_up = b_gD)."""
    latitude = math.radians(50.0)
    c_gamma, c_a = loop_gains(latitude, 30.0, 0.8)
    for east, down in ((0.01, 0.0), (-0.02, 0.0), (0.0, 0.05)):
        gyro_ned = np.array([0.0, east, down]) * DEG_H
        delta_y, _ = steady_state(latitude, c_gamma, c_a, drift_east=-gyro_ned[1], drift_up=gyro_ned[2])
        static = static_errors(latitude, 0.0, gyro_ned, np.zeros(3))[2]
        loop = c_gamma * gyro_ned[2] / (c_a * 7.292115e-5 * math.cos(latitude))
        assert float(delta_y) == pytest.approx(static + loop, rel=1e-12, abs=1e-18)
        if down == 0.0:   # schuler align's tested example: 0.01 deg/h east at 50 deg gives 3.556 arcmin (KPI manual)
            assert abs(float(delta_y)) == pytest.approx(abs(east) / 0.01 * math.radians(3.556 / 60), rel=1e-3)


def test_random_walk_limit_and_loop_noise():
    n = math.radians(0.125) / 60          # tactical ARW, 0.125 deg/sqrt(h)
    latitude = math.radians(45.0)
    # N / (Omega cos L sqrt(T)): 0.125 deg/sqrt(h) over 100 s at 45 deg is 0.0354 rad (hand-worked: 3.636e-5 /
    # (7.292e-5 * 0.7071 * 10) = 0.0705... / 2 = 0.0353)
    assert heading_random_walk(latitude, n, 100.0) == pytest.approx(3.6361e-5 / (7.292115e-5 * math.sqrt(0.5) * 10),
                                                                    rel=1e-4)
    assert heading_random_walk(latitude, n, 100.0) / heading_random_walk(latitude, n, 400.0) == pytest.approx(2.0)
    # the loop averages the east gyro noise over ~4 zeta T: sigma^2 = N^2 (c_a + W)^2 / (2 omega0^2 c_gamma)
    c_gamma, c_a = loop_gains(latitude, 60.0, 0.7)
    rate = 7.292115e-5 * math.cos(latitude)
    omega2 = rate * (c_a + rate)
    closed = n * (c_a + rate) / math.sqrt(2 * omega2 * c_gamma)
    _, _, heading = gyrocompass_noise(latitude, c_gamma, c_a, [0.0, n, 0.0], [0.0, 0.0, 0.0])
    assert heading == pytest.approx(closed, rel=1e-5)   # the closed form leaves out the Omega sin L couplings
    A, _ = gyrocompass_error_model(latitude, c_gamma, c_a)
    assert np.all(np.linalg.eigvals(A).real < 0)


def test_net_rotation_finds_a_disturbance():
    """A body that turns by 0.01 rad about its x axis during the window: the inertial-frame integration sees it."""
    latitude, dt, n = math.radians(34.0), 0.01, 20_000
    angle = np.clip((np.arange(n) + 0.5 - 5_000) / 1_000, 0.0, 1.0) * 0.01      # 0.01 rad over samples 5000-6000
    C = dcm_from_euler(angle, 0.0, 0.3)
    gyro = np.einsum("kji,j->ki", C, earth_rate_ned(latitude))
    gyro[5_000:6_000, 0] += 0.01 / (1_000 * dt)
    accel = np.einsum("kji,j->ki", C, np.array([0.0, 0.0, -G]))
    turned = StaticBatch(gyro[None] * dt, accel[None] * dt, dt, latitude, G)
    rotation = net_rotation(turned)[0]
    # the turn, in NED: 0.01 rad about the body x axis at heading 0.3 rad; rounding and coning: 1e-6 rad
    assert rotation == pytest.approx(0.01 * np.array([math.cos(0.3), math.sin(0.3), 0.0]), abs=1e-6)
    still = static_batch(latitude, 0.0, 0.0, 0.3, seconds=n * dt, dt=dt)
    assert np.linalg.norm(net_rotation(still)[0]) < 1e-12


def test_convergence_time():
    time = np.arange(1.0, 11.0)
    history = np.array([[1.0, 0.5, 0.2, 0.0, 0.01, 0.0, 0.0, 0.0, 0.0, 0.0]])
    assert convergence_time(time, history, np.array([0.0]), 0.1)[0] == 4.0


def test_bad_input_is_refused():
    batch = static_batch(math.radians(45.0), 0.0, 0.0, 0.0, seconds=10.0, dt=0.1)
    with pytest.raises(NotObservable, match="latitude"):
        accuracy_limit("coarse", SIMPLE, latitude=math.radians(89.5), heading=0.0, duration=300.0)
    with pytest.raises(InvalidParameter, match="method"):
        accuracy_limit("sextant", SIMPLE, latitude=0.5, heading=0.0, duration=300.0)
    bad = batch.gyro_increment.copy()
    bad[0, 3, 1] = np.nan
    with pytest.raises(InvalidParameter, match="NaN"):
        StaticBatch(bad, batch.accel_increment, 0.1, 0.5)
    with pytest.raises(InvalidParameter, match="time_constant"):
        loop_gains(0.5, 0.0, 0.8)
    with pytest.raises(InvalidParameter, match="update_interval"):
        align_kalman(batch, SIMPLE, update_interval=float("nan"))
    with pytest.raises(NotObservable):
        align_gyrocompass(static_batch(math.radians(89.9), 0.0, 0.0, 0.0, seconds=10.0, dt=0.1))


@pytest.mark.parametrize("window", [0.0, -600.0, float("nan"), float("inf")])
def test_kalman_tuning_refuses_a_bad_window_by_name(window):
    model = preset("tactical")
    with pytest.raises(InvalidParameter, match=r"window: must be finite and > 0 s"):
        KalmanTuning.from_model(model, window=window)
    # q = B^2 / window: over 400 s the walk is B / 20
    tuning = KalmanTuning.from_model(model, window=400.0)
    np.testing.assert_allclose(tuning.gyro_bias_walk, np.asarray(model.gyro.bias_instability) / 20.0, rtol=1e-15)


def test_a_consumer_grade_record_gives_finite_answers():
    """Heading is meaningless at consumer grade (bias 20 deg/s >> Earth rate): finite numbers and a limit saying so."""
    from schuler.alignment.comparison import AlignmentSettings, compare_alignment, simulated_batch

    model = preset("consumer")
    batch, _ = simulated_batch(model, latitude=0.7, heading=0.3, duration=60.0, sample_interval=0.05,
                               members=[0], seed=3)
    result = compare_alignment(batch, model, AlignmentSettings(), truth=(0.0, 0.0, 0.3))
    for row in result.methods.values():
        assert all(math.isfinite(row[key]) for key in ("roll_rad", "pitch_rad", "heading_rad"))
        assert row["limit_heading_rad"] > 1.0     # rad: the limit says heading is unknown
