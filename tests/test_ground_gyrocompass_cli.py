"""``schuler north`` end to end, and the system's registry entry points."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.ground_gyrocompass import motion
from schuler.ground_gyrocompass.api import SYSTEM, PARAMETERS, resolve_omega_h, run
from schuler.params import parse_parameters

ESTIMATE_KEYS = {"alpha0_rad", "alpha0_dot", "lambda", "Hm", "north_deg", "misfit", "nfev", "method",
                 "alpha0_rad_std", "alpha0_dot_std", "lambda_std", "Hm_std", "north_std_arcsec"}


@pytest.fixture
def record_file(tmp_path, run_cli):
    path = tmp_path / "record.csv"
    out = run_cli("north", "simulate", "--noise", "2 arcsec", "--seed", "4", "--output", path)
    assert out.code == 0, out.stderr
    return path


def test_simulate_writes_the_record(record_file):
    lines = record_file.read_text().splitlines()
    assert lines[0] == "t_s,alpha_rad"
    assert len(lines) == 202  # 0..200 s every 1 s (source 004)


def test_identify_json_keys_and_values(record_file, run_cli):
    out = run_cli("north", "identify", record_file, "--unknowns", "4", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert ESTIMATE_KEYS <= set(data)
    assert data["method"] == "lsq"
    # 2 arcsec noise: north within a few standard errors of the truth -1.23 deg
    assert abs(data["north_deg"] + 1.23) * 3600 < 5 * data["north_std_arcsec"]
    assert data["Hm"] == pytest.approx(0.432, rel=1e-3)


def test_identify_grid_and_figures(record_file, run_cli, tmp_path):
    out = run_cli("north", "identify", record_file, "--unknowns", "2", "--method", "grid", "--out", tmp_path / "f",
                  "--json")
    assert out.code == 0, out.stderr
    assert out.json()["method"] == "grid"
    names = {p.name for p in (tmp_path / "f").iterdir()}
    for stem in ("north_fit", "north_misfit_map", "north_error_vs_time"):
        assert {f"{stem}.png", f"{stem}.svg"} <= names


def test_identify_human_output_shows_deg_arcmin_arcsec(record_file, run_cli):
    out = run_cli("north", "identify", record_file, "--unknowns", "3")
    assert out.code == 0, out.stderr
    for unit in ("deg", "arcmin", "arcsec"):
        assert unit in out.stdout
    assert "-1°13′" in out.stdout


def test_reproduce_json_keys(run_cli):
    out = run_cli("north", "reproduce", "--unknowns", "4", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert ESTIMATE_KEYS <= set(data)
    assert data["alpha0_rad"] == pytest.approx(3.69 * math.pi / 540, rel=1e-9)  # source 004 simulator input
    assert data["lambda"] == pytest.approx(2.15e-3, rel=1e-9)
    assert data["Hm"] == pytest.approx(0.432, rel=1e-9)
    assert len(data["stages"]) == 9
    assert data["table1"]["any_reading_reproduces"] is False


def test_reproduce_human_explains_each_disagreement(run_cli):
    out = run_cli("north", "reproduce", "--unknowns", "2")
    assert out.code == 0, out.stderr
    lines = out.stdout.splitlines()
    # source 004, Table 2 (2 unknowns, stage 2): printed F 3.62e-5 against the computed sum of squares
    row = next(line for line in lines if line.replace(" ", "").startswith("│2│2│900│"))
    assert "3.62e-05" in row and "✗" in row and "[1]" in row
    assert next(line for line in lines if line.startswith("[1] ")).startswith("[1] erratum: the printed F is not")
    # 4 unknowns, stage 1: the printed best cell is not the grid's minimum
    row = next(line for line in lines if line.replace(" ", "").startswith("│4│1│"))
    number = row.rsplit("[", 1)[1].split("]")[0]
    note = next(line for line in lines if line.startswith(f"[{number}] "))
    assert "the printed best (4, 4, 2.2, 0.43) is not the grid's minimum" in note


def test_run_is_simulate_plus_identify(run_cli):
    out = run_cli("north", "run", "--noise", "1 arcsec", "--latitude", "50", "--unknowns", "5", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["omega_h"] == pytest.approx(7.292115e-5 * math.cos(math.radians(50)), rel=1e-12)
    assert abs(data["north_error_arcsec"]) < 5 * data["north_std_arcsec"]


@pytest.mark.parametrize(
    "args, needle",
    [
        (("run", "--lambda", "0"), "--lambda"),
        (("run", "--lambda", "-1e-3"), "--lambda"),
        (("run", "--hm", "0"), "--hm"),
        (("run", "--latitude", "90"), "--latitude"),
        (("run", "--latitude", "-90"), "--latitude"),
        (("run", "--duration", "2", "--unknowns", "4"), "--unknowns"),
        (("run", "--latitude", "50", "--omega-h", "3e-5"), "--latitude"),
        (("simulate", "--noise", "-1", "--output", "x.csv"), "--noise"),
    ],
)
def test_bad_input_is_one_line_exit_2(run_cli, args, needle):
    out = run_cli("north", *args)
    assert out.code == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("schuler: error:") and needle in lines[0]


@pytest.mark.parametrize(
    "body, needle",
    [
        ("t_s,alpha_rad\n0,0\n2,1e-4\n1,2e-4\n3,1e-4\n4,0\n", "line 4"),
        ("t_s,alpha_rad\n0,0\n1,NaN\n", "line 3"),
        ("t_s,alpha_rad\n0,0\n,1e-4\n", "line 3"),
        ("t_s,alpha_rad\n0,0\n1,1e-4\n2,2e-4\n", "need at least"),
    ],
)
def test_bad_record_is_one_line_exit_2(tmp_path, run_cli, body, needle):
    path = tmp_path / "bad.csv"
    path.write_text(body)
    out = run_cli("north", "identify", path, "--unknowns", "4")
    assert out.code == 2
    assert len(out.stderr.strip().splitlines()) == 1 and needle in out.stderr


def test_missing_record_file(tmp_path, run_cli):
    out = run_cli("north", "identify", tmp_path / "none.csv")
    assert out.code == 2 and "no such file" in out.stderr


def test_system_run_matches_parameters():
    assert {p.name for p in SYSTEM.parameters} == {p.name for p in PARAMETERS}
    values = parse_parameters(SYSTEM.parameters, {"unknowns": "2"})
    result = run(**values)
    assert abs(result.north_error_arcsec) < 1e-6  # noise-free, known lambda and Hm
    assert resolve_omega_h() == motion.SOURCE_OMEGA_H


def test_sweep_is_vectorised_and_matches_single_cases():
    durations = np.array([60.0, 120.0, 300.0, 600.0])
    values = {"duration": durations, "noise": np.full(4, 1e-5), "unknowns": np.array([4, 4, 4, 4])}
    out = SYSTEM.sweep(values)
    assert out["north_std_arcsec"].shape == (4,)
    assert np.all(np.diff(out["north_std_arcsec"]) < 0)  # accuracy improves with observation time
    single = SYSTEM.sweep({"duration": durations[2:3], "noise": np.array([1e-5]), "unknowns": np.array([4])})
    assert single["north_std_arcsec"][0] == pytest.approx(out["north_std_arcsec"][2], rel=1e-12)
    mixed = SYSTEM.sweep({"unknowns": np.array([2, 5]), "noise": np.array([1e-5, 1e-5]),
                          "latitude": np.array([np.nan, 0.9])})
    assert mixed["north_std_arcsec"][1] > mixed["north_std_arcsec"][0]


def test_report_section(tmp_path):
    section = SYSTEM.report(tmp_path)
    assert section.system == "north"
    assert all((tmp_path / figure.path).is_file() for figure in section.figures)
    assert len(section.figures) == 4
    rows = {row.quantity: row for row in section.rows}
    assert rows["2 unknowns, stage 1: best cell"].agrees
    assert not rows["4 unknowns, stage 1: best cell"].agrees
    assert rows["4 unknowns: alpha0 by least squares"].agrees
