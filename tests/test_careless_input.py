"""Careless input gets one clear line: unit text read as data, long lines and deep files bounded, ranges stated."""

from __future__ import annotations

import math
import time

import pytest

from schuler.exceptions import InvalidParameter, ScenarioError
from schuler.study.scenario import parse_scenario
from schuler.units import MAX_TEXT_LENGTH, parse_quantity, quoted

G0 = 9.80665
DEG = math.pi / 180


def one_line_error(out) -> str:
    """The single stderr line of a refused command (exit 2, no traceback)."""
    assert out.code == 2, (out.code, out.stderr[-500:])
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("schuler: error: "), out.stderr[-2000:]
    return lines[0]


@pytest.mark.parametrize(
    ("text", "unit", "expected"),
    [
        ("1e-4 g", "g", 1e-4 * G0),
        ("0.01 deg/h", "deg/h", 0.01 * DEG / 3600),
        ("1.5e+3 m", "m", 1500.0),
        ("86_400 s", "s", 86400.0),
        ("10_000", "m", 10000.0),
        ("5 deg/sqrt(h)", "deg/h^0.5", 5 * DEG / 60),
        ("5 deg/√h", "deg/h^0.5", 5 * DEG / 60),
        ("20 ug/√Hz", "m/s^2/Hz^0.5", 20e-6 * G0),
        ("20 µg/√Hz", "m/s^2/Hz^0.5", 20e-6 * G0),
        ("20 μg/sqrt(Hz)", "m/s^2/Hz^0.5", 20e-6 * G0),  # Greek mu as well as the micro sign
        ("150 ppm", "", 150e-6),
        ("3 percent", "", 0.03),
        ("3 %", "", 0.03),
        ("2 arcsec", "rad", 2 * DEG / 3600),
        ("9.81 m/s^2", "g", 9.81),
        ("9.81 m/s**2", "g", 9.81),
        ("0.065 ft/s/sqrt(h)", "m/s/h^0.5", 0.065 * 0.3048 / 60),
        ("0.01 deg/s/g", "deg/h/g", 0.01 * DEG / G0),
        ("1 h^(-1/2)", "Hz^0.5", 1 / 60),
        ("3 °/h", "deg/h", 3 * DEG / 3600),
        ("2e-3 1/s", "1/s", 2e-3),
        ("2e-3/s", "1/s", 2e-3),
        ("0.43 N m s", "N*m*s", 0.43),
        ("1e-3 kg*m^2", "kg*m^2", 1e-3),
        ("20 mrad", "rad", 0.02),
        ("1.5 V/deg", "V/deg", 1.5 / DEG),
    ],
)
def test_units_the_field_writes_are_read(text, unit, expected):
    assert parse_quantity(text, unit, name="x") == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("text", ["10**10**10 deg", "10**10**10", "10**400 deg", "2*3 deg", "1/2 deg", "5 + 1 deg",
                                  "3.69*pi/540 rad"])
def test_an_expression_is_refused_at_once(text):
    start = time.perf_counter()
    with pytest.raises(InvalidParameter, match="a number and a unit, not an expression"):
        parse_quantity(text, "deg", name="latitude")
    assert time.perf_counter() - start < 0.1  # read, not evaluated (10**10**10 would take hours)


@pytest.mark.parametrize(("text", "message"), [
    ("2 m^10", "a power of 10 (at most 4 in size)"),
    ("2 m/s^x", "a power must be a number"),
    ("5 deg/(h", "a parenthesis is not closed"),
    ("12 furlongz", "unknown unit 'furlongz'"),
    ("deg", "it does not start with a number"),
])
def test_a_malformed_unit_says_what_is_wrong(text, message):
    with pytest.raises(InvalidParameter, match=re_escape(message)):
        parse_quantity(text, "m", name="x")


def re_escape(text: str) -> str:
    import re

    return re.escape(text)


def test_numbers_too_large_for_a_float_and_long_text_are_one_message():
    with pytest.raises(InvalidParameter, match=r"'1e400 deg': the number is too large \(floats end near 1.8e308\)"):
        parse_quantity("1e400 deg", "deg", name="latitude")
    with pytest.raises(InvalidParameter, match="the number is too large"):
        parse_quantity(10**400, "deg", name="latitude")
    with pytest.raises(InvalidParameter, match=r"'1e308 mi' is too large once in SI \(m\)"):
        parse_quantity("1e308 mi", "m", name="height")
    text = "1" + " " * 50 + "m" * 100
    with pytest.raises(InvalidParameter, match=f"too long for a quantity \\(at most {MAX_TEXT_LENGTH} characters"):
        parse_quantity(text, "m", name="x")
    with pytest.raises(InvalidParameter) as error:
        parse_quantity("x" * 10**6, "m", name="x")
    assert len(str(error.value)) < 200  # the text is quoted as an excerpt


def test_a_dimensionless_parameter_asks_for_a_plain_number():
    with pytest.raises(InvalidParameter) as error:
        parse_quantity("5 deg", "", name="damping")
    assert str(error.value) == "damping: '5 deg' is not a plain number (expected a plain number, without a unit)"


def test_quoted_cuts_long_text():
    assert quoted("abc") == "'abc'"
    assert quoted("y" * 200) == "'" + "y" * 80 + "...' (200 characters)"
    assert len(quoted(list(range(10**4)))) == 83


def test_every_unit_of_the_examples_and_presets_reads():
    from pathlib import Path

    from schuler.imu.spec import preset
    from schuler.study.scenario import load_scenario

    examples = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.toml"))
    assert len(examples) >= 10
    for path in examples:
        load_scenario(path)
    for grade in ("navigation", "tactical", "industrial", "consumer"):
        preset(grade)


# ---- the command line ------------------------------------------------------------------------------------------


def test_cli_refuses_expressions_and_huge_numbers_in_one_line(run_cli):
    start = time.perf_counter()
    line = one_line_error(run_cli("north", "run", "--alpha0", "10**10**10"))
    assert "--alpha0: cannot read '10**10**10' as a quantity in rad: a number and a unit, not an expression" in line
    line = one_line_error(run_cli("align", "run", "--latitude", "10**400 deg"))
    assert "--latitude: cannot read '10**400 deg'" in line
    line = one_line_error(run_cli("align", "run", "--latitude", "1e400"))
    assert "--latitude: '1e400': the number is too large" in line
    assert time.perf_counter() - start < 20


def test_north_default_alpha0_is_the_source_value(run_cli):
    from schuler.ground_gyrocompass import motion

    out = run_cli("north", "run", "--help")
    assert out.code == 0 and "[default: 0.0214675 rad]" in " ".join(out.stdout.split())
    assert motion.SOURCE_ALPHA0 == pytest.approx(3.69 * math.pi / 540, rel=1e-15)


def test_drift_and_tuning_have_physical_ranges(run_cli):
    line = one_line_error(run_cli("align", "run", "--drift-east", "1e300 deg/h"))
    assert line == "schuler: error: --drift-east: '1e300 deg/h' is outside [-15, 15] deg/h"
    for option in ("--drift-north", "--drift-x", "--drift-y", "--drift-z"):
        assert "is outside [-15, 15] deg/h" in one_line_error(run_cli("align", "run", option, "16"))
    line = one_line_error(run_cli("vertical", "run", "--schuler-tuning", "1e-300"))
    assert line == "schuler: error: --schuler-tuning: '1e-300' is outside [0.01, 100]"
    assert "outside [0.01, 100]" in one_line_error(run_cli("vertical", "run", "--schuler-tuning", "1e301"))
    help_text = " ".join(run_cli("align", "run", "--help").stdout.split())
    assert "a larger drift leaves no north to find. Range [-15, 15] deg/h" in help_text


def test_an_empty_out_is_refused(run_cli, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for args in (("align", "run", "--duration", "60"), ("report",)):
        line = one_line_error(run_cli(*args, "--out", ""))
        assert "--out" in line and "an empty folder name" in line
    assert not list(tmp_path.iterdir())  # nothing written into the current folder


def test_magnitude_out_of_range_gives_the_range(run_cli):
    line = one_line_error(run_cli("errors", "run", "--magnitude", "1e300"))
    assert line == ("schuler: error: --magnitude: '1e300' is out of range: a magnitude is at most 10 deg (tilt), "
                    "30000 ft/s (velocity), 1 g (accelerometer), 3600 deg/h (drift), 90 deg (azimuth)")
    line = one_line_error(run_cli("errors", "run", "--magnitude", "1e300 deg"))
    assert line.endswith("is out of range: a magnitude is at most 10 deg (tilt), 90 deg (azimuth)")


def test_imu_messages_say_what_is_wrong(run_cli, tmp_path):
    record = tmp_path / "record.csv"
    record.write_text("t_s,gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2\n"
                      + "".join(f"{0.01 * k:.2f},0,0,0,0,0,-9.8\n" for k in range(1, 5)), encoding="utf-8")
    line = one_line_error(run_cli("imu", "allan", record, "--columns", "garbage"))
    assert "--columns: 'garbage' is not channel=value; write e.g. 'time=t,gyro_x=wx,accel_x=ax'" in line
    line = one_line_error(run_cli("imu", "allan", record, "--units", "garbage"))
    assert "--units: 'garbage' is not channel=value; write e.g. 'gyro=deg/s,accel=g'" in line
    line = one_line_error(run_cli("imu", "allan", "/dev/zero"))
    assert line == "schuler: error: zero: not a regular file (a device, pipe or socket); give an IMU file"
    assert "no such file" in one_line_error(run_cli("imu", "allan", tmp_path / "missing.csv"))


@pytest.mark.parametrize("suffix", [".csv", ".imu"])
def test_a_huge_header_line_is_refused_with_an_excerpt(run_cli, tmp_path, suffix, monkeypatch):
    from schuler.imu import readers

    path = tmp_path / f"huge{suffix}"
    path.write_text(("%" if suffix == ".imu" else "t_s,") + "x" * 5_000_000 + "\n1,2\n", encoding="utf-8")
    read = []
    original = readers._bounded_lines

    def counting(path_, handle):
        for line in original(path_, handle):
            read.append(len(line))
            yield line

    monkeypatch.setattr(readers, "_bounded_lines", counting)
    line = one_line_error(run_cli("imu", "allan", path))
    assert f"huge{suffix}, line 1: a line longer than 65,536 characters" in line
    assert len(line) < 300  # an excerpt, not the 5-MB line
    assert not read  # refused before the line was handed on whole


def test_a_long_column_list_is_quoted_short(run_cli, tmp_path):
    path = tmp_path / "wide.csv"
    path.write_text("t_s," + ",".join(f"c{k}" for k in range(5000)) + "\n0.01,1\n", encoding="utf-8")
    line = one_line_error(run_cli("imu", "allan", path))
    assert "no column 'gyro_x_rad_s' for gyro_x" in line and len(line) < 300


# ---- scenario files --------------------------------------------------------------------------------------------


def test_a_deeply_nested_scenario_is_not_valid_toml():
    text = 'system = "align"\n[parameters]\nlatitude = ' + "[" * 5000 + "]" * 5000 + "\n"
    with pytest.raises(ScenarioError, match="s.toml: not valid TOML: arrays or tables nested too deeply"):
        parse_scenario(text, source="s.toml")
    text = 'system = "align"\n[parameters]\nlatitude = ' + "{a = " * 5000 + "1" + "}" * 5000 + "\n"
    with pytest.raises(ScenarioError, match="not valid TOML: arrays or tables nested too deeply"):
        parse_scenario(text, source="s.toml")


@pytest.mark.parametrize(("body", "expected"), [
    ("[parameters]\nlatitude = [1, 2]", "[parameters] latitude: expected a number or a string with a unit; "
                                        "got an array [1, 2]"),
    ("[parameters]\nlatitude = 1979-05-27", "[parameters] latitude: expected a number or a string with a unit; "
                                            "got a date 1979-05-27"),
    ("[parameters]\nlatitude = 07:32:00", "got a time of day 07:32:00"),
    ("[parameters]\nlatitude = 1979-05-27T07:32:00", "got a date-time 1979-05-27T07:32:00"),
    ("[parameters]\nmodel = [1]", "[parameters] model: expected one of full, full-ab, simplified (a string); "
                                  "got an array [1]"),
    ("[monte_carlo]\nseed = \"x\"", "[monte_carlo] seed: expected a whole number; got a string 'x'"),
    ("[monte_carlo.uniform]\nlatitude = 5", "[monte_carlo.uniform] latitude: expected two values [low, high]; "
                                            "got an integer 5"),
    ("[outputs]\njson = [1]", "[outputs] json: expected true or false; got an array [1]"),
    ("title = 5", "title: expected a string; got an integer 5"),
])
def test_a_value_of_the_wrong_toml_type_says_what_was_expected_and_given(body, expected):
    with pytest.raises(ScenarioError) as error:
        parse_scenario(f'system = "align"\n{body}\n', source="s.toml")
    assert expected in str(error.value) and "boolean" not in str(error.value).replace("a boolean", "")


def test_long_scenario_values_and_keys_are_quoted_short():
    for text in ('system = "' + "x" * 10**5 + '"\n', 'system = ["a"]\n',
                 'system = "align"\n[parameters]\n' + "k" * 10**5 + " = 1\n",
                 'system = "align"\n[parameters]\nlatitude = "' + "9" * 10**5 + '"\n'):
        with pytest.raises(ScenarioError) as error:
            parse_scenario(text, source="s.toml")
        assert len(str(error.value).split("; allowed:")[0]) < 300


def test_the_lab_answers_a_power_expression_at_once():
    from schuler.lab.controls import parse_typed
    from schuler.study.systems import load_system

    parameters = load_system("align").parameters
    start = time.perf_counter()
    values, errors = parse_typed(parameters, {"latitude": "10**10**10 deg", "azimuth": "1e400 deg"})
    assert time.perf_counter() - start < 0.5  # the lab server stays free (it was busy for minutes)
    assert values is None
    assert errors == {"latitude": "--latitude: cannot read '10**10**10 deg' as a quantity in deg: a number and a "
                                  "unit, not an expression",
                      "azimuth": "--azimuth: '1e400 deg': the number is too large (floats end near 1.8e308)"}


def test_align_compare_refuses_a_huge_initial_window(run_cli):
    line = one_line_error(run_cli("align", "compare", "--imu", "tactical", "--duration", "60",
                                  "--initial-window", "1e308"))
    assert line == "schuler: error: --initial-window: '1e308' is outside (0, 86400] s"
