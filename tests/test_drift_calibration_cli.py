"""``schuler calibrate``: run, reproduce, Monte Carlo, sweeps, files and errors, end to end in-process."""

from __future__ import annotations

import math

import pandas as pd
import pytest

from schuler.core.earth import EARTH_RATE

DEG_H = math.radians(1.0) / 3600.0
ARCMIN = math.radians(1.0) / 60.0


def test_run_json_keys(run_cli):
    out = run_cli("calibrate", "run", "--latitude", "70", "--azimuth", "80", "--drift-x", "0.1 deg/h", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["drift_x_rad_s"] == pytest.approx(0.1 * DEG_H, rel=1e-9)
    assert data["true_drift_x_rad_s"] == pytest.approx(0.1 * DEG_H, rel=1e-12)
    assert data["drift_y_rad_s"] == pytest.approx(0.1 * DEG_H, rel=1e-9)  # drift_y not set: equal to drift_x
    # (3): omega_X0 = Omega cos(phi) sin(A0)
    assert data["earth_rate_component_rad_s"] == pytest.approx(
        EARTH_RATE * math.cos(math.radians(70)) * math.sin(math.radians(80)), rel=1e-9)
    assert 0 <= data["azimuth_rad"] < 2 * math.pi and math.degrees(data["azimuth_rad"]) == pytest.approx(80.0, rel=1e-9)
    assert abs(data["azimuth_error_rad"]) < 1e-12 and data["cycle_time_s"] == 10.0
    assert data["procedure_time_s"] == 40.0  # 2 positions x 2 channels x one 10-s cycle
    assert data["units"]["relative_drift_error"] == "1" and data["units"]["latitude"] == "rad"
    assert data["inputs"]["drift_x"] == pytest.approx(4.84813681109536e-07)
    assert data["schuler_version"] and data["monte_carlo"] is None


def test_monte_carlo_positions_and_files(run_cli, tmp_path):
    out = run_cli("calibrate", "run", "--azimuth", "350", "--mode", "single-axis", "--monte-carlo", "200",
                  "--positions", "3", "--drift-y", "0.2", "--out", tmp_path, "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["monte_carlo"]["members"] == 200 and math.degrees(data["azimuth_rad"]) == pytest.approx(350.0)
    assert {"mean", "std", "rms", "p05", "p95"} <= set(data["monte_carlo"]["statistics"]["azimuth_error_rad"])
    assert data["monte_carlo"]["statistics"]["drift_y_error_rad_s"]["count"] == 0  # single-axis: Y not measured
    assert data["inputs"]["monte_carlo"] == 200 and data["inputs"]["seed"] == 0
    for name in ("calibrate_cycle.png", "calibrate_cycle.svg", "calibrate_monte_carlo.png",
                 "calibrate_monte_carlo.svg"):
        assert (tmp_path / name).stat().st_size > 1000, name
    cycle = pd.read_csv(tmp_path / "calibrate_cycle.csv")
    assert list(cycle.columns) == ["t_s", "platform_angle_rad", "sensor_signal_V", "integrator_output_V_s"]
    assert cycle["t_s"].iloc[-1] == pytest.approx(10.0)
    members = pd.read_csv(tmp_path / "calibrate_monte_carlo.csv")
    assert len(members) == 200 and "azimuth_error_rad" in members
    # the files a Monte Carlo run writes, exactly: the cycle's histories and figure, the members' errors
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == [
        "calibrate_cycle.csv", "calibrate_cycle.png", "calibrate_cycle.svg", "calibrate_monte_carlo.csv",
        "calibrate_monte_carlo.png", "calibrate_monte_carlo.svg"]


@pytest.mark.parametrize("args, option", [
    (("--latitude", "90"), "--latitude"), (("--latitude", "-90"), "--latitude"),
    (("--pulse-duration", "0"), "--pulse-duration"), (("--pulse-duration", "-1 s"), "--pulse-duration"),
    (("--sensor-gain", "0"), "--sensor-gain"), (("--drift-x", "nan"), "--drift-x"),
    (("--azimuth", "nan"), "--azimuth"), (("--drift-x", "0.1 m"), "--drift-x"), (("--positions", "1"), "--positions"),
    (("--mode", "two-axis"), "--mode"), (("--monte-carlo", "-1"), "--monte-carlo"), (("--seed", "-5"), "--seed"),
    (("--tau", "5"), "--tau"), (("--drift", "0.1"), "--drift"), (("--fidelity", "closed"), "--fidelity"),
])
def test_bad_input_one_line_exit_2(run_cli, args, option):
    out = run_cli("calibrate", "run", *args)
    lines = out.stderr.strip().splitlines()
    assert out.code == 2 and len(lines) == 1 and lines[0].startswith("schuler: error:") and option in lines[0]


def test_near_the_pole(run_cli):
    refused = run_cli("calibrate", "run", "--latitude", "89.99")
    assert refused.code == 2 and "--max-latitude" in refused.stderr and "--latitude: 89.99 deg" in refused.stderr
    allowed = run_cli("calibrate", "run", "--latitude", "87", "--max-latitude", "88", "--monte-carlo", "20", "--json")
    assert allowed.code == 0, allowed.stderr
    # one warning for the run and its Monte Carlo
    assert allowed.stderr.count("schuler: warning: latitude 87 deg: azimuth accuracy degrades") == 1
    assert len(allowed.stderr.splitlines()) == 1
    quiet = run_cli("calibrate", "run", "--latitude", "70")
    assert quiet.code == 0 and quiet.stderr == ""


def test_other_asin_branch_only_where_it_exists(run_cli):
    # one channel over two positions measures sin(A0) only: 80 deg and 180 - 80 = 100 deg both fit
    single = run_cli("calibrate", "run", "--azimuth", "80", "--mode", "single-axis", "--positions", "2")
    assert single.code == 0, single.stderr
    branch = next(line for line in single.stdout.splitlines() if "other asin branch" in line)
    assert "100.000000 deg" in branch
    assert "not measured (single-axis)" in single.stdout
    # two channels (or more positions) give A0 by atan2: no second branch to show, though the JSON keeps the key
    three = run_cli("calibrate", "run", "--azimuth", "80", "--mode", "three-axis")
    assert three.code == 0 and "other asin branch" not in three.stdout
    data = run_cli("calibrate", "run", "--azimuth", "80", "--json").json()
    assert math.degrees(data["azimuth_alternative_rad"]) == pytest.approx(80.0)


def test_reproduce(run_cli, tmp_path):
    out = run_cli("calibrate", "reproduce", "--monte-carlo", "300", "--json", "--out", tmp_path)
    assert out.code == 0, out.stderr
    data = out.json()
    rows = {row["quantity"]: row for row in data["rows"]}
    azimuth = rows["RMS azimuth error, modelled three-axis case, scaled budget"]
    assert azimuth["computed"] == pytest.approx(2.0, rel=1e-3) and azimuth["verdict"].startswith("tuned to match")
    drift = rows["mean relative drift error, modelled three-axis case, scaled budget"]
    assert drift["printed"] == "0,34%" and drift["computed"] == pytest.approx(0.34, rel=0.02)
    assert not [row for row in data["rows"] if row["verdict"].startswith("differs")]
    assert data["inputs"] == {"monte_carlo": 300, "seed": 0} and data["units"]["computed"] == "the row's unit"
    assert (tmp_path / "calibrate_reproduction_monte_carlo.svg").stat().st_size > 1000
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == [
        "calibrate_reproduction_monte_carlo.png", "calibrate_reproduction_monte_carlo.svg",
        "calibrate_reproduction_summary.csv"]
    summary = pd.read_csv(tmp_path / "calibrate_reproduction_summary.csv")
    assert summary["rms_azimuth_error_rad"].iloc[1] == pytest.approx(math.radians(2.0 / 60), rel=1e-3)
    human = run_cli("calibrate", "reproduce", "--monte-carlo", "200")
    assert human.code == 0 and "tuned to match" in human.stdout and "deg/h chosen to give it" in human.stdout


SCENARIO = """system = "calibrate"
[parameters]
drift_x = "0.1 deg/h"
[monte_carlo]
seed = 5
[monte_carlo.normal]
drift_x = "0.02 deg/h"
[monte_carlo.uniform]
azimuth = ["0 deg", "360 deg"]
"""


def test_sweep_monte_carlo_does_not_depend_on_chunking():
    # issue 11: "--param tau=4,5,6 --monte-carlo 4" gave different members with --chunk-size 3 and 12 (every
    # chunk reseeded). The sweep's plan, cut both ways, evaluated as the sweep's executors do (no files)
    import numpy as np

    from schuler.drift_calibration.api import SYSTEM
    from schuler.study.plan import plan_sweep
    from schuler.study.scenario import parse_scenario

    scenario = parse_scenario(SCENARIO)
    results = {}
    for chunk in (3, 12):
        plan = plan_sweep(scenario, SYSTEM, ["pulse_duration=4,5,6"], 4, chunk)
        parts = [SYSTEM.evaluate(plan.cases(*plan.chunk_range(i))) for i in range(plan.chunks)]
        results[chunk] = {name: np.concatenate([part[name] for part in parts]) for name in parts[0]}
    assert results[3]["azimuth_error_rad"].size == 12
    for name, values in results[12].items():
        np.testing.assert_allclose(results[3][name], values, rtol=1e-12, atol=0.0, err_msg=name)
    assert np.abs(results[3]["azimuth_error_rad"]).min() > 1e-7  # the budget's random terms were drawn


@pytest.mark.slow  # the sweep's summary figures take about 10 s
def test_sweep_grid_is_the_nominal_procedure(run_cli, tmp_path):
    scenario = tmp_path / "calibrate.toml"
    scenario.write_text(SCENARIO)
    out = run_cli("sweep", scenario, "--param", "azimuth=0:350:50", "--param", "mode=three-axis,single-axis",
                  "--out", tmp_path / "grid", "--no-progress", "--json")
    assert out.code == 0, out.stderr
    table = pd.read_parquet(tmp_path / "grid" / "results.parquet")
    assert len(table) == 16
    assert table["azimuth_error_rad"].abs().max() < 1e-9
    assert table.loc[table["mode"] == "single-axis", "drift_y_rad_s"].isna().all()
