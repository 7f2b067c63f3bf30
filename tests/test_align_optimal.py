"""``schuler align optimal``: the KPI loop (1.19) beside the steady-state Kalman filter of the same sensors."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY
from schuler.core.gyrocompass_design import loop_design, loop_gains
from schuler.core.steady_state import steady_state_gain
from schuler.gyrocompassing import optimal as model
from schuler.gyrocompassing.optimal_run import LOOP_KEYS
from schuler.imu.spec import preset

LATITUDE = math.radians(50.0)
TACTICAL = model.noise_from_imu(preset("tactical"))


def test_steady_gain_is_where_the_time_varying_filter_goes():
    # the slowest closed-loop pole of the tactical filter decays over ~21,000 s: 10^6 s is far past it
    P0 = np.diag([math.radians(0.05) ** 2, math.radians(5) ** 2, 1e-3, 1e-3])
    t = np.arange(0.0, 1.0e6 + 1.0, 20.0)  # steps short against the fast poles (~1 1/s)
    history = model.gain_history(TACTICAL, LATITUDE, P0, t)
    steady = steady_state_gain(*model.loop_model(TACTICAL, LATITUDE)[:4]).gain[:, 0]
    np.testing.assert_allclose(history[-1], steady, rtol=1e-6)
    assert not np.allclose(history[50], steady, rtol=1e-3)  # it does start elsewhere


def test_white_noise_gains_in_closed_form_equal_the_riccati_solver():
    U_eta = EARTH_RATE * math.cos(LATITUDE)
    q_beta, q_delta, r = 1e-10, 4e-9, 1e-10
    A = [[0.0, U_eta], [0.0, 0.0]]
    K = steady_state_gain(A, [[1.0, 0.0]], np.diag([q_beta, q_delta]), [[r]]).gain[:, 0]
    np.testing.assert_allclose(model.gains_for_noise(q_beta, q_delta, r, LATITUDE), K, rtol=1e-9)


@given(T=st.floats(2.0, 3000.0), zeta=st.floats(0.71, 5.0), latitude=st.floats(-1.3, 1.3))
@settings(max_examples=60, deadline=None)
def test_gains_to_t_zeta_and_noise_round_trip(T, zeta, latitude):
    c_gamma, c_a = loop_gains(latitude, T, zeta)
    back_T, back_zeta = loop_design(latitude, c_gamma, c_a)
    assert float(back_T) == pytest.approx(T, rel=1e-12) and float(back_zeta) == pytest.approx(zeta, rel=1e-12)
    ratios = model.noise_for_gains(float(c_gamma), float(c_a), latitude)
    np.testing.assert_allclose(model.gains_for_noise(*ratios, 1.0, latitude), (c_gamma, c_a), rtol=1e-9)


def test_seed_design_optimal_for_and_below_the_return_difference_bound():
    c_gamma, c_a = loop_gains(LATITUDE, 30.0, 0.8)
    q_beta, q_delta = model.noise_for_gains(float(c_gamma), float(c_a), LATITUDE)
    assert q_beta == pytest.approx((4 * 0.8**2 - 2) / 30.0**2, rel=1e-12)  # omega0^2 (4 zeta^2 - 2)
    assert q_delta == pytest.approx(float(c_a) ** 2, rel=1e-12)
    with pytest.raises(Exception, match="return-difference"):
        model.noise_for_gains(*(float(v) for v in loop_gains(LATITUDE, 30.0, 0.7)), LATITUDE)


def test_constant_drift_error_of_the_seed_is_equation_1_21():
    seed = model.seed_accuracy(TACTICAL, LATITUDE)
    U_eta = EARTH_RATE * math.cos(LATITUDE)
    expected = math.hypot(seed.c_gamma / (seed.c_a * U_eta) * TACTICAL.drift_z, TACTICAL.drift_east / U_eta)
    assert seed.azimuth_error_bias_rad == pytest.approx(expected, rel=1e-10)
    assert seed.settling_time_s == pytest.approx(5 * 30.0 / 0.8, rel=1e-12)  # 5 / h, h = zeta / T


def _independent_loop(noise, c_gamma, c_a):
    """(1.19) with the drifts' Gauss-Markov parts, built from the equations, not from loop_model."""
    U_eta, tau, g = EARTH_RATE * math.cos(LATITUDE), noise.correlation_time, STANDARD_GRAVITY
    F = np.array([[-c_gamma, U_eta, -1.0, 0.0], [-c_a, 0.0, 0.0, 1.0], [0, 0, -1 / tau, 0], [0, 0, 0, -1 / tau]])
    # inputs: east and z gyro white noise, accelerometer white noise (through both gains), drift drives
    B = np.array([[-1.0, 0, -c_gamma, 0, 0], [0, 1.0, -c_a, 0, 0], [0, 0, 0, 1.0, 0], [0, 0, 0, 0, 1.0]])
    W = np.diag([noise.gyro_noise**2, noise.gyro_noise_z**2, (noise.accel_noise / g) ** 2,
                 2 * noise.bias_sigma**2 / tau, 2 * noise.bias_sigma_z**2 / tau])
    return F, B @ W @ B.T


def test_lyapunov_variance_equals_a_monte_carlo_of_the_loop():
    noise = dataclasses.replace(TACTICAL, correlation_time=100.0)
    seed = model.seed_accuracy(noise, LATITUDE)
    F, S = _independent_loop(noise, seed.c_gamma, seed.c_a)
    dt, steps, members = 2.0, 2000, 1000  # 4,000 s: 20 settling times and 40 drift correlation times
    # exact discretisation (Van Loan): Phi = e^{F dt}, Qd = int e^{F s} S e^{F^T s} ds
    n = F.shape[0]
    block = scipy.linalg.expm(np.block([[-F, S], [np.zeros((n, n)), F.T]]) * dt)
    phi = block[n:, n:].T
    qd = phi @ block[:n, n:]
    chol = np.linalg.cholesky((qd + qd.T) / 2)
    rng = np.random.default_rng(20261203)
    x = np.zeros((members, n))
    for _ in range(steps):
        x = x @ phi.T + rng.standard_normal((members, n)) @ chol.T
    sample = float(np.var(x[:, 1], ddof=1))
    expected = seed.azimuth_error_sigma_rad**2
    # chi-square band of a 1,000-member variance, 99.9 % two-sided: (0.86, 1.15)
    from scipy.stats import chi2
    low, high = chi2.ppf([0.0005, 0.9995], members - 1) / (members - 1)
    assert low < sample / expected < high


@given(gyro=st.floats(1e-8, 1e-3), gyro_z=st.floats(1e-8, 1e-3), accel=st.floats(1e-6, 1e-2),
       bias=st.floats(0.0, 1e-5), tau=st.floats(10.0, 1e4), T=st.floats(5.0, 300.0), zeta=st.floats(0.3, 3.0))
@settings(max_examples=80, deadline=None)
def test_optimal_loop_is_never_worse_than_the_seed(gyro, gyro_z, accel, bias, tau, T, zeta):
    noise = model.LoopNoise(gyro, gyro_z, accel, bias, bias, correlation_time=tau)
    seed = model.seed_accuracy(noise, LATITUDE, T, zeta)
    best = model.optimal_accuracy(noise, LATITUDE)
    assert best.azimuth_error_sigma_rad <= seed.azimuth_error_sigma_rad * (1 + 1e-9)


def test_cli_json_has_the_issue_keys(run_cli):
    out = run_cli("align", "optimal", "--imu", "navigation", "--latitude", "50", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    for loop in ("seed", "optimal"):
        assert set(LOOP_KEYS) <= set(data[loop])
    assert data["seed"]["time_constant_s"] == pytest.approx(30.0) and data["seed"]["damping"] == pytest.approx(0.8)
    assert data["seed"]["c_gamma"] == pytest.approx(2 * 0.8 / 30.0)
    assert data["optimal"]["azimuth_error_sigma_rad"] < data["seed"]["azimuth_error_sigma_rad"]


def test_figures_are_written(run_cli, tmp_path):
    out = run_cli("align", "optimal", "--imu", "tactical", "--duration", "600", "--out", str(tmp_path))
    assert out.code == 0, out.stderr
    assert {"align_optimal_accuracy.png", "align_optimal_gain.png"} <= {p.name for p in tmp_path.iterdir()}


@pytest.mark.parametrize("args", [("--gyro-noise", "-1"), ("--accel-noise", "0"), ("--imu", "no-such-grade")])
def test_bad_input_exits_2_with_one_line(run_cli, args):
    out = run_cli("align", "optimal", *args)
    assert out.code == 2
    assert len(out.stderr.strip().splitlines()) == 1


def test_a_spec_sheet_sets_the_noise_and_explicit_options_win(run_cli, tmp_path):
    spec = tmp_path / "imu.toml"
    spec.write_text('[gyro]\nrandom_walk = "0.01 deg/sqrt(h)"\nbias_instability = "0.01 deg/h"\n'
                    '[accel]\nrandom_walk = "20 ug/sqrt(Hz)"\n')
    noise = run_cli("align", "optimal", "--imu", str(spec), "--json").json()["noise"]
    assert noise["gyro_noise"] == pytest.approx(math.radians(0.01) / 60, rel=1e-12)  # deg/sqrt(h) -> rad/sqrt(s)
    assert noise["accel_noise"] == pytest.approx(20e-6 * STANDARD_GRAVITY, rel=1e-12)
    assert noise["bias_sigma"] == pytest.approx(math.radians(0.01) / 3600 / 0.9294, rel=1e-3)
    given = run_cli("align", "optimal", "--imu", str(spec), "--accel-noise", "40", "--json").json()["noise"]
    assert given["accel_noise"] == pytest.approx(2 * noise["accel_noise"], rel=1e-12)
