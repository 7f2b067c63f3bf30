"""The real recording: PSINS lasergyro.imu (ring-laser-gyro IMU at rest with disturbances, 100 Hz, 31 min).

The file is not part of the project (PSINS toolbox, BSD-2): the tests read it
from the path in SCHULER_PSINS_IMU and skip when that is unset or missing.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

from schuler.imu.characterise import reproduce_psins
from schuler.imu.files import open_record, read_record
from schuler.imu.plots import allan_figure, write_figures

PSINS = os.environ.get("SCHULER_PSINS_IMU", "")

pytestmark = pytest.mark.skipif(not PSINS or not Path(PSINS).is_file(),
                                reason="set SCHULER_PSINS_IMU to the PSINS lasergyro.imu file to run")

OMEGA = 7.292115e-5


@pytest.fixture(scope="module")
def reproduction():
    return reproduce_psins(PSINS)


def test_file_layout_as_its_readme_states():
    # README: 184,718 samples of 10 ms, g = 9.780327 in header line 2, site 34.246048 N, 108.909664 E, 380 m
    record = read_record(PSINS)
    assert record.samples == 184_718 and record.sample_interval_s == 0.01
    assert record.duration_s == pytest.approx(1847.18)
    assert record.gravity_m_s2 == 9.780327
    assert math.degrees(record.latitude_rad) == pytest.approx(34.246048)
    assert record.height_m == 380.0
    # one gyro count is 0.1 arcsec: every increment is a whole number of counts
    counts = record.gyro / (0.1 * math.pi / 180 / 3600)
    assert np.allclose(counts, np.round(counts), atol=1e-6)
    counts = record.accel / (125e-6 * 9.780327)
    assert np.allclose(counts, np.round(counts), atol=1e-6)


def test_mean_rates_show_earth_rate_and_gravity(reproduction):
    info = reproduction.info
    # at 34.246 deg N: Omega cos L = 6.028e-5 rad/s horizontal, -Omega sin L = -4.104e-5 rad/s down
    assert reproduction.horizontal_earth_rate_ratio == pytest.approx(1.0, abs=0.02)
    assert reproduction.vertical_earth_rate_ratio == pytest.approx(1.0, abs=0.02)
    # heading ~90.6 deg: x (forward) points east, y (right) south, so the north rate shows on -y
    gyro = np.array(info.mean_gyro_rad_s)
    assert gyro[1] == pytest.approx(-OMEGA * math.cos(math.radians(34.246)), rel=0.02)
    assert abs(gyro[0]) < 0.05 * OMEGA
    # specific force z ~ -g in x forward / y right / z down (the file's g is 9.780327)
    assert reproduction.specific_force_z_m_s2 == pytest.approx(-9.7803, abs=0.03)
    assert info.specific_force_m_s2 == pytest.approx(9.7803, abs=0.03)


def test_noise_floor_places_it_in_the_navigation_grade(reproduction):
    analysis = reproduction.analysis
    assert analysis.grade == "navigation"
    assert analysis.grade_margin["tactical"] > 1.0 >= analysis.grade_margin["navigation"]
    # the long-tau gyro Allan deviation falls below 2 deg/h within the record (vehicle disturbances above)
    for axis in "xyz":
        curve = analysis.noise[f"gyro_{axis}"].curve
        assert curve.adev[-1] < 2.0 * math.pi / 180 / 3600


def test_streamed_analysis_equals_the_in_memory_one(reproduction):
    from schuler.imu.characterise import analyse_source

    streamed = analyse_source(open_record(PSINS))
    for name, channel in reproduction.analysis.noise.items():
        assert streamed.noise[name].curve.adev == pytest.approx(channel.curve.adev, rel=1e-9)


def test_report_and_figures(reproduction, tmp_path):
    text = str(reproduction)
    assert "navigation" in text and "Omega cos L" in text
    paths = write_figures({"psins_gyro": allan_figure(reproduction.analysis, "gyro")}, tmp_path)
    assert {p.suffix for p in paths} == {".png", ".svg"} and all(p.stat().st_size > 1000 for p in paths)
    data = reproduction.to_dict()
    assert set(data["noise"]) == {"gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"}
