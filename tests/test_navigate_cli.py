"""``schuler navigate``: run, scenario, Monte Carlo, sweeps, reproduce, files and errors, end to end in-process."""

from __future__ import annotations

import math

import pandas as pd
import pytest

from schuler.navigate.channels import ERROR_CHANNELS
from schuler.study.scenario import parse_scenario
from schuler.study.sweep import run_sweep

ARRAYS = ("t_s", "position_error_north_m", "position_error_east_m", "velocity_error_north_m_s",
          "velocity_error_east_m_s", "roll_error_rad", "pitch_error_rad", "heading_error_rad")
"""The histories of issue 15, item 7, in ``--json``."""

QUICK = ("--duration", "600", "--imu-rate", "10", "--output-step", "60")


def test_run_json_has_the_issue_names(run_cli):
    out = run_cli("navigate", "run", *QUICK, "--velocity-error-north", "0.1", "--heading-error", "1 arcmin",
                  "--gyro-bias-z", "0.01", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    for name in ARRAYS:
        assert len(data[name]) == 11, name
    assert "height_error_m" not in data and "velocity_error_down_m_s" not in data  # the channel is held
    assert data["t_s"][-1] == 600.0
    assert data["final_position_error_north_m"] == data["position_error_north_m"][-1]
    assert data["max_abs_velocity_error_north_m_s"] == pytest.approx(0.1)
    assert data["units"]["position_error_north_m"] == "m" and data["units"]["roll_error_rad"] == "rad"
    assert data["units"]["gyro_bias_z"] == "rad/s" and data["units"]["imu_rate"] == "1/s"
    assert data["inputs"]["gyro_bias_z"] == pytest.approx(math.radians(0.01) / 3600)  # bare numbers: deg/h
    assert data["inputs"]["heading_error"] == pytest.approx(math.radians(1 / 60))
    assert data["inputs"]["mode"] == "strapdown" and data["inputs"]["imu"] is None
    free = run_cli("navigate", "run", *QUICK, "--vertical-channel", "free", "--accel-bias-z", "1e-5 g", "--json").json()
    assert len(free["height_error_m"]) == 11 and len(free["velocity_error_down_m_s"]) == 11
    # 1e-5 g down: the free channel diverges (g/R-unstable), faster than the 0.5 b t^2 of a flat Earth
    assert free["height_error_m"][-1] < -0.5 * 1e-5 * 9.80665 * 600**2


MAIN_KEYS = sorted([
    "schuler_version", "inputs", "trajectory", "mode", "vertical_channel", "imu", "duration_s", "imu_rate_hz",
    "output_step_s", "warnings", *(f"{kind}_{channel}" for channel in ERROR_CHANNELS for kind in ("final", "max_abs")),
    "final_horizontal_position_error_m", "max_horizontal_position_error_m", "t_s", "position_error_north_m",
    "position_error_east_m", "velocity_error_north_m_s", "velocity_error_east_m_s", "roll_error_rad",
    "pitch_error_rad", "heading_error_rad", "monte_carlo", "units", "files"])
"""The top-level keys of ``navigate run --json --out DIR`` on the light case, recorded before the system moved to
the one evaluation (a documented script contract: ``t_s`` and the histories at the top level)."""


def test_the_light_case_keeps_its_json_keys_files_and_columns(run_cli, tmp_path):
    from schuler import get_system
    from test_contract import light

    parameters = get_system("navigate").parameters
    args = [text for key, value in light("navigate").items()
            for text in (parameters[key].option, f"{value!r} {parameters[key].si_unit}")]
    out = run_cli("navigate", "run", *args, "--json", "--out", tmp_path)
    assert out.code == 0, out.stderr
    data = out.json()
    assert sorted(data) == MAIN_KEYS
    # the units of before, and now the outputs' too
    before = {"imu_rate_hz": "Hz", "t_s": "s", "position_error_north_m": "m", "velocity_error_east_m_s": "m/s",
              "heading_error_rad": "rad"}
    assert {name: data["units"][name] for name in before} == before
    assert data["units"]["final_position_error_north_m"] == "m"
    written = sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith("."))
    assert written == ["navigate_errors.csv", "navigate_errors.png", "navigate_errors.svg"]
    table = pd.read_csv(tmp_path / "navigate_errors.csv")
    assert list(table.columns) == list(ARRAYS)
    assert table["position_error_north_m"].tolist() == pytest.approx(data["position_error_north_m"], rel=1e-12)
    # 0.1 m/s north at rest at 45 deg: (dV / w_s) sin(w_s t), 54.6 m after 10 min (as on main: 54.572255355756)
    assert data["final_position_error_north_m"] == pytest.approx(54.572255355756, rel=1e-12)


def test_human_output_and_help(run_cli):
    out = run_cli("navigate", "run", *QUICK, "--mode", "platform", "--roll-error", "1")
    assert out.code == 0 and out.stderr == ""
    assert "platform INS" in out.stdout and "roll error (arcsec)" in out.stdout
    help_text = run_cli("navigate", "run", "--help").stdout
    for option in ("--trajectory", "--vertical-channel", "--position-error-north", "--gyro-bias-x", "--accel-bias-z",
                   "--imu", "--mode", "--monte-carlo", "--sigma-gyro-bias"):
        assert option in help_text, option


def test_the_scenario_gives_the_same_json_as_the_command(run_cli):
    scenario = run_cli("run", "examples/navigate_stationary.toml", "--json")
    assert scenario.code == 0, scenario.stderr
    command = run_cli("navigate", "run", "--trajectory", "stationary", "--latitude", "45", "--heading", "0",
                      "--mode", "strapdown", "--vertical-channel", "off", "--velocity-error-north", "0.1",
                      "--gyro-bias-x", "0.01", "--imu-rate", "100", "--duration", "1 h", "--output-step", "60",
                      "--json")
    assert command.code == 0, command.stderr
    a, b = scenario.json(), command.json()
    assert a == b
    # a 0.01 deg/h north gyro bias at rest: the east error grows as R eps (t - sin(w t) / w), 1.35 km in an hour
    assert a["final_position_error_east_m"] == pytest.approx(1330.0, rel=0.01)


def test_imu_grade_changes_the_errors(run_cli, tmp_path):
    ideal = run_cli("navigate", "run", *QUICK, "--json").json()
    tactical = run_cli("navigate", "run", *QUICK, "--imu", "tactical", "--json").json()
    assert ideal["final_horizontal_position_error_m"] == 0.0
    # +1 sigma of the tactical grade: 1 mg accelerometer biases alone move it by ~ (b / w^2)(1 - cos w t), km
    assert tactical["final_horizontal_position_error_m"] > 1000.0
    assert tactical["imu"] == "tactical grade (ring-laser gyro IMU)"
    spec = tmp_path / "imu.toml"
    spec.write_text('name = "mine"\n[gyro]\nbias = "0.01 deg/h"\n[accel]\nbias = "10 ug"\n')
    mine = run_cli("navigate", "run", *QUICK, "--imu", spec, "--json").json()
    assert 0.0 < mine["final_horizontal_position_error_m"] < tactical["final_horizontal_position_error_m"]
    assert mine["imu"] == "mine"


NOISY_SPEC = """name = "white noise and a Gauss-Markov bias"
[gyro]
bias = "0.01 deg/h"
random_walk = "0.005 deg/sqrt(h)"
gm_sigma = "0.003 deg/h"
gm_correlation_time = "600 s"
[accel]
bias = "20 ug"
random_walk = "20 ug/sqrt(Hz)"
"""
"""A model with noise and one slow process per axis: the IMU layer's simulator draws a block of
65,536 normals per slow process and member, so a full grade (11 flicker terms per axis) costs
seconds per member in a short run."""


def test_monte_carlo_with_the_imu_noise(run_cli, tmp_path):
    spec = tmp_path / "noisy.toml"
    spec.write_text(NOISY_SPEC)
    out = run_cli("navigate", "run", *QUICK, "--imu", spec, "--monte-carlo", "24", "--seed", "3",
                  "--out", tmp_path, "--json")
    assert out.code == 0, out.stderr
    mc = out.json()["monte_carlo"]
    assert mc["members"] == 24 and mc["seed"] == 3
    stats = mc["statistics"]["final_horizontal_position_error_m"]
    assert stats["std"] > 0 and stats["count"] == 24
    assert (tmp_path / "navigate_monte_carlo.png").stat().st_size > 500
    again = run_cli("navigate", "run", *QUICK, "--imu", spec, "--monte-carlo", "24", "--seed", "3", "--json")
    assert again.json()["monte_carlo"] == mc  # the members are addressed: the same seed, the same numbers


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (("--latitude", "90"), "--latitude"),
        (("--latitude", "-89.5"), "--latitude"),
        (("--latitude", "nan"), "--latitude"),
        (("--velocity-error-north", "nan"), "--velocity-error-north"),
        (("--gyro-bias-x", "inf"), "--gyro-bias-x"),
        (("--accel-bias-x", "1 deg"), "--accel-bias-x"),
        (("--trajectory", "missing.toml"), "--trajectory"),
        (("--trajectory", "spiral"), "--trajectory"),
        (("--mode", "gimbal"), "--mode"),
        (("--vertical-channel", "sonar"), "--vertical-channel"),
        (("--imu", "military"), "--imu"),
        (("--output-step", "0.001"), "--output-step"),
        (("--speed", "100"), "--speed"),
        (("--duration", "0"), "--duration"),
        (("--monte-carlo", "-1"), "--monte-carlo"),
    ],
)
def test_bad_input_one_line_exit_2(run_cli, args, option):
    out = run_cli("navigate", "run", *args)
    assert out.code == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("schuler: error:") and option in lines[0], out.stderr


def test_bad_files_one_line_exit_2(run_cli, tmp_path):
    broken = tmp_path / "broken.toml"
    broken.write_text("[start\nlatitude = 45\n")
    out = run_cli("navigate", "run", "--trajectory", broken)
    assert out.code == 2 and out.stderr.startswith("schuler: error: --trajectory:") and "not valid TOML" in out.stderr
    wrong = tmp_path / "wrong.toml"
    wrong.write_text('[start]\nlatitude = 45\n[[waypoint]]\ntime = 0\nspeed = 100\nheadng = 0\n')
    out = run_cli("navigate", "run", "--trajectory", wrong)
    assert out.code == 2 and "waypoint[1].headng: unknown key" in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1
    pole = tmp_path / "pole.toml"
    pole.write_text('[start]\nlatitude = 88\n[[waypoint]]\ntime = 0\nspeed = 300\nheading = 0\n'
                    '[[waypoint]]\ntime = "1 h"\nspeed = 300\nheading = 0\n')
    out = run_cli("navigate", "run", "--trajectory", pole, "--imu-rate", "10")
    assert out.code == 2 and "pole" in out.stderr and len(out.stderr.strip().splitlines()) == 1
    spec = tmp_path / "imu.toml"
    spec.write_text('[gyro]\nbais = "1 deg/h"\n')
    out = run_cli("navigate", "run", *QUICK, "--imu", spec)
    assert out.code == 2 and out.stderr.startswith("schuler: error: --imu:") and "did you mean 'bias'" in out.stderr


def test_memory_is_refused_in_one_line(run_cli, monkeypatch):
    from schuler import memory

    monkeypatch.setenv(memory.ENVIRONMENT, "256 MiB")
    memory._budget_from_environment.cache_clear()
    try:
        out = run_cli("navigate", "run", "--duration", "10 day", "--output-step", "0.01")
    finally:
        memory._budget_from_environment.cache_clear()
    assert out.code == 2
    assert out.stderr.startswith("schuler: error: this run would hold") and "--output-step" in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1


SCENARIO = """system = "navigate"
[parameters]
imu = "{spec}"
imu_rate = "{rate} Hz"
velocity_error_north = "0.1 m/s"
[simulation]
duration = "{duration} s"
output_step = "{step} s"
[monte_carlo]
seed = 8
[monte_carlo.normal]
gyro_bias_z = "0.1 deg/h"
heading_error = "1 arcmin"
"""


def _sweep(run_cli, tmp_path, name, *args, rate=20, duration=120, step=20):
    spec = tmp_path / "noisy.toml"
    spec.write_text(NOISY_SPEC)
    scenario = tmp_path / "navigate.toml"
    scenario.write_text(SCENARIO.format(spec=spec, rate=rate, duration=duration, step=step))
    out_dir = tmp_path / name
    out = run_cli("sweep", scenario, *args, "--out", out_dir, "--no-progress", "--json")
    assert out.code == 0, out.stderr
    return pd.read_parquet(out_dir / "results.parquet")


def test_a_monte_carlo_sweep_does_not_depend_on_the_chunks(tmp_path):
    """The members draw the scenario's distributions and the IMU noise by their case numbers.

    The sweep machinery without its summary plots (their drawing would be most of the time; the command
    line's sweep is the slow test below).
    """
    spec = tmp_path / "noisy.toml"
    spec.write_text(NOISY_SPEC)
    scenario = parse_scenario(SCENARIO.format(spec=spec, rate=20, duration=120, step=20))

    def sweep(name, chunk_size):
        run_sweep(scenario, tmp_path / name, ("mode=strapdown,platform",), monte_carlo=5, chunk_size=chunk_size,
                  progress=False, write_csv=False, plots=False)
        return pd.read_parquet(tmp_path / name / "results.parquet")

    small, large = sweep("small", 3), sweep("large", 10)
    assert len(small) == 10 and small["final_horizontal_position_error_m"].nunique() == 10
    pd.testing.assert_frame_equal(small, large, check_exact=False, rtol=1e-12)


@pytest.mark.slow
def test_a_monte_carlo_sweep_on_a_dask_cluster_is_the_same(run_cli, tmp_path):
    local = _sweep(run_cli, tmp_path, "local", "--monte-carlo", "6", "--chunk-size", "2", "--scheduler", "local",
                   "--workers", "2")
    alone = _sweep(run_cli, tmp_path, "alone", "--monte-carlo", "6", "--chunk-size", "6")
    pd.testing.assert_frame_equal(local, alone, check_exact=False, rtol=1e-12)


@pytest.mark.slow
def test_reproduce(run_cli, tmp_path):
    """Through the command line (the system test runs the same reproduction in the default suite)."""
    out = run_cli("navigate", "reproduce", "--json", "--out", tmp_path)
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["system"] == "navigate" and len(data["rows"]) >= 20
    verdicts = {row["verdict"] for row in data["rows"]}
    assert not any(v.startswith("differs") for v in verdicts)
    assert data["units"]["steady_departure_full"] == "1"
    for name in ("navigate_gyrocompassing.png", "navigate_gyrocompassing.svg", "navigate_gyrocompassing.csv",
                 "navigate_bollay.png", "navigate_drozdovich.png"):
        assert (tmp_path / name).stat().st_size > 500, name
    table = pd.read_csv(tmp_path / "navigate_gyrocompassing.csv")
    assert len(table) == 12 and (table["steady_departure_full"].abs() < 0.01).all()
