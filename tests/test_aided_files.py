"""``schuler aided run`` on files: KF-GINS's formats and configuration, the round trip from a simulated drive,
``navigation.nav`` and ``navigation.csv``, and bad input refused in one line with exit code 2."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from schuler.aided.files import lever_arm_of, load_configuration
from schuler.aided.gnss import GnssRecord
from schuler.aided.kfgins import read_gnss, read_imu, read_navigation, write_gnss, write_imu
from schuler.aided.kfgins_configuration import example_configuration
from schuler.aided.outputs import write_simulated_files
from schuler.exceptions import InvalidParameter
from schuler.imu.files import write_record
from schuler.imu.record import ImuRecord
from schuler.registry import get_system

AIDED = get_system("aided")
WEEK_START = 456_300.0  # s of week of the drive's start: file times are seconds of week
LEVER = {"lever_arm_x": 0.5, "lever_arm_z": -1.0}
NOISY = {"duration": 300.0, "imu_rate": 100.0, "outage_start": 120.0, **LEVER}
IDEAL = {"duration": 300.0, "imu_rate": 200.0, "outage_duration": 0.0, "nominal": True, **LEVER}


@pytest.fixture(scope="module")
def noisy(tmp_path_factory):
    """Member 0 of seed 0 written to KF-GINS's files, and the simulated run of the same member."""
    folder = tmp_path_factory.mktemp("noisy")
    return write_simulated_files(AIDED.case(**NOISY), folder, seed=0, week_start=WEEK_START), AIDED.run(**NOISY)


@pytest.fixture(scope="module")
def ideal(tmp_path_factory):
    """Ideal sensors and noiseless GNSS at 200 Hz, no outage, written to KF-GINS's files."""
    return write_simulated_files(AIDED.case(**IDEAL), tmp_path_factory.mktemp("ideal"), week_start=WEEK_START)


def _on_files(paths, **options):
    return AIDED.run(record=str(paths["imu"]), gnss_file=str(paths["gnss"]), reference=str(paths["reference"]),
                     **options)


# --- round trips --------------------------------------------------------------------------------------------------

def test_a_drive_written_to_files_and_run_on_them_gives_the_simulated_run(noisy):
    paths, simulated = noisy
    result = _on_files(paths, **LEVER)  # the same filter model: the tactical IMU, its start 1-sigma, GNSS velocity
    # the files hold positions to 1e-12 deg (1e-7 m) and times to 1e-9 s: the outputs agree to 1e-6 relative
    for name, value in simulated.outputs.items():
        assert result.outputs[name] == pytest.approx(value, rel=1e-6, abs=1e-9), name
    (outage,), (back,) = simulated.outages, result.outages
    assert back["start_s"] == pytest.approx(WEEK_START + outage["start_s"], abs=1e-6)  # times as in the data
    assert back["duration_s"] == pytest.approx(outage["duration_s"], abs=1e-6)
    assert back["horizontal_error_max_m"] == pytest.approx(outage["horizontal_error_max_m"], rel=1e-6)
    assert result.navigation.time[0] == pytest.approx(WEEK_START + 0.01, abs=1e-9)


def test_zero_velocity_zero_rate_and_the_constraint_run_on_files_as_on_the_simulated_drive(noisy):
    paths, _ = noisy
    aiding = {"aiding": "gnss-position,gnss-velocity,zupt,zaru,nhc", **LEVER}
    simulated = AIDED.run(**{**NOISY, **aiding}, stop_intervals=[[0.0, 25.0]])
    result = _on_files(paths, **aiding, stop_intervals=[[WEEK_START, 25.0]])  # times as in the data
    assert simulated.rejected_by_source["zupt"] == result.rejected_by_source["zupt"] == 0
    # measured: 1.5e-6 relative with zupt alone, 7e-5 with the constraint's 3,000 tight updates on the files'
    # rounded times (1e-9 s) and positions (1e-12 deg), against 1e-6 with GNSS alone
    for name, value in simulated.outputs.items():
        assert result.outputs[name] == pytest.approx(value, rel=2e-4, abs=1e-9), name
    plain = _on_files(paths, **LEVER)
    assert result.outputs["outage_horizontal_error_max_m"] != plain.outputs["outage_horizontal_error_max_m"]


@pytest.mark.parametrize(("options", "words"), [({"aiding": "gnss-position,odometer"}, "odometer: on a simulated"),
                                                ({"aiding": "gnss-position,zupt"}, "`stop_intervals`")])
def test_aiding_that_needs_data_or_a_drive_is_refused_on_files(noisy, options, words):
    with pytest.raises(InvalidParameter, match=words):
        _on_files(noisy[0], **options)


def test_ideal_data_written_to_files_return_the_truth(ideal):
    result = _on_files(ideal, **LEVER)
    assert result.position_error_horizontal_max_m < 1e-3  # spec 07: 1 mm
    assert result.position_error_vertical_rms_m < 1e-3
    assert result.heading_error_rms_rad < math.radians(1e-4)  # and 1e-4 deg
    assert result.rejected_measurements == 0


@pytest.mark.slow
def test_a_kf_gins_configuration_runs_its_model_on_ideal_data_and_returns_the_truth(ideal):
    result = AIDED.run(kf_gins_config=str(ideal["configuration"]), reference=str(ideal["reference"]))
    assert result.position_error_horizontal_max_m < 1e-3
    assert result.heading_error_rms_rad < math.radians(1e-4)
    # KF-GINS's model aids with positions only: three residuals per epoch
    assert result.nis["band"] == pytest.approx([0.0717, 12.838], abs=1e-3)


def test_configuration_paths_resolve_against_its_folder_then_the_working_directory(ideal, tmp_path, monkeypatch):
    beside = load_configuration(ideal["configuration"])
    assert beside.imu_path == ideal["imu"].resolve()
    # a configuration written for KF-GINS, run from the data's folder: paths relative to the working directory
    elsewhere = tmp_path / "configs" / "kf-gins.yaml"
    elsewhere.parent.mkdir()
    elsewhere.write_text(ideal["configuration"].read_text())
    monkeypatch.chdir(ideal["imu"].parent)
    config = load_configuration(elsewhere)
    assert config.imu_path == ideal["imu"].resolve() and config.gnss_path == ideal["gnss"].resolve()


def test_lever_arm_options_win_over_antlever_axis_by_axis(ideal):
    config = load_configuration(ideal["configuration"])
    case = AIDED.case(kf_gins_config=str(ideal["configuration"]), lever_arm_y=0.25)
    assert lever_arm_of(case, config) == (0.5, 0.25, -1.0)


def test_without_a_reference_the_error_keys_are_null_and_the_sigmas_remain(noisy, run_cli):
    paths, simulated = noisy
    out = run_cli("aided", "run", "--record", paths["imu"], "--gnss-file", paths["gnss"], "--kf-gins-config",
                  paths["configuration"], "--imu", "tactical", "--aiding", "gnss-position,gnss-velocity", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["position_error_horizontal_rms_m"] is None and data["heading_error_rms_rad"] is None
    assert data["nees"]["position"]["inside"] is None
    (outage,) = data["outages"]
    assert outage["horizontal_error_max_m"] is None
    # the configuration's start is the truth with its own 1-sigma: the outage's 1-sigma is of the simulated run's order
    assert 0.3 * simulated.outage_horizontal_error_sigma_m < outage["horizontal_error_sigma_m"] \
        < 3 * simulated.outage_horizontal_error_sigma_m
    assert data["outage_horizontal_error_sigma_m"] == pytest.approx(outage["horizontal_error_sigma_m"], rel=1e-12)


def test_out_writes_navigation_nav_that_kf_gins_reader_reads_back_and_navigation_csv(noisy, run_cli, tmp_path):
    import pandas as pd

    paths, _ = noisy
    out = run_cli("aided", "run", "--record", paths["imu"], "--gnss-file", paths["gnss"], "--reference",
                  paths["reference"], "--lever-arm-x", "0.5", "--lever-arm-z", "-1", "--out", tmp_path / "out")
    assert out.code == 0, out.stderr
    nav_path = tmp_path / "out" / "navigation.nav"
    first = nav_path.read_text().splitlines()[0].split()
    assert len(first) == 11 and all(len(first[k].split(".")[1]) >= 9 for k in (2, 3))  # no header; >= 9 decimals
    back = read_navigation(nav_path)
    result = _on_files(paths, **LEVER)
    nav = result.navigation
    assert back.t_s.size == nav.time.size == 30_000  # every IMU epoch
    np.testing.assert_allclose(back.t_s, nav.time, rtol=0, atol=1e-9)
    np.testing.assert_allclose(back.latitude_rad, nav["latitude_rad"], rtol=0, atol=math.radians(1e-12))
    np.testing.assert_allclose(back.longitude_rad, nav["longitude_rad"], rtol=0, atol=math.radians(1e-12))
    np.testing.assert_allclose(back.height_m, nav["height_m"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(back.velocity_ned_m_s[:, 1], nav["velocity_east_m_s"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(back.attitude_rad[:, 2], nav["yaw_rad"], rtol=0, atol=math.radians(1e-9))
    table = pd.read_csv(tmp_path / "out" / "navigation.csv")
    assert list(table.columns[:4]) == ["t_s", "latitude_deg", "longitude_deg", "height_m"]
    assert {"north_sigma_m", "velocity_down_sigma_m_s", "psi_down_sigma_deg"} <= set(table.columns)
    np.testing.assert_allclose(table["latitude_deg"], np.degrees(nav["latitude_rad"]), rtol=1e-15)
    np.testing.assert_allclose(table["north_sigma_m"], nav["north_sigma_m"], rtol=1e-15)


def test_a_simulated_run_writes_navigation_files_too(run_cli, tmp_path):
    out = run_cli("aided", "run", "--duration", "300", "--imu-rate", "20", "--outage-start", "120", "--out", tmp_path)
    assert out.code == 0, out.stderr
    back = read_navigation(tmp_path / "navigation.nav")
    assert back.t_s.size == 6000 and back.t_s[0] == pytest.approx(0.05) and back.t_s[-1] == pytest.approx(300.0)


# --- bad input: one line on stderr, exit code 2 -------------------------------------------------------------------

def _refused(out, *words):
    assert out.code == 2, out.stdout + out.stderr
    assert out.stderr.count("\n") == 1, out.stderr
    assert "nan" not in out.stdout.lower()
    for word in words:
        assert word in out.stderr, out.stderr


def _gnss_with(paths, tmp_path, change) -> str:
    record = read_gnss(paths["gnss"])
    return str(write_gnss(tmp_path / "gnss.txt", change(record)))


def _run(run_cli, paths, *options, gnss=None, record=None):
    return run_cli("aided", "run", "--record", record or paths["imu"], "--gnss-file", gnss or paths["gnss"],
                   "--reference", paths["reference"], *options)


def test_gnss_times_out_of_order_are_refused(noisy, run_cli, tmp_path):
    paths, _ = noisy

    def swap(record: GnssRecord):
        t = record.t_s.copy()
        t[[10, 11]] = t[[11, 10]]
        return dataclasses.replace(record, t_s=np.sort(t))  # written sorted, then the two lines swapped below

    path = tmp_path / "gnss.txt"
    write_gnss(path, swap(read_gnss(paths["gnss"])))
    lines = path.read_text().splitlines()
    lines[10], lines[11] = lines[11], lines[10]
    path.write_text("\n".join(lines) + "\n")
    _refused(_run(run_cli, paths, gnss=path), "--gnss-file", "line 12", "earlier than the one before")


def test_repeated_gnss_times_are_refused(noisy, run_cli, tmp_path):
    paths, _ = noisy
    path = tmp_path / "gnss.txt"
    lines = paths["gnss"].read_text().splitlines()
    path.write_text("\n".join(lines[:5] + [lines[4]] + lines[5:]) + "\n")
    _refused(_run(run_cli, paths, gnss=path), "--gnss-file", "line 6", "repeats the one before")


@pytest.mark.parametrize("sigma", [math.nan, 0.0], ids=["nan", "zero"])
def test_nan_or_zero_gnss_sigmas_are_refused(noisy, run_cli, tmp_path, sigma):
    paths, _ = noisy
    path = tmp_path / "gnss.txt"
    lines = paths["gnss"].read_text().splitlines()
    fields = lines[7].split()
    fields[10] = str(sigma)  # 13 columns: the position 1-sigma north
    lines[7] = " ".join(fields)
    path.write_text("\n".join(lines) + "\n")
    _refused(_run(run_cli, paths, gnss=path), "--gnss-file", "line 8")


def test_a_gnss_span_outside_the_imu_span_is_refused(noisy, run_cli, tmp_path):
    paths, _ = noisy
    gnss = _gnss_with(paths, tmp_path, lambda r: dataclasses.replace(r, t_s=r.t_s + 3600.0))
    _refused(_run(run_cli, paths, gnss=gnss), "--gnss-file", "does not overlap")


def test_increments_where_rates_are_expected_are_refused(noisy, run_cli, tmp_path):
    paths, _ = noisy
    imu = read_imu(paths["imu"])
    # the project's CSV holds rates: a record of increments written as if they were rates is 100 times too small
    wrong = ImuRecord(time_s=imu.time_s, gyro=imu.gyro, accel=imu.accel, kind="rate",
                      sample_interval_s=imu.sample_interval_s)
    csv = write_record(wrong, tmp_path / "imu.csv")
    _refused(_run(run_cli, paths, record=csv), "--record", "specific force")


def test_rates_where_increments_are_expected_are_refused(noisy, run_cli, tmp_path):
    paths, _ = noisy
    imu = read_imu(paths["imu"])
    rates = dataclasses.replace(imu, gyro=imu.gyro_rate_rad_s, accel=imu.accel_m_s2)  # KF-GINS text holds increments
    txt = write_imu(tmp_path / "imu.txt", rates)
    _refused(_run(run_cli, paths, record=txt), "--record", "velocity increments")


def test_a_lever_arm_in_the_wrong_unit_is_refused(noisy, run_cli):
    paths, _ = noisy
    _refused(_run(run_cli, paths, "--lever-arm-x", "1.5 deg"), "--lever-arm-x")


def test_a_misspelt_configuration_key_is_refused_with_a_suggestion(noisy, run_cli, tmp_path):
    paths, _ = noisy
    bad = tmp_path / "kf-gins.yaml"
    bad.write_text(paths["configuration"].read_text().replace("antlever:", "antlevel:"))
    (tmp_path / "imu.txt").symlink_to(paths["imu"])
    (tmp_path / "gnss.txt").symlink_to(paths["gnss"])
    _refused(run_cli("aided", "run", "--kf-gins-config", bad), "antlevel", "did you mean 'antlever'?")


def test_files_without_an_initial_state_are_refused(noisy, run_cli):
    paths, _ = noisy
    _refused(run_cli("aided", "run", "--record", paths["imu"], "--gnss-file", paths["gnss"]), "--kf-gins-config",
             "initial state")


def test_a_monte_carlo_on_files_is_refused(noisy, run_cli):
    paths, _ = noisy
    _refused(_run(run_cli, paths, "--monte-carlo", "4"), "--monte-carlo", "no random terms")


def test_the_example_configuration_is_complete():
    assert "antlever" in example_configuration() and "corrtime" in example_configuration()


def test_a_gap_in_the_imu_stamps_is_refused(noisy, run_cli, tmp_path):
    paths, _ = noisy
    lines = paths["imu"].read_text().splitlines()
    path = tmp_path / "imu.txt"
    path.write_text("\n".join(lines[:1000] + lines[1010:]) + "\n")  # 10 samples lost: 0.1 s
    _refused(_run(run_cli, paths, record=path), "--record", "sample 1001", "off the uniform grid")
