"""``schuler errors`` end to end, in-process."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.core.earth import FOOT

ROW_KEYS = {"source", "earth", "quantity", "computed_ft", "printed_ft", "agrees", "note"}


def test_reproduce_json_rows(run_cli):
    out = run_cli("errors", "reproduce", "--json")
    assert out.code == 0, out.stderr
    rows = out.json()["rows"]
    assert all(set(row) == ROW_KEYS for row in rows)
    assert {row["source"] for row in rows} == {"tilt", "velocity", "accelerometer", "drift", "azimuth", "hover"}
    assert {row["earth"] for row in rows} == {"flat", "spherical", "vertical"}
    assert {row["quantity"] for row in rows} == {"at_10120s", "max", "at_T"}
    tilt_max = next(r for r in rows if (r["source"], r["quantity"]) == ("tilt", "max"))
    assert tilt_max["printed_ft"] == 3650 and not tilt_max["agrees"] and "7,300" in tilt_max["note"]
    hover = next(r for r in rows if r["source"] == "hover")
    assert hover["computed_ft"] / 5280 == pytest.approx(715.4, abs=0.05)


def test_reproduce_units_change_only_the_human_output(run_cli):
    assert run_cli("errors", "reproduce", "--units", "mi", "--json").json()["rows"] == \
        run_cli("errors", "reproduce", "--json").json()["rows"]
    feet = run_cli("errors", "reproduce").stdout
    miles = run_cli("errors", "reproduce", "--units", "mi").stdout
    assert "288,000" in feet and "7,298.55" in feet
    assert "54.5455" in miles and "(mi)" in miles  # 288,000 ft in miles


def test_run_drift_json(run_cli):
    out = run_cli("errors", "run", "--source", "drift", "--magnitude", "0.01 deg/h", "--duration", "6 h",
                  "--step", "60 s", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    t = np.array(data["t_s"])
    assert t[0] == 0 and t[-1] == 21_600 and t.size == 361
    for key in ("flat_m", "spherical_m", "simulated_m"):
        assert len(data[key]) == t.size
    np.testing.assert_allclose(data["simulated_m"], data["spherical_m"], atol=1e-6)
    omega = math.sqrt(9.80665 / 6.371e6)
    assert data["schuler_period_s"] == pytest.approx(2 * math.pi / omega, rel=1e-12)
    epsilon = math.radians(0.01) / 3600
    assert data["spherical_m"][-1] == pytest.approx(6.371e6 * epsilon / omega * (omega * 21_600 - math.sin(omega * 21_600)))


@pytest.mark.parametrize("source, magnitude", [("tilt", "0.01"), ("velocity", "1"), ("accelerometer", "1e-4"),
                                               ("azimuth", "36 arcsec")])
def test_run_other_sources_with_bare_numbers_in_the_source_unit(run_cli, source, magnitude):
    data = run_cli("errors", "run", "--source", source, "--magnitude", magnitude, "--earth", "bollay", "--json").json()
    expected = {"tilt": math.radians(0.01), "velocity": FOOT, "accelerometer": 1e-4 * 9.80665,
                "azimuth": math.radians(0.01)}[source]
    assert data["inputs"]["magnitude"] == pytest.approx(expected, rel=1e-12)
    assert data["schuler_period_s"] == pytest.approx(5060.0, rel=1e-12)


def test_run_radius_and_gravity_override_the_preset(run_cli):
    data = run_cli("errors", "run", "--radius", "6400 km", "--gravity", "9.81", "--json").json()
    assert data["schuler_period_s"] == pytest.approx(2 * math.pi * math.sqrt(6.4e6 / 9.81), rel=1e-12)


def test_run_human_output_in_feet_and_files(run_cli, tmp_path):
    out = run_cli("errors", "run", "--source", "velocity", "--units", "ft", "--step", "101.2", "--out", str(tmp_path))
    assert out.code == 0 and "(ft)" in out.stdout
    assert {p.suffix for p in tmp_path.iterdir()} == {".png", ".svg", ".csv"}


@pytest.mark.parametrize(
    "args, option",
    [
        (["--magnitude", "-1"], "--magnitude"),
        (["--magnitude", "nan"], "--magnitude"),
        (["--duration", "-5"], "--duration"),
        (["--duration", "nan"], "--duration"),
        (["--radius", "0"], "--radius"),
        (["--source", "gyro"], "--source"),
        (["--source", "tilt", "--magnitude", "1 ft/s"], "--magnitude"),
        (["--duration", "5 m"], "--duration"),
        (["--step", "2 h", "--duration", "1 h"], "--step"),
        (["--units", "km"], "--units"),
    ],
)
def test_run_bad_input_is_one_line_naming_the_option(run_cli, args, option):
    out = run_cli("errors", "run", *args)
    assert out.code == 2
    assert out.stderr.count("\n") == 1 and out.stderr.startswith("schuler: error:")
    assert option in out.stderr


@pytest.mark.slow
def test_plot_writes_png_and_svg(run_cli, tmp_path):
    out = run_cli("errors", "plot", "--out", str(tmp_path), "--points", "101", "--json")
    assert out.code == 0, out.stderr
    names = {p.name for p in tmp_path.iterdir()}
    for stem in ("tilt", "velocity", "accelerometer", "drift", "azimuth", "overview", "vertical"):
        assert {f"errors_{stem}.png", f"errors_{stem}.svg"} <= names
    assert len(out.json()["files"]) == 14


def test_vertical_command(run_cli):
    data = run_cli("errors", "vertical", "--order", "2", "--time-constant", "50 s", "--step", "25", "--json").json()
    assert data["k1_per_s"] == pytest.approx(0.04)
    assert max(data["poles_real_per_s"]) < 0
    assert data["aided_m"][-1] == pytest.approx(data["aided_steady_state_m"], rel=1e-6)
    out = run_cli("errors", "vertical", "--k2", "1e-7")
    assert out.code == 2 and "--k2" in out.stderr


def test_period_command(run_cli):
    data = run_cli("errors", "period", "--thrust-factor", "9", "--json").json()
    assert data["thrust_period_s"] == pytest.approx(data["nominal_period_s"] / 3, rel=1e-12)
    out = run_cli("errors", "period", "--speed", "8 km/s", "--json")
    assert out.code == 0 and "orbital speed" in out.stderr
    assert out.json()["flight_period_s"] is None  # infinite: JSON has no inf
