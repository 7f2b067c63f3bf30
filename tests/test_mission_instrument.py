"""The mission's instrument and alignment choices: the strapdown gyrocompass, and an IMU given as a recording."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY
from schuler.exceptions import InvalidParameter, ScenarioError
from schuler.imu.files import write_record
from schuler.imu.simulate import simulate_record
from schuler.imu.spec import load_spec_file, preset
from schuler.mission.api import SYSTEM
from schuler.mission.covariance import covariance_budget
from schuler.mission.evaluation import PARAMETERS
from schuler.mission.setup import CONSTANT_SOURCES, mission_setup
from schuler.mission.stages import initial_state_map
from schuler.study.scenario import load_scenario

WHITE_SPEC = """\
name = "white noise only"
[gyro]
random_walk = "0.15 deg/sqrt(h)"
[accel]
random_walk = "100 ug/sqrt(Hz)"
"""


def setup_of(**values):
    case = PARAMETERS.case(values)
    return mission_setup({name: case[name] for name in PARAMETERS.names})


def test_the_strapdown_gyrocompass_leaves_the_static_limits():
    # level, x north, y east: the static limits of a stationary self-alignment (Groves 2013, Sec. 5.6.2; the spec's
    # "Alignment at rest"): heading error = -b_gE / (Omega cos L) + (b_aE / g) tan L, tilt psi_N = b_aE / g;
    # the heading error is -psi_D. Per unit source; closed form against the map to rounding
    setup = setup_of(alignment="strapdown-gyrocompass", trajectory="stationary", heading=0.0,
                     latitude=math.radians(50.0), duration=3600.0)
    x0 = initial_state_map(setup, np.eye(3), 7)
    gyro_east, accel_east = (x0[CONSTANT_SOURCES.index(name)] for name in ("gyro_bias_y", "accel_bias_y"))
    horizontal_rate = EARTH_RATE * math.cos(setup.latitude)
    assert -gyro_east[-1] == pytest.approx(-1.0 / horizontal_rate, rel=1e-12)
    assert -accel_east[-1] == pytest.approx(math.tan(setup.latitude) / STANDARD_GRAVITY, rel=1e-12)
    assert accel_east[-3] == pytest.approx(1.0 / STANDARD_GRAVITY, rel=1e-12)


def test_the_strapdown_gyrocompass_is_the_kalman_steady_state_to_first_order():
    # both solve -(Omega x psi)_E + epsilon_E = 0 at rest and average the white noises over T_a (stages' notes)
    common = {"imu": "tactical", "trajectory": "flight", "duration": 1800.0, "alignment_duration": 600.0}
    analytic = covariance_budget(setup_of(alignment="strapdown-gyrocompass", **common))
    kalman = covariance_budget(setup_of(alignment="kalman", **common))
    assert np.allclose(analytic.sigma("horizontal_position"), kalman.sigma("horizontal_position"), rtol=1e-12, atol=0)
    assert analytic.shares() == pytest.approx(kalman.shares(), rel=1e-12, abs=1e-15)


@pytest.fixture(scope="module")
def white_imu(tmp_path_factory):
    """A spec of white noises only and a 2-min record of it at 100 Hz, written to CSV."""
    folder = tmp_path_factory.mktemp("instrument")
    spec = folder / "white.toml"
    spec.write_text(WHITE_SPEC)
    record = simulate_record(load_spec_file(spec), duration=120.0, sample_interval=0.01, seed=7)
    return spec, write_record(record, folder / "white.csv")


def test_a_recording_gives_the_mission_its_identified_noise(white_imu):
    spec, recording = white_imu
    common = {"trajectory": "stationary", "duration": 3600.0, "calibration": "multi-position"}
    recorded = setup_of(imu=str(recording), **common)
    true = load_spec_file(spec)
    # N from the Allan curve of 12,000 samples: its estimate near tau = 1 s has ~ 1 % standard error; 5 % is
    # several of them. A white-noise record resolves no slow term, so nothing else enters the model
    assert np.allclose(recorded.gyro_random_walk, true.gyro.random_walk, rtol=0.05, atol=0)
    assert np.allclose(recorded.accel_random_walk, true.accel.random_walk, rtol=0.05, atol=0)
    assert np.all(recorded.error_model.gyro.bias_instability == 0) and np.all(recorded.error_model.gyro.bias == 0)
    # multi-position calibration of white noise: the least-squares floor N / sqrt(T_c), per axis
    assert np.allclose(recorded.gyro_bias_sigma(), recorded.gyro_random_walk / math.sqrt(600.0), rtol=1e-12)
    # every source scales with N, so the mission's 1-sigma follows the identified N (5 %)
    from_record = SYSTEM.run(imu=str(recording), **common)
    from_spec = SYSTEM.run(imu=str(spec), **common)
    assert from_record.instrument == "identified from white.csv"
    assert from_record.position_error_sigma_m == pytest.approx(from_spec.position_error_sigma_m, rel=0.05)


def test_a_scenario_names_its_recording(run_cli, white_imu, tmp_path):
    _, recording = white_imu
    scenario = tmp_path / "recorded.toml"
    scenario.write_text(f'system = "mission"\n[parameters]\nimu = "{recording.as_posix()}"\n'
                        'trajectory = "stationary"\nduration = "1 h"\n')
    out = run_cli("run", scenario, "--json")
    assert out.code == 0, out.stderr
    assert out.json()["inputs"]["imu"] == recording.as_posix()
    assert out.json() == run_cli("mission", "run", "--imu", recording, "--trajectory", "stationary",
                                 "--duration", "1 h", "--json").json()


@pytest.mark.parametrize("arguments, message", [
    (("--imu", "no-such-record.csv"), "--imu: 'no-such-record.csv' is neither a grade"),
    (("--imu", "navigation", "--grade", "tactical"), "--grade: renamed to '--imu'"),
    (("--imu-spec", "my-imu.toml"), "--imu-spec: renamed to '--imu'"),
    (("--instrument", "navigation"), "--instrument: renamed to '--imu'"),
])
def test_a_bad_instrument_is_refused_in_one_line(run_cli, arguments, message):
    out = run_cli("mission", "run", *arguments, "--duration", "600", "--trajectory", "stationary")
    assert out.code == 2 and out.stderr.count("\n") == 1
    assert message in out.stderr


@pytest.mark.parametrize("former", ["grade", "imu_spec", "instrument"])
def test_the_former_instrument_parameters_are_refused_naming_imu(former, tmp_path):
    # issue 24: one IMU parameter; the three it replaces are refused in one line, from Python and in a scenario
    with pytest.raises(InvalidParameter, match=f"^{former}: renamed to 'imu'"):
        SYSTEM.run(**{former: "navigation"}, trajectory="stationary", duration=600.0)
    scenario = tmp_path / "former.toml"
    scenario.write_text(f'system = "mission"\n[parameters]\n{former} = "navigation"\n')
    with pytest.raises(ScenarioError, match=f"{former}.*renamed to 'imu'"):
        load_scenario(scenario)


def test_one_imu_parameter_takes_a_grade_or_a_spec_file(white_imu):
    spec, _ = white_imu
    common = {"trajectory": "stationary", "duration": 600.0}
    assert SYSTEM.case()["imu"] == "tactical"
    assert SYSTEM.run(imu="navigation", **common).instrument == preset("navigation").name
    assert SYSTEM.run(**common).outputs == SYSTEM.run(imu="tactical", **common).outputs
    from_spec = SYSTEM.run(imu=str(spec), **common)
    assert from_spec.instrument == "white noise only"
    budget = covariance_budget(mission_setup({**SYSTEM.case(**common), "imu": "tactical"}, model=load_spec_file(spec)))
    assert from_spec.position_error_sigma_m == budget.sigma("horizontal_position")[-1]
