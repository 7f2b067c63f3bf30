"""The 3-D psi-angle INS error model on a rotating Earth: modes, single-channel limit, the three-d action."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.core.earth import (
    BOLLAY,
    EARTH_RATE,
    MEAN_RADIUS,
    STANDARD_GRAVITY,
    earth_rate_ned,
    gravity_ned,
    meridian_radius,
    transport_rate_ned,
    transverse_radius,
)
from schuler.core.lti import simulate
from schuler.exceptions import InvalidParameter
from schuler.navigation_errors.single_channel import flat_error, spherical_error
from schuler.navigation_errors.three_d import (
    foucault_velocity_response,
    propagate_along,
    psi_angle_model,
    stationary_modes,
    wgs84_error_matrices,
    wgs84_gravity_gradient,
    wgs84_psi_angle_model,
)
from schuler.navigation_errors.three_d_run import THREE_D_PARAMETERS, three_d


def _sorted_by_frequency(values):
    values = np.asarray(values)
    return values[np.lexsort((values.real, values.imag))]


@pytest.mark.parametrize("latitude_deg", [0.0, 10.0, 45.0, 60.0, -33.0, 80.0])
def test_stationary_eigenvalues_match_the_exact_theory(latitude_deg):
    L = math.radians(latitude_deg)
    model = psi_angle_model(L, MEAN_RADIUS, STANDARD_GRAVITY, EARTH_RATE)
    computed = _sorted_by_frequency(model.eigenvalues())
    omega_s = math.sqrt(STANDARD_GRAVITY / MEAN_RADIUS)
    omega_z = EARTH_RATE * math.sin(L)
    split = math.sqrt(omega_s**2 + omega_z**2)
    exact = _sorted_by_frequency(1j * np.array([
        0.0, EARTH_RATE, -EARTH_RATE, split + omega_z, -(split + omega_z), split - omega_z, -(split - omega_z)]))
    np.testing.assert_allclose(computed, exact, rtol=0, atol=1e-6 * EARTH_RATE)
    nonzero = np.abs(exact) > 0
    np.testing.assert_allclose(computed[nonzero], exact[nonzero], rtol=1e-6)
    np.testing.assert_allclose(_sorted_by_frequency(stationary_modes(L, MEAN_RADIUS, STANDARD_GRAVITY, EARTH_RATE)),
                               exact, rtol=1e-15)


def test_non_rotating_limit_of_a_north_drift_is_the_single_channel_formula():
    # drift about east makes a north error: (R eps / omega)(omega t - sin omega t), Bollay (1966) eq. (4)
    epsilon = math.radians(0.01) / 3600
    R, g = BOLLAY.radius, BOLLAY.effective_gravity
    model = psi_angle_model(math.radians(30.0), R, g, 0.0)
    t = np.linspace(0.0, 10_120.0, 241)
    inputs = np.zeros(6)
    inputs[4] = epsilon
    response = simulate(model, t, inputs=inputs)
    closed = spherical_error("drift", epsilon, t, R, g)
    np.testing.assert_allclose(response["position_error_north"], closed, rtol=0, atol=1e-9 * closed.max())
    np.testing.assert_allclose(response["position_error_east"], 0.0, atol=1e-12)


@pytest.mark.parametrize("source, state, input_index", [("tilt", 5, None), ("velocity", 2, None),
                                                        ("accelerometer", None, 0)])
def test_non_rotating_limit_reproduces_the_other_channel_sources(source, state, input_index):
    R, g = MEAN_RADIUS, STANDARD_GRAVITY
    magnitude = {"tilt": 1e-4, "velocity": 0.5, "accelerometer": 1e-3}[source]
    model = psi_angle_model(0.7, R, g, 0.0)
    initial = np.zeros(7)
    inputs = np.zeros(6)
    if state is not None:
        initial[state] = magnitude
    else:
        inputs[input_index] = magnitude
    t = np.linspace(0.0, 8000.0, 161)
    north = simulate(model, t, initial_state=initial, inputs=inputs)["position_error_north"]
    closed = spherical_error(source, magnitude, t, R, g)
    np.testing.assert_allclose(north, closed, rtol=0, atol=1e-9 * np.abs(closed).max())


def test_foucault_modulation_of_a_velocity_error():
    L = math.radians(45.0)
    model = psi_angle_model(L, MEAN_RADIUS, STANDARD_GRAVITY, EARTH_RATE)
    t = np.linspace(0.0, 86_400.0, 481)
    response = simulate(model, t, initial_state=[0, 0, 1.0, 0, 0, 0, 0])
    north, east = foucault_velocity_response(t, 1.0, L, MEAN_RADIUS, STANDARD_GRAVITY, EARTH_RATE)
    amplitude = 1.0 / math.sqrt(STANDARD_GRAVITY / MEAN_RADIUS)
    np.testing.assert_allclose(response["position_error_north"], north, atol=1e-7 * amplitude)
    np.testing.assert_allclose(response["position_error_east"], east, atol=1e-7 * amplitude)
    # the swing turns east (clockwise from above) in the northern hemisphere: east error builds up
    assert np.max(east) > 0.5 * amplitude


def test_constant_velocity_attitude_modes_follow_the_total_frame_rate():
    L, V_E, V_N = math.radians(40.0), 250.0, 120.0
    model = psi_angle_model(L, MEAN_RADIUS, STANDARD_GRAVITY, EARTH_RATE, velocity_north=V_N, velocity_east=V_E)
    frame_rate = np.array([EARTH_RATE * math.cos(L) + V_E / MEAN_RADIUS, -V_N / MEAN_RADIUS,
                           -EARTH_RATE * math.sin(L) - V_E * math.tan(L) / MEAN_RADIUS])
    psi_block = model.A[4:, 4:]
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(psi_block).imag),
                               [-np.linalg.norm(frame_rate), 0.0, np.linalg.norm(frame_rate)], atol=1e-15)
    assert not np.allclose(model.A, psi_angle_model(L, MEAN_RADIUS, STANDARD_GRAVITY, EARTH_RATE).A)
    # without speed it is the stationary model
    np.testing.assert_array_equal(
        psi_angle_model(L, MEAN_RADIUS, STANDARD_GRAVITY, EARTH_RATE, 0.0, 0.0).A,
        psi_angle_model(L, MEAN_RADIUS, STANDARD_GRAVITY, EARTH_RATE).A)


def test_flat_limit_of_the_three_d_model_is_the_flat_formula():
    # radius -> large with g fixed: the Schuler loop opens, a tilt gives g psi t^2 / 2 over a short time
    model = psi_angle_model(0.3, 1e15, STANDARD_GRAVITY, 0.0)
    t = np.linspace(0.0, 600.0, 61)
    north = simulate(model, t, initial_state=[0, 0, 0, 0, 0, 1e-4, 0])["position_error_north"]
    np.testing.assert_allclose(north, flat_error("tilt", 1e-4, t, STANDARD_GRAVITY), rtol=1e-6)


def test_vertical_channel_is_unstable_near_sqrt_two_omega_s():
    model = psi_angle_model(math.radians(45.0), MEAN_RADIUS, STANDARD_GRAVITY, EARTH_RATE, vertical_channel=True)
    assert model.n_states == 9
    growth = np.max(model.eigenvalues().real)
    # Coriolis couples it to the horizontal channels: shifted by O((Omega / omega_s)^2) = 3e-3
    assert growth == pytest.approx(math.sqrt(2 * STANDARD_GRAVITY / MEAN_RADIUS), rel=5e-3)


@pytest.mark.parametrize("kwargs, name", [({"latitude": math.pi / 2}, "latitude"), ({"radius": 0.0}, "radius"),
                                          ({"rate": -1.0}, "rate"), ({"velocity_east": np.nan}, "velocity_east")])
def test_three_d_bad_input(kwargs, name):
    arguments = {"latitude": 0.5, "radius": MEAN_RADIUS, "gravity": STANDARD_GRAVITY, "rate": EARTH_RATE} | kwargs
    with pytest.raises(InvalidParameter) as error:
        psi_angle_model(**arguments)
    assert error.value.name == name


# --- the three-d action -------------------------------------------------------------------------------

def _three_d(**values):
    return three_d(**THREE_D_PARAMETERS.case(**values))


def test_action_sign_convention_a_positive_east_drift_makes_a_positive_north_error():
    # drift = -(gyro bias) resolved east: the platform turns about east, Bollay's Delta_theta_y > 0 -> Delta_S_x > 0
    epsilon = math.radians(0.01) / 3600
    result = _three_d(drift_east=epsilon, earth_rate=0.0, earth="bollay", duration=10_120.0, output_step=10.0)
    closed = spherical_error("drift", epsilon, result.t_s, BOLLAY.radius, BOLLAY.effective_gravity)
    np.testing.assert_allclose(result.states["position_error_north"], closed, rtol=0, atol=1e-9 * closed.max())
    assert result.final_position_error_north_m / 0.3048 == pytest.approx(10_258.5, abs=0.05)  # Bollay: 10,250 ft
    np.testing.assert_allclose(result.states["position_error_east"], 0.0, atol=1e-12)


def test_action_accelerometer_bias_north_gives_the_single_channel_error():
    bias = 1e-4 * STANDARD_GRAVITY
    result = _three_d(accel_bias_north=bias, earth_rate=0.0, duration=8000.0, output_step=20.0)
    closed = spherical_error("accelerometer", bias, result.t_s, MEAN_RADIUS, STANDARD_GRAVITY)
    np.testing.assert_allclose(result.states["position_error_north"], closed, rtol=0, atol=1e-9 * closed.max())


def test_action_foucault_rotation_and_modes_on_the_rotating_earth():
    L = math.radians(45.0)
    result = _three_d(latitude=L, initial_velocity_error_north=1.0, duration=86_400.0, output_step=180.0)
    north, east = foucault_velocity_response(result.t_s, 1.0, L, MEAN_RADIUS, STANDARD_GRAVITY, EARTH_RATE)
    amplitude = 1.0 / math.sqrt(STANDARD_GRAVITY / MEAN_RADIUS)
    np.testing.assert_allclose(result.states["position_error_north"], north, atol=1e-7 * amplitude)
    np.testing.assert_allclose(result.states["position_error_east"], east, atol=1e-7 * amplitude)
    assert result.foucault_rate_rad_s == pytest.approx(EARTH_RATE * math.sin(L), rel=1e-15)
    eigenvalues = result.eigenvalues_real_per_s + 1j * result.eigenvalues_imag_rad_s
    np.testing.assert_allclose(_sorted_by_frequency(eigenvalues),
                               _sorted_by_frequency(stationary_modes(L, MEAN_RADIUS, STANDARD_GRAVITY, EARTH_RATE)),
                               atol=1e-6 * EARTH_RATE)
    assert result.to_dict()["final_attitude_error_down_rad"] == pytest.approx(result.final_attitude_error_down_rad,
                                                                              rel=1e-14)


def test_action_initial_attitude_error_is_a_tilt():
    # psi_E(0) acts as Bollay's level misalignment on a non-rotating Earth: R psi (1 - cos omega t)
    psi = math.radians(0.01)
    result = _three_d(initial_attitude_error_east=psi, earth_rate=0.0, duration=6000.0, output_step=30.0)
    closed = spherical_error("tilt", psi, result.t_s, MEAN_RADIUS, STANDARD_GRAVITY)
    np.testing.assert_allclose(result.states["position_error_north"], closed, rtol=0, atol=1e-9 * closed.max())


def test_action_warns_when_the_latitude_changes_much():
    with pytest.warns(UserWarning, match="moves .* deg in latitude"):
        _three_d(velocity_north=250.0, duration=3600.0)  # 900 km: 8 deg of latitude


@pytest.mark.parametrize("values, name", [({"accel_bias_down": 1e-3}, "accel_bias_down"),
                                          ({"latitude": math.pi / 2}, "latitude"),
                                          ({"output_step": 1e6}, "output_step"),
                                          ({"drift_est": 1e-8}, "drift_est"),
                                          ({"vertical_channel": True, "duration": 2e5}, "duration")])
def test_action_bad_input(values, name):
    with pytest.raises(InvalidParameter) as error:
        _three_d(**values)
    assert error.value.name == name


# --- WGS-84: gravity gradient, models along a trajectory ---------------------------------------------


@pytest.mark.parametrize("latitude_deg, height", [(0.0, 0.0), (45.0, 10_000.0), (-70.0, 3000.0)])
def test_wgs84_gravity_gradient_matches_finite_differences(latitude_deg, height):
    # delta_g = g(L + dL, h + dh) resolved in the computed frame minus g(L, h): g^n(L+dL, h+dh) + dtheta x g - g
    L = math.radians(latitude_deg)
    G = wgs84_gravity_gradient([L], [height])[0]
    g0 = gravity_ned(L, height)
    for dr in (np.array([10.0, 0.0, 0.0]), np.array([0.0, 10.0, 0.0]), np.array([0.0, 0.0, 1.0])):
        dL = dr[0] / (meridian_radius(L) + height)
        dlon = dr[1] / ((transverse_radius(L) + height) * math.cos(L))
        dtheta = np.array([dlon * math.cos(L), -dL, -dlon * math.sin(L)])
        difference = gravity_ned(L + dL, height - dr[2]) + np.cross(dtheta, g0) - g0
        np.testing.assert_allclose(G @ dr, difference, rtol=1e-5, atol=1e-12)  # second order: ~1e-13


def test_wgs84_model_at_rest_holds_the_height_by_dropping_the_vertical_rows():
    F_free, _ = wgs84_error_matrices([0.6], [100.0], [[0.0, 0.0, 0.0]], [[0.0, 0.0, -9.8]], vertical_channel=True)
    F_held, _ = wgs84_error_matrices([0.6], [100.0], [[0.0, 0.0, 0.0]], [[0.0, 0.0, -9.8]])
    keep = [0, 1, 3, 4, 6, 7, 8]
    np.testing.assert_array_equal(F_held[0], F_free[0][np.ix_(keep, keep)])
    # the vertical channel diverges with -dg/dh = 2 g / a (1 + f + m - 2 f sin^2 L) ~ 2 g / R
    growth = np.max(wgs84_psi_angle_model(0.6, vertical_channel=True).eigenvalues().real)
    assert growth == pytest.approx(math.sqrt(2 * 9.80 / 6.37e6), rel=5e-3)


def test_propagation_with_constant_coefficients_is_the_engine_exactly():
    L, h, v = math.radians(35.0), 500.0, np.array([120.0, -80.0, 0.0])
    model = wgs84_psi_angle_model(L, h, v)  # steady flight: f = -g + (2 Omega + rho) x v
    t = np.linspace(0.0, 7200.0, 73)
    x0 = np.array([100.0, -40.0, 0.2, 0.1, 1e-5, -2e-5, 3e-4])
    u = np.array([1e-4, 0.0, -2e-4, 1e-8, 0.0, -1e-8])
    expected = simulate(model, t, initial_state=x0, inputs=u).states
    K = t.size - 1
    rho = transport_rate_ned(L, h, v[0], v[1])
    f = -gravity_ned(L, h) + np.cross(2 * earth_rate_ned(L) + rho, v)
    states = propagate_along(t, np.full(K, L), np.full(K, h), np.tile(v, (K, 1)), np.tile(f, (K, 1)), x0, u)
    # the engine builds Phi^k by doubling, this product step by step: rounding differs by ~1e-9
    np.testing.assert_allclose(states, expected, rtol=0, atol=1e-8 * np.abs(expected).max())


@pytest.mark.parametrize("kwargs, name", [({"latitude": [math.pi / 2]}, "latitude"),
                                          ({"time": [0.0, 1.0, 1.0]}, "time"),
                                          ({"inputs": [1.0, 2.0]}, "inputs"),
                                          ({"initial_state": np.zeros(5)}, "initial_state")])
def test_propagate_along_bad_input(kwargs, name):
    arguments = {"time": [0.0, 1.0], "latitude": [0.5], "height": [0.0], "velocity_ned": [[0.0, 0.0, 0.0]],
                 "specific_force_ned": [[0.0, 0.0, -9.8]], "initial_state": np.zeros(7)} | kwargs
    with pytest.raises(InvalidParameter) as error:
        propagate_along(**arguments)
    assert error.value.name == name
