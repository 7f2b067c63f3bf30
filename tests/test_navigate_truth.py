"""Trajectories, TOML profiles, and the truth / ideal IMU by inverse mechanization."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from schuler.core.attitude import dcm_from_quaternion, euler_from_quaternion
from schuler.core.earth import EARTH_RATE, somigliana_gravity, transverse_radius
from schuler.exceptions import InvalidParameter
from schuler.navigate.mechanization import navigate
from schuler.navigate.profile import load_profile, parse_profile
from schuler.navigate.trajectory import (
    GreatCircle,
    Stationary,
    WaypointProfile,
    smoothstep,
)
from schuler.navigate.truth import TruthGenerator, ideal_imu

PROFILE = Path(__file__).resolve().parents[1] / "examples" / "profiles" / "manoeuvring_flight.toml"
POSITION_CHANNELS = ("position_error_north_m", "position_error_east_m", "height_error_m")

# Stated floor of "ideal IMU -> truth" over 1 h at 100 Hz on the manoeuvring profile (the issue's
# target is 1e-6 m). Measured: 2e-7 m with the vertical channel held, 6e-7 m free (its instability
# amplifies rounding by e^(sqrt(2) w_s t) ~ 500 over the hour); the platform reproduces the truth exactly.
POSITION_FLOOR = 1e-6
VELOCITY_FLOOR = 1e-8
ATTITUDE_FLOOR = 1e-11


def test_stationary_ideal_imu_is_earth_rate_and_gravity():
    L = math.radians(52.0)
    imu = ideal_imu(Stationary(latitude=L, roll=0.02, pitch=-0.05, heading=2.0), duration=2.0, imu_rate=100.0)
    C = dcm_from_quaternion(imu.quaternion[0])
    expected_rate = C.T @ (EARTH_RATE * np.array([math.cos(L), 0.0, -math.sin(L)]))
    expected_force = C.T @ np.array([0.0, 0.0, -somigliana_gravity(L)])
    # Increments are exact for the discrete algorithm; against the continuous values they differ by
    # O((Omega dt)^2) ~ 5e-13 relative, and by the rounding of the truth's quaternion products, ~1e-16 rad
    # on a 5e-7 rad increment (measured 9e-15 rad/s)
    np.testing.assert_allclose(imu.angular_rate_rad_s, np.tile(expected_rate, (200, 1)), rtol=0, atol=1e-13)
    np.testing.assert_allclose(imu.specific_force_m_s2, np.tile(expected_force, (200, 1)), rtol=0, atol=1e-11)
    np.testing.assert_allclose(imu.latitude_rad, L, rtol=0, atol=0)


def test_level_flight_east_feels_the_centripetal_and_coriolis_lift():
    # flying east at V along the equator the accelerometers read -g + 2 Omega V + V^2 / R_E upward
    V = 250.0
    path = GreatCircle(latitude=0.0, longitude=0.0, height=0.0, heading=math.pi / 2, speed=V, duration=10.0)
    imu = ideal_imu(path, duration=10.0, imu_rate=50.0)
    expected = -somigliana_gravity(0.0) + 2 * EARTH_RATE * V + V**2 / transverse_radius(0.0)
    # the discrete algorithm's increments differ from the continuous values by O((rho dt)^2) ~ 1e-12
    np.testing.assert_allclose(imu.specific_force_m_s2[:, 2], expected, rtol=5e-12)
    np.testing.assert_allclose(imu.latitude_rad, 0.0, atol=1e-15)


def test_great_circle_keeps_clairauts_constant():
    path = GreatCircle(latitude=math.radians(40.0), longitude=0.0, height=3000.0, heading=math.radians(60.0),
                       speed=300.0, duration=7200.0)
    imu = ideal_imu(path, duration=7200.0, imu_rate=10.0)
    heading = euler_from_quaternion(imu.quaternion)[:, 2]
    L = imu.latitude_rad
    clairaut = (transverse_radius(L) + 3000.0) * np.cos(L) * np.sin(heading)
    # the truth's position is the algorithm's trapezoid integral of the velocity, the heading the ODE's:
    # they agree to O(dt^2) (measured 1.2e-9 relative over 2 h at 10 Hz)
    np.testing.assert_allclose(clairaut, clairaut[0], rtol=5e-9)
    assert np.degrees(heading[-1] - heading[0]) > 10.0


def test_chunking_does_not_change_the_truth():
    profile = load_profile(PROFILE)
    whole = [part.increments for part in TruthGenerator(profile, 600.0, 50.0).chunks(30_000)]
    pieces = [part.increments for part in TruthGenerator(profile, 600.0, 50.0).chunks(777)]
    np.testing.assert_array_equal(np.concatenate(whole), np.concatenate(pieces))


@pytest.mark.parametrize("size", [0, -5, 2.5, True])
def test_chunks_refuses_a_size_that_is_not_a_positive_whole_number(size):
    truth = TruthGenerator(Stationary(latitude=0.5, longitude=0.0, height=0.0), 10.0, 10.0)
    with pytest.raises(InvalidParameter, match=r"chunk_size: must be a whole number of IMU intervals >= 1"):
        truth.chunks(size)
    assert [part.increments.shape[0] for part in truth.chunks(np.int64(40))] == [40, 40, 20]


@pytest.mark.parametrize("mode, vertical_channel", [("strapdown", "off"), ("strapdown", "free"),
                                                    ("platform", "off"), ("platform", "free")])
def test_ideal_imu_returns_the_truth_on_a_manoeuvring_profile(mode, vertical_channel):
    result = navigate(load_profile(PROFILE), 3600.0, imu_rate=100.0, output_step=10.0, mode=mode,
                      vertical_channel=vertical_channel)
    position = max(np.abs(result.channel(name)).max() for name in POSITION_CHANNELS)
    velocity = max(np.abs(result.channel(f"velocity_error_{axis}_m_s")).max() for axis in ("north", "east", "down"))
    assert position <= POSITION_FLOOR
    assert velocity <= VELOCITY_FLOOR
    assert np.abs(result.attitude_error_rad).max() <= ATTITUDE_FLOOR


def test_zero_errors_give_zero_growth_at_rest():
    # three hours at 100 Hz, heading and roll off zero: position stays within 1e-7 m (measured 1.6e-8 m)
    result = navigate(Stationary(latitude=math.radians(45.0), roll=0.1, heading=0.3), 3 * 3600.0, imu_rate=100.0,
                      output_step=60.0)
    assert max(np.abs(result.channel(name)).max() for name in POSITION_CHANNELS) <= 1e-7
    assert np.abs(result.attitude_error_rad).max() <= 1e-15


def test_smoothstep_profiles_are_c2():
    value, first, second = smoothstep(np.array([0.0, 1.0]))
    np.testing.assert_array_equal(value, [0.0, 1.0])
    np.testing.assert_array_equal(first, [0.0, 0.0])
    np.testing.assert_array_equal(second, [0.0, 0.0])
    profile = load_profile(PROFILE)
    # velocity and its first two derivatives are continuous across every waypoint (finite differences)
    h = 1e-3
    for t in profile.times[1:-1]:
        v = [profile.kinematics(np.array([t + k * h]))[0][0] for k in (-2, -1, 0, 1, 2)]
        left_acc = (v[2] - v[1]) / h
        right_acc = (v[3] - v[2]) / h
        np.testing.assert_allclose(left_acc, right_acc, atol=5e-4 * (1 + np.abs(left_acc).max()))
        left_jerk = (v[2] - 2 * v[1] + v[0]) / h**2
        right_jerk = (v[4] - 2 * v[3] + v[2]) / h**2
        np.testing.assert_allclose(left_jerk, right_jerk, atol=0.05)


def test_profile_format_and_validation(tmp_path):
    profile = load_profile(PROFILE)
    assert profile.duration == 3600.0 and profile.times.size == 9
    assert profile.latitude == pytest.approx(math.radians(45.0))
    units = parse_profile({"start": {"latitude": "0.5 rad", "height": "1 km"},
                           "waypoint": [{"time": "0 s", "speed": "1 km/h", "heading": "0.25 turn"}]})
    assert units.latitude == 0.5 and units.height == 1000.0
    assert units.speeds[0] == pytest.approx(1 / 3.6) and units.headings[0] == pytest.approx(math.pi / 2)
    cases = [
        ({"waypoint": [{"time": 0, "speed": 1, "heading": 0}]}, "start"),
        ({"start": {"latitude": 91.0}, "waypoint": [{"time": 0, "speed": 1, "heading": 0}]}, "latitude"),
        ({"start": {"latitude": 10.0}}, "waypoint"),
        ({"start": {"latitude": 10.0}, "waypoint": [{"time": 5, "speed": 1, "heading": 0}]}, "waypoint[1].time"),
        ({"start": {"latitude": 10.0}, "waypoint": [{"time": 0, "speed": 1, "heading": 0},
                                                     {"time": 0, "speed": 1, "heading": 0}]}, "waypoint[2].time"),
        ({"start": {"latitude": 10.0}, "waypoint": [{"time": 0, "speed": -1, "heading": 0}]}, "waypoint[1].speed"),
        ({"start": {"latitude": 10.0}, "waypoint": [{"time": 0, "heading": 0}]}, "waypoint[1].speed"),
        ({"start": {"latitude": 10.0, "alt": 3}, "waypoint": [{"time": 0, "speed": 1, "heading": 0}]}, "start.alt"),
        ({"start": {"latitude": 10.0}, "waypoint": [{"time": 0, "speed": "3 kg", "heading": 0}]},
         "waypoint[1].speed"),
        ({"start": {"latitude": 10.0}, "speed": 3, "waypoint": []}, "speed"),
    ]
    for data, name in cases:
        with pytest.raises(InvalidParameter) as error:
            parse_profile(data)
        assert error.value.name == name, data
    broken = tmp_path / "broken.toml"
    broken.write_text("[start\nlatitude = 3")
    with pytest.raises(InvalidParameter, match="not valid TOML"):
        load_profile(broken)
    with pytest.raises(InvalidParameter, match="cannot read"):
        load_profile(tmp_path / "missing.toml")


def test_trajectory_bad_input():
    with pytest.raises(InvalidParameter, match="pole"):
        GreatCircle(latitude=math.radians(80.0), longitude=0.0, height=0.0, heading=0.0, speed=300.0, duration=36000.0)
    with pytest.raises(InvalidParameter) as error:
        Stationary(latitude=math.radians(89.5))
    assert error.value.name == "latitude"
    with pytest.raises(InvalidParameter) as error:
        WaypointProfile(0.1, 0.0, 0.0, times=[0.0, 10.0], speeds=[1.0], headings=[0.0, 0.0],
                        flight_path_angles=[0.0, 0.0])
    assert error.value.name == "waypoint"
    with pytest.raises(InvalidParameter) as error:
        ideal_imu(Stationary(latitude=0.1), duration=1.005, imu_rate=100.0)
    assert error.value.name == "duration"
