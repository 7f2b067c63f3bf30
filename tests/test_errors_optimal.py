"""``schuler errors optimal``: the baro-aided vertical channel's k1, k2, k3 beside the Kalman gains."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.stats import chi2

from schuler.core.steady_state import (
    loop_error_covariance,
    loop_monte_carlo,
    noise_ratios_for_gain,
    riccati_solution,
    steady_state_gain,
)
from schuler.navigation_errors.api import baro_loop, optimal
from schuler.navigation_errors.inputs import earth_constants
from schuler.navigation_errors.vertical_channel import critically_damped_gains

R, G = earth_constants("default")
OMEGA2 = G / R
MEMBERS = 1000
BAND = (chi2.ppf(0.0005, MEMBERS) / MEMBERS, chi2.ppf(0.9995, MEMBERS) / MEMBERS)


def _gain(order, tau):
    gains = critically_damped_gains(order, tau, R, G)
    return np.array([gains.k1, gains.k2, gains.k3])[:order, None]


@pytest.mark.parametrize("order", [2, 3])
def test_steady_gains_are_the_time_varying_filters_limit(order):
    loop = baro_loop("tactical", 1.0, 1.0, order, R, G)
    steady = steady_state_gain(loop.A, loop.C, loop.Q, loop.R).gain[:, 0]
    P0 = np.diag([1.0, 0.01, 1e-4][:order])
    P = riccati_solution(loop.A, loop.C, loop.Q, loop.R, P0, [0.0, 30.0, 7200.0])
    np.testing.assert_allclose(P[-1][:, 0] / loop.R[0, 0], steady, rtol=1e-6)
    assert np.max(np.abs(P[1][:, 0] / loop.R[0, 0] / steady - 1)) > 1e-2  # 30 s in: not yet
    assert optimal(imu="tactical", order=order).time_varying_gain_error < 1e-6


@pytest.mark.parametrize("order", [2, 3])
def test_seed_loop_lyapunov_equals_monte_carlo(order):
    loop = baro_loop("tactical", 1.0, 1.0, order, R, G)
    K = _gain(order, 100.0)
    P = loop_error_covariance(loop.A, K, loop.C, loop.Q, loop.R)
    # from rest, 8 settling times (5 tau each): the steady state within far less than the sampling band
    errors = loop_monte_carlo(loop.A, K, loop.C, loop.Q, loop.R, np.zeros((order, order)), 4000.0, 5.0, MEMBERS, 3)
    for index in range(order):
        assert BAND[0] < np.mean(errors[:, index] ** 2) / P[index, index] < BAND[1]


@settings(max_examples=40, deadline=None)
@given(st.floats(0.05, 50.0), st.floats(1e-2, 1e2), st.floats(20.0, 2000.0), st.sampled_from([2, 3]),
       st.sampled_from(["navigation", "tactical", "industrial"]))
def test_optimal_is_no_worse_than_the_seed(baro_noise, noise_scale, tau, order, imu):
    loop = baro_loop(imu, baro_noise, 1.0, order, R, G)
    Q = loop.Q * noise_scale
    seed = loop_error_covariance(loop.A, _gain(order, tau), loop.C, Q, loop.R)
    steady = steady_state_gain(loop.A, loop.C, Q, loop.R)
    best = loop_error_covariance(loop.A, steady.gain, loop.C, Q, loop.R)
    assert np.linalg.eigvalsh(seed - best).min() >= -1e-9 * np.abs(seed).max()
    assert best[0, 0] <= seed[0, 0] * (1 + 1e-9)


@pytest.mark.parametrize("tau", [30.0, 100.0, 400.0])
def test_the_critically_damped_design_is_optimal_only_with_a_height_random_walk(tau):
    loop = baro_loop("tactical", 1.0, 1.0, 3, R, G)
    K = _gain(3, tau)
    ratios = noise_ratios_for_gain(loop.A, loop.C, K, np.eye(3))
    expected = (3 / tau**2 - 4 * OMEGA2, 3 / tau**4 - 4 * OMEGA2**2, 1 / tau**6)  # the module docstring's closed form
    np.testing.assert_allclose(ratios, expected, rtol=1e-6)
    # and back: the Riccati equation with those ratios returns the seed's gains
    np.testing.assert_allclose(steady_state_gain(loop.A, loop.C, np.diag(ratios), [[1.0]]).gain, K, rtol=1e-6)
    loop2 = baro_loop("tactical", 1.0, 1.0, 2, R, G)
    ratios2 = noise_ratios_for_gain(loop2.A, loop2.C, _gain(2, tau), np.eye(2))
    np.testing.assert_allclose(ratios2, (2 / tau**2 - 4 * OMEGA2, 1 / tau**4 - 4 * OMEGA2**2), rtol=1e-6)


def test_a_slow_seed_is_optimal_for_no_noise():
    # tau beyond sqrt(3) / (2 omega_s) would need a negative height random walk: the return difference fails
    tau = 1.2 * np.sqrt(3.0) / (2.0 * np.sqrt(OMEGA2))
    result = optimal(imu="navigation", time_constant=tau)
    assert result.seed["optimal_for_noise_ratios"] is None
    assert result.optimal["optimal_for_noise_ratios"][0] == pytest.approx(0.0, abs=1e-12)


@settings(max_examples=30, deadline=None)
@given(st.floats(1e-16, 1e-6), st.floats(1e-10, 1e-4), st.floats(1e-2, 1e2))
def test_the_bias_gain_is_the_root_of_the_bias_noise_ratio(bias_psd, accel_psd, baro_psd):
    # the identity's constant term: k3^2 = q_b / r, so a constant bias (q_b -> 0) drives k3 to zero (spec 07)
    A = np.array([[0.0, 1.0, 0.0], [2 * OMEGA2, 0.0, 1.0], [0.0, 0.0, 0.0]])
    gain = steady_state_gain(A, [[1.0, 0.0, 0.0]], np.diag([0.0, accel_psd, bias_psd]), [[baro_psd]]).gain
    assert gain[2, 0] == pytest.approx(np.sqrt(bias_psd / baro_psd), rel=1e-6)


def test_constant_biases_added_deterministically():
    second = optimal(imu="tactical", order=2, baro_bias=2.0)
    b0 = 1e-3 * 9.80665  # the tactical grade's 1 mg turn-on bias
    assert second.seed["height_error_bias_m"] == pytest.approx((b0 + second.seed["k2_per_s2"] * 2.0) / 1e-4, rel=1e-9)
    k2 = second.optimal["k2_per_s2"]
    assert second.optimal["height_error_bias_m"] == pytest.approx((b0 + k2 * 2.0) / (k2 - 2 * OMEGA2), rel=1e-9)
    third = optimal(imu="tactical", order=3, baro_bias=2.0)
    assert third.seed["height_error_bias_m"] == third.optimal["height_error_bias_m"] == 2.0


def test_cli_json_figures_and_bad_input(run_cli, tmp_path):
    out = run_cli("errors", "optimal", "--imu", "navigation", "--baro-noise", "0.5", "--json", "--out", tmp_path)
    assert out.code == 0, out.stderr
    data = out.json()
    keys = {"k1_per_s", "k2_per_s2", "k3_per_s3", "height_error_sigma_m", "height_error_bias_m", "settling_time_s"}
    assert keys <= set(data["seed"]) and keys <= set(data["optimal"])
    assert data["seed"]["k1_per_s"] == pytest.approx(0.03, rel=1e-12)  # tau = 100 s, third order: 3 / tau
    assert data["optimal"]["height_error_sigma_m"] <= data["seed"]["height_error_sigma_m"]
    assert {"errors_optimal_noise.png", "errors_optimal_gain.svg"} <= {p.name for p in tmp_path.iterdir()}
    for args, option in ((("--baro-noise", "-1"), "--baro-noise"), (("--imu", "nonsense"), "--imu"),
                         (("--order", "2", "--k3", "1e-6"), "k3"), (("--k1", "1e-4", "--k2", "1e-6"), "k2")):
        bad = run_cli("errors", "optimal", *args)
        assert bad.code == 2, bad.stderr
        lines = bad.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("schuler: error:") and option in lines[0], bad.stderr
