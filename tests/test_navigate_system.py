"""``schuler navigate`` on the contract: evaluate = the library, members and chunks, the IMU layer's models, memory."""

from __future__ import annotations

import math
import tracemalloc

import numpy as np
import pytest

from schuler.contract import Cases
from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY, radii_of_curvature, somigliana_gravity
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.imu.simulate import simulate_members
from schuler.imu.spec import preset
from schuler.memory import MemoryBudgetExceeded
from schuler.navigate import imu_noise
from schuler.navigate.api import SYSTEM
from schuler.navigate.errors import ConstantSensorErrors, InitialErrors
from schuler.navigate.evaluation import NOISE_MEMBERS, OUTPUTS, PARAMETERS, setup
from schuler.navigate.mechanization import navigate
from schuler.navigate.trajectory import GreatCircle, Stationary
from schuler.navigate.truth import TruthGenerator
from schuler.reproduction import Reproduction

DEG_PER_H = math.radians(1.0) / 3600.0
ARCMIN = math.radians(1.0) / 60.0
PROFILE = "examples/profiles/manoeuvring_flight.toml"
QUICK = {"duration": 600.0, "imu_rate": 10.0, "output_step": 60.0}


def same(a: float, b: float, rel: float = 1e-12) -> bool:
    return a == b or math.isclose(a, b, rel_tol=rel, abs_tol=1e-300)


def test_outputs_are_final_and_largest_of_every_channel():
    names = [o.name for o in OUTPUTS]
    assert len(names) == 20 and names[0] == "final_position_error_north_m"
    assert "max_abs_heading_error_rad" in names and "max_horizontal_position_error_m" in names
    assert {o.display for o in OUTPUTS if o.unit == "rad"} == {"arcsec"}
    # the parameter names of issue 15, item 7
    for name in ("trajectory", "latitude", "longitude", "height", "heading", "speed", "duration", "imu_rate",
                 "output_step", "vertical_channel", "position_error_north", "position_error_east",
                 "velocity_error_north", "velocity_error_east", "roll_error", "pitch_error", "heading_error",
                 "gyro_bias_x", "gyro_bias_y", "gyro_bias_z", "accel_bias_x", "accel_bias_y", "accel_bias_z", "imu",
                 "mode"):
        assert name in PARAMETERS, name
    defaults = SYSTEM.case()
    assert defaults["mode"] == "strapdown" and defaults["imu"] is None and defaults["trajectory"] == "stationary"
    assert setup(defaults).trajectory == Stationary(latitude=math.radians(45.0))  # height 0, heading 0


def test_the_system_runs_the_library_with_the_values_given():
    """Every option reaches navigate() in SI: the system's numbers are the library's, bit for bit."""
    values = {"latitude": math.radians(30.0), "heading": math.radians(40.0), "position_error_north": 12.0,
              "position_error_east": -7.0, "velocity_error_north": 0.05, "velocity_error_east": -0.02,
              "roll_error": 2 * ARCMIN, "pitch_error": -ARCMIN, "heading_error": 5 * ARCMIN,
              "gyro_bias_x": 0.01 * DEG_PER_H, "gyro_bias_y": -0.02 * DEG_PER_H, "gyro_bias_z": 0.005 * DEG_PER_H,
              "accel_bias_x": 1e-4 * STANDARD_GRAVITY, "accel_bias_z": -5e-5 * STANDARD_GRAVITY,
              "vertical_channel": "baro", "mode": "platform", **QUICK}
    result = SYSTEM.run(**values)
    direct = navigate(Stationary(latitude=values["latitude"], heading=values["heading"]), 600.0, imu_rate=10.0,
                      output_step=60.0, mode="platform", vertical_channel="baro",
                      initial_errors=InitialErrors(**{k: [values.get(k, 0.0)] for k in (
                          "position_error_north", "position_error_east", "velocity_error_north",
                          "velocity_error_east", "roll_error", "pitch_error", "heading_error")}),
                      sensor_errors=ConstantSensorErrors(gyro_bias=[[values[f"gyro_bias_{a}"] for a in "xyz"]],
                                                 accel_bias=[[values["accel_bias_x"], 0.0, values["accel_bias_z"]]]))
    histories = result.histories["navigate_errors"]
    for name in ("position_error_north_m", "velocity_error_east_m_s", "heading_error_rad", "height_error_m"):
        np.testing.assert_array_equal(histories[name], direct.channel(name)[0])
    assert result.final_pitch_error_rad == direct.pitch_error_rad[0, -1]
    assert result.max_abs_roll_error_rad == np.abs(direct.roll_error_rad).max()


def test_a_velocity_error_gives_the_foucault_modulated_schuler_oscillation():
    """dV north at rest: errors (dV / w') sin(w' t) (cos, sin)(W_z t), w'^2 = g / R_N + W_z^2, W_z = Omega sin L.

    The closed form of the two horizontal channels coupled by the vertical Earth rate (Titterton and
    Weston 2004, Sec. 12.3.3); it takes one radius (R_N) for both, the INS has R_E east (0.3 % apart at
    45 deg), and it leaves out the 24-h mode: 1e-3 of the amplitude dV / w over an hour.
    """
    dv = 0.01
    result = SYSTEM.run(velocity_error_north=dv, duration=3600.0, imu_rate=10.0, output_step=60.0)
    latitude = math.radians(45.0)
    R_N, _ = radii_of_curvature(latitude)
    w = math.sqrt(float(somigliana_gravity(latitude)) / R_N)
    vertical_rate = EARTH_RATE * math.sin(latitude)
    w_split = math.hypot(w, vertical_rate)
    frame = result.to_dataframe()
    t = frame.index.to_numpy()
    amplitude = dv / w_split * np.sin(w_split * t)
    np.testing.assert_allclose(frame["position_error_north_m"], amplitude * np.cos(vertical_rate * t),
                               rtol=0, atol=1e-3 * dv / w)
    np.testing.assert_allclose(frame["position_error_east_m"], amplitude * np.sin(vertical_rate * t),
                               rtol=0, atol=1e-3 * dv / w)


def test_a_batch_is_its_cases_one_by_one():
    """Cases of different trajectories, modes and grids in one evaluate equal each evaluated alone (1e-12)."""
    values = {
        "trajectory": np.array(["stationary", "great-circle", "great-circle", PROFILE], dtype=object),
        "speed": np.array([None, 200.0, 200.0, None]),
        "heading": np.array([0.3, 1.0, 1.0, None]),
        "latitude": np.array([0.5, 0.9, 0.9, None]),
        "mode": np.array(["strapdown", "strapdown", "platform", "strapdown"], dtype=object),
        "velocity_error_east": np.array([0.1, 0.2, 0.2, 0.05]),
        "gyro_bias_z": np.array([1e-7, 0.0, 2e-7, 0.0]),
        "duration": np.array([600.0, 600.0, 600.0, None]),
        "imu_rate": np.full(4, 10.0), "output_step": np.full(4, 60.0),
    }
    batch = SYSTEM.evaluate_values(values)
    for i in range(4):
        one = SYSTEM.evaluate_values({k: v[i:i + 1] for k, v in values.items()})
        for name, array in batch.items():
            assert same(float(one[name][0]), float(array[i])), (i, name)
    assert np.all(np.isfinite(np.stack(list(batch.values()))))
    # the profile ran for its own hour
    assert SYSTEM.run(trajectory=PROFILE, imu_rate=10.0, output_step=60.0).duration_s == 3600.0


def test_monte_carlo_members_draw_the_sigmas():
    """sigma_velocity_error: the members' final north errors spread as sigma |sin(w t)| / w (Schuler, first order)."""
    sigma = 0.1
    case = SYSTEM.case(sigma_velocity_error=sigma, **QUICK)
    summary = SYSTEM.monte_carlo(case, 400, RandomStreams(11))
    latitude = math.radians(45.0)
    R_N, R_E = radii_of_curvature(latitude)
    w = math.sqrt(float(somigliana_gravity(latitude)) / math.sqrt(R_N * R_E))
    expected = sigma * abs(math.sin(w * 600.0)) / w
    # 400 members: the sample std has a standard error of 3.5 %; 4 of them
    assert summary.statistics["final_position_error_north_m"]["std"] == pytest.approx(expected, rel=0.14)
    # a run without Monte Carlo is the nominal case (realisation False): the sigmas draw nothing
    nominal = SYSTEM.run(sigma_velocity_error=sigma, **QUICK)
    assert not SYSTEM.realisation and nominal.final_position_error_north_m == 0.0


def test_imu_members_are_independent_of_chunking_and_of_the_order_of_members():
    case = SYSTEM.case(imu="tactical", sigma_heading_error=ARCMIN, duration=120.0, imu_rate=50.0, output_step=20.0)
    streams = RandomStreams(4)
    whole = SYSTEM.evaluate(Cases.from_case(case, 5, members=np.arange(10, 15), random=streams))
    parts = [SYSTEM.evaluate(Cases.from_case(case, 1, members=np.array([m]), random=streams)) for m in (12, 10)]
    for name in whole:
        assert same(float(parts[0][name][0]), float(whole[name][2])), name
        assert same(float(parts[1][name][0]), float(whole[name][0])), name
    assert np.ptp(whole["final_horizontal_position_error_m"]) > 0
    assert NOISE_MEMBERS == 21  # members per run with noise: one random-number block per stream and window


def test_imu_noise_is_the_imu_layers_simulation():
    """A member's increment errors are its samples from schuler.imu.simulate minus the truth, times dt."""
    model = preset("tactical")
    generator = TruthGenerator(Stationary(latitude=0.7, heading=0.4), 10.0, 100.0)
    rate, force = imu_noise.initial_inputs(generator, "strapdown")
    noise = imu_noise.ImuNoise(model, seed=9, interval=0.01, true_rate=rate, true_specific_force=force)
    members = np.array([3, 7])
    first = noise.increments(members, 0, 600, 0.01)
    second = noise.increments(members, 600, 1000, 0.01)
    gyro, accel = simulate_members(imu_noise.noise_model(model), samples=1000, sample_interval=0.01,
                                   members=members, seed=9, true_gyro=rate, true_accel=force)
    np.testing.assert_allclose(np.concatenate([first[0], second[0]], axis=1), (gyro - rate) * 0.01,
                               rtol=0, atol=1e-18)
    np.testing.assert_allclose(np.concatenate([first[1], second[1]], axis=1), (accel - force) * 0.01,
                               rtol=0, atol=1e-15)
    # the white part dominates at 100 Hz: angle increments of std N sqrt(dt) (0.125 deg/sqrt(h))
    assert np.std(first[0]) == pytest.approx(model.gyro.random_walk[0] * math.sqrt(0.01), rel=0.1)


def test_the_nominal_imu_case_takes_every_constant_at_one_sigma():
    model = preset("tactical")
    result = SYSTEM.run(imu="tactical", **QUICK)
    constants = imu_noise.representative_constants(model, 1, [0.0, 0.0, -9.8])
    direct = navigate(Stationary(latitude=math.radians(45.0)), 600.0, imu_rate=10.0, output_step=60.0,
                      sensor_errors=ConstantSensorErrors(**constants.as_dict()),
                      initial_errors=InitialErrors(roll_error=[0.0]))
    np.testing.assert_array_equal(result.histories["navigate_errors"]["position_error_east_m"],
                                  direct.position_error_east_m[0])
    assert result.imu == model.name
    # +1 sigma: 1 deg/h, 150 ppm, 0.5 mrad, 1 mg on every axis
    assert constants.gyro_bias[0].tolist() == pytest.approx([DEG_PER_H] * 3)
    assert constants.accel_scale_factor[0].tolist() == pytest.approx([300e-6] * 3)
    assert constants.gyro_misalignment[0, 0, 1] == pytest.approx(0.5e-3) and constants.gyro_misalignment[0, 1, 1] == 0
    # the consumer grade's 3 % scale factors and 20 mrad misalignments stay within the library's limits when drawn
    consumer = imu_noise.drawn_constants(preset("consumer"), 0, np.arange(2000))
    ConstantSensorErrors(**consumer.as_dict())


def test_g_sensitivity_enters_with_the_specific_force():
    """Industrial grade: G at +1 sigma (0.01 deg/s/g each entry) times f0 = (0, 0, -g) joins the gyro bias."""
    model = preset("industrial")
    constants = imu_noise.representative_constants(model, 1, [0.0, 0.0, -STANDARD_GRAVITY])
    g_part = constants.gyro_bias[0] - model.gyro.bias
    assert g_part.tolist() == pytest.approx([-math.radians(0.01)] * 3, rel=1e-9)


def test_trajectory_checks():
    with pytest.raises(InvalidParameter, match="latitude: is set by the profile"):
        SYSTEM.run(trajectory=PROFILE, latitude=0.3)
    with pytest.raises(InvalidParameter, match="speed: applies to the great-circle trajectory only"):
        SYSTEM.run(speed=100.0, **QUICK)
    with pytest.raises(InvalidParameter, match="trajectory: 'helix' is neither"):
        SYSTEM.run(trajectory="helix", **QUICK)
    with pytest.raises(InvalidParameter, match="heading: the great circle passes within 1 deg of a pole"):
        SYSTEM.run(trajectory="great-circle", latitude=math.radians(80), speed=2000.0, duration=3600.0)
    with pytest.raises(InvalidParameter, match="latitude"):
        SYSTEM.run(latitude=math.radians(89.5))
    with pytest.raises(InvalidParameter, match="output_step: .* not a whole number of IMU intervals"):
        SYSTEM.run(output_step=0.015, duration=600.0)
    with pytest.raises(InvalidParameter, match="imu: 'bogus' is neither a grade"):
        SYSTEM.run(imu="bogus", **QUICK)
    path = GreatCircle(latitude=0.5, longitude=0.0, height=0.0, heading=1.0, speed=200.0, duration=600.0)
    assert setup(SYSTEM.case(trajectory="great-circle", latitude=0.5, heading=1.0, speed=200.0, **QUICK)) \
        .trajectory.kinematics(600.0)[0][0].tolist() == pytest.approx(path.kinematics(600.0)[0][0].tolist(), rel=1e-12)


def test_memory_is_refused_before_allocating(monkeypatch):
    from schuler import memory

    monkeypatch.setenv(memory.ENVIRONMENT, "64 MiB")
    memory._budget_from_environment.cache_clear()
    tracemalloc.start()
    try:
        with pytest.raises(MemoryBudgetExceeded, match="change `duration` or `output_step`"):
            SYSTEM.run(duration=86400.0, output_step=0.01)  # 8.6 million outputs of 23 values
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
        memory._budget_from_environment.cache_clear()
    assert peak < 32 * 2**20
    # within the budget the members of a Monte Carlo are run in parts, not refused
    case = SYSTEM.case(sigma_gyro_bias=DEG_PER_H, duration=3600.0, imu_rate=1.0, output_step=1.0)
    assert SYSTEM.member_bytes(case) == 3601 * 23 * 8


def test_files_of_a_run(tmp_path):
    result = SYSTEM.run(monte_carlo=30, sigma_position_error=10.0, vertical_channel="free", **QUICK)
    files = SYSTEM.write(result, tmp_path)
    names = sorted(p.name for p in files)
    assert names == ["navigate_errors.csv", "navigate_errors.png", "navigate_errors.svg", "navigate_monte_carlo.png",
                     "navigate_monte_carlo.svg"]
    import pandas as pd

    table = pd.read_csv(tmp_path / "navigate_errors.csv")
    assert list(table.columns)[:2] == ["t_s", "position_error_north_m"] and "height_error_m" in table
    assert table["t_s"].iloc[-1] == 600.0
    assert SYSTEM.figures(SYSTEM.case()) == {}  # what is neither a run nor the reproduction has no figures


def test_reproduction_rows_and_files(tmp_path):
    reproduction = SYSTEM.reproduce()
    assert isinstance(reproduction, Reproduction) and not reproduction.failures
    rows = {row.quantity: row for row in reproduction.rows}
    bollay = rows["level misalignment 0.01 deg, largest error: nonlinear strapdown, WGS-84, rotating Earth"]
    # Bollay's 7300 ft = 2 R Delta_theta with his R = 3960 mi; WGS-84's R_E gives 2 x 6378137 m x 1.745e-4
    assert bollay.printed == "7300" and bollay.computed == pytest.approx(2 * 6378137.0 * math.radians(0.01) / 0.3048,
                                                                         rel=1e-3)
    for row in reproduction.rows:
        if row.note.startswith("departs by"):
            departure = abs(float(row.note.split()[2])) / 100
            assert ("more than 1 %" in row.note) == (departure > 0.01), row
    drozdovich = rows["Delta v_y: nonlinear mean against the forced solution (26)/(29) along the same path"]
    assert drozdovich.verdict == "agrees within 1 %"
    table = reproduction.details["gyrocompassing"]
    assert len(table) == 12 and table[0]["initial_azimuth_error_rad"] == pytest.approx(ARCMIN)
    assert table[-1]["initial_azimuth_error_rad"] == pytest.approx(0.4)
    files = SYSTEM.write(reproduction, tmp_path)
    assert {p.name for p in files} >= {"navigate_gyrocompassing.png", "navigate_gyrocompassing.svg",
                                       "navigate_gyrocompassing.csv", "navigate_bollay.png", "navigate_drozdovich.svg"}
    from PIL import Image

    for path in files:
        if path.suffix == ".png":
            with Image.open(path) as image:
                assert image.width <= 7 * 100, path  # 7 in at matplotlib's 100 dpi
