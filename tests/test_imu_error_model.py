"""Sensor error models: spec-sheet units against hand-worked values, PSD vs samples, Gauss-Markov and flicker."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.exceptions import InvalidParameter, ScenarioError
from schuler.imu.error_model import (
    FLICKER_FLOOR,
    GAUSS_MARKOV_PEAK,
    ErrorModel,
    SensorErrors,
    flicker_terms,
    gauss_markov_allan_variance,
    gauss_markov_for_bias_instability,
    white_noise_sample_std,
)
from schuler.imu.spec import GRADES, PRESET_SPECS, error_model_from_spec, load_spec_file, preset
from schuler.units import parse_quantity

DEG = math.pi / 180


# Hand-worked conversions (spec 06; pi/180 = 0.0174533, 1 h = 3600 s, g0 = 9.80665 m/s^2)
@pytest.mark.parametrize("text, unit, expected", [
    ("1 deg/sqrt(h)", "deg/h^0.5", DEG / 60),                  # 0.0174533 / 60 = 2.9089e-4 rad/sqrt(s)
    ("1 deg/√h", "deg/h^0.5", 2.908882e-4),
    ("1 deg/h/sqrt(Hz)", "deg/h^0.5", DEG / 3600),             # 4.8481e-6 rad/sqrt(s)
    ("60 deg/h/√Hz", "deg/h^0.5", DEG / 60),                   # N[deg/sqrt(h)] = N[deg/h/sqrt(Hz)] / 60
    ("1 mdeg/s/sqrt(Hz)", "deg/h^0.5", 1e-3 * DEG),            # 1.7453e-5 rad/sqrt(s)
    ("1 ug/sqrt(Hz)", "m/s/h^0.5", 9.80665e-6),                # 9.80665e-6 m/s/sqrt(s)
    ("1 m/s/sqrt(h)", "m/s/h^0.5", 1 / 60),                    # 0.016667 m/s/sqrt(s)
    ("1 deg/h", "deg/h", DEG / 3600),                          # 4.8481e-6 rad/s
    ("1 ug", "ug", 9.80665e-6),
    ("1 mg", "ug", 9.80665e-3),
    ("150 ppm", "ppm", 1.5e-4),
    ("0.5 mrad", "mrad", 5e-4),
    ("1 deg/h/g", "deg/h/g", DEG / 3600 / 9.80665),            # 4.9437e-7 rad/s per m/s^2
    ("0.065 ft/s/sqrt(h)", "m/s/h^0.5", 0.065 * 0.3048 / 60),  # HG1700 VRW: 3.302e-4 m/s/sqrt(s)
])
def test_spec_sheet_units_against_hand_worked_values(text, unit, expected):
    assert parse_quantity(text, unit, name="x") == pytest.approx(expected, rel=1e-6)


def test_bare_g_is_gram_where_mass_is_expected():
    # a torque in "g*m" keeps pint's gram: the gravity reading is only for units without mass
    assert parse_quantity("1 g*m^2/s^2", "N*m", name="torque") == pytest.approx(1e-3)


def test_per_sample_std_is_density_over_root_dt():
    # sigma_d = N / sqrt(dt): 0.125 deg/sqrt(h) at 100 Hz -> 3.636e-5 / 0.1 = 3.636e-4 rad/s
    n = parse_quantity("0.125 deg/sqrt(h)", "deg/h^0.5", name="N")
    assert white_noise_sample_std(n, 0.01) == pytest.approx(3.6361e-4, rel=1e-4)


def test_simulated_white_noise_has_the_per_sample_std():
    from schuler.imu.simulate import simulate_members

    n, dt = 3.6361e-5, 0.005
    gyro, _ = simulate_members(ErrorModel(gyro=SensorErrors(random_walk=n)), samples=200_000,
                               sample_interval=dt, members=1, seed=4)
    # 200,000 samples: the sample std is within 3 x sqrt(1/(2n)) = 0.5 % of the truth
    assert gyro[0].std(axis=0) == pytest.approx(np.full(3, n / math.sqrt(dt)), rel=0.005)


def test_gauss_markov_allan_peak_and_bias_instability_mapping():
    # the issue: peak ~0.62 sigma near tau ~1.9 T, so B ~ 0.93 sigma
    tau_over_t, peak = GAUSS_MARKOV_PEAK
    assert tau_over_t == pytest.approx(1.893, abs=1e-3)
    assert peak == pytest.approx(0.6174, abs=1e-4)
    assert 1.0 / gauss_markov_for_bias_instability(1.0) == pytest.approx(0.9294, abs=1e-4)
    # brute-force check of the closed form's maximum on a fine grid
    tau = np.geomspace(0.1, 100.0, 200_001)
    adev = np.sqrt(gauss_markov_allan_variance(tau, 2.0, 10.0))
    assert adev.max() / 2.0 == pytest.approx(peak, rel=1e-8)
    assert tau[adev.argmax()] / 10.0 == pytest.approx(tau_over_t, rel=1e-4)


def test_gauss_markov_limits_are_rate_random_walk_and_white_noise():
    sigma, t = 3.0, 50.0
    # tau << T: K^2 tau / 3 with K^2 = 2 sigma^2 / T; tau >> T: N^2 / tau with N^2 = 2 sigma^2 T
    assert gauss_markov_allan_variance(0.01, sigma, t) == pytest.approx(2 * sigma**2 / t * 0.01 / 3, rel=1e-3)
    assert gauss_markov_allan_variance(1e6, sigma, t) == pytest.approx(2 * sigma**2 * t / 1e6, rel=1e-3)


def test_simulated_gauss_markov_follows_its_closed_form():
    from schuler.imu.allan import allan_deviation
    from schuler.imu.simulate import simulate_members

    sigma, t, dt = 1e-5, 2.0, 0.05
    gyro, _ = simulate_members(ErrorModel(gyro=SensorErrors(gm_sigma=sigma, gm_correlation_time_s=t)),
                               samples=400_000, sample_interval=dt, members=1, seed=9)
    curve = allan_deviation(gyro[0, :, 0], dt)
    exact = np.sqrt(gauss_markov_allan_variance(curve.tau_s, sigma, t))
    # point samples of a random-walk-like process exceed the continuous formula by (1 + 1/(2 m^2)) in
    # variance at lag m: 1.5 at m = 1 (what the record shows), under 2 % from m = 5 on
    lag = np.rint(curve.tau_s / dt)
    assert curve.adev[0] / exact[0] == pytest.approx(math.sqrt(1.5), rel=0.02)
    far = lag >= 5
    # every point inside its 99 % band (68 % bands widened by 2.6) plus that 2 %
    half_width = 2.6 * (curve.adev_upper - curve.adev_lower) / 2
    assert np.all(np.abs(curve.adev - exact)[far] <= (half_width + 0.02 * exact)[far])


@pytest.mark.parametrize("tau_range", [(1.0, 1000.0), (0.1, 10.0), (10.0, 1e5)])
def test_flicker_sum_is_flat_within_three_percent(tau_range):
    sigmas, times = flicker_terms(2.0, tau_range)
    tau = np.geomspace(*tau_range, 200)
    adev = np.sqrt(sum(gauss_markov_allan_variance(tau, s, t) for s, t in zip(sigmas, times)))
    assert np.all(np.abs(adev / (FLICKER_FLOOR * 2.0) - 1.0) < 0.03)


def test_sensor_errors_validate_shapes_and_signs():
    errors = SensorErrors(bias=1.0, misalignment=0.5)
    assert errors.bias.shape == (3,) and errors.misalignment[0, 0] == 0.0 and errors.misalignment[0, 1] == 0.5
    with pytest.raises(InvalidParameter, match="random_walk"):
        SensorErrors(random_walk=-1.0)
    with pytest.raises(InvalidParameter, match="bias.*shape"):
        SensorErrors(bias=[1.0, 2.0])
    with pytest.raises(InvalidParameter, match="g-sensitivity is a gyro error"):
        ErrorModel(accel=SensorErrors(g_sensitivity=1e-6))


def test_spec_file_parses_units_and_refuses_unknown_keys(tmp_path):
    path = tmp_path / "imu.toml"
    path.write_text("""
name = "my imu"
[gyro]
random_walk = "7.5 deg/h/sqrt(Hz)"
bias = ["1 deg/h", "2 deg/h", 0.5]
quantization_step = "0.1 arcsec"
misalignment = "0.5 mrad"
flicker_tau_range = ["1 s", "2000 s"]
[accel]
random_walk = "120 ug/sqrt(Hz)"
scale_factor = "300 ppm"
""", encoding="utf-8")
    model = load_spec_file(path)
    assert model.name == "my imu"
    assert model.gyro.random_walk == pytest.approx(np.full(3, 0.125 * DEG / 60))
    assert model.gyro.bias == pytest.approx(np.array([1.0, 2.0, 0.5]) * DEG / 3600)  # bare number: deg/h
    assert model.gyro.quantization == pytest.approx(np.full(3, 0.1 / math.sqrt(12) * DEG / 3600))
    assert model.gyro.flicker_tau_range_s == (1.0, 2000.0)
    assert model.accel.random_walk == pytest.approx(np.full(3, 120 * 9.80665e-6))
    path.write_text('[gyro]\nrandom_wlak = "1 deg/sqrt(h)"\n', encoding="utf-8")
    with pytest.raises(InvalidParameter, match="gyro.random_wlak: unknown key; did you mean 'random_walk'"):
        load_spec_file(path)
    path.write_text('[gyro]\nrandom_walk = "1 m/s"\n', encoding="utf-8")
    with pytest.raises(InvalidParameter, match="gyro.random_walk"):
        load_spec_file(path)
    path.write_text('[gyro\n', encoding="utf-8")
    with pytest.raises(ScenarioError, match="not valid TOML"):
        load_spec_file(path)
    with pytest.raises(InvalidParameter, match="not both"):
        error_model_from_spec({"gyro": {"quantization": 1, "quantization_step": 1}})
    with pytest.raises(InvalidParameter, match="did you mean 'accel'"):
        error_model_from_spec({"acel": {}})


@pytest.mark.parametrize("grade", GRADES)
def test_presets_cite_a_source_and_load(grade):
    model = preset(grade)
    assert PRESET_SPECS[grade]["source"] and model.gyro.random_walk[0] > 0 and model.accel.random_walk[0] > 0


def test_preset_figures_as_published():
    # Honeywell HG1700 brochure: ARW 0.125 deg/sqrt(h), gyro bias 1 deg/h, VRW 0.065 ft/s/sqrt(h), accel bias 1 mg
    tactical = preset("tactical")
    assert tactical.gyro.random_walk[0] == pytest.approx(3.6361e-5, rel=1e-4)
    assert tactical.gyro.bias[0] == pytest.approx(4.8481e-6, rel=1e-4)
    assert tactical.accel.random_walk[0] == pytest.approx(3.302e-4, rel=1e-3)
    assert tactical.accel.bias[0] == pytest.approx(9.80665e-3)
    # InvenSense MPU-6050: 0.005 deg/s/sqrt(Hz) = 0.3 deg/sqrt(h); 400 ug/sqrt(Hz); z zero-g +/-80 mg
    consumer = preset("consumer")
    assert consumer.gyro.random_walk[0] == pytest.approx(0.3 * DEG / 60)
    assert consumer.accel.random_walk[0] == pytest.approx(400 * 9.80665e-6)
    assert consumer.accel.bias[2] == pytest.approx(0.08 * 9.80665)
    with pytest.raises(InvalidParameter, match="did you mean 'tactical'"):
        preset("tactcal")
