"""``schuler align``: run, reproduce, Monte Carlo, sweeps, files and errors, end to end in-process."""

from __future__ import annotations

import math

import pandas as pd
import pytest

ARCMIN = math.radians(1) / 60
ISSUE_KEYS = {
    "azimuth_error_rad", "azimuth_error_analytic_rad", "level_error_beta_rad", "settling_time_s",
    "settling_time_simulated_s", "c_gamma", "c_a", "constraints_ok",
}


def test_run_json_has_the_issue_keys(run_cli):
    out = run_cli("align", "run", "--latitude", "50", "--azimuth", "30", "--drift-east", "0.01 deg/h", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert ISSUE_KEYS <= set(data)
    # issue 6: 0.01 deg/h east drift at 50 deg gives 3.556 arcmin; T = 30 s, zeta = 0.8 -> c_Gamma = 0.0533 1/s
    assert data["azimuth_error_rad"] / ARCMIN == pytest.approx(3.556, abs=5e-4)
    assert data["azimuth_error_rad"] == pytest.approx(data["azimuth_error_analytic_rad"], rel=1e-9)
    assert data["settling_time_s"] == pytest.approx(187.5)
    assert data["settling_time_simulated_s"] == pytest.approx(187.5, rel=0.03)
    assert data["c_gamma"] == pytest.approx(0.0533, abs=5e-5)
    assert data["c_a"] == pytest.approx(23.70, abs=0.005)
    assert data["constraints_ok"] is True
    assert data["units"]["c_a"] == "1/s" and data["units"]["latitude"] == "rad"
    assert data["inputs"]["drift_east"] == pytest.approx(4.84813681109536e-08)
    assert data["inputs"]["fidelity"] == "simulated"


def test_closed_fidelity_is_a_named_choice(run_cli):
    closed = run_cli("align", "run", "--drift-east", "0.01 deg/h", "--fidelity", "closed", "--json").json()
    assert closed["fidelity"] == "closed" and closed["settling_time_simulated_s"] is None
    assert closed["azimuth_error_rad"] / ARCMIN == pytest.approx(3.556, abs=5e-4)
    assert run_cli("align", "run", "--fidelity", "rough").code == 2


@pytest.mark.parametrize("model", ["full", "full-ab", "simplified"])
def test_run_models_and_human_output(run_cli, model):
    out = run_cli("align", "run", "--model", model, "--drift-north", "0.02", "--duration", "1800")
    assert out.code == 0, out.stderr
    assert f"{model} model" in out.stdout and "constraints" in out.stdout and out.stderr == ""
    assert "arcmin" in out.stdout


def test_accelerometer_bias_reported_as_full_minus_simplified(run_cli):
    data = run_cli("align", "run", "--accel-bias-x", "1e-4 g", "--json").json()
    assert data["azimuth_error_analytic_rad"] == 0.0
    assert data["full_minus_simplified_rad"] / (ARCMIN / 60) == pytest.approx(-24.57, abs=0.02)
    assert data["azimuth_error_rad"] == pytest.approx(data["full_minus_simplified_rad"], rel=1e-6)


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (("--latitude", "90"), "--latitude"),
        (("--latitude", "-90"), "--latitude"),
        (("--c-gamma", "-0.05"), "--c-gamma"),
        (("--c-a", "-3"), "--c-a"),
        (("--damping", "0"), "--damping"),
        (("--damping", "-0.5"), "--damping"),
        (("--drift-east", "nan"), "--drift-east"),
        (("--latitude", "nan"), "--latitude"),
        (("--drift-east", "0.01 m"), "--drift-east"),
        (("--model", "fast"), "--model"),
        (("--monte-carlo", "-1"), "--monte-carlo"),
        (("--seed", "-5"), "--seed"),
    ],
)
def test_bad_input_one_line_exit_2(run_cli, args, option):
    out = run_cli("align", "run", *args)
    assert out.code == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("schuler: error:") and option in lines[0]


def test_near_the_pole(run_cli):
    refused = run_cli("align", "run", "--latitude", "87")
    assert refused.code == 2 and "--max-latitude" in refused.stderr and "latitude" in refused.stderr
    allowed = run_cli("align", "run", "--latitude", "87", "--max-latitude", "89", "--drift-east", "0.01", "--json")
    assert allowed.code == 0
    assert "degrades" in allowed.stderr
    data = allowed.json()
    # never a NaN: every number is finite (JSON null would mark a non-finite value)
    assert data["monte_carlo"] is None
    assert all(value is not None for key, value in data.items() if key != "monte_carlo")
    assert data["azimuth_error_rad"] / ARCMIN == pytest.approx(3.556 * 0.6428 / 0.05234, rel=1e-3)


SCENARIO = """system = "align"
[parameters]
drift_east = "{drift} deg/h"
model = "{model}"
[simulation]
duration = "1500 s"
output_step = "1 s"
"""


def _sweep(run_cli, tmp_path, *args, model="full", drift=0.01):
    scenario = tmp_path / "align.toml"
    scenario.write_text(SCENARIO.format(model=model, drift=drift))
    out_dir = tmp_path / "sweep"
    out = run_cli("sweep", scenario, *args, "--out", out_dir, "--no-progress", "--json")
    assert out.code == 0, out.stderr
    return pd.read_parquet(out_dir / "results.parquet")


def test_sweep_grid_includes_stop_on_grid(run_cli, tmp_path):
    table = _sweep(run_cli, tmp_path, "--param", "latitude=0:80:10", "--fidelity", "closed")
    assert table["latitude_deg"].tolist() == pytest.approx([0, 10, 20, 30, 40, 50, 60, 70, 80])
    assert table["azimuth_error_analytic_rad"][5] / ARCMIN == pytest.approx(3.556, abs=5e-4)
    assert table["settling_time_simulated_s"].isna().all()  # closed form: nothing simulated


def test_sweep_simulated_two_axes(run_cli, tmp_path):
    table = _sweep(run_cli, tmp_path, "--param", "drift_east=0:0.02:0.01", "--param", "accel-bias-x=0,1e-4",
                   model="simplified")
    assert len(table) == 6
    assert table["azimuth_error_rad"].tolist() == pytest.approx(table["azimuth_error_analytic_rad"].tolist(),
                                                                rel=1e-9, abs=1e-12)
    assert (table["constraints_ok"] == 1).all()


def test_sweep_compares_models_case_by_case(run_cli, tmp_path):
    # lab tasks 2 and 3: the same cases on (1.17) in (mu, nu) and on (1.19)
    table = _sweep(run_cli, tmp_path, "--param", "model=full,simplified", "--param", "latitude=20,60",
                   "--param", "accel_bias_x=1e-4,1e-4", drift=0.0)
    assert table["model"].tolist()[::2] == ["full", "full", "simplified", "simplified"]
    simulated = table["azimuth_error_rad"].to_numpy() / ARCMIN
    assert simulated[4:] == pytest.approx([0.0] * 4, abs=1e-12)  # (1.19): no accelerometer effect
    # (1.17): about eps_alpha tan(latitude) = -1e-4 tan(latitude) rad
    assert simulated[0] == pytest.approx(-0.3438 * 0.36397, rel=3e-3)


def test_run_monte_carlo_with_files(run_cli, tmp_path):
    out = run_cli("align", "run", "--monte-carlo", "400", "--duration", "1200", "--sigma-accel", "0",
                  "--out", tmp_path, "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    mc = data["monte_carlo"]
    assert mc["members"] == 400
    # 400 members: the sample std is within 3 standard errors (3.5 % each) of the analytic 1-sigma
    assert mc["statistics"]["azimuth_error_rad"]["std"] == pytest.approx(data["azimuth_error_sigma_rad"], rel=0.11)
    assert {"p05", "p50", "p95", "mean", "std", "rms"} <= set(mc["statistics"]["azimuth_error_rad"])
    for name in ("align_time_history.png", "align_phase_trajectory.svg", "align_monte_carlo.png",
                 "align_time_history.csv"):
        assert (tmp_path / name).stat().st_size > 500


def test_reproduce(run_cli, tmp_path):
    out = run_cli("align", "reproduce", "--json", "--out", tmp_path)
    assert out.code == 0, out.stderr
    data = out.json()
    rows = {row["quantity"]: row for row in data["rows"]}
    c_gamma = rows["c_Gamma for T = 30 s, zeta = 0.8"]
    assert (c_gamma["printed"], c_gamma["verdict"]) == ("0.08", "erratum")
    assert c_gamma["computed"] == pytest.approx(0.05333, abs=1e-5)
    assert "units" in data and data["schuler_version"]
    assert (tmp_path / "align_reproduction_time_history.png").stat().st_size > 500
    human = run_cli("align", "reproduce")
    assert "c_a for T = 30 s" in human.stdout
    # each note is numbered in the table and printed below it
    lines = human.stdout.splitlines()
    assert any(line.startswith("[1] c_Gamma = 2 zeta / T; the printed 0.08 needs zeta = 1.20") for line in lines)
    assert "(1.24) C1 has 'delta_2'" in human.stdout  # the equation errata without a number follow


def test_degradation_warning_is_printed_once(run_cli):
    # the full model's run and its simplified companion share the case: one warning, not two
    out = run_cli("align", "run", "--latitude", "80")
    assert out.code == 0
    assert out.stderr.count("schuler: warning: latitude 80 deg: azimuth accuracy degrades") == 1
    assert len(out.stderr.splitlines()) == 1
