"""``navigate run --record FILE``: a recorded IMU file replayed as a static vehicle against a stationary truth."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

from schuler.exceptions import InvalidParameter
from schuler.imu.error_model import ErrorModel
from schuler.imu.files import read_record, write_record
from schuler.imu.record import ImuRecord
from schuler.imu.simulate import simulate_record, static_truth
from schuler.imu.spec import preset
from schuler.navigate.api import SYSTEM
from schuler.navigate.errors import ConstantSensorErrors
from schuler.navigate.mechanization import navigate
from schuler.navigate.recording import increments, replay
from schuler.navigate.trajectory import Stationary
from schuler.navigate.truth import ideal_imu

PSINS = os.environ.get("SCHULER_PSINS_IMU", "")
LATITUDE, HEADING = math.radians(45.0), math.radians(30.0)
CHANNELS = ("position_error_north_m", "position_error_east_m", "velocity_error_north_m_s", "velocity_error_east_m_s",
            "roll_error_rad", "pitch_error_rad", "heading_error_rad")
SITE = ("--latitude", "45", "--heading", "30", "--output-step", "10")
"""A CSV record carries no site or attitude: the options give them (the simulated IMU is level)."""


def _record(model, path: Path, seed: int = 11) -> Path:
    """90 s at 50 Hz of a level IMU at rest at 45 deg, heading 30 deg, written to the project's CSV."""
    record = simulate_record(model, duration=90.0, sample_interval=0.02, seed=seed, latitude=LATITUDE,
                             heading=HEADING)
    return write_record(record, path / "static.csv")


def test_replay_equals_the_library_on_the_same_samples(run_cli, tmp_path):
    path = _record(preset("tactical"), tmp_path)
    out = run_cli("navigate", "run", "--record", path, *SITE, "--json")
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
    assert data["inputs"]["record"] == str(path) and data["inputs"]["imu"] is None
    assert data["imu"] == "recording static.csv (static)"


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
                         sensor_errors=ConstantSensorErrors(gyro_bias=gyro_bias, accel_bias=accel_bias))
    for channel in CHANNELS:
        a, b = np.asarray(getattr(replayed, channel)), np.asarray(getattr(synthetic, channel))
        # the record's Earth rate and gravity (closed form) against the truth's inverse mechanization differ at
        # the floor of the ideal record (2e-10 m/s in 90 s): measured <= 3.4e-9 of each channel's largest error
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-8 * np.abs(b).max(), err_msg=channel)


def test_an_ideal_record_navigates_at_the_numerical_floor(run_cli, tmp_path):
    path = _record(ErrorModel(), tmp_path)
    data = run_cli("navigate", "run", "--record", path, *SITE, "--json").json()
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
    (("--imu", "tactical"), "--record", "leave imu out"),
])
def test_refusals_are_one_line(run_cli, tmp_path, options, name, words):
    path = _record(ErrorModel(), tmp_path)
    out = run_cli("navigate", "run", "--record", path, *SITE, *options)
    assert out.code == 2, out.stdout
    assert out.stderr.startswith(f"schuler: error: {name}:") and words in out.stderr, out.stderr
    assert len(out.stderr.strip().splitlines()) == 1


def test_a_csv_record_needs_its_site(run_cli, tmp_path):
    path = _record(ErrorModel(), tmp_path)
    out = run_cli("navigate", "run", "--record", path, "--heading", "30")
    assert out.code == 2 and out.stderr.startswith("schuler: error: --record:") and "--latitude" in out.stderr
    out = run_cli("navigate", "run", "--record", path, "--latitude", "45")
    assert out.code == 2 and out.stderr.startswith("schuler: error: --record:") and "--heading" in out.stderr
    shorter = run_cli("navigate", "run", "--record", path, *SITE, "--duration", "30", "--json").json()
    assert shorter["t_s"][-1] == 30.0


def test_a_recording_given_as_imu_is_refused_naming_record(run_cli, tmp_path):
    path = _record(ErrorModel(), tmp_path)
    out = run_cli("navigate", "run", "--imu", path, *SITE)
    assert out.code == 2 and len(out.stderr.strip().splitlines()) == 1
    assert out.stderr.startswith("schuler: error: --imu: static.csv is a recording: replay it with record "
                                 "(--record FILE)"), out.stderr
    # by its suffix too, before looking for the file
    with pytest.raises(InvalidParameter, match="imu: lasergyro.imu is a recording: replay it with record"):
        SYSTEM.run(imu="lasergyro.imu", duration=60.0)


@pytest.mark.skipif(not (PSINS and Path(PSINS).is_file()),
                    reason="set SCHULER_PSINS_IMU to the PSINS lasergyro.imu file to run")
def test_the_psins_recording_drifts_as_its_mean_sensor_errors(run_cli):
    """300 s of the PSINS ring-laser record against the stationary truth of its header (site, level, heading).

    The check: the replay's errors are those of constant biases equal to the record's mean gyro and
    accelerometer errors over the 300 s against that truth (mean rate - the truth's ideal rate), navigated
    on the synthetic truth. The mean gyro errors are 1.86, -1.16, 0.14 deg/h (x, y, z) and the
    accelerometer's 0.150, -0.049, 0.001 m/s^2: the header's level attitude against a record tilted about
    0.9 deg in pitch and 0.35 deg in roll (PSINS marks the header "maybe inaccurate"). The vehicle was
    disturbed, so the errors vary around their means: measured, the horizontal position error at 300 s
    (6.94 km) is within 2.9 % of the constant-bias model's (7.14 km), the east one (body x, heading 90.6 deg)
    within 1.4 %, the heading error within 3.7 %; the bounds below leave about 2x margin.
    """
    out = run_cli("navigate", "run", "--record", PSINS, "--duration", "300", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["t_s"][-1] == 300.0 and data["inputs"]["imu_rate"] is None
    case = SYSTEM.case(record=PSINS, duration=300.0)
    recording = replay(PSINS, case)
    ideal = ideal_imu(recording.trajectory, 300.0, recording.imu_rate)
    dt = 1.0 / recording.imu_rate
    gyro_bias = recording.increments[:, :3].mean(axis=0) / dt - ideal.angular_rate_rad_s.mean(axis=0)
    accel_bias = recording.increments[:, 3:].mean(axis=0) / dt - ideal.specific_force_m_s2.mean(axis=0)
    np.testing.assert_allclose(np.degrees(gyro_bias) * 3600, [1.86, -1.16, 0.14], atol=0.01)
    model = navigate(recording.trajectory, 300.0, imu_rate=recording.imu_rate, output_step=10.0,
                     sensor_errors=ConstantSensorErrors(gyro_bias=gyro_bias, accel_bias=accel_bias))
    horizontal = math.hypot(model.position_error_north_m[-1], model.position_error_east_m[-1])
    assert data["final_horizontal_position_error_m"] == pytest.approx(horizontal, rel=0.06)
    assert data["final_position_error_east_m"] == pytest.approx(model.position_error_east_m[-1], rel=0.03)
    assert data["final_heading_error_rad"] == pytest.approx(model.heading_error_rad[-1], rel=0.08)
