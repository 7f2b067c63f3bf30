"""``schuler imu``'s JSON keys and files as recorded before the one evaluation, and the layer's Python functions.

The key orders and file columns below were recorded from ``schuler imu run``, ``allan`` and ``reproduce`` on main
before ``imu`` moved to ``evaluate(cases, histories=True)``: the move keeps them.
"""

from __future__ import annotations

import csv
import os
from pathlib import Path

import pytest

from schuler.imu.results import CHANNELS

TERMS = ("N", "B", "K", "Q", "R")
RUN_EXTRA_KEYS = ["model", "model_source", "seed", "member", "samples", "duration_s", "sample_interval_s",
                  "latitude_rad", "azimuth_rad", "all_within", "grade", "grade_margin", "true_terms", "checks", "noise",
                  "monte_carlo", "units"]
OUTPUT_KEYS = [f"noise_{channel}_{term}" for channel in CHANNELS for term in TERMS] + ["fraction_within_tolerance"]
NOISE_UNIT_KEYS = ["N", "B", "K", "Q", "R", "noise.*.sigma.*", "noise.*.upper_bound.*", "noise.*.dominant_tau_s.*",
                   "adev", "adev_lower", "adev_upper", "edf", "chi2_per_point"]
GRADE_UNIT_KEYS = ["grade_margin", "navigation", "tactical", "industrial", "consumer", "samples"]
RUN_UNIT_KEYS = ["duration", "imu_rate", "output_step", "latitude", "azimuth", *OUTPUT_KEYS, *NOISE_UNIT_KEYS,
                 "true", "identified", "sigma", "method_bias", "tolerance", *GRADE_UNIT_KEYS, "seed", "member"]
CURVE_COLUMNS = ["tau_s"] + [f"{channel}_{column}" for channel in CHANNELS for column in (
    (f"adev_{u}", f"adev_lower_{u}", f"adev_upper_{u}", "edf") for u in ["rad_s" if "gyro" in channel else "m_s2"])
    for column in column]
ALLAN_FILES = {"imu_allan.csv", "imu_allan_gyro.png", "imu_allan_gyro.svg", "imu_allan_accel.png",
               "imu_allan_accel.svg"}
PSINS = Path(os.environ.get("SCHULER_PSINS_IMU") or "/work/shared/data/psins/lasergyro.imu")


def _columns(path: Path) -> list[str]:
    with open(path, encoding="utf-8") as handle:
        return next(csv.reader(handle))


@pytest.fixture(scope="module")
def industrial_csv(tmp_path_factory):
    """5 min of an industrial-grade IMU at 100 Hz (``schuler imu simulate``)."""
    from schuler.cli import main

    path = tmp_path_factory.mktemp("imu") / "industrial.csv"
    with pytest.raises(SystemExit) as done:
        main(["imu", "simulate", "--grade", "industrial", "--duration", "300", "-o", str(path)])
    assert done.value.code == 0
    return path


def test_run_json_keys_units_and_out_files_are_kept(run_cli, tmp_path):
    out = run_cli("imu", "run", "--duration", "120", "--json", "--out", tmp_path / "run")
    assert out.code == 0, out.stderr
    data = out.json()
    assert list(data) == ["schuler_version", "inputs", *OUTPUT_KEYS, *RUN_EXTRA_KEYS, "files"]
    assert list(data["units"]) == RUN_UNIT_KEYS
    assert data["seed"] == 0 and data["member"] == 0 and data["samples"] == 12_000
    assert list(data["noise"]["gyro_x"]) == [*("Q", "N", "B", "K", "R"), "sigma", "upper_bound", "resolved",
                                             "dominant_tau_s", "chi2_per_point", "tau_s", "adev", "adev_lower",
                                             "adev_upper", "edf"]
    assert list(data["checks"][0]) == ["channel", "term", "true", "identified", "sigma", "method_bias", "tolerance",
                                       "within"]
    assert {Path(f).name for f in data["files"]} == ALLAN_FILES
    assert _columns(tmp_path / "run" / "imu_allan.csv") == CURVE_COLUMNS


def test_run_monte_carlo_out_files_are_kept(run_cli, tmp_path):
    out = run_cli("imu", "run", "--duration", "120", "--monte-carlo", "2", "--json", "--out", tmp_path)
    assert out.code == 0, out.stderr
    names = {Path(f).name for f in out.json()["files"]}
    assert names == ALLAN_FILES | {"imu_monte_carlo.png", "imu_monte_carlo.svg"}


def test_allan_json_keys_and_out_files_are_kept(industrial_csv, run_cli, tmp_path):
    out = run_cli("imu", "allan", industrial_csv, "--json", "--out", tmp_path)
    assert out.code == 0, out.stderr
    data = out.json()
    assert list(data) == ["schuler_version", "inputs", "source", "samples", "sample_interval_s", "duration_s", "grade",
                          "grade_margin", "noise", "units", "files"]
    assert list(data["units"]) == ["latitude", "per_octave", *NOISE_UNIT_KEYS, *GRADE_UNIT_KEYS]
    assert {Path(f).name for f in data["files"]} == ALLAN_FILES
    assert _columns(tmp_path / "imu_allan.csv") == CURVE_COLUMNS


def test_reproduce_out_files_are_kept(run_cli, tmp_path, monkeypatch):
    monkeypatch.setenv("SCHULER_PSINS_IMU", "")
    out = run_cli("imu", "reproduce", "--json", "--out", tmp_path)
    assert out.code == 0, out.stderr
    assert {Path(f).name for f in out.json()["files"]} == {
        "imu_reproduction_tactical.csv", *(f"imu_reproduction_tactical_{s}.{e}" for s in ("gyro", "accel")
                                           for e in ("png", "svg"))}
    assert _columns(tmp_path / "imu_reproduction_tactical.csv") == CURVE_COLUMNS
