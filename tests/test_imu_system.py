"""The IMU layer on the contract: evaluate, run, the nominal record, reproduction, static attitude, memory."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from schuler.contract import monte_carlo
from schuler.core.earth import EARTH_RATE
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter, SchulerError
from schuler.imu import actions, evaluation
from schuler.imu.api import SYSTEM
from schuler.imu.reproduction import PSINS_ENVIRONMENT, reproduce
from schuler.imu.static import static_attitude

PSINS = os.environ.get(PSINS_ENVIRONMENT, "")
HAS_PSINS = bool(PSINS) and Path(PSINS).is_file()
SHORT = {"duration": 300.0}


@pytest.fixture
def budget(monkeypatch):
    """A memory budget of 64 MiB for the test (``SCHULER_MEMORY_BUDGET``)."""
    from schuler import memory

    monkeypatch.setenv(memory.ENVIRONMENT, "64 MiB")
    monkeypatch.setenv(memory.TIME_ENVIRONMENT, "none")  # long records would be refused for time first
    memory._budget_from_environment.cache_clear()
    yield
    memory._budget_from_environment.cache_clear()


def test_the_nominal_record_is_monte_carlo_member_zero_of_seed_zero():
    result = SYSTEM.run(**SHORT)
    summary = monte_carlo(SYSTEM.evaluate, SYSTEM.outputs, SYSTEM.case(**SHORT), 2, RandomStreams(0))
    for name, value in result.outputs.items():
        first = summary.samples[name][0]
        assert (math.isnan(value) and math.isnan(first)) or first == value, name
    # another member is another record: its identified N differs, within the tolerance of both
    assert summary.samples["noise_gyro_x_N"][1] != result.outputs["noise_gyro_x_N"]
    assert np.all(summary.samples["fraction_within_tolerance"] == 1.0)


def test_outputs_are_the_identified_terms_and_nan_where_not_resolved():
    result = SYSTEM.run(imu="tactical", **SHORT)
    truth = math.radians(0.125) / 60  # HG1700 ARW 0.125 deg/sqrt(h) in rad/sqrt(s)
    for axis in "xyz":
        # 5 min at 100 Hz: N is known to ~0.5 % (3 sigma + method bias ~ 1.5 %)
        assert result.outputs[f"noise_gyro_{axis}_N"] == pytest.approx(truth, rel=0.015)
        # rate random walk and rate ramp need hours: not resolved, so NaN (null in JSON)
        assert math.isnan(result.outputs[f"noise_gyro_{axis}_K"]) and math.isnan(result.outputs[f"noise_gyro_{axis}_R"])
    data = result.to_dict()
    assert data["noise_gyro_x_K"] is None and data["noise"]["gyro_x"]["resolved"]["K"] is False
    assert data["noise"]["gyro_x"]["N"] == pytest.approx(result.outputs["noise_gyro_x_N"], rel=1e-12)
    assert data["true_terms"]["gyro_x"]["N"] == pytest.approx(truth, rel=1e-12)
    assert result.outputs["fraction_within_tolerance"] == 1.0 and data["all_within"] is True


def test_output_step_is_the_same_as_the_rate_it_implies():
    by_rate = SYSTEM.evaluate_values({"imu_rate": 100.0, **SHORT})
    by_step = SYSTEM.evaluate_values({"output_step": 0.01, **SHORT})
    for name in by_rate:
        np.testing.assert_array_equal(by_rate[name], by_step[name], err_msg=name)
    with pytest.raises(InvalidParameter, match="imu_rate: cannot be combined with output_step"):
        SYSTEM.run(imu_rate=100.0, output_step=0.01)


def test_a_spec_file_is_simulated_and_identified(tmp_path):
    spec = tmp_path / "part.toml"
    spec.write_text('name = "test part"\n[gyro]\nrandom_walk = "0.3 deg/sqrt(h)"\n'
                    '[accel]\nrandom_walk = "100 ug/sqrt(Hz)"\n', encoding="utf-8")
    result = SYSTEM.run(imu=str(spec), **SHORT)
    assert result.model == "test part"
    assert result.outputs["noise_gyro_y_N"] == pytest.approx(math.radians(0.3) / 60, rel=0.015)
    assert result.outputs["noise_accel_z_N"] == pytest.approx(100e-6 * 9.80665, rel=0.015)
    assert math.isnan(result.outputs["noise_gyro_y_B"])  # no bias instability in the spec
    for old in ("grade", "spec"):  # the one IMU parameter of every system, the old names refused
        with pytest.raises(InvalidParameter, match=f"{old}: renamed to 'imu'"):
            SYSTEM.run(**{old: str(spec)})
    with pytest.raises(SchulerError, match="missing.toml' is neither a grade"):
        SYSTEM.run(imu=str(tmp_path / "missing.toml"), **SHORT)
    # a recording stands for the model of its identified terms: simulated and identified again
    recording = tmp_path / "part.parquet"
    actions.simulate(recording, imu=str(spec), duration=1800.0, imu_rate=100.0, seed=3)
    again = SYSTEM.run(imu=str(recording), **SHORT)
    assert again.outputs["noise_gyro_y_N"] == pytest.approx(math.radians(0.3) / 60, rel=0.03)


def test_too_short_records_and_memory_are_refused_before_simulating(budget):
    with pytest.raises(InvalidParameter, match="duration: 1 s at 0.01 s per sample gives 100 samples"):
        SYSTEM.run(duration=1.0)
    # 30 days at 1 kHz: 2.6e9 samples, ~660 GB: refused at once, nothing allocated
    with pytest.raises(SchulerError, match=r"this record would hold .* more than the memory budget of 64 MiB; "
                                           r"change `duration` or `imu_rate`"):
        SYSTEM.run(duration=30 * 86400.0, imu_rate=1000.0)
    case = SYSTEM.case(duration=3600.0, imu_rate=100.0)
    assert SYSTEM.member_bytes(case) == 360_000 * evaluation.BYTES_PER_SAMPLE


@pytest.mark.slow
def test_round_trip_over_seeds_and_rates_through_the_system():
    # the system's Monte Carlo: 6 records per rate, industrial grade (N and B resolved in 20 min)
    for rate in (50.0, 200.0):
        summary = SYSTEM.monte_carlo(SYSTEM.case(imu="industrial", duration=1200.0, imu_rate=rate), 6,
                                     RandomStreams(3))
        stats = summary.statistics["fraction_within_tolerance"]
        # each record checks 11 or 12 resolved terms against 3 sigma + method bias: of 66-72 checks about 0.2 fall
        # outside by chance, 3 or more with probability 0.1 %; a mean fraction >= 1 - 2/66 allows at most 2
        assert stats["mean"] >= 1 - 2 / 66, (rate, stats)
        n = summary.statistics["noise_gyro_x_N"]
        truth = math.radians(0.007)  # 0.007 deg/s/sqrt(Hz) in rad/sqrt(s)
        # the mean of 6 records is within 1 % of the data-sheet figure; their spread is a few tenths of a percent
        assert n["mean"] == pytest.approx(truth, rel=0.01) and n["std"] / truth < 0.01


@settings(max_examples=40, deadline=None)
@given(latitude=st.floats(-80, 80), roll=st.floats(-60, 60), pitch=st.floats(-60, 60), heading=st.floats(0, 359.9))
def test_static_attitude_inverts_the_earth_rate_and_gravity(latitude, roll, pitch, heading):
    lat = math.radians(latitude)
    c_bn = Rotation.from_euler("ZYX", [heading, pitch, roll], degrees=True).as_matrix()
    omega_n = EARTH_RATE * np.array([math.cos(lat), 0.0, -math.sin(lat)])
    f_n = np.array([0.0, 0.0, -9.8])
    attitude = static_attitude(c_bn.T @ omega_n, c_bn.T @ f_n)
    assert math.degrees(attitude.latitude_rad) == pytest.approx(latitude, abs=1e-9)
    assert math.degrees(attitude.roll_rad) == pytest.approx(roll, abs=1e-7)
    assert math.degrees(attitude.pitch_rad) == pytest.approx(pitch, abs=1e-7)
    difference = (math.degrees(attitude.heading_rad) - heading + 180.0) % 360.0 - 180.0
    assert difference == pytest.approx(0.0, abs=1e-7)


def test_static_attitude_refuses_what_has_no_north():
    with pytest.raises(InvalidParameter, match="parallel to gravity"):
        static_attitude([0.0, 0.0, -EARTH_RATE], [0.0, 0.0, -9.8])
    with pytest.raises(InvalidParameter, match="zero mean"):
        static_attitude([0.0, 0.0, 0.0], [0.0, 0.0, -9.8])


def test_reproduction_without_the_recording(monkeypatch):
    monkeypatch.setenv(PSINS_ENVIRONMENT, "")
    reproduction = reproduce()
    assert not reproduction.failures and len(reproduction.rows) == 9
    assert all(row.verdict.startswith("agrees within") for row in reproduction.rows)
    assert any("PSINS recording lasergyro.imu is absent" in note for note in reproduction.notes)
    tactical = next(row for row in reproduction.rows if row.quantity.startswith("tactical: gyro N"))
    assert tactical.printed == "0.125 deg/√h" and tactical.computed == pytest.approx(0.125, rel=0.01)
    with pytest.raises(InvalidParameter, match="recording: 'nowhere.imu' is not a file"):
        reproduce(recording="nowhere.imu")


@pytest.mark.skipif(not HAS_PSINS, reason=f"set {PSINS_ENVIRONMENT} to the PSINS lasergyro.imu file to run")
def test_reproduction_of_the_psins_recording():
    reproduction = reproduce(recording=PSINS)
    rows = {row.quantity.split(":")[1].strip()[:20]: row
            for row in reproduction.rows if row.quantity.startswith("PSINS")}
    assert not reproduction.failures and len(rows) == 3
    latitude = rows["latitude from the me"]
    # header line 2: 34.246048 deg; the double-vector latitude of the whole record: 34.62 deg
    assert latitude.printed == "34.246048" and latitude.computed == pytest.approx(34.62, abs=0.01)
    heading = rows["heading from the mea"]
    assert heading.printed == "yaw0 = -90.6" and heading.computed == pytest.approx(88.59, abs=0.01)
    gravity = rows["magnitude of the mea"]
    assert gravity.printed == "9.780327" and gravity.computed == pytest.approx(9.7955, abs=1e-3)
    assert reproduction.details["psins_grade"] == "navigation"
    assert reproduction.details["psins_earth_rate_ratio"] == pytest.approx(0.9875, abs=1e-3)
