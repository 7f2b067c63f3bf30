"""``schuler vertical optimal``: Drozdovich's undamped vertical beside the velocity-aided Kalman loop."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.stats import chi2

from schuler.core.earth import PRESETS
from schuler.core.steady_state import (
    loop_covariance_history,
    loop_error_covariance,
    loop_monte_carlo,
    noise_ratios_for_gain,
    riccati_solution,
    steady_state_gain,
)
from schuler.exceptions import InvalidParameter
from schuler.gyro_vertical.api import (
    level_gains,
    level_gains_from_period,
    level_noise_ratios,
    level_period_damping,
    optimal,
    vertical_loop,
)

G, R = PRESETS["default"].gravity, PRESETS["default"].radius
MEMBERS = 1000
# the sample variance about the known mean 0 of N Gaussian errors: N s^2 / sigma^2 is chi-square(N); 99.9 % band
BAND = (chi2.ppf(0.0005, MEMBERS) / MEMBERS, chi2.ppf(0.9995, MEMBERS) / MEMBERS)


def _level(gyro_psd, accel_psd):
    A = np.array([[0.0, 1.0 / R], [-G, 0.0]])
    return A, np.array([[0.0, 1.0]]), np.diag([gyro_psd, accel_psd])


def test_steady_gain_is_the_time_varying_filters_limit():
    loop = vertical_loop("navigation", 0.1, 1.0, math.radians(60.0))
    steady = steady_state_gain(loop.A, loop.C, loop.Q, loop.R)
    P = riccati_solution(loop.A, loop.C, loop.Q, loop.R, loop.P0, [0.0, 600.0, 86400.0])
    gain = P[-1] @ loop.C.T / loop.R[0, 0]
    large = np.abs(steady.gain) > 1e-9 * np.abs(steady.gain).max()
    np.testing.assert_allclose(gain[large], steady.gain[large], rtol=1e-6)
    # ten minutes in, the filter is still far from it: the comparison can fail
    early = P[1] @ loop.C.T / loop.R[0, 0]
    assert np.max(np.abs(early[large] / steady.gain[large] - 1.0)) > 1e-3
    assert optimal("navigation", duration=86400.0).time_varying_gain_error < 1e-6


def test_seed_loop_lyapunov_equals_monte_carlo():
    # the seed (K = 0, undamped) after 6 h and the optimal loop at steady state, against 1,000 members each
    loop = vertical_loop("tactical", 0.1, 1.0, math.radians(60.0))
    zero = np.zeros((8, 2))
    seed = loop_covariance_history(loop.A, zero, loop.C, loop.Q, loop.R, loop.P0, [0.0, 6 * 3600.0])[-1]
    errors = loop_monte_carlo(loop.A, zero, loop.C, loop.Q, loop.R, loop.P0, 6 * 3600.0, 60.0, MEMBERS, seed=7)
    for index in (0, 1, 2, 3):  # tilts and velocity errors
        assert BAND[0] < np.mean(errors[:, index] ** 2) / seed[index, index] < BAND[1]
    steady = steady_state_gain(loop.A, loop.C, loop.Q, loop.R)
    P = loop_error_covariance(loop.A, steady.gain, loop.C, loop.Q, loop.R)
    errors = loop_monte_carlo(loop.A, steady.gain, loop.C, loop.Q, loop.R, loop.P0, 4 * 3600.0, 10.0, MEMBERS, seed=8)
    for index in (0, 1, 2, 3):
        assert BAND[0] < np.mean(errors[:, index] ** 2) / P[index, index] < BAND[1]


@settings(max_examples=20, deadline=None)
@given(st.floats(0.003, 10.0), st.floats(1e-2, 1e2), st.floats(-80.0, 80.0))
def test_optimal_is_no_worse_than_the_seed(velocity_noise, noise_scale, latitude_deg):
    # the Kalman filter from the seed's start beats the seed's fixed (zero) gain at every time, in the matrix sense
    loop = vertical_loop("tactical", velocity_noise, 1.0, math.radians(latitude_deg))
    Q = loop.Q * noise_scale
    times = np.concatenate([[0.0], np.geomspace(60.0, 6 * 3600.0, 6)])
    seed = loop_covariance_history(loop.A, np.zeros((8, 2)), loop.C, Q, loop.R, loop.P0, times)
    best = riccati_solution(loop.A, loop.C, Q, loop.R, loop.P0, times)
    for S, P in zip(seed[1:], best[1:]):
        block = (S - P)[:4, :4]
        assert np.linalg.eigvalsh(block).min() >= -1e-9 * np.abs(S[:4, :4]).max()
    # and the steady-state loop beats any other stable gain near it
    steady = steady_state_gain(loop.A, loop.C, Q, loop.R)
    other = loop_error_covariance(loop.A, steady.gain * 1.3, loop.C, Q, loop.R)
    assert np.all(np.diag(other)[:4] >= np.diag(steady.covariance)[:4] * (1 - 1e-9))


@settings(max_examples=40, deadline=None)
@given(st.floats(1e-14, 1e-6), st.floats(1e-10, 1e-2), st.floats(1e-4, 10.0))
def test_level_gains_round_trip(gyro_psd, accel_psd, velocity_psd):
    gains = level_gains(gyro_psd, accel_psd, velocity_psd, G, R)
    A, C, Q = _level(gyro_psd, accel_psd)
    are = steady_state_gain(A, C, Q, [[velocity_psd]]).gain[:, 0]
    np.testing.assert_allclose(gains, are, rtol=1e-6)
    ratios = level_noise_ratios(*gains, G, R)
    np.testing.assert_allclose(ratios, (gyro_psd / velocity_psd, accel_psd / velocity_psd), rtol=1e-6)
    np.testing.assert_allclose(noise_ratios_for_gain(A, C, np.array(gains), np.eye(2)), ratios, rtol=1e-5)
    period, damping = level_period_damping(*gains, G, R)
    np.testing.assert_allclose(level_gains_from_period(period, damping, G, R), gains, rtol=1e-9)


def test_the_seed_is_optimal_only_for_a_noise_free_instrument():
    assert level_noise_ratios(0.0, 0.0, G, R) == (0.0, 0.0)
    assert level_period_damping(0.0, 0.0, G, R) == pytest.approx((2 * math.pi * math.sqrt(R / G), 0.0), rel=1e-12)
    # a 10-minute loop needs zeta^2 >= (1 - omega_s^2 / omega_n^2) / 2: 0.6 is too little, 0.75 enough
    with pytest.raises(InvalidParameter, match="return-difference"):
        level_noise_ratios(*level_gains_from_period(600.0, 0.6, G, R), G, R)
    assert min(level_noise_ratios(*level_gains_from_period(600.0, 0.75, G, R), G, R)) > 0
    # a loop slower than Schuler's is optimal for no noise either
    with pytest.raises(InvalidParameter, match="return-difference"):
        level_noise_ratios(*level_gains_from_period(7200.0, 1.0, G, R), G, R)


def test_constant_biases_added_deterministically():
    # at the equator the channels split: the seed's oscillation is centred on Delta v = -R eps, beta = b / g
    from schuler.imu.spec import preset

    result = optimal("tactical", latitude=0.0, duration=3600.0)
    drift = float(preset("tactical").gyro.bias[0])
    assert result.seed["velocity_error_bias_m_s"] == pytest.approx(R * drift, rel=1e-9)
    # the Kalman loop estimates the drift: its constant-bias error is far smaller
    assert result.optimal["velocity_error_bias_m_s"] < 1e-3 * result.seed["velocity_error_bias_m_s"]


def test_navigation_beats_tactical_and_the_seed_never_settles():
    nav, tac = optimal("navigation"), optimal("tactical")
    assert nav.seed["settling_time_s"] is None and nav.seed["damping"] == pytest.approx(0.0, abs=1e-12)
    assert nav.optimal["velocity_error_sigma_m_s"] < tac.optimal["velocity_error_sigma_m_s"]
    # a fast loop's damping tends to 1 / sqrt(2) (the second-order Kalman loop of a random walk)
    assert tac.optimal["damping"] == pytest.approx(1 / math.sqrt(2), abs=0.01)


def test_cli_json_figures_and_bad_input(run_cli, tmp_path):
    out = run_cli("vertical", "optimal", "--imu", "navigation", "--velocity-noise", "0.05", "--json", "--out",
                  tmp_path)
    assert out.code == 0, out.stderr
    data = out.json()
    keys = {"velocity_error_sigma_m_s", "velocity_error_bias_m_s", "k1_over_h_per_m", "tilt_gain_per_m",
            "velocity_gain_per_s", "period_s", "damping", "settling_time_s"}
    assert keys <= set(data["seed"]) and keys <= set(data["optimal"])
    assert data["seed"]["k1_over_h_per_m"] == pytest.approx(1.0 / R, rel=1e-12)
    assert data["inputs"]["velocity_noise"] == 0.05
    assert {"vertical_optimal_noise.png", "vertical_optimal_gain.svg"} <= {p.name for p in tmp_path.iterdir()}
    for args, option in ((("--velocity-noise", "0"), "--velocity-noise"), (("--imu", "nonsense"), "--imu"),
                         (("--duration", "100", "--update-interval", "20"), "--duration")):
        bad = run_cli("vertical", "optimal", *args)
        assert bad.code == 2, bad.stderr
        lines = bad.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("schuler: error:") and option in lines[0], bad.stderr


def test_imu_from_a_spec_file(tmp_path):
    spec = tmp_path / "imu.toml"
    spec.write_text('name = "sheet"\n[gyro]\nrandom_walk = "0.125 deg/sqrt(h)"\nbias_instability = "0.3 deg/h"\n'
                    'bias = "1 deg/h"\n[accel]\nrandom_walk = "0.065 ft/s/sqrt(h)"\nbias_instability = "50 ug"\n'
                    'bias = "1 mg"\n')
    sheet, grade = optimal(str(spec), duration=3600.0), optimal("tactical", duration=3600.0)
    assert sheet.optimal["velocity_error_sigma_m_s"] == pytest.approx(grade.optimal["velocity_error_sigma_m_s"],
                                                                      rel=1e-12)
