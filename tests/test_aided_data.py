"""The data of aided navigation: KF-GINS's formats and configuration, simulated GNSS, odometer and barometer."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from schuler.aided.epochs import interpolate_positions, simulate_barometer, simulate_odometer, truth_at
from schuler.aided.gnss import (
    GnssRecord,
    detect_outages,
    gnss_measurements,
    gnss_truth,
    schedule_outages,
    simulate_gnss,
)
from schuler.aided.kfgins import (
    MAGNITUDE_FACTOR,
    NavigationRecord,
    check_overlap,
    check_specific_force,
    read_gnss,
    read_imu,
    read_navigation,
    write_gnss,
    write_imu,
    write_navigation,
)
from schuler.aided.kfgins_configuration import example_configuration, read_configuration
from schuler.core.attitude import dcm_from_quaternion, euler_from_quaternion
from schuler.core.earth import STANDARD_GRAVITY, earth_rate_ned, radii_of_curvature, transport_rate_ned
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.imu.record import ImuRecord
from schuler.navigate.drive import drive
from schuler.navigate.trajectory import Stationary
from schuler.navigate.truth import ideal_imu

WEEK_START = 456_300.0
DRIVE = drive()
SHORT = 200.0  # s of the drive: the first stop, a start, a cruise, the first turn


@pytest.fixture(scope="module")
def imu200():
    return ideal_imu(DRIVE, SHORT, imu_rate=200.0)


def _ned_metres(latitude, longitude, height, reference):
    """North, east, down differences (m) of positions from a reference (lat, lon, h), first order."""
    R_N, R_E = radii_of_curvature(reference[0])
    return np.stack([(latitude - reference[0]) * (R_N + reference[2]),
                     (longitude - reference[1]) * (R_E + reference[2]) * np.cos(reference[0]),
                     -(height - reference[2])], axis=-1)


# --- KF-GINS formats: round trips to the written precision -------------------------------------------------------

def test_imu_file_round_trip_is_exact_for_increments(tmp_path, imu200):
    record = ImuRecord(time_s=WEEK_START + imu200.t_s, gyro=imu200.angle_increment_rad,
                       accel=imu200.velocity_increment_m_s, kind="increment", sample_interval_s=imu200.interval_s)
    back = read_imu(write_imu(tmp_path / "imu.txt", record), imu_rate=200.0)
    assert back.kind == "increment" and back.sample_interval_s == 0.005 and back.samples == 40_000
    np.testing.assert_array_equal(back.gyro, record.gyro)  # 17 significant digits: exact
    np.testing.assert_array_equal(back.accel, record.accel)
    np.testing.assert_allclose(back.time_s, record.time_s, rtol=0, atol=5e-10 + 1e-10)  # 9 decimals


@pytest.mark.parametrize("velocity", [False, True], ids=["7 columns", "13 columns"])
def test_gnss_file_round_trip(tmp_path, velocity):
    record = simulate_gnss(DRIVE, SHORT, imu_rate=50.0, velocity_sigma=0.05 if velocity else None,
                           streams=RandomStreams(3))
    record = dataclasses.replace(record, t_s=record.t_s + WEEK_START)
    path = write_gnss(tmp_path / "gnss.txt", record)
    assert len(path.read_text().splitlines()[0].split()) == (13 if velocity else 7)
    back = read_gnss(path)
    # latitude and longitude to 1e-12 deg (1.7e-14 rad), heights and velocities to 1e-9 m, m/s, sigmas exact
    np.testing.assert_allclose(back.latitude_rad, record.latitude_rad, rtol=0, atol=1e-14 + 1e-15)
    np.testing.assert_allclose(back.longitude_rad, record.longitude_rad, rtol=0, atol=1e-14 + 1e-15)
    np.testing.assert_allclose(back.height_m, record.height_m, rtol=0, atol=5e-10 + 1e-12)
    np.testing.assert_array_equal(back.position_sigma_m, record.position_sigma_m)
    np.testing.assert_allclose(back.t_s, record.t_s, rtol=0, atol=5e-10 + 1e-10)
    if velocity:
        np.testing.assert_allclose(back.velocity_ned_m_s, record.velocity_ned_m_s, rtol=0, atol=5e-10 + 1e-13)
        np.testing.assert_array_equal(back.velocity_sigma_m_s, record.velocity_sigma_m_s)
    else:
        assert back.velocity_ned_m_s is None


def test_navigation_file_is_kf_gins_result_layout(tmp_path, imu200):
    euler = euler_from_quaternion(imu200.quaternion)
    record = NavigationRecord(np.full(imu200.t_s.size, 2300), WEEK_START + imu200.t_s, imu200.latitude_rad,
                              imu200.longitude_rad, imu200.height_m, imu200.velocity_ned_m_s, euler)
    path = write_navigation(tmp_path / "navigation.nav", record)
    first = path.read_text().splitlines()[0].split()
    assert len(first) == 11 and first[0] == "2300"  # no header: the first line is data
    assert all(len(first[k].split(".")[1]) >= 9 for k in (2, 3))  # latitude, longitude: at least 9 decimals
    back = read_navigation(path)
    np.testing.assert_array_equal(back.week, record.week)
    np.testing.assert_allclose(back.latitude_rad, record.latitude_rad, rtol=0, atol=1e-14 + 1e-15)
    np.testing.assert_allclose(back.velocity_ned_m_s, record.velocity_ned_m_s, rtol=0, atol=5e-10 + 1e-13)
    np.testing.assert_allclose(back.attitude_rad, record.attitude_rad, rtol=0, atol=math.radians(5e-10) + 1e-15)


def test_readers_take_commas_tabs_comments_and_trailing_spaces(tmp_path):
    path = tmp_path / "gnss.txt"
    path.write_text("# a comment line\n456300.000,30.5,114.5,20.0,0.01,0.02,0.03\n\n"
                    "  456301.000\t30.5000001 114.5   20.1    0.01    0.02    0.03 # fixed\n"
                    "456301.000 30.5 114.5 20.1 0.01 0.02 0.03\n")
    with pytest.raises(InvalidParameter, match="gnss.txt line 5: time 456301.000000 s repeats"):
        read_gnss(path)  # the line counted in the file, comments and blank lines included
    path.write_text("\n".join(path.read_text().splitlines()[:-1]) + "\n")
    record = read_gnss(path)
    assert record.epochs == 2
    assert math.degrees(record.latitude_rad[1]) == pytest.approx(30.5000001, abs=1e-12)
    np.testing.assert_array_equal(record.position_sigma_m[0], [0.01, 0.02, 0.03])


# --- KF-GINS formats: bad input, one line each ---------------------------------------------------------------------

GOOD_GNSS = ["456300.0 30.5 114.5 20.0 0.01 0.01 0.02", "456301.0 30.5 114.5 20.0 0.01 0.01 0.02",
             "456302.0 30.5 114.5 20.0 0.01 0.01 0.02"]


def _gnss_with(line_3: str) -> str:
    return "\n".join([GOOD_GNSS[0], GOOD_GNSS[1], line_3]) + "\n"


@pytest.mark.parametrize("third_line, message", [
    ("456302.0 30.5 114.5 20.0 0.01 0.01", "gnss_file: gnss.txt line 3: 6 columns, expected 7 or 13"),
    ("456302.0 30.5 114.5 20.0 0.01 0.01 0.02 1 2 3", "gnss_file: gnss.txt line 3: 10 columns, expected 7 or 13"),
    ("456302.0 30.5 114.5 twenty 0.01 0.01 0.02", "gnss_file: gnss.txt line 3: not a number: 'twenty' in "
                                                  "'456302.0 30.5 114.5 twenty 0.01 0.01 0.02'"),
    ("456301.0 30.5 114.5 20.0 0.01 0.01 0.02", "gnss_file: gnss.txt line 3: time 456301.000000 s repeats the one "
                                                "before"),
    ("456300.5 30.5 114.5 20.0 0.01 0.01 0.02", "gnss_file: gnss.txt line 3: time 456300.500000 s is earlier than "
                                                "the one before"),
    ("456302.0 30.5 114.5 20.0 0.01 nan 0.02", "gnss_file: gnss.txt line 3: nan is not a finite number"),
    ("456302.0 30.5 114.5 20.0 0.01 0.0 0.02", "gnss_file: gnss.txt line 3: position 1-sigma east is 0.0"),
    ("456302.0 30.5 114.5 20.0 0.01 0.01 -0.02", "gnss_file: gnss.txt line 3: position 1-sigma down is -0.02"),
    ("456302.0 95.5 114.5 20.0 0.01 0.01 0.02", "gnss_file: gnss.txt line 3: latitude 95.5 deg is beyond"),
    ("456302.0 30.5 114.5 20.0 0 0 0 0.01 0.01 0.02 0.1 0.1 0.1", "gnss_file: gnss.txt line 3: 13 columns, line 1 "
                                                                   "has 7 (every line needs the same)"),
])
def test_bad_gnss_files_get_one_line_naming_the_line(tmp_path, third_line, message):
    path = tmp_path / "gnss.txt"
    path.write_text(_gnss_with(third_line))
    with pytest.raises(InvalidParameter) as error:
        read_gnss(path)
    assert str(error.value).startswith(message), str(error.value)
    assert "\n" not in str(error.value)


def test_non_numeric_text_is_quoted_at_most_80_characters(tmp_path):
    path = tmp_path / "gnss.txt"
    path.write_text(_gnss_with("Time Latitude Longitude " + "x" * 200))
    with pytest.raises(InvalidParameter) as error:
        read_gnss(path)
    quoted = str(error.value).split(" in ", 1)[1]
    assert str(error.value).startswith("gnss_file: gnss.txt line 3: not a number: 'Time'")
    assert len(quoted) <= 82 and quoted.endswith("...'")


def test_missing_and_empty_files(tmp_path):
    with pytest.raises(InvalidParameter, match="imu_file: .*nothing.txt: no such file"):
        read_imu(tmp_path / "nothing.txt")
    (tmp_path / "empty.txt").write_text("# only a comment\n\n")
    with pytest.raises(InvalidParameter, match="gnss_file: empty.txt: no data lines"):
        read_gnss(tmp_path / "empty.txt")


def _imu_file(tmp_path, accel_scale=1.0, rate=200.0, n=400, repeat_at=None):
    t = WEEK_START + np.arange(1, n + 1) / rate
    if repeat_at is not None:
        t[repeat_at] = t[repeat_at - 1]
    accel = np.tile([0.0, 0.0, -STANDARD_GRAVITY / rate], (n, 1)) * accel_scale
    record = ImuRecord(time_s=t, gyro=np.full((n, 3), 1e-7), accel=accel, kind="increment",
                       sample_interval_s=1.0 / rate)
    return write_imu(tmp_path / "imu.txt", record)


def test_bad_imu_files(tmp_path):
    with pytest.raises(InvalidParameter) as error:
        read_imu(_imu_file(tmp_path, accel_scale=200.0), imu_rate=200.0)
    assert str(error.value) == ("imu_file: expected velocity increments over 0.005-s intervals: median |dv| should "
                                "be near g dt = 0.04903 m/s, it is 9.807 m/s, 200 times that (specific force in "
                                "m/s^2?)")
    with pytest.raises(InvalidParameter) as error:
        read_imu(_imu_file(tmp_path), imu_rate=100.0)
    assert str(error.value) == ("imudatarate: 100 Hz disagrees with imu.txt's stamps: their median interval is "
                                "0.005 s (200 Hz)")
    with pytest.raises(InvalidParameter, match=r"imu_file: imu.txt line 8: time .* repeats the one before"):
        read_imu(_imu_file(tmp_path, repeat_at=7))
    path = tmp_path / "eight.txt"
    path.write_text("456300.005 0 0 0 0 0 -0.049 1.0\n456300.010 0 0 0 0 0 -0.049 1.0\n")
    assert read_imu(path, columns=8).samples == 2  # imudatalen 8: the first seven columns are read
    with pytest.raises(InvalidParameter, match="imu_file: eight.txt line 1: 8 columns, expected 7"):
        read_imu(path)


def test_the_magnitude_check_threshold():
    dt = 0.005
    level = np.array([[0.0, 0.0, STANDARD_GRAVITY * dt]])
    for factor in (1.0, 0.99 * MAGNITUDE_FACTOR, 1.01 / MAGNITUDE_FACTOR):
        check_specific_force(level * factor, dt, "increment")
        check_specific_force(level * factor / dt, dt, "rate")
    for factor in (1.01 * MAGNITUDE_FACTOR, 0.99 / MAGNITUDE_FACTOR):
        with pytest.raises(InvalidParameter):
            check_specific_force(level * factor, dt, "increment")
    with pytest.raises(InvalidParameter) as error:
        check_specific_force(level, dt, "rate", name="record")
    assert str(error.value) == ("record: expected specific force: median |f| should be near g = 9.807 m/s^2, it is "
                                "0.04903 m/s^2, 0.005 times that (velocity increments over 0.005-s intervals?)")


def test_gnss_that_does_not_overlap_the_imu_is_refused(imu200):
    record = ImuRecord(time_s=imu200.t_s, gyro=imu200.angle_increment_rad, accel=imu200.velocity_increment_m_s,
                       kind="increment", sample_interval_s=imu200.interval_s)
    gnss = simulate_gnss(DRIVE, SHORT, imu_rate=50.0)
    check_overlap(record, gnss)
    with pytest.raises(InvalidParameter, match=r"gnss_file: the GNSS span \[456301.000, 456500.000\] s does not "
                                               r"overlap the IMU's \[0.000, 200.000\] s"):
        check_overlap(record, dataclasses.replace(gnss, t_s=gnss.t_s + WEEK_START))


# --- The KF-GINS configuration -----------------------------------------------------------------------------------

def _config(tmp_path, text=None, name="kf-gins.yaml"):
    path = tmp_path / name
    path.write_text(example_configuration() if text is None else text)
    return path


def test_the_configuration_is_read_into_si(tmp_path):
    config = read_configuration(_config(tmp_path))
    deg = math.pi / 180
    assert config.imu_path == (tmp_path / "imu.txt").resolve() and config.output_path == (tmp_path / "results")
    assert (config.imu_columns, config.imu_rate_hz, config.start_time_s, config.end_time_s) == (7, 200.0, 0.0, None)
    np.testing.assert_allclose(config.initial_position, [30.5 * deg, 114.5 * deg, 20.0], rtol=1e-15)
    np.testing.assert_allclose(config.initial_attitude_sigma_rad, np.array([0.05, 0.05, 0.5]) * deg, rtol=1e-15)
    np.testing.assert_allclose(config.gyro_angle_random_walk_rad_sqrt_s, 0.1 * deg / 60, rtol=1e-15)
    np.testing.assert_allclose(config.accel_velocity_random_walk_m_s_sqrt_s, 0.1 / 60, rtol=1e-15)
    np.testing.assert_allclose(config.gyro_bias_sigma_rad_s, deg / 3600, rtol=1e-15)
    np.testing.assert_allclose(config.accel_bias_sigma_m_s2, 100 * 1e-5, rtol=1e-15)  # 100 mGal = 1e-3 m/s^2
    np.testing.assert_allclose(config.gyro_scale_factor_sigma, 500e-6, rtol=1e-15)
    assert config.correlation_time_s == 3600.0
    np.testing.assert_array_equal(config.antenna_lever_arm_m, [0.5, 0.0, -1.0])
    # the optional initial 1-sigma: initbgstd given; initsgstd absent, so gsstd (as KF-GINS)
    np.testing.assert_allclose(config.initial_gyro_bias_sigma_rad_s, deg / 3600, rtol=1e-15)
    np.testing.assert_array_equal(config.initial_gyro_scale_factor_sigma, config.gyro_scale_factor_sigma)
    with pytest.raises(dataclasses.FrozenInstanceError):
        config.imu_rate_hz = 100.0
    with pytest.raises(ValueError):
        config.antenna_lever_arm_m[0] = 1.0


def test_paths_resolve_against_the_configuration_folder_or_a_base(tmp_path):
    (tmp_path / "config").mkdir()
    path = _config(tmp_path / "config", example_configuration(imu_path="./dataset/imu.txt"))
    assert read_configuration(path).imu_path == (tmp_path / "config" / "dataset" / "imu.txt").resolve()
    assert read_configuration(path, base=tmp_path).imu_path == (tmp_path / "dataset" / "imu.txt").resolve()


def _edit(old: str, new: str) -> str:
    text = example_configuration()
    assert old in text
    return text.replace(old, new)


@pytest.mark.parametrize("text, message", [
    (_edit("initpos:", "initpso:"), "initpso: unknown key; did you mean 'initpos'?"),
    (_edit("  arw:", "  arww:"), "imunoise.arww: unknown key; did you mean 'arw'?"),
    (_edit("antlever: [0.5, 0.0, -1.0]", "antlevel: [0.5, 0.0, -1.0]"), "antlevel: unknown key; did you mean "
                                                                        "'antlever'?"),
    (_edit("imudatarate: 200 ", "#"), "imudatarate: missing from kf-gins.yaml"),
    (_edit("  corrtime: 1.0", "#"), "imunoise.corrtime: missing from kf-gins.yaml"),
    (_edit("[30.5, 114.5, 20.0]", "[30.5, 114.5]"), "initpos: must be a list of 3 numbers in deg, deg, m"),
    (_edit("initvel: [0.0, 0.0, 0.0]", "initvel: fast"), "initvel: must be a list of 3 numbers in m/s, got 'fast'"),
    (_edit("initattstd: [0.05, 0.05, 0.5]", "initattstd: [0.05, yes, 0.5]"), "initattstd: must be a finite number"),
    (_edit("initposstd: [0.1, 0.1, 0.2]", "initposstd: [0.1, -0.1, 0.2]"), "initposstd: standard deviations "
                                                                            "must be >= 0"),
    (_edit("antlever: [0.5, 0.0, -1.0]", "antlever: [500, 0, -1000]"), "antlever: [500, 0, -1000] is longer than "
                                                                       "30 m"),
    (_edit("imudatarate: 200", "imudatarate: 200.5"), "imudatarate: must be a whole number >= 1"),
    (_edit("endtime: -1 ", "endtime: 10 ").replace("starttime: 0 ", "starttime: 20 "), "starttime: starttime 20 s "
                                                                                       "and endtime 10 s"),
    (_edit("  corrtime: 1.0", "  corrtime: 0"), "imunoise.corrtime: must be > 0 h"),
    (_edit("imudatalen: 7", "imudatalen: 7\nimudatalen: 8"), "imudatalen: given twice in kf-gins.yaml (line 6)"),
    (_edit("initvel: [0.0, 0.0, 0.0]", "initvel: [0.0, 0.0, 0.0"), "kf_gins_config: kf-gins.yaml line"),
    (_edit("imupath: \"imu.txt\"", "imupath: 7"), "imupath: must be a path (text), got 7"),
])
def test_bad_configurations_are_refused_naming_the_key(tmp_path, text, message):
    with pytest.raises(InvalidParameter) as error:
        read_configuration(_config(tmp_path, text))
    assert str(error.value).startswith(message), str(error.value)
    assert "\n" not in str(error.value)


def test_a_negative_endtime_and_kf_gins_own_optional_keys(tmp_path):
    text = _edit("endtime: -1 ", "endtime: -5 ").replace("initbgstd: [1.0, 1.0, 1.0]", "#initbgstd: [2, 2, 2]")
    config = read_configuration(_config(tmp_path, text))
    assert config.end_time_s is None
    np.testing.assert_array_equal(config.initial_gyro_bias_sigma_rad_s, config.gyro_bias_sigma_rad_s)


# --- GNSS records, outages -----------------------------------------------------------------------------------------

def test_gnss_records_refuse_bad_epochs():
    t = np.array([1.0, 2.0, 2.0])
    sigma = np.full((3, 3), 0.5)
    with pytest.raises(InvalidParameter, match="epoch 3: time 2.000000 s repeats the one before"):
        GnssRecord(t, np.zeros(3), np.zeros(3), np.zeros(3), sigma)
    sigma[1, 2] = np.nan
    with pytest.raises(InvalidParameter, match="epoch 2: position 1-sigma down is nan"):
        GnssRecord(np.arange(3.0), np.zeros(3), np.zeros(3), np.zeros(3), sigma)


def test_outages_scheduled_removed_and_detected_back(tmp_path):
    outages = schedule_outages(30.0, 20.0, every=60.0, end=SHORT)
    assert outages == ((30.0, 20.0), (90.0, 20.0), (150.0, 20.0))
    record = simulate_gnss(DRIVE, SHORT, imu_rate=50.0, outages=outages)
    assert record.epochs == 200 - 60
    assert not np.any((record.t_s >= 30.0) & (record.t_s < 50.0))
    assert record.outages() == outages
    # read back from a file in seconds of week
    shifted = dataclasses.replace(record, t_s=record.t_s + WEEK_START)
    detected = read_gnss(write_gnss(tmp_path / "gnss.txt", shifted)).outages()
    np.testing.assert_allclose(np.array(detected) - [WEEK_START, 0.0], outages, rtol=0, atol=1e-9)
    # a gap of exactly twice the interval is not an outage; longer is
    assert detect_outages([0.0, 1.0, 3.0, 4.0]) == ()
    assert detect_outages([0.0, 1.0, 3.5, 4.5]) == ((2.0, 1.5),)
    with pytest.raises(InvalidParameter, match="outage_every: 20 s must exceed the outage duration 20 s"):
        schedule_outages(30.0, 20.0, every=20.0, end=SHORT)
    with pytest.raises(InvalidParameter, match="outages: the outage at 40 s starts before the one at 30 s ends"):
        record.without([(30.0, 20.0), (40.0, 5.0)])


# --- Truth between IMU samples, lever arm, latency -----------------------------------------------------------------

def test_interpolation_between_samples_against_the_truth_at_skipped_samples(imu200):
    # nodes every other 200-Hz sample (100 Hz), interpolated at the samples skipped: measured 1.2e-9 m
    t = np.concatenate([[0.0], imu200.t_s])
    position = np.column_stack([imu200.latitude_rad, imu200.longitude_rad, imu200.height_m])
    position = np.vstack([[DRIVE.latitude, DRIVE.longitude, DRIVE.height], position])
    velocity = np.vstack([np.zeros(3), imu200.velocity_ned_m_s])
    even, odd = slice(0, None, 2), slice(1, None, 2)
    interpolated = interpolate_positions(t[even], position[even], velocity[even], t[odd])
    error = _ned_metres(interpolated[:, 0], interpolated[:, 1], interpolated[:, 2], position[odd].T)
    assert np.abs(error).max() <= 1e-8


def test_truth_at_imu_samples_is_the_truth(imu200):
    k = np.array([0, 1, 7_999, 8_000, 28_001, 39_999])
    truth = truth_at(DRIVE, SHORT, imu200.t_s[k], imu_rate=200.0, chunk_size=5_000)  # across block boundaries
    np.testing.assert_allclose(truth.latitude_rad, imu200.latitude_rad[k], rtol=0, atol=1e-15)
    np.testing.assert_allclose(truth.longitude_rad, imu200.longitude_rad[k], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(truth.velocity_ned_m_s, imu200.velocity_ned_m_s[k])


def test_body_rate_is_the_ideal_gyro_less_the_earth_and_transport_rates(imu200):
    # through the first turn, at the middle of each IMU interval (where the interval's mean rate is best):
    # measured 1.5e-7 rad/s off on rates up to 0.375 rad/s (the mean over 5 ms differs from the middle value by
    # dt^2 omega'' / 24, and omega_in^b is taken at the interval's end)
    j = np.arange(27_400, 29_200, 50)
    C = dcm_from_quaternion(imu200.quaternion[j])
    rates = earth_rate_ned(imu200.latitude_rad[j]) + transport_rate_ned(
        imu200.latitude_rad[j], imu200.height_m[j], imu200.velocity_ned_m_s[j, 0], imu200.velocity_ned_m_s[j, 1])
    expected = imu200.angular_rate_rad_s[j] - np.einsum("nji,nj->ni", C, rates)
    truth = truth_at(DRIVE, SHORT, imu200.t_s[j] - 0.5 * imu200.interval_s, imu_rate=200.0)
    assert np.abs(expected[:, 2]).max() > 0.3
    np.testing.assert_allclose(truth.body_rate_rad_s, expected, rtol=0, atol=1e-6)


def test_lever_arm_position_and_velocity_signs():
    # heading east, antenna 1 m forward and 0.5 m up: it is 1 m east of the IMU and 0.5 m higher
    path = Stationary(latitude=math.radians(30.0), heading=math.pi / 2)
    truth = gnss_truth(path, 5.0, imu_rate=10.0, lever_arm=(1.0, 0.0, -0.5))
    offset = _ned_metres(truth.position[:, 0], truth.position[:, 1], truth.position[:, 2],
                         (path.latitude, path.longitude, path.height))
    np.testing.assert_allclose(offset, np.tile([0.0, 1.0, -0.5], (5, 1)), rtol=0, atol=1e-9)
    np.testing.assert_allclose(truth.velocity_ned_m_s, 0.0, rtol=0, atol=1e-15)
    with pytest.raises(InvalidParameter, match=r"lever_arm: \[500.0, 0.0, -300.0\] is longer than 30 m"):
        gnss_truth(path, 5.0, imu_rate=10.0, lever_arm=(500.0, 0.0, -300.0))  # in mm


def test_antenna_velocity_is_the_derivative_of_its_position():
    # on the first turn a 2-m arm to the left moves at V - psi' l_y forward. The truth's position is the trapezoid
    # integral of its velocity (as the navigator's): its slope between samples differs from v by O(dt^2 jerk),
    # measured 2.2e-6 m/s at 200 Hz
    arm = np.array([0.3, -2.0, -1.5])
    t = np.array([140.0, 141.0, 142.0])
    h = 1e-3
    truths = [truth_at(DRIVE, SHORT, t + d, imu_rate=200.0) for d in (-h, 0.0, h)]
    positions = [truth.at_lever_arm(arm)[0] for truth in truths]
    velocity = truths[1].at_lever_arm(arm)[1]
    derivative = (_ned_metres(*positions[2].T, positions[1].T) - _ned_metres(*positions[0].T, positions[1].T)) / (2 * h)
    np.testing.assert_allclose(derivative, velocity, rtol=0, atol=1e-5)
    C = dcm_from_quaternion(truths[1].quaternion)
    forward = np.einsum("nji,nj->ni", C, velocity)[:, 0]
    np.testing.assert_allclose(forward, 8.0 - truths[1].body_rate_rad_s[:, 2] * arm[1], rtol=0, atol=1e-6)
    assert np.all(truths[1].body_rate_rad_s[:, 2] > 0.05)  # a right turn


def test_epochs_off_the_imu_samples(imu200):
    # 1-Hz epochs 2.5 ms after the 200-Hz samples, between two of them: the cubic Hermite interpolant's middle is
    # the chord's middle plus (v_before - v_after) dt / 8 (up to 9.4e-6 m here); measured 1.2e-9 m from it
    record = simulate_gnss(DRIVE, SHORT, imu_rate=200.0, time_offset=0.0025)
    assert record.t_s[0] == 0.0025 and record.t_s[-1] == pytest.approx(199.0025, abs=1e-12)
    k = np.round((record.t_s - 0.0025) * 200.0).astype(int) - 1  # the sample before each epoch
    k = k[k >= 0]
    before = np.column_stack([imu200.latitude_rad[k], imu200.longitude_rad[k], imu200.height_m[k]])
    after = np.column_stack([imu200.latitude_rad[k + 1], imu200.longitude_rad[k + 1], imu200.height_m[k + 1]])
    got = np.column_stack([record.latitude_rad, record.longitude_rad, record.height_m])[-k.size:]
    error = _ned_metres(got[:, 0], got[:, 1], got[:, 2], (0.5 * (before + after)).T)
    expected = (imu200.velocity_ned_m_s[k] - imu200.velocity_ned_m_s[k + 1]) * imu200.interval_s / 8.0
    assert np.abs(expected).max() > 5e-6
    np.testing.assert_allclose(error, expected, rtol=0, atol=1e-8)
    with pytest.raises(InvalidParameter, match=r"time_offset: must lie in \[0, 1\) s, got 1.5"):
        simulate_gnss(DRIVE, SHORT, imu_rate=200.0, time_offset=1.5)


def test_latency_stamps_the_position_late(imu200):
    # stamped t, true at t - 0.3 s: which is an IMU sample, so the noise-free record equals the truth there
    record = simulate_gnss(DRIVE, SHORT, imu_rate=200.0, latency=0.3)
    k = np.round((record.t_s - 0.3) * 200.0).astype(int) - 1
    assert record.t_s[0] == 1.0 and record.t_s[-1] == SHORT
    np.testing.assert_allclose(record.latitude_rad, imu200.latitude_rad[k], rtol=0, atol=1e-15)
    np.testing.assert_allclose(record.longitude_rad, imu200.longitude_rad[k], rtol=0, atol=1e-15)
    late = simulate_gnss(DRIVE, SHORT, imu_rate=200.0, latency=1.5)
    assert late.t_s[0] == 2.0


# --- Noise: seeded statistics, addressed draws ---------------------------------------------------------------------

AT_REST = Stationary(latitude=math.radians(30.5), longitude=math.radians(114.5), height=20.0)
EPOCHS = 4_000


@pytest.fixture(scope="module")
def rest_truth():
    return gnss_truth(AT_REST, float(EPOCHS), imu_rate=1.0, gnss_rate=1.0)


def test_gnss_noise_has_the_stated_sigma(rest_truth):
    sigma = np.array([0.5, 0.8, 1.5])
    record = gnss_measurements(rest_truth, position_sigma=sigma, velocity_sigma=0.05, streams=RandomStreams(11))
    error = _ned_metres(record.latitude_rad, record.longitude_rad, record.height_m,
                        (AT_REST.latitude, AT_REST.longitude, AT_REST.height))
    # 4,000 normal draws: the sample std within 4 standard errors (sqrt(1/(2n)) = 1.1 %), the mean within
    # 4 sigma / sqrt(n)
    np.testing.assert_allclose(error.std(axis=0) / sigma, 1.0, rtol=0, atol=4 * math.sqrt(1 / (2 * EPOCHS)))
    assert np.all(np.abs(error.mean(axis=0)) <= 4 * sigma / math.sqrt(EPOCHS))
    np.testing.assert_allclose(record.velocity_ned_m_s.std(axis=0) / 0.05, 1.0, atol=4 * math.sqrt(1 / (2 * EPOCHS)))
    np.testing.assert_array_equal(record.position_sigma_m, np.tile(sigma, (EPOCHS, 1)))
    assert abs(np.corrcoef(error[:, 0], error[:, 1])[0, 1]) <= 4 / math.sqrt(EPOCHS)


def test_a_member_s_draws_depend_on_nothing_else(rest_truth):
    streams = RandomStreams(5)
    member = gnss_measurements(rest_truth, streams=streams, member=7)
    other = gnss_measurements(rest_truth, streams=streams, member=8)
    assert not np.array_equal(member.latitude_rad, other.latitude_rad)
    cut = gnss_measurements(rest_truth, streams=streams, member=7, outages=[(100.0, 900.0)])
    keep = np.isin(member.t_s, cut.t_s)
    np.testing.assert_array_equal(cut.latitude_rad, member.latitude_rad[keep])
    again = gnss_measurements(rest_truth, streams=RandomStreams(5), member=7)
    np.testing.assert_array_equal(again.height_m, member.height_m)
    with pytest.raises(InvalidParameter, match="member: must be a whole number >= 0, got -1"):
        gnss_measurements(rest_truth, streams=streams, member=-1)


def test_odometer_speed_of_the_wheel_point():
    ideal = simulate_odometer(DRIVE, SHORT, imu_rate=50.0, sigma=0.0)
    speed = np.linalg.norm(DRIVE.kinematics(ideal.t_s)[0], axis=1)
    np.testing.assert_allclose(ideal.speed_m_s, speed, rtol=0, atol=1e-12)
    # the right rear wheel (0.8 m right, 1.2 m back) through the right turn: slower by psi' 0.8
    wheel = simulate_odometer(DRIVE, SHORT, imu_rate=50.0, lever_arm=(-1.2, 0.8, 1.0), sigma=0.0,
                              scale_factor_error=0.01)
    rate = truth_at(DRIVE, SHORT, wheel.t_s, imu_rate=50.0).body_rate_rad_s[:, 2]
    np.testing.assert_allclose(wheel.speed_m_s, 1.01 * (speed - 0.8 * rate), rtol=0, atol=1e-9)
    assert rate.max() > 0.3
    noisy = simulate_odometer(AT_REST, float(EPOCHS), imu_rate=10.0, streams=RandomStreams(2))
    assert noisy.sigma_m_s == 0.05 and noisy.t_s.size == 10 * EPOCHS
    np.testing.assert_allclose(noisy.speed_m_s.std() / 0.05, 1.0, atol=4 * math.sqrt(1 / (20 * EPOCHS)))


def test_barometer_height_is_bias_plus_noise():
    record = simulate_barometer(AT_REST, float(EPOCHS), imu_rate=1.0, bias=3.0, streams=RandomStreams(4))
    assert record.sigma_m == 0.5 and record.t_s.size == EPOCHS
    error = record.height_m - 20.0
    assert abs(error.mean() - 3.0) <= 4 * 0.5 / math.sqrt(EPOCHS)
    np.testing.assert_allclose(error.std() / 0.5, 1.0, atol=4 * math.sqrt(1 / (2 * EPOCHS)))
    ideal = simulate_barometer(DRIVE, SHORT, imu_rate=50.0, bias=0.0, sigma=0.0)
    np.testing.assert_allclose(ideal.height_m, 20.0, rtol=0, atol=1e-6)
