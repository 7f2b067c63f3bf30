"""The nonlinear INS against closed forms: single error sources, vertical channel, noise, batches, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.core.earth import (
    gravity_height_coefficient,
    meridian_radius,
    somigliana_gravity,
)
from schuler.exceptions import InvalidParameter
from schuler.navigate.errors import ConstantSensorErrors, InitialErrors, WhiteNoise
from schuler.navigate.mechanization import navigate, output_interval
from schuler.navigate.trajectory import Stationary
from schuler.navigation_errors.single_channel import spherical_error
from schuler.navigation_errors.vertical_channel import hover_altitude_error

LATITUDE = math.radians(30.0)
AT_REST = Stationary(latitude=LATITUDE)


def _north_channel():
    """Radius and gravity of the north Schuler channel at rest at LATITUDE."""
    return float(meridian_radius(LATITUDE)), float(somigliana_gravity(LATITUDE))


# Bollay's (1966) closed forms (single_channel.spherical_error) in the small-error limit. On a non-rotating
# Earth the north channel at rest is exactly Bollay's: x'' + (g / R_N) x = g theta + Delta_a. Heading 0:
# a pitch error -theta is psi_E = theta, an accelerometer bias on body x reads north, a gyro bias -eps on
# body y is a drift eps about east (spec 06: epsilon = -C b_g). The nonlinear residual is second order
# in the error (measured 3e-8 .. 6e-7 of the maximum); 2e-6 of the maximum bounds it.
SOURCES = [
    ("tilt", 2e-5, {"initial_errors": InitialErrors(pitch_error=-2e-5)}),
    ("velocity", 0.05, {"initial_errors": InitialErrors(velocity_error_north=0.05)}),
    ("accelerometer", 1e-4, {"sensor_errors": ConstantSensorErrors(accel_bias=[1e-4, 0.0, 0.0])}),
    ("drift", 1e-8, {"sensor_errors": ConstantSensorErrors(gyro_bias=[0.0, -1e-8, 0.0])}),
]


@pytest.mark.parametrize("source, magnitude, errors", SOURCES, ids=[s[0] for s in SOURCES])
def test_single_error_sources_follow_bollays_closed_forms(source, magnitude, errors):
    result = navigate(AT_REST, 10_000.0, imu_rate=10.0, output_step=50.0, earth_rate=0.0, **errors)
    R, g = _north_channel()
    closed = spherical_error(source, magnitude, result.t_s, R, g)
    north = result.position_error_north_m
    np.testing.assert_allclose(north, closed, rtol=0, atol=2e-6 * np.abs(closed).max())
    assert np.abs(result.position_error_east_m).max() <= 1e-6 * np.abs(closed).max()


def test_free_vertical_channel_diverges_as_the_hover_problem():
    # Bollay (1966), Problem 4 on WGS-84: delta_h'' - k1 g0 delta_h = b, k1 g0 = -dg/dh, from rest
    bias = -1e-5  # the accelerometer reads low along body z (down): the computed vertical acceleration is b up
    result = navigate(AT_REST, 3000.0, imu_rate=10.0, output_step=30.0, vertical_channel="free", earth_rate=0.0,
                      sensor_errors=ConstantSensorErrors(accel_bias=[0.0, 0.0, bias]))
    g0 = float(somigliana_gravity(LATITUDE))
    radius = 2.0 / float(gravity_height_coefficient(LATITUDE))  # 2 omega^2 = k1 g0 = 2 g0 / radius
    closed = hover_altitude_error(result.t_s, -bias, radius, g0)
    np.testing.assert_allclose(result.height_error_m, closed, rtol=0, atol=1e-3 * np.abs(closed).max())
    assert result.height_error_m[-1] > 0


def test_baro_loop_settles_on_the_barometer():
    # third-order loop: the accelerometer error is estimated, the height error tends to the baro error
    result = navigate(AT_REST, 4000.0, imu_rate=10.0, output_step=100.0, vertical_channel="baro", baro_error=12.0,
                      sensor_errors=ConstantSensorErrors(accel_bias=[0.0, 0.0, 3e-4]))
    assert result.height_error_m[-1] == pytest.approx(12.0, abs=0.05)
    assert np.abs(result.velocity_error_down_m_s[-1]) < 1e-3


def _mode_differences(scale: float) -> dict[str, tuple[float, float]]:
    """Largest |strapdown - platform| and |strapdown| per channel, errors scaled by ``scale``."""
    initial = InitialErrors(position_error_north=30.0 * scale, velocity_error_east=0.02 * scale,
                            roll_error=1e-5 * scale, pitch_error=-2e-5 * scale, heading_error=3e-4 * scale)
    sensors = ConstantSensorErrors(gyro_bias=np.array([1e-8, -2e-8, 3e-8]) * scale,
                           accel_bias=np.array([1e-4, -5e-5, 0.0]) * scale)
    runs = [navigate(Stationary(latitude=math.radians(45.0)), 4 * 3600.0, imu_rate=10.0, output_step=60.0,
                     mode=mode, initial_errors=initial, sensor_errors=sensors) for mode in ("strapdown", "platform")]
    return {name: (float(np.abs(runs[0].channel(name) - runs[1].channel(name)).max()),
                   float(np.abs(runs[0].channel(name)).max()))
            for name in ("position_error_north_m", "position_error_east_m", "velocity_error_north_m_s",
                         "roll_error_rad", "pitch_error_rad", "heading_error_rad")}


def test_platform_and_strapdown_agree_at_rest_with_small_errors():
    # level, heading 0: the body axes are the platform's. The two mechanizations differ in second order
    # only (measured 5e-5 .. 1e-3 of each channel's maximum): halving every error quarters the difference
    full, half = _mode_differences(1.0), _mode_differences(0.5)
    for name, (difference, size) in full.items():
        assert difference <= 2e-3 * size, name
        assert 3.6 <= difference / half[name][0] <= 4.4, name


def test_a_batch_runs_its_members_as_single_runs_would():
    errors = InitialErrors(velocity_error_north=[0.1, -0.2, 0.05], heading_error=[0.0, 1e-3, -2e-3])
    sensors = ConstantSensorErrors(gyro_bias=[[1e-8, 0, 0], [0, 2e-8, 0], [0, 0, -3e-8]],
                           accel_scale_factor=[[1e-4, 0, 0], [0, 0, 0], [0, 0, 5e-5]])
    batch = navigate(Stationary(latitude=0.7, heading=1.0), 1800.0, imu_rate=20.0, output_step=60.0,
                     initial_errors=errors, sensor_errors=sensors)
    assert batch.members == 3 and batch.position_error_north_m.shape == (3, 31)
    for i in range(3):
        single = navigate(Stationary(latitude=0.7, heading=1.0), 1800.0, imu_rate=20.0, output_step=60.0,
                          initial_errors=InitialErrors(velocity_error_north=errors.velocity_error_north[i],
                                                       heading_error=errors.heading_error[i]),
                          sensor_errors=ConstantSensorErrors(gyro_bias=sensors.gyro_bias[i],
                                                     accel_scale_factor=sensors.accel_scale_factor[i]))
        np.testing.assert_array_equal(batch.position_error_north_m[i], single.position_error_north_m)
        np.testing.assert_array_equal(batch.heading_error_rad[i], single.heading_error_rad)


def test_initial_errors_are_reported_back_at_time_zero():
    errors = InitialErrors(position_error_north=1500.0, position_error_east=-800.0, height_error=3.0,
                           velocity_error_north=0.3, velocity_error_east=-0.1, velocity_error_down=0.02,
                           roll_error=1e-3, pitch_error=-2e-3, heading_error=0.05)
    result = navigate(Stationary(latitude=math.radians(60.0), heading=3.1), 10.0, imu_rate=10.0, output_step=10.0,
                      vertical_channel="free", initial_errors=errors)
    for name in ("position_error_north", "position_error_east", "height_error", "velocity_error_north",
                 "velocity_error_east", "velocity_error_down", "roll_error", "pitch_error", "heading_error"):
        unit = "_m" if "position" in name or "height" in name else ("_m_s" if "velocity" in name else "_rad")
        assert result.channel(name + unit)[0] == pytest.approx(float(getattr(errors, name)), rel=1e-9, abs=1e-12)


def test_white_noise_makes_a_velocity_random_walk():
    # 200 members, 60 s at rest: the Schuler loop has no time to act (w_s t = 0.07), so the north
    # velocity error is the integral of white noise, std N_a sqrt(t); a 200-member std is within
    # 3 sigma = 3 / sqrt(2 * 199) = 15 % of it
    density = 1e-3
    noise = WhiteNoise(velocity_random_walk=density, seed=11)
    result = navigate(Stationary(latitude=0.5), 60.0, imu_rate=100.0, output_step=60.0, noise=noise,
                      member_ids=np.arange(200))
    spread = result.velocity_error_north_m_s[:, -1].std()
    assert spread == pytest.approx(density * math.sqrt(60.0), rel=0.15)
    # a member's noise depends on its number only, not on the batch it runs in
    alone = navigate(Stationary(latitude=0.5), 60.0, imu_rate=100.0, output_step=60.0, noise=noise, member_ids=[17])
    np.testing.assert_array_equal(alone.velocity_error_north_m_s[0], result.velocity_error_north_m_s[17])


def test_uncompensated_centripetal_acceleration_shifts_the_position():
    # a computer modelling gravitation instead of gravity keeps Omega^2 R_E sin L cos L north: the Schuler
    # loop settles on x = W / w^2 (twice that at the oscillation's peak after half a period)
    result = navigate(AT_REST, 5000.0, imu_rate=5.0, output_step=50.0, centripetal_compensation=False)
    R, g = _north_channel()
    from schuler.core.earth import centripetal_acceleration_ned

    w_star = float(centripetal_acceleration_ned(LATITUDE)[0])
    closed = spherical_error("accelerometer", w_star, result.t_s, R, g)
    np.testing.assert_allclose(result.position_error_north_m, closed, rtol=0, atol=0.01 * closed.max())


@pytest.mark.parametrize("kwargs, name", [
    ({"mode": "gimbal"}, "mode"),
    ({"vertical_channel": "on"}, "vertical_channel"),
    ({"output_step": 0.15}, "output_step"),
    ({"output_step": 700.0}, "duration"),
    ({"imu_rate": 0.0}, "imu_rate"),
    ({"earth_rate_latitude": "entered"}, "earth_rate_latitude"),
    ({"azimuth_reference": True}, "azimuth_reference"),
    ({"baro_error": np.nan}, "baro_error"),
    ({"member_ids": [1, 2], "initial_errors": InitialErrors(roll_error=[0.0, 1e-3, 2e-3])}, "initial_errors"),
    ({"member_ids": [-1]}, "member_ids"),
    ({"max_memory": 10_000}, "output_step"),
])
def test_navigate_bad_input(kwargs, name):
    arguments = {"imu_rate": 10.0, "output_step": 10.0} | kwargs
    with pytest.raises(InvalidParameter) as error:
        navigate(AT_REST, 1000.0, **arguments)
    assert error.value.name == name


@pytest.mark.parametrize("factory, name", [
    (lambda: InitialErrors(roll_error=4.0), "roll_error"),
    (lambda: InitialErrors(velocity_error_north=[np.inf]), "velocity_error_north"),
    (lambda: ConstantSensorErrors(gyro_bias=[1.0, 2.0]), "gyro_bias"),
    (lambda: ConstantSensorErrors(gyro_misalignment=np.eye(3) * 1e-3), "gyro_misalignment"),
    (lambda: ConstantSensorErrors(accel_scale_factor=[0.6, 0, 0]), "accel_scale_factor"),
    (lambda: ConstantSensorErrors(gyro_bias=[[0, 0, 0]] * 2, accel_bias=[[0, 0, 0]] * 3), "gyro_bias"),
    (lambda: WhiteNoise(angle_random_walk=-1.0), "angle_random_walk"),
])
def test_error_models_bad_input(factory, name):
    with pytest.raises(InvalidParameter) as error:
        factory().members
    assert error.value.name == name


def test_memory_is_estimated_before_allocating():
    with pytest.raises(InvalidParameter, match="MiB"):
        navigate(AT_REST, 48 * 3600.0, imu_rate=1.0, output_step=1.0,
                 initial_errors=InitialErrors(roll_error=np.zeros(100_000)))


def test_result_json_names_units_and_rendering():
    import json

    held = navigate(AT_REST, 600.0, imu_rate=10.0, output_step=60.0, initial_errors=InitialErrors(roll_error=1e-4))
    data = json.loads(json.dumps(held.to_dict()))
    for name in ("t_s", "position_error_north_m", "position_error_east_m", "velocity_error_north_m_s",
                 "velocity_error_east_m_s", "roll_error_rad", "pitch_error_rad", "heading_error_rad"):
        assert len(data[name]) == 11, name
    assert "height_error_m" not in data and "velocity_error_down_m_s" not in data  # the channel is held
    assert data["units"]["imu_rate_hz"] == "Hz" and data["members"] is None
    text = str(held)
    assert "roll_error (arcsec)" in text and "20.63" in text  # 1e-4 rad = 20.63 arcsec at t = 0 ... max
    free = navigate(AT_REST, 600.0, imu_rate=10.0, output_step=60.0, vertical_channel="free",
                    initial_errors=InitialErrors(height_error=[1.0, 2.0]))
    data = free.to_dict()
    assert np.shape(data["height_error_m"]) == (2, 11) and data["members"] == 2
    assert "std final" in str(free)


@pytest.mark.parametrize("rate", [float("nan"), float("inf"), 0.0, -100.0])
def test_output_interval_refuses_a_bad_imu_rate_by_name(rate):
    with pytest.raises(InvalidParameter, match=r"imu_rate: must be finite and > 0 Hz"):
        output_interval(1.0, rate)
    assert output_interval(0.5, 200.0) == 100
