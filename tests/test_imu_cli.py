"""``schuler imu ...`` and ``--imu`` end to end, in-process: JSON keys of issue 14, files, errors, memory."""

from __future__ import annotations

import math
import os
from pathlib import Path

import pytest

from schuler.core.earth import EARTH_RATE, normal_gravity
from schuler.imu.results import CHANNELS
from schuler.imu.spec import preset
from schuler.imu.system_inputs import align_inputs, north_inputs

PSINS = os.environ.get("SCHULER_PSINS_IMU", "")
HAS_PSINS = bool(PSINS) and Path(PSINS).is_file()
TERMS = ("N", "B", "K", "Q", "R")


@pytest.fixture(scope="module")
def navigation_csv(tmp_path_factory):
    """10 min of a navigation-grade IMU at 45 deg N heading east, written by ``schuler imu simulate``."""
    from schuler.cli import main

    path = tmp_path_factory.mktemp("imu") / "navigation.csv"
    with pytest.raises(SystemExit) as done:
        main(["imu", "simulate", "--imu", "navigation", "--duration", "600", "--imu-rate", "100", "--latitude", "45",
              "--azimuth", "90", "-o", str(path)])
    assert done.value.code == 0
    return path


def test_simulate_then_info_shows_the_earth_rate_and_gravity(navigation_csv, run_cli):
    out = run_cli("imu", "info", navigation_csv, "--latitude", "45", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["samples"] == 60_000 and data["sample_interval_s"] == 0.01 and data["duration_s"] == 600.0
    gyro, accel = data["mean_gyro_rad_s"], data["mean_accel_m_s2"]
    assert len(gyro) == len(accel) == 3
    # heading east (x forward = east, y right = south, z down): omega_b = Omega [0, -cos L, -sin L], f_b = [0, 0, -g].
    # Navigation grade: 0.0035 deg/h bias, 0.002 deg/sqrt(h) over 10 min: means within 0.05 deg/h (2.4e-7 rad/s)
    lat = math.radians(45.0)
    expected = [0.0, -EARTH_RATE * math.cos(lat), -EARTH_RATE * math.sin(lat)]
    assert gyro == pytest.approx(expected, abs=2.4e-7)
    # HG9900 accelerometers: 100 ppm scale factor on g and 25 ug bias (1 sigma ~1.0e-3 m/s^2): 3 sigma
    assert accel == pytest.approx([0.0, 0.0, -float(normal_gravity(lat))], abs=3e-3)
    assert data["latitude_rad"] == pytest.approx(lat) and data["units"]["samples"] == "1"
    text = run_cli("imu", "info", navigation_csv)
    assert text.code == 0 and "mean gyro (x, y, z)" in text.stdout


def test_allan_of_a_file_has_the_issues_json_keys_and_writes_figures(navigation_csv, run_cli, tmp_path):
    out = run_cli("imu", "allan", navigation_csv, "--json", "--out", tmp_path / "allan")
    assert out.code == 0, out.stderr
    data = out.json()
    for channel in CHANNELS:
        noise = data["noise"][channel]
        assert set(TERMS) <= set(noise)
        assert len(noise["tau_s"]) == len(noise["adev"]) > 10
    # 0.002 deg/sqrt(h) (HG9900) in rad/sqrt(s), identified from 10 min within 3 %
    assert data["noise"]["gyro_x"]["N"] == pytest.approx(math.radians(0.002) / 60, rel=0.03)
    assert data["units"]["N"].startswith("rad/s^0.5") and data["units"]["adev"].startswith("rad/s")
    names = {Path(f).name for f in data["files"]}
    assert {"imu_allan_gyro.png", "imu_allan_gyro.svg", "imu_allan_accel.png", "imu_allan.csv"} <= names


def test_run_json_has_flat_outputs_and_the_nested_noise(run_cli):
    out = run_cli("imu", "run", "--imu", "industrial", "--duration", "10 min", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["inputs"]["imu"] == "industrial" and data["inputs"]["duration"] == 600.0
    for channel in CHANNELS:
        for term in TERMS:
            assert f"noise_{channel}_{term}" in data and term in data["noise"][channel]
        assert len(data["noise"][channel]["tau_s"]) == len(data["noise"][channel]["adev"])
    assert data["noise_gyro_x_N"] == pytest.approx(data["noise"]["gyro_x"]["N"], rel=1e-12)
    assert data["units"]["noise_gyro_x_N"] == "rad/s^0.5" and data["units"]["noise_accel_x_B"] == "m/s^2"
    assert data["fraction_within_tolerance"] == 1.0 and data["grade"] == "industrial"
    assert data["true_terms"]["gyro_x"]["N"] == pytest.approx(math.radians(0.007), rel=1e-12)


def test_run_monte_carlo_adds_the_statistics_of_independent_records(run_cli, tmp_path):
    out = run_cli("imu", "run", "--imu", "consumer", "--duration", "120", "--monte-carlo", "3", "--seed", "4",
                  "--json", "--out", tmp_path)  # --out: the Allan figures of the nominal record and the Monte Carlo
    assert out.code == 0, out.stderr
    data = out.json()
    stats = data["monte_carlo"]["statistics"]["noise_gyro_x_N"]
    assert data["monte_carlo"]["members"] == 3 and stats["count"] == 3 and stats["std"] > 0
    assert stats["mean"] == pytest.approx(math.radians(0.005), rel=0.03)  # MPU-6000: 0.005 deg/s/sqrt(Hz)
    assert (tmp_path / "imu_monte_carlo.png").is_file()


def test_simulate_writes_parquet_and_refuses_other_suffixes_and_memory(run_cli, tmp_path, monkeypatch):
    out = run_cli("imu", "simulate", "--imu", "industrial", "--duration", "60", "--imu-rate", "200", "-o",
                  tmp_path / "r.parquet", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["samples"] == 12_000 and data["files"] == [str(tmp_path / "r.parquet")]
    info = run_cli("imu", "info", tmp_path / "r.parquet", "--json").json()
    assert info["samples"] == 12_000 and info["sample_interval_s"] == pytest.approx(0.005)
    out = run_cli("imu", "simulate", "-o", tmp_path / "r.txt")
    assert out.code == 2 and "--output: r.txt: write .parquet (native, streamed) or .csv" in out.stderr
    from schuler import memory

    monkeypatch.setenv(memory.ENVIRONMENT, "16 MiB")
    memory._budget_from_environment.cache_clear()
    try:
        out = run_cli("imu", "simulate", "--duration", "1 h", "-o", tmp_path / "big.csv")
        assert out.code == 2 and "this CSV file would hold" in out.stderr and "--duration" in out.stderr
        out = run_cli("imu", "run", "--duration", "1 h")
        assert out.code == 2 and "this record would hold" in out.stderr
    finally:
        memory._budget_from_environment.cache_clear()
    assert not (tmp_path / "big.csv").exists() and not list(tmp_path.glob("*.part"))


def test_errors_name_the_option_file_line_and_column(run_cli, tmp_path):
    out = run_cli("imu", "info", tmp_path / "missing.csv")
    assert out.code == 2 and "missing.csv: no such file" in out.stderr
    bad = tmp_path / "bad.csv"
    bad.write_text("t_s,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2\n"
                   "0.01,0,0,0,0,0,-9.8\n0.02,0,0,nan,0,0,-9.8\n0.03,0,0,0,0,0,-9.8\n", encoding="utf-8")
    out = run_cli("imu", "info", bad)
    assert out.code == 2 and "bad.csv, line 3, column 4" in out.stderr, out.stderr
    out = run_cli("imu", "run", "--grade", "tactical")
    assert out.code == 2 and "--grade: renamed to '--imu'" in out.stderr
    out = run_cli("imu", "simulate", "--spec", "x.toml", "-o", "x.csv")
    assert out.code == 2 and "--spec: renamed to '--imu'" in out.stderr
    out = run_cli("imu", "run", "--imu", "tactcal")
    assert out.code == 2 and "--imu: 'tactcal' is neither a grade" in out.stderr
    out = run_cli("imu", "info", bad, "--units", "gyro=deg/s,speed=m/s")
    assert out.code == 2 and "--units: unknown channel 'speed'" in out.stderr
    out = run_cli("imu", "info", bad, "--columns", "gyro_x")
    assert out.code == 2 and "--columns: 'gyro_x' is not channel=value" in out.stderr
    parquet = tmp_path / "r.parquet"
    assert run_cli("imu", "simulate", "--duration", "10", "-o", parquet).code == 0
    out = run_cli("imu", "allan", parquet, "--latitude", "45")
    assert out.code == 2 and "--latitude: applies to CSV files only; r.parquet is .parquet" in out.stderr


def test_csv_mapping_options(run_cli, tmp_path):
    # a logger's layout: milliseconds, deg/s and g, axes x right, y forward, z up
    path = tmp_path / "logger.csv"
    rows = ["ms,wx,wy,wz,ax,ay,az"] + [f"{10 * k},0.1,0.2,0.3,0.01,0.02,1.0" for k in range(1, 401)]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    out = run_cli("imu", "info", path, "--json", "--columns", "time=ms,gyro_x=wx,gyro_y=wy,gyro_z=wz,accel_x=ax,"
                  "accel_y=ay,accel_z=az", "--units", "time=ms,gyro=deg/s,accel=g", "--axes", "RFU")
    assert out.code == 0, out.stderr
    data = out.json()
    # RFU -> FRD: (x, y, z)_frd = (y, x, -z)_file
    assert data["mean_gyro_rad_s"] == pytest.approx([math.radians(0.2), math.radians(0.1), -math.radians(0.3)])
    assert data["mean_accel_m_s2"] == pytest.approx([0.02 * 9.80665, 0.01 * 9.80665, -9.80665])
    assert data["sample_interval_s"] == pytest.approx(0.01) and data["samples"] == 400


def test_imu_on_align_changes_the_drifts_as_the_mapping_says(run_cli):
    plain = run_cli("align", "run", "--duration", "600", "--azimuth", "20", "--json").json()
    out = run_cli("align", "run", "--duration", "600", "--azimuth", "20", "--imu", "tactical", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    expected = align_inputs(preset("tactical"), heading=math.radians(20.0)).values
    for name in ("drift_east", "drift_north", "drift_z", "accel_bias_x", "accel_bias_y", "sigma_drift"):
        assert data["inputs"][name] == pytest.approx(expected[name], rel=1e-12), name
    assert data["inputs"]["imu"] == "tactical" and plain["inputs"]["drift_east"] == 0.0
    # a 0.28 deg/h residual east drift turns the azimuth by about drift / (U cos 50 deg): ~1.7 deg
    assert abs(data["azimuth_error_analytic_rad"]) > 100 * abs(plain["azimuth_error_analytic_rad"])
    east = run_cli("align", "run", "--duration", "600", "--imu", "tactical", "--drift-east", "0", "--json").json()
    assert east["inputs"]["drift_east"] == 0.0 and east["inputs"]["drift_north"] == pytest.approx(
        align_inputs(preset("tactical")).values["drift_north"])
    window = run_cli("align", "run", "--duration", "600", "--imu", "tactical", "--imu-window", "1 h", "--json").json()
    assert window["inputs"]["imu_window"] == 3600.0 and window["units"]["imu_window"] == "s"


def test_imu_on_calibrate_north_and_errors(run_cli, tmp_path):
    calibrate = run_cli("calibrate", "run", "--imu", "tactical", "--json")
    assert calibrate.code == 0, calibrate.stderr
    assert calibrate.json()["inputs"]["drift_x"] == pytest.approx(-math.radians(1.0) / 3600)
    north = run_cli("north", "run", "--imu", "navigation", "--duration", "600", "--json")
    assert north.code == 0, north.stderr
    step = north.json()["inputs"]["output_step"]
    assert north.json()["inputs"]["readout_noise"] == pytest.approx(
        north_inputs(preset("navigation"), step=step).values["readout_noise"])
    errors = run_cli("errors", "run", "--imu", "tactical", "--source", "accelerometer", "--json")
    assert errors.code == 0, errors.stderr
    # HG1700 accelerometer: 1 mg turn-on bias and its 50 ug flicker change: ~1 mg
    assert errors.json()["inputs"]["magnitude"] == pytest.approx(1e-3 * 9.80665, rel=0.01)
    spec = tmp_path / "part.toml"
    spec.write_text('[gyro]\nbias = "2 deg/h"\n', encoding="utf-8")
    assert run_cli("calibrate", "run", "--imu", spec, "--json").json()["inputs"]["drift_y"] == pytest.approx(
        -math.radians(2.0) / 3600)


def test_imu_option_errors(run_cli):
    out = run_cli("calibrate", "run", "--imu", "consumer")
    assert out.code == 2 and "--imu: consumer: drift_x from the IMU" in out.stderr
    out = run_cli("align", "run", "--imu-window", "1 h")
    assert out.code == 2 and "--imu-window: applies with --imu only" in out.stderr
    out = run_cli("north", "run", "--imu", "nothing.toml")
    assert out.code == 2 and "--imu: 'nothing.toml' is neither a grade" in out.stderr
    out = run_cli("vertical", "run", "--imu-window", "1 h")
    assert out.code == 2 and "--imu-window: applies with --imu only" in out.stderr


@pytest.mark.skipif(not HAS_PSINS, reason="set SCHULER_PSINS_IMU to the PSINS lasergyro.imu file to run")
def test_info_of_the_psins_recording(run_cli):
    out = run_cli("imu", "info", PSINS, "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    # README: 184,718 samples of 10 ms; at 34.246 deg N, heading ~90.6 deg: the north rate shows on -y
    assert data["samples"] == 184_718 and data["sample_interval_s"] == 0.01
    assert data["mean_gyro_rad_s"][1] == pytest.approx(-EARTH_RATE * math.cos(math.radians(34.246)), rel=0.02)
    assert data["mean_accel_m_s2"][2] == pytest.approx(-9.7803, abs=0.03)
