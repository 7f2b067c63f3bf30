"""``schuler errors`` end to end, in-process: run, reproduce, the actions, files and one-line errors."""

from __future__ import annotations

import math

import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from schuler.core.earth import FOOT, STATUTE_MILE

ROW_KEYS = {"quantity", "printed", "where", "computed", "unit", "verdict", "note"}


def test_reproduce_json_rows(run_cli):
    out = run_cli("errors", "reproduce", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["schuler_version"] and data["units"]["computed"] == "the row's unit"
    rows = data["rows"]
    assert len(rows) == 22 and all(set(row) == ROW_KEYS for row in rows)
    assert {row["where"] for row in rows} >= {"Problem 3, summary table", "Problem 4, solution"}
    assert not [row for row in rows if row["verdict"].startswith("differs")]
    tilt_max = next(r for r in rows if r["quantity"].endswith("largest error") and r["printed"] == "3650")
    assert tilt_max["verdict"] == "erratum" and "7300 ft" in tilt_max["note"]
    hover = next(r for r in rows if r["quantity"].startswith("hover"))
    assert (hover["printed"], hover["unit"], hover["verdict"]) == ("724", "mi", "erratum")
    assert hover["computed"] == pytest.approx(715.4, abs=0.05)  # Bollay, Problem 4 with z(0) = z'(0) = 0
    assert data["details"]["schuler_period_s"] == pytest.approx(5060.0)


def test_reproduce_human_output_prints_values_as_printed(run_cli):
    out = run_cli("errors", "reproduce")
    assert out.code == 0, out.stderr
    for text in ("288,000", "1.62 \u00d7 10^6", "4,170", "agrees within 0.5 %", "erratum", "Problem 3, summary table"):
        assert text in out.stdout


def test_run_drift_json(run_cli):
    out = run_cli("errors", "run", "--source", "drift", "--magnitude", "0.01 deg/h", "--duration", "6 h",
                  "--output-step", "60 s", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    omega = math.sqrt(9.80665 / 6.371e6)
    epsilon = math.radians(0.01) / 3600
    assert data["inputs"]["magnitude"] == pytest.approx(epsilon, rel=1e-12)
    assert data["inputs"]["duration"] == 21_600 and data["inputs"]["output_step"] == 60
    assert data["units"]["magnitude"] == "rad/s" and data["units"]["duration"] == "s"
    assert data["schuler_period_s"] == pytest.approx(2 * math.pi / omega, rel=1e-12)
    # Bollay's drift error on the default Earth: (R eps / omega)(omega t - sin omega t)
    expected = 6.371e6 * epsilon / omega * (omega * 21_600 - math.sin(omega * 21_600))
    assert data["final_spherical_m"] == pytest.approx(expected, rel=1e-9)
    assert data["simulation_minus_closed_m"] < 1e-9 * data["max_spherical_m"]
    assert data["fidelity"] == "simulated" and data["inputs"]["fidelity"] == "simulated"


@pytest.mark.parametrize("source, magnitude", [("tilt", "0.01"), ("velocity", "1"), ("accelerometer", "1e-4"),
                                               ("azimuth", "36 arcsec")])
def test_run_other_sources_with_bare_numbers_in_the_source_unit(run_cli, source, magnitude):
    data = run_cli("errors", "run", "--source", source, "--magnitude", magnitude, "--earth", "bollay", "--json").json()
    expected = {"tilt": math.radians(0.01), "velocity": FOOT, "accelerometer": 1e-4 * 9.80665,
                "azimuth": math.radians(0.01)}[source]
    assert data["inputs"]["magnitude"] == pytest.approx(expected, rel=1e-12)
    assert data["schuler_period_s"] == pytest.approx(5060.0, rel=1e-12)


def test_speed_bare_numbers_are_m_per_s_and_unit_strings_still_work(run_cli):
    bare = run_cli("errors", "run", "--source", "azimuth", "--speed", "804.672", "--json").json()
    miles = run_cli("errors", "run", "--source", "azimuth", "--speed", "0.5 mi/s", "--json").json()
    default = run_cli("errors", "run", "--source", "azimuth", "--json").json()
    assert bare["inputs"]["speed"] == 804.672
    assert miles["final_flat_m"] == pytest.approx(bare["final_flat_m"], rel=1e-12)
    assert default["inputs"]["speed"] == pytest.approx(0.5 * STATUTE_MILE, rel=1e-12)


def test_run_radius_and_gravity_override_the_preset(run_cli):
    data = run_cli("errors", "run", "--radius", "6400 km", "--gravity", "9.81", "--json").json()
    assert data["schuler_period_s"] == pytest.approx(2 * math.pi * math.sqrt(6.4e6 / 9.81), rel=1e-12)
    assert data["radius_m"] == 6.4e6 and data["gravity_m_s2"] == 9.81


def test_run_closed_fidelity(run_cli):
    data = run_cli("errors", "run", "--source", "tilt", "--fidelity", "closed", "--json").json()
    assert data["fidelity"] == "closed" and data["simulation_minus_closed_m"] is None


def test_run_human_output_and_files(run_cli, tmp_path):
    out = run_cli("errors", "run", "--source", "velocity", "--output-step", "101.2", "--out", tmp_path)
    assert out.code == 0, out.stderr
    assert " ft)" in out.stdout and "Schuler period" in out.stdout and "simulated" in out.stdout
    # the hidden record lists the files of the run (schuler.io.FILE_SET_RECORD)
    shown = {p.name for p in tmp_path.iterdir() if not p.name.startswith(".")}
    assert shown == {"errors_run_velocity.png", "errors_run_velocity.svg", "errors_run_velocity.csv"}
    table = pd.read_csv(tmp_path / "errors_run_velocity.csv")
    assert table["t_s"].iloc[-1] == 10_120 and len(table) == 101


def test_run_shows_a_spherical_error_far_below_the_flat_one(run_cli):
    # 1e8 s of 0.01 deg/h drift: flat 7.9e16 m, spherical 3.1e7 m; a floor scaled by the flat error hid the latter
    out = run_cli("errors", "run", "--duration", "1e8")
    assert out.code == 0 and out.stderr == "", out.stderr
    rows = {line.split("\u2502")[1].strip(): line.split("\u2502")[2].strip()
            for line in out.stdout.splitlines() if line.count("\u2502") == 3}
    assert rows["spherical Earth at 1e+08 s (simulated)"] == "30,887,641 m (101,337,404 ft)"
    assert rows["largest spherical-Earth error (closed form)"] == "30,887,641 m (101,337,404 ft)"
    # rounding noise is still hidden: the spherical column at t = 0 reads 0, not 1e-20
    assert run_cli("errors", "run", "--duration", "1e8", "--json").json()["warnings"] == []


def test_run_warns_when_the_simulation_loses_its_accuracy(run_cli):
    # R = 1 km, g = 1000 m/s^2: 1.6e8 Schuler periods of 6.3 s in 1e9 s, far past what the simulation holds
    out = run_cli("errors", "run", "--radius", "1", "--gravity", "1000", "--duration", "1e9", "--json")
    assert out.code == 0
    data = out.json()
    # how much is lost after 1.6e8 periods depends on the rounding of the linear-algebra libraries (0.53-0.87 of
    # the error seen); what matters is that it is far past the tolerance and that the warning says how far
    relative = data["simulation_minus_closed_m"] / data["max_spherical_m"]
    assert relative > 0.1
    [message] = data["warnings"]
    assert f"departs from the closed form by {relative:.2g} of the error's size" in message
    assert "1.59e+08 Schuler" in message
    assert out.stderr == f"schuler: warning: {message}\n"
    # a day on the same Earth is within the tolerance: no warning
    quiet = run_cli("errors", "run", "--radius", "1", "--gravity", "1000", "--duration", "1 d", "--json")
    assert quiet.stderr == "" and quiet.json()["warnings"] == []


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
        (["--output-step", "2 h", "--duration", "1 h"], "--output-step"),
        (["--speed", "3 deg"], "--speed"),
        (["--step", "10"], "--step"),
        (["--fidelity", "exact"], "--fidelity"),
        (["--seed", "-1"], "--seed"),
    ],
)
def test_run_bad_input_is_one_line_naming_the_option(run_cli, args, option):
    out = run_cli("errors", "run", *args)
    assert out.code == 2
    assert out.stderr.count("\n") == 1 and out.stderr.startswith("schuler: error:")
    assert option in out.stderr


def test_run_refuses_a_grid_beyond_the_memory_budget(run_cli, monkeypatch):
    monkeypatch.setenv("SCHULER_MEMORY_BUDGET", "100 MiB")
    out = run_cli("errors", "run", "--duration", "1e9 s", "--output-step", "1e-3 s")
    assert out.code == 2 and out.stderr.count("\n") == 1
    assert "memory budget" in out.stderr and "--output-step" in out.stderr


def test_run_monte_carlo_without_random_terms_is_refused(run_cli):
    out = run_cli("errors", "run", "--monte-carlo", "3", "--json")
    assert out.code == 2 and "--monte-carlo: errors has no random terms" in out.stderr


@pytest.mark.slow
def test_plot_writes_png_svg_and_csv(run_cli, tmp_path):
    out = run_cli("errors", "plot", "--out", tmp_path, "--points", "101", "--json")
    assert out.code == 0, out.stderr
    names = {p.name for p in tmp_path.iterdir()}
    for stem in ("tilt", "velocity", "accelerometer", "drift", "azimuth", "overview", "vertical"):
        assert {f"errors_{stem}.png", f"errors_{stem}.svg"} <= names
    assert len(out.json()["files"]) == 16
    assert len(pd.read_csv(tmp_path / "errors_problem3.csv")) == 101


def test_plot_without_out_prints_the_summary(run_cli):
    out = run_cli("errors", "plot", "--points", "11")
    assert out.code == 0 and "--out DIR" in out.stdout and "7,298.55" in out.stdout
    assert run_cli("errors", "plot", "--points", "2").code == 2


def test_vertical_command(run_cli):
    data = run_cli("errors", "vertical", "--order", "2", "--time-constant", "50 s", "--output-step", "25",
                   "--json").json()
    assert data["k1_per_s"] == pytest.approx(0.04)
    assert max(data["poles_real_per_s"]) < 0
    assert data["final_aided_m"] == pytest.approx(data["aided_steady_state_m"], rel=1e-6)
    assert data["units"]["k1_per_s"] == "1/s" and data["units"]["accel_bias_up"] == "m/s^2"
    for args, option in ((["--k2", "1e-7"], "--k2"), (["--time-constant", "50", "--k1", "0.1"], "--time-constant"),
                         (["--order", "2", "--k3", "1e-7"], "--k3"), (["--accelerometer-error", "1e-4"],
                                                                     "--accelerometer-error")):
        out = run_cli("errors", "vertical", *args)
        assert out.code == 2 and option in out.stderr and out.stderr.count("\n") == 1


def test_vertical_files(run_cli, tmp_path):
    out = run_cli("errors", "vertical", "--duration", "600", "--out", tmp_path)
    assert out.code == 0, out.stderr
    assert {p.suffix for p in tmp_path.iterdir() if not p.name.startswith(".")} == {".png", ".svg", ".csv"}


def test_period_command(run_cli):
    data = run_cli("errors", "period", "--thrust-factor", "9", "--json").json()
    assert data["thrust_period_s"] == pytest.approx(data["nominal_period_s"] / 3, rel=1e-12)
    out = run_cli("errors", "period", "--speed", "8 km/s", "--json")
    assert out.code == 0 and "orbital speed" in out.stderr
    assert out.json()["flight_period_s"] is None  # infinite: JSON has no inf


def test_three_d_command(run_cli, tmp_path):
    out = run_cli("errors", "three-d", "--latitude", "45", "--initial-velocity-error-north", "1 ft/s",
                  "--earth-rate", "0", "--duration", "5060 s", "--output-step", "10", "--json", "--out", tmp_path)
    assert out.code == 0, out.stderr
    data = out.json()
    # non-rotating Earth: Bollay's single channel, Delta_V / omega = 805 ft (R = 6,371 km here: 257 m)
    omega = math.sqrt(9.80665 / 6.371e6)
    # sampled every 10 s, the peak is missed by at most (omega dt / 2)^2 / 2 = 2e-5 relative
    assert data["max_horizontal_position_error_m"] == pytest.approx(FOOT / omega, rel=2e-5)
    assert data["final_position_error_down_m"] is None and data["vertical_channel"] is False
    assert data["inputs"]["latitude"] == pytest.approx(math.radians(45))
    names = {p.name for p in tmp_path.iterdir()}
    assert {"errors_three_d.png", "errors_three_d.svg", "errors_three_d_track.png", "errors_three_d.csv"} <= names
    columns = pd.read_csv(tmp_path / "errors_three_d.csv").columns
    assert {"t_s", "position_error_north_m", "velocity_error_east_m_s", "attitude_error_down_rad"} <= set(columns)


def test_three_d_shows_a_channel_far_smaller_than_the_other(run_cli):
    # at the equator the channels decouple: 1e-7 m/s north gives (dV / omega) sin(omega t) = -7.8e-5 m beside
    # 782 km east; a floor scaled by the horizontal error showed it as 0
    args = ("errors", "three-d", "--latitude", "0", "--initial-velocity-error-east", "1000",
            "--initial-velocity-error-north", "1e-7", "--duration", "3600")
    north = run_cli(*args, "--json").json()["final_position_error_north_m"]
    omega = math.sqrt(9.80665 / 6.371e6)
    assert north == pytest.approx(1e-7 / omega * math.sin(omega * 3600), rel=1e-6)
    out = run_cli(*args)
    assert out.code == 0 and "-7.81755e-05 m (-0.000256481 ft), -781,755 m (-2,564,813 ft)" in out.stdout


def test_three_d_refuses_a_down_bias_without_the_vertical_channel(run_cli):
    out = run_cli("errors", "three-d", "--accel-bias-down", "1e-4")
    assert out.code == 2 and "--accel-bias-down" in out.stderr and "vertical channel only" in out.stderr
    out = run_cli("errors", "three-d", "--accel-bias-down", "1e-4", "--vertical-channel", "--duration", "600",
                  "--json")
    assert out.code == 0, out.stderr
    assert out.json()["final_position_error_down_m"] > 0  # reads high along down: the indicated height sinks


def test_help_lists_the_actions(run_cli):
    out = run_cli("errors", "--help")
    for command in ("run", "reproduce", "vertical", "period", "plot", "three-d"):
        assert command in out.stdout
    assert "Bollay" in out.stdout


FUZZ_VALUES = ["0", "-1", "1", "1e300", "-1e300", "nan", "inf", "-inf", "1e-300", "abc", "", "5 m", "3 deg",
               "1 g", "2 h", "0.5 mi/s", "1e5", "0.01 deg/h", "2"]
FUZZ_OPTIONS = {
    "run": ["--source", "--magnitude", "--duration", "--output-step", "--speed", "--earth", "--radius", "--gravity",
            "--fidelity", "--monte-carlo", "--seed"],
    "vertical": ["--accel-bias-up", "--duration", "--output-step", "--order", "--time-constant", "--k1", "--k2",
                 "--k3", "--baro-bias", "--radius", "--gravity"],
    "period": ["--thrust-factor", "--speed", "--path-radius", "--earth", "--gravity"],
    "three-d": ["--latitude", "--velocity-north", "--duration", "--output-step", "--drift-east", "--accel-bias-down",
                "--initial-attitude-error-down", "--earth-rate", "--radius"],
    "plot": ["--points"],
}


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_fuzz_every_command_ends_with_exit_0_or_one_line_exit_2(run_cli, monkeypatch, data):
    # careless inputs: every outcome is a result or one line naming the problem, never a traceback
    monkeypatch.setenv("SCHULER_MEMORY_BUDGET", "200 MiB")
    command = data.draw(st.sampled_from(sorted(FUZZ_OPTIONS)))
    options = data.draw(st.lists(st.sampled_from(FUZZ_OPTIONS[command]), min_size=1, max_size=3, unique=True))
    args = []
    for option in options:
        args += [option, data.draw(st.sampled_from(FUZZ_VALUES) | st.floats(allow_nan=True).map(repr))]
    out = run_cli("errors", command, *args, "--json")
    assert out.code in (0, 2), (args, out.stderr)
    assert "Traceback" not in out.stderr
    if out.code == 2:
        assert out.stderr.startswith("schuler: error:") and out.stderr.count("\n") == 1, (args, out.stderr)
    else:
        assert "NaN" not in out.stdout and "Infinity" not in out.stdout


@pytest.mark.slow
def test_sweep_over_sources_reads_each_magnitude_in_its_source_unit(run_cli, tmp_path):
    scenario = tmp_path / "errors.toml"
    scenario.write_text('system = "errors"\n[parameters]\nsource = "tilt"\nmagnitude = 0.01\nearth = "bollay"\n')
    out = run_cli("sweep", scenario, "--param", "source=tilt,drift", "--param", "magnitude=0.01,0.02",
                  "--fidelity", "closed", "--out", tmp_path / "sweep", "--no-progress", "--json")
    assert out.code == 0, out.stderr
    table = pd.read_parquet(tmp_path / "sweep" / "results.parquet")
    assert table["source"].tolist() == ["tilt", "tilt", "drift", "drift"]
    # Bollay, Problem 3: 0.01 deg of tilt -> 7300 ft at most; 0.01 deg/h of drift -> 10,250 ft at 10,120 s
    assert (table["max_spherical_m"] / FOOT).tolist() == pytest.approx([7298.5, 14597.1, 10258.5, 20517.0], abs=0.1)
    # the scenario's magnitude, converted for its own source, is not applied to the other source
    refused = run_cli("sweep", scenario, "--param", "source=tilt,drift", "--out", tmp_path / "refused",
                      "--no-progress")
    assert refused.code == 2 and "sources of different units" in refused.stderr
