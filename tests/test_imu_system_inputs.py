"""From an error model to the other systems' inputs: conventions, signs and magnitudes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.exceptions import InvalidParameter
from schuler.imu.error_model import FLICKER_FLOOR, ErrorModel, SensorErrors
from schuler.imu.spec import preset
from schuler.imu.system_inputs import (
    align_inputs,
    calibrate_inputs,
    errors_inputs,
    north_inputs,
    residual_bias,
)

OMEGA = 7.292115e-5


def constant_bias_model(gyro_bias=(1e-6, 2e-6, 3e-6), accel_bias=(1e-3, 2e-3, 3e-3)):
    return ErrorModel(gyro=SensorErrors(bias=gyro_bias), accel=SensorErrors(bias=accel_bias), name="biases")


def test_platform_drift_is_minus_the_bias_resolved_in_ned():
    # heading 0: body x = north, y = east, z = down; epsilon = -C_b^n b, drift_z (platform up) = -epsilon_down
    inputs = align_inputs(constant_bias_model(), calibrated_gyros=False)
    assert inputs.values["drift_north"] == pytest.approx(-1e-6)
    assert inputs.values["drift_east"] == pytest.approx(-2e-6)
    assert inputs.values["drift_z"] == pytest.approx(3e-6)
    # platform x = body y (right), platform y = body x (forward)
    assert (inputs.values["accel_bias_x"], inputs.values["accel_bias_y"]) == pytest.approx((2e-3, 1e-3))
    # Monte Carlo sigmas: rms of the two horizontal axes, and z
    assert inputs.values["sigma_drift"] == pytest.approx(math.sqrt((1e-12 + 4e-12) / 2))
    assert inputs.values["sigma_drift_z"] == pytest.approx(3e-6)
    assert inputs.values["sigma_accel"] == pytest.approx(math.sqrt((1e-6 + 4e-6) / 2))
    # heading 90 deg: body x = east, y = south
    turned = align_inputs(constant_bias_model(), heading=math.pi / 2, calibrated_gyros=False)
    assert turned.values["drift_east"] == pytest.approx(-1e-6)
    assert turned.values["drift_north"] == pytest.approx(2e-6)
    assert turned.sigmas["drift_north"] == pytest.approx(2e-6) and turned.sigmas["drift_east"] == pytest.approx(1e-6)


def test_the_mapping_names_the_ported_systems_parameters():
    from schuler.registry import get_system

    tactical = preset("tactical")
    mapped = {"align": align_inputs(tactical), "calibrate": calibrate_inputs(tactical),
              "north": north_inputs(tactical, step=1.0)}
    for name, inputs in mapped.items():
        parameters = get_system(name).parameters
        assert set(inputs.values) <= set(parameters.names), (name, set(inputs.values) - set(parameters.names))
        assert set(inputs.parameter_units) == set(inputs.values)
        for key in inputs.values:
            assert parameters[key].si_unit == inputs.parameter_units[key], (name, key)
    # errors: one magnitude per source of the system
    from schuler.navigation_errors.single_channel import SOURCES

    assert set(errors_inputs(tactical, latitude=0.8).values) == set(SOURCES)


def test_calibration_removes_the_turn_on_gyro_bias_but_not_the_accelerometer_one():
    inputs = align_inputs(constant_bias_model())
    assert inputs.values["drift_east"] == 0.0 and inputs.values["drift_z"] == 0.0
    assert inputs.values["accel_bias_x"] == pytest.approx(2e-3)


def test_residual_drift_is_root_two_times_the_slow_allan_deviation():
    # flicker B: sqrt(2) x 0.6643 B whatever the window; white noise and quantisation do not count
    errors = SensorErrors(bias_instability=1e-6, flicker_tau_range_s=(1.0, 1e4), random_walk=1e-3, quantization=1e-3)
    residual = residual_bias(errors, 300.0, include_turn_on=False)
    assert residual == pytest.approx(np.full(3, math.sqrt(2) * FLICKER_FLOOR * 1e-6), rel=0.04)
    # rate random walk: sqrt(2 K^2 T / 3)
    walk = residual_bias(SensorErrors(rate_random_walk=1e-8), 600.0, include_turn_on=False)
    assert walk == pytest.approx(np.full(3, math.sqrt(2 * 1e-16 * 600 / 3)))


def test_calibrate_north_and_errors_inputs():
    tactical = preset("tactical")
    calibrate = calibrate_inputs(tactical)
    assert calibrate.values["drift_x"] == pytest.approx(-math.radians(1.0) / 3600)         # HG1700: 1 deg/h, -b
    assert calibrate.values["drift_y"] == pytest.approx(-math.radians(1.0) / 3600)
    assert calibrate.values["angle_random_walk"] == pytest.approx(math.radians(0.125) / 60)  # 0.125 deg/sqrt(h)
    # platform X = body y, Y = body x
    skewed = calibrate_inputs(ErrorModel(gyro=SensorErrors(bias=(1e-6, 2e-6, 0.0), random_walk=(3e-6, 4e-6, 0.0))))
    assert (skewed.values["drift_x"], skewed.values["drift_y"]) == pytest.approx((-2e-6, -1e-6))
    assert skewed.values["angle_random_walk"] == pytest.approx(math.sqrt((9e-12 + 16e-12) / 2))
    north = north_inputs(ErrorModel(gyro=SensorErrors(random_walk=2e-5, quantization=3e-6)), step=4.0)
    assert north.values["readout_noise"] == pytest.approx(math.sqrt(9e-12 + 4e-10 * 4.0))
    latitude = math.radians(60.0)
    errors = errors_inputs(constant_bias_model(accel_bias=(3e-3, 4e-3, 0.0)), latitude=latitude)
    bias = math.sqrt((9e-6 + 16e-6) / 2)
    assert errors.values["accelerometer"] == pytest.approx(bias)
    assert errors.values["tilt"] == pytest.approx(bias / 9.80665)
    assert errors.values["drift"] == 0.0 and errors.values["velocity"] == 0.0
    assert errors.values["azimuth"] == pytest.approx(bias * math.tan(latitude) / 9.80665)
    assert set(errors.to_dict()["values"]) == {"tilt", "velocity", "accelerometer", "drift", "azimuth"}


def test_first_order_scaling_halves_every_input():
    full = align_inputs(preset("industrial"), heading=0.4)
    half = align_inputs(preset("industrial").scaled(0.5), heading=0.4)
    for name, value in full.values.items():
        assert half.values[name] == pytest.approx(value / 2)


def test_bad_arguments():
    with pytest.raises(InvalidParameter, match="window"):
        align_inputs(preset("tactical"), window=0.0)
    with pytest.raises(InvalidParameter, match="latitude"):
        errors_inputs(preset("tactical"), latitude=math.pi / 2)
    assert "drift_east" in str(align_inputs(preset("tactical")))
