"""``schuler align``: run, sweep, reproduce, Monte Carlo, files and errors, end to end in-process."""

from __future__ import annotations

import pytest

ISSUE_KEYS = {
    "azimuth_error_arcmin", "azimuth_error_analytic_arcmin", "level_error_beta_arcmin", "settling_time_s",
    "settling_time_simulated_s", "c_gamma", "c_a", "constraints_ok",
}


def test_run_json_has_the_issue_keys(run_cli):
    out = run_cli("align", "run", "--latitude", "50", "--azimuth", "30", "--drift-east", "0.01 deg/h", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert ISSUE_KEYS <= set(data)
    # issue 6: 0.01 deg/h east drift at 50 deg gives 3.556 arcmin; T = 30 s, zeta = 0.8 -> c_Gamma = 0.0533 1/s
    assert data["azimuth_error_arcmin"] == pytest.approx(3.556, abs=5e-4)
    assert data["azimuth_error_arcmin"] == pytest.approx(data["azimuth_error_analytic_arcmin"], rel=1e-9)
    assert data["settling_time_s"] == pytest.approx(187.5)
    assert data["settling_time_simulated_s"] == pytest.approx(187.5, rel=0.03)
    assert data["c_gamma"] == pytest.approx(0.0533, abs=5e-5)
    assert data["c_a"] == pytest.approx(23.70, abs=0.005)
    assert data["constraints_ok"] is True
    assert data["units"]["c_a"] == "1/s"
    assert data["inputs"]["drift_east"] == pytest.approx(4.84813681109536e-08)


@pytest.mark.parametrize("model", ["full", "full-ab", "simplified"])
def test_run_models_and_human_output(run_cli, model):
    out = run_cli("align", "run", "--model", model, "--drift-north", "0.02", "--duration", "1800")
    assert out.code == 0, out.stderr
    assert f"{model} model" in out.stdout and "constraints" in out.stdout and out.stderr == ""


def test_accelerometer_error_reported_as_full_minus_simplified(run_cli):
    data = run_cli("align", "run", "--accel-error-x", "1e-4 g", "--json").json()
    assert data["azimuth_error_analytic_arcmin"] == 0.0
    assert data["full_minus_simplified_arcsec"] == pytest.approx(-24.57, abs=0.02)
    assert data["azimuth_error_arcmin"] * 60 == pytest.approx(data["full_minus_simplified_arcsec"], rel=1e-6)


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
    assert data["azimuth_error_arcmin"] == pytest.approx(3.556 * 0.6428 / 0.05234, rel=1e-3)


def test_sweep_grid_includes_stop_on_grid(run_cli):
    out = run_cli("align", "sweep", "latitude=0:80:10", "--drift-east", "0.01 deg/h", "--analytic", "--json")
    assert out.code == 0, out.stderr
    columns = out.json()["columns"]
    assert columns["latitude_deg"] == pytest.approx([0, 10, 20, 30, 40, 50, 60, 70, 80])
    assert columns["azimuth_error_analytic_arcmin"][5] == pytest.approx(3.556, abs=5e-4)
    off_grid = run_cli("align", "sweep", "damping=0.5:1:0.3", "--analytic", "--json").json()["columns"]
    assert off_grid["damping"] == pytest.approx([0.5, 0.8])
    drifts = run_cli("align", "sweep", "drift_east=0:0.05:0.01", "--analytic", "--json").json()["columns"]
    assert drifts["drift_east_deg_per_h"] == pytest.approx([0, 0.01, 0.02, 0.03, 0.04, 0.05])
    in_degrees = run_cli("align", "sweep", "latitude_error=0:1:0.5 deg", "--analytic", "--json").json()["columns"]
    assert in_degrees["latitude_error_arcmin"] == pytest.approx([0, 30, 60])


def test_sweep_simulated_two_axes_with_files(run_cli, tmp_path):
    out = run_cli("align", "sweep", "drift_east=0:0.02:0.01", "accel-error-x=0,1e-4", "--model", "simplified",
                  "--out", tmp_path, "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    columns = data["columns"]
    assert len(columns["azimuth_error_arcmin"]) == 6
    assert columns["azimuth_error_arcmin"] == pytest.approx(columns["azimuth_error_analytic_arcmin"], rel=1e-9, abs=1e-12)
    assert data["all_constraints_ok"] is True
    for name in ("align_sweep.png", "align_sweep.svg", "align_sweep.csv"):
        assert (tmp_path / name).stat().st_size > 500


@pytest.mark.parametrize("spec", ["latitude=0:10", "latitude=0:10:-1", "speed=1:2:1", "latitude=a:b:c", "latitude"])
def test_sweep_bad_axis(run_cli, spec):
    out = run_cli("align", "sweep", spec)
    assert out.code == 2 and out.stderr.startswith("schuler: error:")


def test_run_monte_carlo_with_files(run_cli, tmp_path):
    out = run_cli("align", "run", "--monte-carlo", "400", "--duration", "1200", "--sigma-accel", "0",
                  "--out", tmp_path, "--json")
    assert out.code == 0, out.stderr
    mc = out.json()["monte_carlo"]
    assert mc["members"] == 400
    # 400 members: the sample std is within 3 standard errors (3.5 % each) of the analytic 1-sigma
    assert mc["azimuth_error_std_arcmin"] == pytest.approx(mc["azimuth_error_sigma_analytic_arcmin"], rel=0.11)
    assert set(mc["azimuth_error_percentiles_arcmin"]) == {"p5", "p50", "p95"}
    for name in ("align_time_history.png", "align_phase_trajectory.svg", "align_monte_carlo.png",
                 "align_time_history.csv"):
        assert (tmp_path / name).stat().st_size > 500


def test_reproduce(run_cli):
    out = run_cli("align", "reproduce", "--json")
    assert out.code == 0, out.stderr
    rows = {row["quantity"]: row for row in out.json()["rows"]}
    assert rows["c_Gamma for T = 30 s, zeta = 0.8"]["printed"] == 0.08
    assert rows["c_Gamma for T = 30 s, zeta = 0.8"]["computed"] == pytest.approx(0.05333, abs=1e-5)
    assert rows["c_Gamma for T = 30 s, zeta = 0.8"]["agrees"] is False
    human = run_cli("align", "reproduce")
    assert "c_a for T = 30 s" in human.stdout
    # each note is numbered in the table and printed below it; a disagreeing row's note is its erratum
    lines = human.stdout.splitlines()
    c_gamma = next(line for line in lines if line.startswith("│ c_Gamma for T = 30 s"))
    assert "NO" in c_gamma and "[1]" in c_gamma
    assert any(line.startswith("[1] erratum: c_Gamma = 2 zeta / T; the printed 0.08 needs zeta = 1.20")
               for line in lines)
    assert "(1.24) C1 has 'delta_2'" in human.stdout  # the equation errata without a number follow


def test_degradation_warning_is_printed_once(run_cli):
    # the full model's run and its simplified companion share the case: one warning, not two
    out = run_cli("align", "run", "--latitude", "80")
    assert out.code == 0
    assert out.stderr.count("schuler: warning: latitude 80 deg: azimuth accuracy degrades") == 1
    assert len(out.stderr.splitlines()) == 1


def test_sweep_compares_models_case_by_case(run_cli):
    # lab tasks 2 and 3: the same cases on (1.17) in (mu, nu) and on (1.19)
    out = run_cli("align", "sweep", "model=full,simplified", "latitude=20,60", "--accel-error-x", "1e-4", "--json")
    assert out.code == 0, out.stderr
    columns = out.json()["columns"]
    assert columns["model"] == ["full", "full", "simplified", "simplified"]
    simulated, analytic = columns["azimuth_error_arcmin"], columns["azimuth_error_analytic_arcmin"]
    assert simulated[2:] == pytest.approx([0.0, 0.0], abs=1e-12)  # (1.19): no accelerometer effect
    # (1.17): about eps_alpha tan(latitude) = -1e-4 tan(latitude) rad
    assert simulated[0] == pytest.approx(-0.3438 * 0.36397, rel=3e-3)
    assert analytic == pytest.approx([0.0] * 4, abs=1e-12)
