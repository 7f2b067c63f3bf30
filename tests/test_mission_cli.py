"""``schuler NAME run SCENARIO`` and ``schuler NAME sweep SCENARIO``: a system's scenario under its own group."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pandas as pd
import pytest

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


@pytest.mark.parametrize("system, scenario", [("mission", "mission_tactical.toml"),
                                              ("align", "align_gyrocompassing.toml")])
def test_run_with_a_scenario_gives_the_json_of_schuler_run(run_cli, system, scenario):
    path = EXAMPLES / scenario
    under_group = run_cli(system, "run", path, "--json")
    assert under_group.code == 0, under_group.stderr
    assert under_group.json() == run_cli("run", path, "--json").json()


def test_options_typed_win_over_the_scenario(run_cli):
    out = run_cli("align", "run", EXAMPLES / "align_gyrocompassing.toml", "--latitude", "30", "--duration", "600",
                  "--json")
    assert out.code == 0, out.stderr
    inputs = out.json()["inputs"]
    assert inputs["latitude"] == pytest.approx(math.radians(30)) and inputs["duration"] == 600.0  # typed
    assert inputs["drift_east"] == pytest.approx(math.radians(0.01) / 3600)  # the file's 0.01 deg/h
    assert inputs["time_constant"] == 300.0 and inputs["model"] == "full"


def test_a_typed_imu_replaces_the_scenarios_instrument(run_cli):
    # the file: latitude 50 deg, full model, 1 h at 1 s, [instrument] tactical; --imu navigation replaces the table
    over_file = run_cli("align", "run", EXAMPLES / "imu_align_tactical.toml", "--imu", "navigation", "--json")
    typed = run_cli("align", "run", "--latitude", "50", "--model", "full", "--duration", "1 h", "--output-step", "1",
                    "--imu", "navigation", "--json")
    assert over_file.code == 0, over_file.stderr
    assert over_file.json() == typed.json()
    assert over_file.json() != run_cli("run", EXAMPLES / "imu_align_tactical.toml", "--json").json()


@pytest.mark.parametrize("command", ["run", "sweep"])
def test_a_scenario_of_another_system_is_refused_in_one_line(run_cli, tmp_path, command):
    out = run_cli("align", command, EXAMPLES / "mission_tactical.toml", *(("--out", tmp_path) if command == "sweep"
                                                                          else ()))
    assert out.code == 2 and out.stdout == ""
    assert out.stderr.count("\n") == 1 and "'mission' is a scenario of schuler mission" in out.stderr


def test_sweep_under_the_group_gives_the_summary_of_schuler_sweep(run_cli, tmp_path, monkeypatch):
    # a 30-min flight (the shortest the profile allows is 28 min) keeps the 4 covariance analyses quick; the
    # summary plots (a second each, the same code under both commands) are left out
    import schuler.study.plots

    monkeypatch.setattr(schuler.study.plots, "plot_sweep_summary", lambda *args, **kwargs: [])
    grid = ("--param", "imu=navigation,tactical", "--param", "alignment_duration=300,600",
            "--param", "duration=1800")
    scenario = EXAMPLES / "mission_tactical.toml"
    under_group = run_cli("mission", "sweep", scenario, *grid, "--out", tmp_path / "group", "--json")
    plain = run_cli("sweep", scenario, *grid, "--out", tmp_path / "plain", "--json")
    assert under_group.code == 0, under_group.stderr
    group_summary = json.loads((tmp_path / "group" / "summary.json").read_text())
    plain_summary = json.loads((tmp_path / "plain" / "summary.json").read_text())
    assert group_summary["manifest"]["cases"] == 4
    assert group_summary == plain_summary
    # the printed JSON differs only by the folder and the timings
    varying = ("out_dir", "files", "cases_per_second", "seconds_total", "seconds")
    group_printed, plain_printed = ({k: v for k, v in out.json().items() if k not in varying}
                                    for out in (under_group, plain))
    assert group_printed == plain_printed


@pytest.mark.slow
def test_the_nonlinear_members_run_on_a_dask_cluster_as_in_process(run_cli, tmp_path):
    """Beyond one run's members: `mission sweep --monte-carlo N --scheduler ...` (the sweeps' executors)."""
    scenario = EXAMPLES / "mission_tactical.toml"

    def members(name, *options):
        out = run_cli("mission", "sweep", scenario, "--param", "duration=1800", "--monte-carlo", "6",
                      "--no-csv", "--out", tmp_path / name, *options)
        assert out.code == 0, out.stderr
        return pd.read_parquet(tmp_path / name / "results.parquet")

    dask = members("dask", "--chunk-size", "2", "--scheduler", "local", "--workers", "2")
    alone = members("alone", "--chunk-size", "6")
    assert dask["member_position_error_m"].nunique() == 6
    pd.testing.assert_frame_equal(dask, alone, check_exact=False, rtol=1e-12)


@pytest.mark.slow
def test_the_covariance_over_the_members_agrees_with_their_monte_carlo(run_cli):
    # the example's members draw their heading from [monte_carlo.uniform] (0-360 deg), so the covariance to
    # compare with is over their headings, not at the file's 30 deg. Band: two sampling standard errors of the
    # members' RMS, std(e^2) / (2 RMS sqrt(N)), about 3.5 % at 300 members
    out = run_cli("mission", "run", EXAMPLES / "mission_tactical.toml", "--monte-carlo", "300", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    compared = data["monte_carlo"]
    band = 2.0 * compared["position_error_sigma_standard_error_m"]
    assert 0.02 < band / compared["position_error_sigma_m"] < 0.15
    assert abs(compared["covariance_position_error_sigma_m"] - compared["position_error_sigma_m"]) <= band
    # the nominal heading's covariance (kept as the top-level key) is not the members' and lies outside the band
    nominal = data["position_error_sigma_m"]
    assert compared["nominal_covariance_position_error_sigma_m"] == pytest.approx(nominal, rel=1e-12)
    assert abs(data["position_error_sigma_m"] - compared["position_error_sigma_m"]) > 2 * band
    rms = compared["statistics"]["member_position_error_m"]["rms"]
    assert compared["position_error_sigma_m"] == pytest.approx(rms, rel=1e-12)


def test_the_table_labels_each_covariance_beside_the_monte_carlo(run_cli):
    out = run_cli("mission", "run", "--imu", "navigation", "--trajectory", "stationary", "--duration", "600",
                  "--monte-carlo", "4")
    assert out.code == 0, out.stderr
    for label in ("1-sigma (covariance at the nominal case)",
                  "covariance over the Monte Carlo members' cases (RMS of their 1-sigma)",
                  "Monte Carlo (4 members, nonlinear INS): RMS, its sampling 1-sigma"):
        assert label in " ".join(out.stdout.split())
