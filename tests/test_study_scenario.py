"""Scenario files: validation messages, the ``schuler run SCENARIO.toml`` command, equivalence with the API."""

from __future__ import annotations

import math

import numpy as np
import pytest

import test_study_fake_system as fake
from schuler.exceptions import ScenarioError
from schuler.study.scenario import load_scenario, parse_scenario

GOOD = """\
system = "fake"
title = "A study"

[parameters]
latitude = "45 deg"
drift_east = 0.02          # bare number: deg/h
method = "table"
members = 2

[simulation]
duration = "2 h"
output_step = "0.5 s"

[outputs]
json = false

[monte_carlo]
seed = 7
cases = 10
[monte_carlo.normal]
drift_east = "0.005 deg/h"
[monte_carlo.uniform]
gain = [0.5, 2]
"""


@pytest.fixture(autouse=True)
def fake_system(monkeypatch):
    fake.register(monkeypatch)


def write(tmp_path, text, name="scenario.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_a_scenario_gives_si_values_defaults_and_monte_carlo(tmp_path):
    scenario = load_scenario(write(tmp_path, GOOD))
    assert scenario.system == "fake" and scenario.title == "A study"
    assert scenario.values["latitude"] == pytest.approx(math.radians(45))
    assert scenario.values["drift_east"] == pytest.approx(math.radians(0.02) / 3600)
    assert scenario.values["duration"] == 7200.0 and scenario.values["output_step"] == 0.5
    assert scenario.values["gain"] == 1.0  # default
    assert scenario.values["members"] == 2 and scenario.values["method"] == "table"
    mc = scenario.monte_carlo
    assert (mc.seed, mc.cases) == (7, 10)
    assert mc.distributions["drift_east"].first == pytest.approx(math.radians(0.005) / 3600)
    assert (mc.distributions["gain"].first, mc.distributions["gain"].second) == (0.5, 2.0)
    assert scenario.values.given == {"latitude", "drift_east", "method", "members", "duration", "output_step"}


def test_run_prints_what_the_api_returns(tmp_path, run_cli):
    path = write(tmp_path, GOOD)
    out = run_cli("run", path, "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    expected = fake.FAKE.run(**load_scenario(path).given())
    assert data["azimuth_error_rad"] == pytest.approx(expected.azimuth_error_rad, rel=1e-12)
    assert data["settling_time_s"] == 2 * 7200.0
    assert data["inputs"]["latitude"] == pytest.approx(math.radians(45))
    text = run_cli("run", path)
    assert text.code == 0 and "azimuth_error (arcmin)" in text.stdout


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        # unknown key, with a suggestion and the allowed keys
        ('system = "fake"\n[parameters]\nlattitude = 50\n',
         "[parameters] lattitude: unknown key; did you mean 'latitude'?"),
        ('system = "fake"\ncolour = "red"\n', "colour: unknown key"),
        ('system = "fake"\n[simulation]\ntime = "1 h"\n',
         "[simulation] time: unknown key; allowed: duration, output_step"),
        ('system = "fake"\n[outputs]\nfolder = "x"\n', "[outputs] folder: unknown key"),
        ('system = "fake"\n[parameters]\nduration = "1 h"\n[simulation]\nduration = "2 h"\n',
         "[simulation] duration: also set as [parameters] duration; set it once"),
        # bad unit: dimension checked
        ('system = "fake"\n[parameters]\ndrift_east = "0.01 m"\n',
         "[parameters] drift_east: '0.01 m' is not an angular rate"),
        ('system = "fake"\n[parameters]\nlatitude = "50 furlongs"\n', "[parameters] latitude: "),
        ('system = "fake"\n[simulation]\nduration = "2 deg"\n', "[simulation] duration: '2 deg' is not a time"),
        # out of range
        ('system = "fake"\n[parameters]\nlatitude = "95 deg"\n',
         "[parameters] latitude: '95 deg' is outside [-89, 89] deg"),
        ('system = "fake"\n[parameters]\ngain = 0\n', "[parameters] gain: 0 is outside (0, inf)"),
        ('system = "fake"\n[parameters]\nmethod = "guess"\n',
         "[parameters] method: 'guess' is not one of closed, table"),
        ('system = "fake"\n[parameters]\nmembers = 0\n', "[parameters] members: 0 is outside [1, inf)"),
        # wrong types
        ('system = "fake"\n[parameters]\nlatitude = [1, 2]\n',
         "[parameters] latitude: expected a number or a string with a unit; got an array [1, 2]"),
        ('system = "fake"\nparameters = 3\n', "parameters: 3 must be a table"),
        # system
        ('[parameters]\nlatitude = 1\n', "system: missing"),
        ('system = "gyro"\n', "system: 'gyro' is not one of"),
        # Monte Carlo tables
        ('system = "fake"\n[monte_carlo.normal]\ndrift_east = "1 m"\n',
         "[monte_carlo.normal] drift_east: '1 m' is not an angular rate"),
        ('system = "fake"\n[monte_carlo.uniform]\nlatitude = ["10 deg", "99 deg"]\n',
         "[monte_carlo.uniform] latitude: '99 deg' is outside"),
        ('system = "fake"\n[monte_carlo.uniform]\nlatitude = [20, 10]\n',
         "[monte_carlo.uniform] latitude: [20, 10]: the lower end"),
        ('system = "fake"\n[monte_carlo.normal]\nmethod = "x"\n',
         "[monte_carlo.normal] method: only numeric parameters"),
        ('system = "fake"\n[monte_carlo]\ncases = 0\n', "[monte_carlo] cases: 0"),
        # malformed TOML
        ('system = "fake"\n[parameters\nlatitude = 1\n', "not valid TOML: "),
        ('system = "fake"\nlatitude = \n', "not valid TOML: "),
    ],
)
def test_a_bad_scenario_gives_one_line_naming_the_key_and_exit_2(tmp_path, run_cli, text, expected):
    path = write(tmp_path, text)
    out = run_cli("run", path)
    assert out.code == 2
    assert out.stdout == ""
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1, out.stderr
    assert lines[0].startswith(f"schuler: error: {path}: ")
    assert expected in lines[0]


def test_a_normal_spread_needs_a_value_to_spread_around(tmp_path, run_cli):
    from schuler.study.scenario import Distribution
    from schuler.study.systems import load_system

    spec = next(p for p in load_system("align").parameters if p.name == "c_gamma")
    assert spec.default is None  # the case this guards: no default, nothing set in the file
    with pytest.raises(ScenarioError, match=r"\[monte_carlo.normal\] c_gamma: has no value to spread around"):
        Distribution("normal", 0.1).draw(spec, None, 0, np.arange(3))
    path = write(tmp_path, 'system = "align"\n[monte_carlo]\ncases = 4\n[monte_carlo.normal]\nc_gamma = 0.1\n')
    out = run_cli("run", path)
    assert out.code == 2 and out.stdout == ""
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1, out.stderr
    assert lines[0].startswith(f"schuler: error: {path}: [monte_carlo.normal] c_gamma: has no value")


def test_malformed_toml_names_the_line(tmp_path):
    with pytest.raises(ScenarioError, match=r"line 3"):
        parse_scenario('system = "fake"\n[parameters]\nlatitude = = 1\n', source="x.toml")


def test_a_missing_or_unreadable_file_is_one_clear_line(tmp_path, run_cli):
    out = run_cli("run", tmp_path / "nowhere.toml")
    assert out.code == 2
    assert out.stderr.strip() == f"schuler: error: {tmp_path / 'nowhere.toml'}: no such scenario file"
    folder = tmp_path / "folder.toml"
    folder.mkdir()
    out = run_cli("run", folder)
    assert out.code == 2 and "folder.toml' is a directory" in out.stderr
    with pytest.raises(ScenarioError, match="cannot read the scenario file"):
        load_scenario(folder)


def test_outputs_table_and_options(tmp_path, run_cli, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = write(tmp_path, 'system = "fake"\n[outputs]\ndirectory = "out"\njson = true\n')
    scenario = load_scenario(path)
    assert scenario.out_dir is not None and scenario.out_dir.name == "out" and scenario.as_json
    out = run_cli("run", path)
    assert out.code == 0
    assert out.json()["method"] == "closed"  # [outputs] json = true


def test_every_parameter_value_is_checked_by_its_parameter(tmp_path):
    # values exactly at an inclusive bound pass; the strings keep their units
    scenario = parse_scenario('system = "fake"\n[parameters]\nlatitude = "-89 deg"\ndrift_east = "0 deg/h"\n')
    assert scenario.values["latitude"] == pytest.approx(-math.radians(89))
    assert scenario.values["drift_east"] == 0.0
    assert np.isfinite(scenario.definition().run(**scenario.given()).azimuth_error_rad)


@pytest.mark.parametrize("name", ["errors", "vertical", "calibrate", "align", "north", "navigate"])
def test_every_real_system_gets_a_schema_from_its_parameters(name, tmp_path, run_cli):
    from schuler.study.systems import load_system

    system = load_system(name)
    if system is None:
        pytest.skip(f"system {name!r} is not installed yet")
    path = write(tmp_path, f'system = "{name}"\n[parameters]\nno_such_option = 1\n')
    out = run_cli("run", path)
    assert out.code == 2
    allowed = ", ".join(p.name for p in system.parameters)
    assert f"[parameters] no_such_option: unknown key; allowed: {allowed}" in out.stderr
    latitude = next((p for p in system.parameters if p.name == "latitude"), None)
    if latitude is not None:
        out = run_cli("run", write(tmp_path, f'system = "{name}"\n[parameters]\nlatitude = "95 deg"\n'))
        assert out.code == 2
        assert f"[parameters] latitude: '95 deg' is outside {latitude.range_text()}" in out.stderr
        out = run_cli("run", write(tmp_path, f'system = "{name}"\n[parameters]\nlatitude = "95 m"\n'))
        assert out.code == 2 and "[parameters] latitude: '95 m' is not an angle" in out.stderr
