"""An IMU for the other systems (``--imu``, ``[instrument]``): the mapping reaches each system's parameters."""

from __future__ import annotations

import json
import math

import pytest

from schuler.exceptions import InvalidParameter, ScenarioError
from schuler.imu.instrument import IMU_SYSTEMS, apply_instrument, instrument_options, resolve_model
from schuler.imu.simulate import write_simulation
from schuler.imu.spec import preset
from schuler.imu.system_inputs import align_inputs, errors_inputs, north_inputs, residual_bias, vertical_inputs
from schuler.registry import get_system
from schuler.study.scenario import parse_scenario


def applied(system: str, imu: str = "tactical", **given):
    definition = get_system(system)
    case = definition.parameters.case(given)
    return apply_instrument(system, definition.parameters, case, imu)[0]


def test_align_takes_the_residual_drifts_resolved_at_its_azimuth():
    azimuth = math.radians(30.0)
    case = applied("align", azimuth=azimuth)
    expected = align_inputs(preset("tactical"), heading=azimuth).values
    for name in ("drift_east", "drift_north", "drift_z", "accel_bias_x", "accel_bias_y", "sigma_drift",
                 "sigma_drift_z", "sigma_accel"):
        assert case[name] == pytest.approx(expected[name], rel=1e-12), name
    # HG1700 with 0.3 deg/h flicker: residual drift r = sqrt(2) x 0.664 x 0.3 deg/h ~ 0.28 deg/h per axis; the
    # horizontal drift -R(A) (r, r) has magnitude sqrt(2) r at any azimuth A
    residual = math.hypot(case["drift_east"], case["drift_north"]) / math.sqrt(2)
    assert math.degrees(residual) * 3600 == pytest.approx(0.28, rel=0.03)
    assert case["accel_bias_x"] == pytest.approx(1e-3 * 9.80665, rel=0.01)  # 1 mg turn-on bias kept


def test_explicit_values_win_over_the_imu():
    case = applied("align", drift_east=0.0, sigma_accel=1e-5)
    assert case["drift_east"] == 0.0 and case["sigma_accel"] == 1e-5
    assert case["drift_north"] < 0.0  # still the IMU's


def test_calibrate_north_and_errors():
    calibrate = applied("calibrate")
    assert calibrate["drift_x"] == pytest.approx(-math.radians(1.0) / 3600)  # -(1 deg/h): drift = -bias
    assert calibrate["angle_random_walk"] == pytest.approx(math.radians(0.125) / 60)
    north = applied("north", output_step=2.0)
    assert north["readout_noise"] == pytest.approx(north_inputs(preset("tactical"), step=2.0).values["readout_noise"])
    assert north["readout_noise"] == pytest.approx(math.radians(0.125) / 60 * math.sqrt(2.0))  # N sqrt(h), Q = 0
    for source in ("drift", "accelerometer", "tilt", "azimuth"):
        errors = applied("errors", source=source)
        expected = errors_inputs(preset("tactical"), latitude=math.radians(45.0)).values[source]
        assert errors["magnitude"] == pytest.approx(expected, rel=1e-12), source


def test_values_out_of_a_systems_range_are_refused_by_name():
    # consumer MEMS: 20 deg/s turn-on bias, beyond calibrate's 3600 deg/h
    with pytest.raises(InvalidParameter, match=r"imu: consumer: drift_x from the IMU \(-72000 deg/h is outside "
                                               r"\[-3600, 3600\] deg/h\); give --drift-x explicitly"):
        applied("calibrate", "consumer")
    assert applied("calibrate", "consumer", drift_x=1e-6, drift_y=1e-6)["drift_x"] == 1e-6
    with pytest.raises(InvalidParameter, match="'teactical' is neither a grade"):
        applied("align", "teactical")
    with pytest.raises(InvalidParameter, match="applies to align, calibrate, north, errors, vertical runs, not imu"):
        apply_instrument("imu", get_system("imu").parameters, get_system("imu").case(), "tactical")


def test_options_offered_to_each_system():
    assert [p.name for p in instrument_options("align")] == ["imu", "imu_window"]
    assert [p.name for p in instrument_options("errors")] == ["imu", "imu_window", "imu_latitude"]
    assert [p.name for p in instrument_options("calibrate")] == ["imu"]
    assert [p.name for p in instrument_options("vertical")] == ["imu", "imu_window"]
    assert len(instrument_options("imu")) == 0
    assert set(IMU_SYSTEMS) == {"align", "calibrate", "north", "errors", "vertical"}


def test_the_vertical_takes_the_residual_drifts_of_its_level_axes(run_cli):
    tactical = preset("tactical")
    case = applied("vertical")
    gyro = residual_bias(tactical.gyro, 600.0, include_turn_on=False)
    accel = residual_bias(tactical.accel, 600.0, include_turn_on=True)
    # housing x, y = body y, x; drift = -b_g at +1 sigma (turn-on bias calibrated out), accelerometers kept whole
    assert [case["drift_x"], case["drift_y"]] == pytest.approx([-gyro[1], -gyro[0]], rel=1e-12)
    assert [case["accel_bias_x"], case["accel_bias_y"]] == pytest.approx([accel[1], accel[0]], rel=1e-12)
    assert case["drift_x"] == pytest.approx(vertical_inputs(tactical).values["drift_x"], rel=1e-12)
    # sqrt(2) x the flicker floor 0.664 B, B = 0.3 deg/h: 0.282 deg/h (the preset's flicker ends at 1000 s)
    assert math.degrees(abs(case["drift_x"])) * 3600.0 == pytest.approx(0.282, rel=0.02)
    # Python equals the command line, and a value given explicitly wins
    vertical = get_system("vertical")
    ran = vertical.run(imu="tactical", duration=3600.0)
    out = run_cli("vertical", "run", "--imu", "tactical", "--duration", "3600", "--json")
    assert out.code == 0, out.stderr
    typed = json.loads(out.stdout)
    for name, value in ran.to_dict().items():
        if isinstance(value, float):
            assert typed[name] == pytest.approx(value, rel=1e-12, abs=1e-300), name
    assert vertical.run(imu="tactical", duration=3600.0).to_dict() != vertical.run(duration=3600.0).to_dict()
    assert applied("vertical", drift_x=1e-7)["drift_x"] == 1e-7


def test_a_recording_gives_its_identified_terms(tmp_path):
    path = write_simulation(tmp_path / "rec.parquet", preset("industrial"), duration=600.0, sample_interval=0.01,
                            seed=4)
    model = resolve_model(str(path))
    # identified from 10 min at 100 Hz: N of the industrial preset (0.007 deg/s/sqrt(Hz)) within 3 %
    assert model.gyro.random_walk[0] == pytest.approx(math.radians(0.007), rel=0.03)
    calibrate = applied("calibrate", str(path))
    assert calibrate["angle_random_walk"] == pytest.approx(math.radians(0.007), rel=0.03)
    assert calibrate["drift_x"] == 0.0  # an Allan curve cannot see a constant bias


def test_a_scenario_names_its_instrument(tmp_path):
    spec = tmp_path / "part.toml"
    spec.write_text('[gyro]\nrandom_walk = "0.5 deg/sqrt(h)"\n', encoding="utf-8")
    scenario_file = tmp_path / "north.toml"
    scenario_file.write_text('system = "north"\n[parameters]\noutput_step = "4 s"\n'
                             '[instrument]\nimu = "part.toml"\n', encoding="utf-8")  # relative to the scenario
    from schuler.study.scenario import load_scenario

    scenario = load_scenario(scenario_file)
    assert scenario.values["readout_noise"] == pytest.approx(math.radians(0.5) / 60 * 2.0)
    assert scenario.instrument == {"imu": "part.toml"} and "readout_noise" in scenario.given()
    text = 'system = "align"\n[parameters]\ndrift_east = "0 deg/h"\n[instrument]\nimu = "navigation"\n'
    values = parse_scenario(text).values
    assert values["drift_east"] == 0.0 and values["drift_north"] != 0.0
    with pytest.raises(ScenarioError, match=r"\[instrument\] imu_window: unknown key; allowed: imu"):
        parse_scenario('system = "calibrate"\n[instrument]\nimu = "tactical"\nimu_window = "1 h"\n')
    with pytest.raises(ScenarioError, match="instrument: unknown key"):
        parse_scenario('system = "imu"\n[instrument]\nimu = "tactical"\n')
    assert parse_scenario('system = "vertical"\n[instrument]\nimu = "tactical"\n').values["drift_x"] \
        == pytest.approx(applied("vertical")["drift_x"], rel=1e-12)
    with pytest.raises(ScenarioError, match=r"\[instrument\] imu: consumer: drift_x from the IMU"):
        parse_scenario('system = "calibrate"\n[instrument]\nimu = "consumer"\n')
