"""The drive trajectory: the ideal IMU returns the truth, stops are still, the kinematics are smooth, roll is zero."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.core.attitude import euler_from_quaternion
from schuler.exceptions import InvalidParameter
from schuler.navigate.drive import GroundVehicleProfile, drive
from schuler.navigate.mechanization import navigate
from schuler.navigate.trajectory import WaypointProfile
from schuler.navigate.truth import ideal_imu

DRIVE = drive()
IMU_RATE = 100.0


@pytest.fixture(scope="module")
def imu():
    return ideal_imu(DRIVE, DRIVE.duration, imu_rate=IMU_RATE)


def test_ideal_imu_of_the_drive_navigated_returns_the_truth():
    # 1,500 s at 200 Hz (300,000 samples), no errors: measured 4.9e-9 m, 2.1e-11 m/s, 5.7e-15 rad
    result = navigate(DRIVE, DRIVE.duration, imu_rate=200.0, output_step=1.0)
    position = max(np.abs(result.channel(name)).max()
                   for name in ("position_error_north_m", "position_error_east_m", "height_error_m"))
    velocity = max(np.abs(result.channel(f"velocity_error_{axis}_m_s")).max() for axis in ("north", "east", "down"))
    assert position <= 1e-7
    assert velocity <= 1e-9
    assert np.abs(result.attitude_error_rad).max() <= 1e-13


def test_default_drive_is_what_a_user_expects(imu):
    assert isinstance(DRIVE, WaypointProfile) and DRIVE.name == "drive"
    assert DRIVE.duration == 1500.0
    assert math.degrees(DRIVE.latitude) == pytest.approx(30.5, abs=1e-12)
    assert math.degrees(DRIVE.longitude) == pytest.approx(114.5, abs=1e-12)
    assert DRIVE.height == 20.0
    stops = DRIVE.stationary_intervals()
    assert len(stops) == 4 and all(end - start == pytest.approx(25.0, abs=1e-9) for start, end in stops)
    turns = np.diff(DRIVE.headings)
    np.testing.assert_allclose(np.abs(turns[turns != 0]), math.pi / 2, rtol=0, atol=1e-15)
    assert np.count_nonzero(turns) == 6
    speed = np.linalg.norm(imu.velocity_ned_m_s, axis=1)
    assert speed.max() == pytest.approx(20.0, abs=1e-9)
    # a level road: the height stays that of the start
    assert np.abs(imu.height_m - 20.0).max() <= 1e-6


def test_speed_is_zero_during_stops(imu):
    for start, end in DRIVE.stationary_intervals():
        t = np.linspace(start, end, 501)
        velocity, _ = DRIVE.kinematics(t)
        assert np.abs(velocity).max() == 0.0
        inside = (imu.t_s >= start) & (imu.t_s <= end)
        assert np.abs(imu.velocity_ned_m_s[inside]).max() == 0.0


def test_kinematics_are_smooth_no_jumps_in_specific_force(imu):
    dt = 1.0 / IMU_RATE
    # jerk and yaw acceleration of the default drive: measured 1.30 m/s^3 and 0.147 rad/s^2. A jump in specific
    # force of 0.1 m/s^2 would show as 10 m/s^3 between two samples
    assert np.abs(np.diff(imu.specific_force_m_s2, axis=0)).max() / dt <= 1.5
    assert np.abs(np.diff(imu.angular_rate_rad_s, axis=0)).max() / dt <= 0.16
    h = 1e-3
    for t in DRIVE.times[1:-1]:
        v = [DRIVE.kinematics(np.array([t + k * h]))[0][0] for k in (-1, 0, 1)]
        np.testing.assert_allclose((v[1] - v[0]) / h, (v[2] - v[1]) / h, atol=5e-3)


def test_a_car_does_not_bank_its_turns_feel_lateral_force(imu):
    euler = euler_from_quaternion(imu.quaternion)
    assert np.abs(euler[:, 0]).max() <= 1e-15
    assert np.abs(euler[:, 1]).max() <= 1e-15
    # the middle of the first turn: yaw rate 15/8 V / R (the smoothstep's peak), lateral force V psi' on body y
    # (plus the Coriolis term 2 Omega V sin L ~ 6e-4 m/s^2)
    start, end = DRIVE.times[4], DRIVE.times[5]
    k = int(round(0.5 * (start + end) * IMU_RATE)) - 1
    rate = 15.0 / 8.0 * 8.0 / 40.0
    assert imu.angular_rate_rad_s[k, 2] == pytest.approx(rate, abs=1e-4)
    assert imu.specific_force_m_s2[k, 1] == pytest.approx(8.0 * rate, abs=2e-3)


def test_the_drive_is_deterministic_and_scales_with_its_parameters():
    again = drive()
    for key in ("times", "speeds", "headings", "flight_path_angles"):
        np.testing.assert_array_equal(getattr(DRIVE, key), getattr(again, key))
    short = drive(duration=600.0, stops=3, stop_duration=20.0, heading=math.radians(45.0))
    assert isinstance(short, GroundVehicleProfile) and short.duration == 600.0
    assert len(short.stationary_intervals()) == 3
    assert short.headings[0] == pytest.approx(math.radians(45.0))


@pytest.mark.parametrize("options, message", [
    ({"duration": 150.0}, "duration: 150 s is too short: 4 stops of 25 s and 3 legs"),
    ({"stops": 1}, "stops: must be a whole number in [2, 100]"),
    ({"road_speed": -3.0}, "road_speed: must lie in (0, 70]"),
    ({"turn_radius": float("nan")}, "turn_radius: must lie in (0, 10000]"),
    ({"latitude": math.radians(89.5)}, "latitude: must lie within +/-89 deg"),
])
def test_bad_drive_parameters_are_refused_in_one_line(options, message):
    with pytest.raises(InvalidParameter) as error:
        drive(**options)
    assert str(error.value).startswith(message)


def test_navigate_offers_the_drive_and_its_ideal_imu_returns_the_truth():
    """``schuler navigate --trajectory drive``, ideal sensors, free vertical channel: the errors stay at rounding.

    600 s with 3 stops at 100 Hz; measured 7.1e-10 m, 3.8e-12 m/s, 3.6e-15 rad: the library's bounds above.
    """
    from schuler.navigate.api import SYSTEM

    result = SYSTEM.run(trajectory="drive", duration=600.0, stops=3, imu_rate=100.0, output_step=1.0,
                        vertical_channel="free")
    assert result.trajectory == "drive" and result.duration_s == 600.0 and result.warnings == []
    position = max(result.max_horizontal_position_error_m, result.max_abs_height_error_m)
    velocity = max(getattr(result, f"max_abs_velocity_error_{axis}_m_s") for axis in ("north", "east", "down"))
    attitude = max(getattr(result, f"max_abs_{angle}_error_rad") for angle in ("roll", "pitch", "heading"))
    assert position <= 1e-7
    assert velocity <= 1e-9
    assert attitude <= 1e-13


def test_the_drive_options_reach_the_drive():
    from schuler.navigate.api import SYSTEM
    from schuler.navigate.evaluation import setup

    default = setup(SYSTEM.case(trajectory="drive")).trajectory
    assert (default.latitude, default.longitude, default.height, default.duration) == \
        (DRIVE.latitude, DRIVE.longitude, DRIVE.height, 1500.0)  # the drive of schuler aided
    np.testing.assert_array_equal(default.times, DRIVE.times)
    options = {"stops": 3, "stop_duration": 20.0, "city_speed": 12.0, "road_speed": 25.0, "turn_speed": 6.0,
               "turn_radius": 30.0, "acceleration": 2.0}
    start = {"latitude": 0.6, "longitude": 0.1, "height": 5.0, "heading": 0.5}
    chosen = setup(SYSTEM.case(trajectory="drive", duration=900.0, **start, **options)).trajectory
    expected = drive(duration=900.0, **start, **options)
    for key in ("times", "speeds", "headings"):
        np.testing.assert_array_equal(getattr(chosen, key), getattr(expected, key))
    assert (chosen.latitude, chosen.longitude, chosen.height) == (0.6, 0.1, 5.0)


@pytest.mark.parametrize("values, message", [
    ({"trajectory": "stationary", "stops": 3}, "stops: applies to the drive trajectory only"),
    ({"trajectory": "great-circle", "road_speed": 30.0}, "road_speed: applies to the drive trajectory only"),
    ({"trajectory": "drive", "speed": 10.0}, "speed: applies to the great-circle trajectory only (the drive sets"),
    ({"trajectory": "drive", "duration": 100.0}, "duration: 100 s is too short"),
])
def test_drive_options_elsewhere_are_refused(values, message):
    from schuler.navigate.api import SYSTEM

    with pytest.raises(InvalidParameter) as error:
        SYSTEM.run(**values)
    assert str(error.value).startswith(message)


def test_the_command_line_drives(run_cli):
    out = run_cli("navigate", "run", "--trajectory", "drive", "--duration", "10 min", "--stops", "3",
                  "--imu-rate", "20", "--output-step", "5", "--velocity-error-north", "0.1", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["trajectory"] == "drive" and data["t_s"][-1] == 600.0 and data["inputs"]["stops"] == 3
    # 0.1 m/s north: the Schuler oscillation (dV / w_s) sin(w_s t), 54.6 m after 10 min as at rest (measured 54.597
    # on the drive, 54.598 at rest at 45 deg): the slow drive barely couples into it
    assert data["max_horizontal_position_error_m"] == pytest.approx(54.6, rel=1e-3)
