"""``navigate run --imu RECORD``: a recorded IMU file replayed as a static vehicle against a stationary truth."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

from schuler.imu.error_model import ErrorModel
from schuler.imu.files import read_record, write_record
from schuler.imu.record import ImuRecord
from schuler.imu.simulate import simulate_record, static_truth
from schuler.imu.spec import preset
from schuler.navigate.errors import SensorErrors
from schuler.navigate.mechanization import navigate
from schuler.navigate.recording import increments
from schuler.navigate.trajectory import Stationary

PSINS = os.environ.get("SCHULER_PSINS_IMU", "")
LATITUDE, HEADING = math.radians(45.0), math.radians(30.0)
CHANNELS = ("position_error_north_m", "position_error_east_m", "velocity_error_north_m_s", "velocity_error_east_m_s",
            "roll_error_rad", "pitch_error_rad", "heading_error_rad")
SITE = ("--latitude", "45", "--heading", "30", "--output-step", "10")
"""A CSV record carries no site or attitude: the options give them (the simulated IMU is level)."""


def _record(model, path: Path, seed: int = 11) -> Path:
    """90 s at 50 Hz of a level IMU at rest at 45 deg, heading 30 deg, written to the project's CSV."""
    record = simulate_record(model, duration_s=90.0, sample_interval_s=0.02, seed=seed, latitude_rad=LATITUDE,
                             heading_rad=HEADING)
    return write_record(record, path / "static.csv")


def test_replay_equals_the_library_on_the_same_samples(run_cli, tmp_path):
    path = _record(preset("tactical"), tmp_path)
    out = run_cli("navigate", "run", "--imu", path, *SITE, "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["t_s"][-1] == 90.0 and len(data["t_s"]) == 10
    direct = navigate(Stationary(latitude=LATITUDE, heading=HEADING), 90.0, imu_rate=50.0, output_step=10.0,
                      recorded_increments=increments(read_record(path)))
    for channel in CHANNELS:
        expected = np.asarray(getattr(direct, channel))
        # the same samples through the same loops: equal but for the JSON's decimal round trip
        np.testing.assert_allclose(data[channel], expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max(),
                                   err_msg=channel)
    # tactical grade (1 deg/h, 1 mg at +1 sigma and its noise) moves the INS by metres in 90 s, not nanometres
    assert 1.0 < data["max_horizontal_position_error_m"] < 1e3
    assert data["inputs"]["imu"] == str(path)


def test_a_constant_bias_record_replays_as_the_synthetic_bias(tmp_path):
    """A record whose only error is a gyro and an accelerometer bias navigates as the synthetic truth with them."""
    gyro_bias, accel_bias = np.array([1e-6, -2e-6, 3e-6]), np.array([2e-4, -1e-4, 0.0])
    gyro_true, accel_true = static_truth(LATITUDE, HEADING)
    n = 4500
    record = ImuRecord(time_s=0.02 * np.arange(1, n + 1), gyro=np.tile(gyro_true + gyro_bias, (n, 1)),
                       accel=np.tile(accel_true + accel_bias, (n, 1)), kind="rate", sample_interval_s=0.02)
    record = read_record(write_record(record, tmp_path / "biased.csv"))
    replayed = navigate(Stationary(latitude=LATITUDE, heading=HEADING), 90.0, imu_rate=50.0, output_step=10.0,
                        recorded_increments=increments(record))
    synthetic = navigate(Stationary(latitude=LATITUDE, heading=HEADING), 90.0, imu_rate=50.0, output_step=10.0,
                         sensor_errors=SensorErrors(gyro_bias=gyro_bias, accel_bias=accel_bias))
    for channel in CHANNELS:
        a, b = np.asarray(getattr(replayed, channel)), np.asarray(getattr(synthetic, channel))
        # the record's Earth rate and gravity (closed form) against the truth's inverse mechanization: 1e-6 of
        # the bias-driven errors (0.5 b_a t^2 = 0.8 m north at 90 s)
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-6 * np.abs(b).max(), err_msg=channel)


def test_an_ideal_record_navigates_at_the_numerical_floor(run_cli, tmp_path):
    path = _record(ErrorModel(), tmp_path)
    data = run_cli("navigate", "run", "--imu", path, *SITE, "--json").json()
    # floor: double rounding of Omega dt ~ 1e-6 rad and g dt ~ 0.2 m/s per sample over 4500 samples
    assert data["max_horizontal_position_error_m"] < 1e-6
    assert data["max_abs_velocity_error_north_m_s"] < 1e-8 and data["max_abs_velocity_error_east_m_s"] < 1e-8
    assert max(data["max_abs_roll_error_rad"], data["max_abs_pitch_error_rad"], data["max_abs_heading_error_rad"]) \
        < 1e-12


@pytest.mark.parametrize(("options", "name", "words"), [
    (("--monte-carlo", "10"), "--monte-carlo", "one member"),
    (("--duration", "120"), "--duration", "longer than the recording"),
    (("--imu-rate", "100"), "--imu-rate", "differs from the recording's 50 Hz"),
    (("--trajectory", "great-circle"), "--trajectory", "static vehicle"),
    (("--mode", "platform"), "--mode", "strapdown"),
])
def test_refusals_are_one_line(run_cli, tmp_path, options, name, words):
    path = _record(ErrorModel(), tmp_path)
    out = run_cli("navigate", "run", "--imu", path, *SITE, *options)
    assert out.code == 2, out.stdout
    assert out.stderr.startswith(f"schuler: error: {name}:") and words in out.stderr, out.stderr
    assert len(out.stderr.strip().splitlines()) == 1


def test_a_csv_record_needs_its_site(run_cli, tmp_path):
    path = _record(ErrorModel(), tmp_path)
    out = run_cli("navigate", "run", "--imu", path, "--heading", "30")
    assert out.code == 2 and out.stderr.startswith("schuler: error: --imu:") and "--latitude" in out.stderr
    out = run_cli("navigate", "run", "--imu", path, "--latitude", "45")
    assert out.code == 2 and out.stderr.startswith("schuler: error: --imu:") and "--heading" in out.stderr
    shorter = run_cli("navigate", "run", "--imu", path, *SITE, "--duration", "30", "--json").json()
    assert shorter["t_s"][-1] == 30.0
