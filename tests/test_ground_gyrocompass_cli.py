"""``schuler north`` end to end in-process: run, reproduce, identify, simulate, files and errors."""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd
import pytest

ARCSEC = math.radians(1.0) / 3600.0
TRUE_NORTH = -3.69 * math.pi / 540  # -alpha0 of the source's simulator (Fedorov et al. 2020, before Table 1)
IDENTIFY_KEYS = {"alpha0_rad", "alpha0_dot_rad_s", "decay_rate", "hm", "north_rad", "misfit_rad2",
                 "model_evaluations", "method", "alpha0_std_rad", "alpha0_dot_std_rad_s", "decay_rate_std", "hm_std",
                 "north_std_rad"}
SI_SUFFIXES = ("_rad", "_s", "_rad_s", "_rad2")


@pytest.fixture
def record_file(tmp_path, run_cli):
    path = tmp_path / "record.csv"
    out = run_cli("north", "simulate", "--readout-noise", "2 arcsec", "--seed", "4", "-o", path)
    assert out.code == 0, out.stderr
    return path


def numeric_keys_without_unit(data: dict) -> set[str]:
    return {key for key, value in data.items() if isinstance(value, (int, float)) and not isinstance(value, bool)
            and not key.endswith(SI_SUFFIXES)}


def test_simulate_writes_the_record(record_file):
    lines = record_file.read_text().splitlines()
    assert lines[0] == "t_s,alpha_rad"
    assert len(lines) == 202  # 0..200 s every 1 s (Fedorov et al. 2020, before Table 1)


def test_identify_json_keys_and_values(record_file, run_cli):
    out = run_cli("north", "identify", record_file, "--unknowns", "4", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert IDENTIFY_KEYS <= set(data)
    assert data["method"] == "lsq" and data["schuler_version"]
    # 2 arcsec noise: north within a few standard errors of the truth -1.23 deg
    assert abs(data["north_rad"] - TRUE_NORTH) < 5 * data["north_std_rad"]
    assert data["hm"] == pytest.approx(0.432, rel=1e-3)
    assert numeric_keys_without_unit(data) <= set(data["units"])


@pytest.mark.slow
def test_identify_grid_and_figures(record_file, run_cli, tmp_path):
    out = run_cli("north", "identify", record_file, "--unknowns", "2", "--method", "grid", "--out", tmp_path / "f",
                  "--json")
    assert out.code == 0, out.stderr
    assert out.json()["method"] == "grid"
    names = {p.name for p in (tmp_path / "f").iterdir()}
    for stem in ("north_fit", "north_misfit_map", "north_error_vs_time"):
        assert {f"{stem}.png", f"{stem}.svg"} <= names
    table = pd.read_csv(tmp_path / "f" / "north_record_fit.csv")
    assert list(table.columns) == ["t_s", "observed_rad", "fitted_rad", "residual_rad"]
    assert (table["observed_rad"] - table["fitted_rad"] - table["residual_rad"]).abs().max() < 1e-15


def test_identify_human_output_shows_deg_arcmin_arcsec(record_file, run_cli):
    out = run_cli("north", "identify", record_file, "--unknowns", "3")
    assert out.code == 0, out.stderr
    for unit in ("deg", "arcmin", "arcsec"):
        assert unit in out.stdout
    assert "-1°13′" in out.stdout
    # the optimiser's own words ("`xtol` termination condition is satisfied") never reach the user
    assert "xtol" not in out.stdout and "termination" not in out.stdout and out.stderr == ""
    assert "variable projection converged" in out.stdout


def test_run_member_zero_is_simulate_then_identify(record_file, run_cli):
    # the record of `simulate --seed 4` is member 0 of `run --monte-carlo 1 --seed 4`: same noise, same estimate
    run = run_cli("north", "run", "--readout-noise", "2 arcsec", "--monte-carlo", "1", "--seed", "4", "--json").json()
    identified = run_cli("north", "identify", record_file, "--json").json()
    member = run["monte_carlo"]["statistics"]["north_error_rad"]["mean"]
    # the CSV keeps every digit (repr), so only the fit's round-off separates them
    assert member == pytest.approx(identified["north_rad"] - TRUE_NORTH, rel=1e-9, abs=1e-15)


def test_run_json_nominal_case_and_units(run_cli):
    out = run_cli("north", "run", "--readout-noise", "1 arcsec", "--latitude", "50", "--unknowns", "5", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["omega_h"] == pytest.approx(7.292115e-5 * math.cos(math.radians(50)), rel=1e-12)
    # nominal case: the noise-free record gives north to round-off, beside the standard error the noise predicts
    assert abs(data["north_error_rad"]) < 1e-12
    assert 0.05 * ARCSEC < data["north_std_predicted_rad"] < 5 * ARCSEC
    assert data["inputs"]["readout_noise"] == pytest.approx(ARCSEC)
    assert data["inputs"]["fidelity"] == "closed"
    assert numeric_keys_without_unit(data) <= set(data["units"])
    assert data["units"]["readout_noise"] == "rad"


def test_run_monte_carlo_agrees_with_prediction(run_cli):
    out = run_cli("north", "run", "--readout-noise", "5 arcsec", "--duration", "300", "--monte-carlo", "300",
                  "--seed", "11", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    stats = data["monte_carlo"]["statistics"]
    assert stats["converged"]["mean"] == 1.0
    # 300 members: the sample std is within 4 standard errors (4.1 % each) of the linearised prediction
    assert stats["north_error_rad"]["std"] == pytest.approx(data["north_std_predicted_rad"], rel=0.17)
    # the estimator is unbiased to well within the scatter of the mean (std / sqrt(300))
    assert abs(stats["north_error_rad"]["mean"]) < 4 * stats["north_error_rad"]["std"] / math.sqrt(300)


@pytest.mark.slow
def test_run_writes_figures_and_data(run_cli, tmp_path):
    out = run_cli("north", "run", "--readout-noise", "5 arcsec", "--monte-carlo", "20", "--out", tmp_path)
    assert out.code == 0, out.stderr
    assert "records identified and converged" in out.stdout
    for name in ("north_fit.png", "north_fit.svg", "north_monte_carlo.png", "north_monte_carlo.svg",
                 "north_error_vs_time.png", "north_misfit_map.svg", "north_record_fit.csv"):
        assert (tmp_path / name).stat().st_size > 500


def test_simulated_fidelity_is_a_named_choice(run_cli):
    closed = run_cli("north", "run", "--unknowns", "3", "--json").json()
    simulated = run_cli("north", "run", "--unknowns", "3", "--fidelity", "simulated", "--json").json()
    assert simulated["fidelity"] == "simulated" and closed["fidelity"] == "closed"
    # eq. (9) against DOP853 at rtol 1e-12: the records differ by < 1e-9 rad, so does north
    assert simulated["north_rad"] == pytest.approx(closed["north_rad"], abs=1e-9)
    assert run_cli("north", "run", "--fidelity", "rough").code == 2


def test_reproduce_json(run_cli, tmp_path):
    out = run_cli("north", "reproduce", "--unknowns", "4", "--json", "--out", tmp_path)
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["schuler_version"] and "units" in data
    rows = {row["quantity"]: row for row in data["rows"]}
    assert not [row for row in data["rows"] if row["verdict"].startswith("differs")]
    alpha0 = rows["alpha0 identified (4 unknowns, lsq)"]
    assert (alpha0["printed"], alpha0["where"]) == ("3,69π/540", "simulator input, before Table 1")
    assert alpha0["computed"] == pytest.approx(3.69, rel=1e-9)
    identification = data["details"]["identification"]
    assert identification["decay_rate"] == pytest.approx(2.15e-3, rel=1e-9)
    assert identification["hm"] == pytest.approx(0.432, rel=1e-9)
    assert len(data["details"]["stages_in_source_units"]) == 9
    assert not any(reading["reproduces"] for reading in data["details"]["table1_readings"])
    for name in ("north_fit.png", "north_misfit_map.svg", "north_table1.csv"):
        assert (tmp_path / name).stat().st_size > 500
    table = pd.read_csv(tmp_path / "north_table1.csv")
    assert len(table) == 247 and {"printed_misfit_rad2", "sum_of_squares_rad2"} <= set(table.columns)


def test_reproduce_human_explains_each_disagreement(run_cli):
    out = run_cli("north", "reproduce", "--unknowns", "2")
    assert out.code == 0, out.stderr
    lines = out.stdout.splitlines()
    # text after Table 1: the second approximation's printed F 0.362*10^-4 is not the computed sum of squares
    start = next(i for i, line in enumerate(lines) if "2 unknowns, stage" in line and "0.362*10^-4" in line)
    assert "erratum" in lines[start]
    number = lines[start].rsplit("[", 1)[1].split("]")[0]
    note = next(line for line in lines if line.startswith(f"[{number}] "))
    assert "the source's misfit is not F" in note
    # 4 unknowns, stage 1: the printed best cell is not the grid's minimum
    assert any("the printed best (4, 4, 2.2, 0.43) is not the grid's minimum" in line for line in lines)


@pytest.mark.parametrize(
    "args, needle",
    [
        (("run", "--decay-rate", "0"), "--decay-rate"),
        (("run", "--decay-rate", "-1e-3"), "--decay-rate"),
        (("run", "--hm", "0"), "--hm"),
        (("run", "--latitude", "90"), "--latitude"),
        (("run", "--latitude", "-90"), "--latitude"),
        (("run", "--duration", "2", "--unknowns", "4"), "--unknowns"),
        (("run", "--output-step", "300"), "--output-step"),
        (("run", "--latitude", "50", "--omega-h", "3e-5"), "--latitude"),
        (("run", "--readout-noise", "1 m"), "--readout-noise"),
        (("run", "--seed", "-1"), "--seed"),
        (("run", "--monte-carlo", "-1"), "--monte-carlo"),
        (("run", "--lambda", "2e-3"), "--lambda"),
        (("run", "--step", "1"), "--step"),
        (("run", "--noise", "1"), "--noise"),
        (("simulate", "--readout-noise", "-1", "-o", "x.csv"), "--readout-noise"),
        (("simulate", "--seed", "-5", "-o", "x.csv"), "--seed"),
        (("reproduce", "--unknowns", "6"), "--unknowns"),
        (("reproduce", "--method", "fast"), "--method"),
    ],
)
def test_bad_input_is_one_line_exit_2(run_cli, args, needle, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    out = run_cli("north", *args)
    assert out.code == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("schuler: error:") and needle in lines[0]
    assert not (tmp_path / "x.csv").exists()


@pytest.mark.parametrize("command", [("run",), ("simulate", "-o", "big.csv")])
def test_memory_refused_before_allocating(run_cli, command, tmp_path, monkeypatch):
    # issue 13: 1e9 s every 1e-3 s is 1e12 samples (7 TiB for the record alone): one line naming the options
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SCHULER_TIME_BUDGET", "none")  # the time estimate would refuse it first
    out = run_cli("north", *command, "--duration", "1e9 s", "--output-step", "1e-3 s")
    assert out.code == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "memory budget" in lines[0] and "--duration or --output-step" in lines[0]
    assert not list(tmp_path.iterdir())


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


@pytest.mark.parametrize(
    "content",
    [
        "t_s,alpha_rad\n0,0\n1,1e-5\n# café\n".encode("latin-1"),
        "t_s,alpha_rad\n0,0\n1,1e-5\n".encode("utf-16"),
        b"\x7fELF\x02\x01\x01\x00\x00\x00\x00\x00\x00\x00\x00\x00\x03\x00>\x00\x01\x00\x00\x00" * 50,
    ],
    ids=["latin-1", "utf-16", "binary"],
)
def test_record_not_utf8_is_one_clear_error(tmp_path, run_cli, content):
    path = tmp_path / "record.csv"
    path.write_bytes(content)
    out = run_cli("north", "identify", path)
    assert out.code == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and str(path) in lines[0] and "UTF-8" in lines[0]
    assert "UnicodeDecodeError" not in out.stderr


def test_record_with_byte_order_mark_is_accepted(record_file, tmp_path, run_cli):
    # a spreadsheet's "CSV UTF-8" starts with a byte-order mark
    marked = tmp_path / "marked.csv"
    marked.write_bytes(b"\xef\xbb\xbf" + record_file.read_bytes())
    plain = run_cli("north", "identify", record_file, "--json").json()
    out = run_cli("north", "identify", marked, "--json")
    assert out.code == 0, out.stderr
    assert out.json()["north_rad"] == plain["north_rad"]


def test_missing_record_file(tmp_path, run_cli):
    out = run_cli("north", "identify", tmp_path / "none.csv")
    assert out.code == 2 and "no such file" in out.stderr


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="needs a folder where files cannot be created")
def test_unwritable_output_names_the_users_path(run_cli):
    out = run_cli("north", "simulate", "-o", "/proc/x.csv")
    assert out.code == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "/proc/x.csv" in lines[0] and ".part" not in lines[0]


def test_help_shows_the_new_names(run_cli):
    help_text = run_cli("north", "run", "--help").stdout
    for option in ("--decay-rate", "--output-step", "--readout-noise", "--monte-carlo", "--seed", "--fidelity"):
        assert option in help_text
    for old in ("--lambda", "--noise ", "--step "):
        assert old not in help_text
    assert "--seed" in run_cli("north", "simulate", "--help").stdout
    assert "--seed" not in run_cli("north", "identify", "--help").stdout


FIT_FILES = {f"{stem}.{ext}" for stem in ("north_fit", "north_misfit_map", "north_error_vs_time")
             for ext in ("png", "svg")} | {"north_record_fit.csv"}
RUN_KEYS = {"converged", "fidelity", "files", "identified_alpha0_dot_rad_s", "identified_alpha0_rad",
            "identified_decay_rate", "identified_directive_coefficient", "identified_hm", "identified_offset_rad",
            "identified_torque", "inputs", "method", "misfit_rad2", "model_evaluations", "monte_carlo",
            "north_error_rad", "north_rad", "north_std_predicted_rad", "north_std_rad", "omega_h", "reading",
            "readout_noise_rad", "residual_rms_rad", "samples", "schuler_version", "true_north_rad", "units",
            "unknowns"}
COMMANDS = {
    "run": (("run",), RUN_KEYS, FIT_FILES),
    "run-monte-carlo": (("run", "--monte-carlo", "5"), RUN_KEYS,
                        FIT_FILES | {"north_monte_carlo.png", "north_monte_carlo.svg"}),
    "simulate": (("simulate", "-o", "{tmp}/rec.csv"),
                 {"directive_coefficient", "duration_s", "files", "inputs", "omega_h", "output_step_s", "reading",
                  "readout_noise_rad", "record_file", "samples", "schuler_version", "seed", "true_north_rad",
                  "units"}, {"north_record.png", "north_record.svg"}),
    "identify": (("identify", "{tmp}/rec.csv"),
                 {"alpha0_dot_rad_s", "alpha0_dot_std_rad_s", "alpha0_rad", "alpha0_std_rad", "converged",
                  "convergence", "correlation", "decay_rate", "decay_rate_std", "directive_coefficient",
                  "directive_coefficient_std", "files", "hm", "hm_std", "identified", "inertia", "inputs", "method",
                  "misfit_rad2", "model_evaluations", "north_rad", "north_std_rad", "offset_rad", "offset_std_rad",
                  "omega_h", "reading", "residual_rms_rad", "samples", "schuler_version", "torque", "torque_std",
                  "units", "unknowns"}, FIT_FILES),
    "reproduce": (("reproduce",),
                  {"constants", "details", "files", "inputs", "notes", "rows", "schuler_version", "source", "system",
                   "units"},
                  {"north_fit.png", "north_fit.svg", "north_misfit_map.png", "north_misfit_map.svg",
                   "north_table1.csv"}),
    "compare": (("compare", "--monte-carlo", "4", "--duration", "60"),
                {"axes", "carousel_period_s", "duration_s", "files", "grade", "ground_gyrocompass", "heading_rad",
                 "inputs", "latitude_rad", "members", "methods", "notes", "sample_interval_s", "schuler_version",
                 "seed", "units", "versus_grade", "versus_time"},
                {"north_compare_accuracy.csv", "north_compare_accuracy.png", "north_compare_accuracy.svg"}),
}
"""What each command gave with --json and --out before north moved to the one evaluation (its keys and files)."""


@pytest.mark.slow
def test_every_command_keeps_its_json_keys_and_files(run_cli, tmp_path):
    light = ("--duration", "600", "--readout-noise", "1")
    for name, (args, keys, files) in COMMANDS.items():
        args = tuple(arg.format(tmp=tmp_path) for arg in args)
        extra = light if args[0] in ("run", "simulate") else ()
        out = run_cli("north", *args, *extra, "--json", "--out", tmp_path / name)
        assert out.code == 0, (name, out.stderr)
        data = out.json()
        assert set(data) == keys, name
        assert {p.name for p in (tmp_path / name).iterdir() if not p.name.startswith(".")} == files, name
        assert {Path(f).name for f in data["files"]} >= files, name
    run = pd.read_csv(tmp_path / "run" / "north_record_fit.csv")
    assert list(run.columns) == ["t_s", "observed_rad", "fitted_rad", "residual_rad"] and len(run) == 601
    assert list(pd.read_csv(tmp_path / "identify" / "north_record_fit.csv").columns) == list(run.columns)
    assert list(pd.read_csv(tmp_path / "reproduce" / "north_table1.csv").columns) == [
        "k", "m", "alpha0_rad", "alpha0_dot_rad_s", "printed_misfit_rad2", "sum_of_squares_rad2", "misprint"]
    assert list(pd.read_csv(tmp_path / "compare" / "north_compare_accuracy.csv").columns) == [
        "duration_s", "two_position", "four_position", "carousel", "ground_gyrocompass"]
    data = run_cli("north", "run", *light, "--json").json()
    assert data["converged"] is True and data["samples"] == 601 and data["units"]["unknowns"] == "1"
