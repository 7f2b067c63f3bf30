"""``schuler imu``'s JSON keys and files as recorded before the one evaluation, and the layer's Python functions.

The key orders and file columns below were recorded from ``schuler imu run``, ``allan`` and ``reproduce`` on main
before ``imu`` moved to ``evaluate(cases, histories=True)``: the move keeps them.
"""

from __future__ import annotations

import csv
import math
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
PSINS = Path(os.environ.get("SCHULER_PSINS_IMU", ""))  # set by `make test` where the recording is


def _columns(path: Path) -> list[str]:
    with open(path, encoding="utf-8") as handle:
        return next(csv.reader(handle))


@pytest.fixture(scope="module")
def industrial_csv(tmp_path_factory):
    """5 min of an industrial-grade IMU at 100 Hz (``schuler imu simulate``)."""
    from schuler.cli import main

    path = tmp_path_factory.mktemp("imu") / "industrial.csv"
    with pytest.raises(SystemExit) as done:
        main(["imu", "simulate", "--imu", "industrial", "--duration", "300", "-o", str(path)])
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


def _close(python, cli, path=""):
    """Python's JSON equals the command's to 1e-12 (numbers), exactly otherwise."""
    if isinstance(cli, dict):
        assert set(python) >= set(cli), path
        for key, value in cli.items():
            _close(python[key], value, f"{path}.{key}")
    elif isinstance(cli, list):
        assert len(python) == len(cli), path
        for index, (a, b) in enumerate(zip(python, cli)):
            _close(a, b, f"{path}[{index}]")
    elif isinstance(cli, float) and not isinstance(python, bool):
        assert python == pytest.approx(cli, rel=1e-12, abs=0.0), path
    else:
        assert python == cli, path


@pytest.fixture(scope="module")
def degree_csv(tmp_path_factory, industrial_csv):
    """The industrial record with its own column names, gyros in deg/s and accelerometers in g."""
    import numpy as np
    import pandas as pd

    frame = pd.read_csv(industrial_csv)
    out = pd.DataFrame({"t": frame["t_s"]})
    for axis in "xyz":
        out[f"w{axis}"] = np.degrees(frame[f"gyro_{axis}_rad_s"])
    for axis in "xyz":
        out[f"a{axis}"] = frame[f"accel_{axis}_m_s2"] / 9.80665
    path = tmp_path_factory.mktemp("imu") / "degrees.csv"
    out.to_csv(path, index=False, float_format="%.17g")
    return path


COLUMNS = "time=t,gyro_x=wx,gyro_y=wy,gyro_z=wz,accel_x=ax,accel_y=ay,accel_z=az"


def test_allan_deviation_and_identify_from_python_equal_the_command(industrial_csv, run_cli):
    import schuler.imu

    cli = run_cli("imu", "allan", industrial_csv, "--json").json()
    result = schuler.imu.allan_deviation(industrial_csv)
    data = result.to_dict()
    _close(data, {key: cli[key] for key in data if key != "units"})
    # the identified terms are the command's, per channel and term (SI)
    terms = schuler.imu.identify(str(industrial_csv))
    identified = terms.to_dict()["terms"]
    for channel in CHANNELS:
        _close(identified[channel], {key: value for key, value in cli["noise"][channel].items()
                                     if key in (*TERMS, "sigma", "upper_bound", "resolved", "chi2_per_point")})
    # the record in memory gives the same analysis (one chunk instead of a stream)
    from_record = schuler.imu.allan_deviation(schuler.imu.read_record(industrial_csv))
    assert from_record.noise["gyro_x"].curve.adev == pytest.approx(cli["noise"]["gyro_x"]["adev"], rel=1e-9)
    # industrial grade (Xsens MTi 1): N = 0.007 deg/s/sqrt(Hz) in rad/sqrt(s), 5 min identify it within 3 %
    assert terms.terms["gyro_x"]["N"] == pytest.approx(math.radians(0.007), rel=0.03)
    assert result.grade == cli["grade"] == "industrial"


def test_the_results_plot_and_tabulate_by_tau(industrial_csv):
    import matplotlib.pyplot as plt

    import schuler.imu

    result = schuler.imu.allan_deviation(industrial_csv, channels=["gyro_x", "accel_z"])
    frame = result.to_dataframe()
    assert frame.index.name == "tau_s" and list(frame.columns) == [
        "gyro_x_adev_rad_s", "gyro_x_adev_lower_rad_s", "gyro_x_adev_upper_rad_s", "gyro_x_edf",
        "accel_z_adev_m_s2", "accel_z_adev_lower_m_s2", "accel_z_adev_upper_m_s2", "accel_z_edf"]
    assert frame.attrs["units"]["tau_s"] == "s" and frame.attrs["units"]["accel_z_adev_m_s2"] == "m/s^2"
    full = schuler.imu.allan_deviation(industrial_csv)
    # one channel's curve does not depend on the others analysed beside it
    assert frame["gyro_x_adev_rad_s"].to_numpy() == pytest.approx(full.noise["gyro_x"].curve.adev, rel=1e-12)
    assert result.grade == "industrial" and set(result.figures()) == {"imu_allan_gyro", "imu_allan_accel"}
    plt.close("all")
    assert result.plot() is not None and "gyro_x" in result._repr_html_()
    plt.close("all")
    terms = schuler.imu.identify(industrial_csv, channels="accel_y")
    table = terms.to_dataframe()
    assert table.loc[("accel_y", "N"), "unit"] == "m/s^1.5" and len(table) == 5
    assert terms.grade is None and terms.plot() is not None  # no gyro analysed: no grade
    plt.close("all")


def test_python_options_are_values_not_command_text(degree_csv, industrial_csv, run_cli):
    import pint

    import schuler.imu

    cli = run_cli("imu", "allan", degree_csv, "--columns", COLUMNS, "--units", "gyro=deg/s,accel=g", "--json").json()
    columns = dict(pair.split("=") for pair in COLUMNS.split(","))
    units = pint.UnitRegistry()
    by_text = schuler.imu.allan_deviation(degree_csv, columns=columns, units={"gyro": "deg/s", "accel": "g"})
    by_pint = schuler.imu.identify(degree_csv, columns=columns, units={"gyro": units.deg / units.s, "accel": "g"})
    for channel in CHANNELS:
        _close(by_text.to_dict()["noise"][channel], cli["noise"][channel], channel)
        _close(by_pint.terms[channel]["N"], cli["noise"][channel]["N"], channel)
    # the same record in SI: the same terms within the rounding of the degree file (17 digits)
    si = schuler.imu.identify(industrial_csv)
    assert by_pint.terms["gyro_y"]["N"] == pytest.approx(si.terms["gyro_y"]["N"], rel=1e-9)


def test_python_functions_refuse_what_does_not_apply(industrial_csv):
    import schuler.imu
    from schuler.exceptions import InvalidParameter

    with pytest.raises(InvalidParameter, match="channels: 'gyrox' is not a channel; did you mean 'gyro_x'"):
        schuler.imu.allan_deviation(industrial_csv, channels=["gyrox"])
    with pytest.raises(InvalidParameter, match="per_octave"):
        schuler.imu.allan_deviation(industrial_csv, per_octave=0)
    record = schuler.imu.read_record(industrial_csv)
    with pytest.raises(InvalidParameter, match="units: applies to a file, not to a record in memory"):
        schuler.imu.identify(record, units={"gyro": "deg/s"})
    with pytest.raises(InvalidParameter, match="units: unknown channel 'gyr'; channels are time, gyro, accel"):
        schuler.imu.read_record(industrial_csv, units={"gyr": "deg/s"})


@pytest.mark.skipif(not PSINS.is_file(),
                    reason="set SCHULER_PSINS_IMU to the PSINS lasergyro.imu file to run")
def test_the_psins_recording_through_allan_deviation():
    import schuler.imu

    result = schuler.imu.allan_deviation(PSINS)
    # 184,718 samples of 10 ms (the file's README); the gyro floor places it in the navigation grade
    assert result.samples == 184_718 and result.sample_interval_s == 0.01 and result.grade == "navigation"
    frame = result.to_dataframe()
    # the long-tau gyro Allan deviation falls below 2 deg/h within the record (as tests/test_imu_psins.py)
    assert (frame.filter(like="gyro").filter(like="adev_rad_s").iloc[-1] < math.radians(2.0) / 3600).all()
    assert result.figures().keys() == {"imu_allan_gyro", "imu_allan_accel"}
