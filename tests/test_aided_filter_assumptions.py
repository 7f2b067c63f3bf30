"""The filter's stated IMU model (``filter_*``): in place of the one derived from the IMU layer, in the units
users write; the IMU's own values give the same run to the bit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.aided.error_state import DEFAULT_CORRELATION_TIME, ErrorProcess, filter_model, overridden
from schuler.aided.evaluation import assumed
from schuler.exceptions import InvalidParameter
from schuler.imu.spec import preset
from schuler.registry import get_system

AIDED = get_system("aided")
RUN = {"duration": 900.0, "seed": 2}


def test_stating_the_imus_own_values_changes_nothing():
    derived = filter_model(preset("tactical"))
    same = AIDED.run(filter_angle_random_walk=float(derived.angle_random_walk[0]),
                     filter_velocity_random_walk=float(derived.velocity_random_walk[0]), **RUN)
    base = AIDED.run(**RUN)
    assert same.position_error_horizontal_rms_m == base.position_error_horizontal_rms_m
    assert same.outages == base.outages


def test_written_values_reach_the_model_in_si():
    case = AIDED.parameters.parse({"filter_angle_random_walk": "0.5", "filter_velocity_random_walk": "0.06",
                                   "filter_gyro_bias": "3", "filter_accel_bias": "0.5",
                                   "filter_correlation_time": "2", "filter_bias_model": "gauss-markov"})
    model = assumed(case, filter_model(preset("consumer")))
    np.testing.assert_allclose(model.angle_random_walk, math.radians(0.5) / 60.0, rtol=1e-14)
    np.testing.assert_allclose(model.velocity_random_walk, 0.06 / 60.0, rtol=1e-14)
    np.testing.assert_allclose(model.gyro_bias.sigma, math.radians(3.0) / 3600.0, rtol=1e-14)
    np.testing.assert_allclose(model.accel_bias.sigma, 0.5e-3 * 9.80665, rtol=1e-14)
    assert model.gyro_bias.correlation_time == model.accel_bias.correlation_time == 7200.0
    # the Gauss-Markov driving density: q = 2 sigma^2 / T
    np.testing.assert_allclose(model.gyro_bias.density, 2.0 * (math.radians(3.0) / 3600.0) ** 2 / 7200.0,
                               rtol=1e-14)


def test_a_changed_bias_model_keeps_the_spread_over_its_time():
    gauss_markov = ErrorProcess("gauss-markov", 1e-5, correlation_time=1800.0)
    model = overridden(filter_model(preset("tactical")), bias="random-walk")
    assert model.gyro_bias.kind == "random-walk"
    walk = overridden(model.__class__(1e-4, 1e-3, gauss_markov, gauss_markov), bias="random-walk")
    np.testing.assert_allclose(walk.gyro_bias.random_walk, math.sqrt(2.0 * 1e-10 / 1800.0), rtol=1e-14)
    constant = overridden(model.__class__(1e-4, 1e-3, ErrorProcess("constant", 1e-5), gauss_markov),
                          bias="gauss-markov")
    assert constant.gyro_bias.correlation_time == DEFAULT_CORRELATION_TIME
    assert overridden(model, bias="constant").gyro_bias.density.tolist() == [0.0, 0.0, 0.0]


def test_a_larger_stated_noise_widens_the_predicted_outage_drift():
    base = AIDED.run(**RUN).outages[0]["horizontal_error_sigma_m"]
    wide = AIDED.run(filter_angle_random_walk="5 deg/sqrt(h)", **RUN).outages[0]["horizontal_error_sigma_m"]
    assert wide > 5.0 * base


def test_bad_values_are_one_line_and_exit_2(run_cli):
    out = run_cli("aided", "run", "--filter-bias-model", "markov")
    assert out.code == 2 and out.stderr.count("\n") == 1 and "gauss-markov" in out.stderr
    out = run_cli("aided", "run", "--filter-angle-random-walk", "0.1 m")
    assert out.code == 2 and out.stderr.count("\n") == 1
    with pytest.raises(InvalidParameter, match="bias"):
        overridden(filter_model(preset("tactical")), bias="markov")
