"""North finders, multi-position calibration and the three ``compare`` commands.

Round trips on simulated records: what goes in (azimuth, biases, scale factors, misalignments) comes out
within the predicted 1-sigma; the commands' JSON carries the documented keys, the figures the documented size.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from schuler.alignment._multi_static_fits import mean_covariance
from schuler.alignment.calibration_comparison import calibration_model, compare_calibration
from schuler.alignment.commands import align_compare
from schuler.alignment.multi_static import MultiStaticPlan, calibrate_multi_static, identifiable_truth
from schuler.alignment.north import AXES, NORTH_METHODS, find_north, north_sigma, schedule, turntable_rates
from schuler.alignment.north_comparison import compare_north
from schuler.alignment.plots import comparison_data_files, comparison_figures
from schuler.alignment.six_position import SixPositionPlan, calibrate_six_position
from schuler.core.attitude import wrap_angle
from schuler.core.earth import earth_rate_ned
from schuler.exceptions import InvalidParameter
from schuler.imu.simulate import ImuSimulator
from schuler.imu.spec import preset

LATITUDE = math.radians(45.0)
METHOD_NAMES = ("coarse", "inertial_frame", "kalman", "gyrocompass")


@pytest.mark.parametrize("method", NORTH_METHODS)
@pytest.mark.parametrize("axes", AXES)
@pytest.mark.parametrize("heading_deg", [30.0, 100.0, -150.0])
def test_north_finders_recover_the_azimuth_of_noise_free_rates(method, axes, heading_deg):
    """Exact Earth rates plus a bias per gyro in, the azimuth out to rounding (1e-9 rad)."""
    heading = math.radians(heading_deg)
    start, end = schedule(method, samples=400, sample_interval=0.5)
    rates = turntable_rates(LATITUDE, heading, start, end, 0.5)[:, :len(axes)]
    rates = rates + np.array([3e-6, -2e-6])[:len(axes)]   # a bias per gyro, rad/s
    estimate = find_north(rates[None], start, end, LATITUDE, method, axes)
    truth = abs(heading) if estimate.ambiguous else heading
    assert float(wrap_angle(estimate.heading_rad[0] - truth)) == pytest.approx(0.0, abs=1e-9)
    assert estimate.bias_rad_s[0] == pytest.approx(np.array([3e-6, -2e-6])[:len(axes)], abs=1e-14)


def test_north_sigma_closed_forms():
    """N / (Omega cos L sqrt(T)) with two gyros; sqrt(2) of it with one turned; / |sin psi| at two positions."""
    n, duration = 1e-5, 400.0
    base = n / (7.292115e-5 * math.cos(LATITUDE) * math.sqrt(duration))
    assert north_sigma("carousel", "xy", n, LATITUDE, duration) == pytest.approx(base, rel=1e-6)
    assert north_sigma("four_position", "x", n, LATITUDE, duration) == pytest.approx(math.sqrt(2) * base, rel=1e-6)
    assert north_sigma("two_position", "x", n, LATITUDE, duration, math.radians(30)) == pytest.approx(2 * base,
                                                                                                      rel=1e-6)
    with pytest.raises(InvalidParameter, match="method"):
        north_sigma("three_position", "x", n, LATITUDE, duration)


def test_north_comparison_puts_system_5_on_the_same_time_axis():
    """compare_north with a stand-in for schuler north: its curve sits beside the three methods, per duration.

    (The Monte Carlo spreads against the closed forms are tests/test_alignment_monte_carlo.py's, at 1,000
    members; the grade's flicker makes the simulator slow, so few members here.)
    """
    calls = []

    def ground_gyrocompass(durations, noise, latitude):
        calls.append((np.asarray(durations).copy(), noise, latitude))
        return noise / np.sqrt(np.asarray(durations))

    result = compare_north("tactical", latitude=LATITUDE, heading=math.radians(30), duration=120.0,
                           sample_interval=0.5, members=4, seed=3, ground_gyrocompass=ground_gyrocompass)
    assert set(result.methods) == set(NORTH_METHODS)
    assert len(result.versus_time["ground_gyrocompass"]) == len(result.versus_time["duration_s"])
    assert result.ground_gyrocompass["sigma_rad"] == pytest.approx(calls[-1][1] / math.sqrt(120.0))
    for method, row in result.methods.items():
        # one record's error within 4.5 of its fit's 1-sigma, and that 1-sigma within a factor 2 of the closed form
        assert abs(row["error_rad"]) < 4.5 * row["sigma_rad"], method
        assert 0.5 < row["sigma_rad"] / row["analytic_sigma_rad"] < 2.0, method
    grades = result.versus_grade
    assert grades["navigation"]["carousel"] < grades["tactical"]["carousel"]


def test_six_position_calibration_is_exact_without_noise():
    """Noise-free six positions with a rate test: biases, scale factors and misalignments to rounding."""
    plan = SixPositionPlan(latitude_rad=LATITUDE, dwell_s=10.0, turn_s=20.0, sample_interval_s=0.1)
    gyro_true, accel_true = plan.truth()
    rng = np.random.default_rng(5)
    gyro_matrix = np.eye(3) + rng.normal(0, 1e-3, (3, 3))
    accel_matrix = np.eye(3) + rng.normal(0, 1e-3, (3, 3))
    gyro_bias, accel_bias = rng.normal(0, 1e-5, 3), rng.normal(0, 1e-2, 3)
    fit = calibrate_six_position(gyro_true @ gyro_matrix.T + gyro_bias, accel_true @ accel_matrix.T + accel_bias,
                                 plan)
    assert fit.gyro_bias == pytest.approx(gyro_bias, abs=1e-12)
    assert fit.accel_bias == pytest.approx(accel_bias, abs=1e-10)
    assert fit.gyro_matrix == pytest.approx(gyro_matrix, abs=1e-9)
    assert fit.accel_matrix == pytest.approx(accel_matrix, abs=1e-10)


def test_multi_static_calibration_is_exact_without_noise():
    """Noise-free hand-held record with sensor errors: what the method can identify, to 1e-6."""
    plan = MultiStaticPlan(positions=15, sample_interval_s=0.02, latitude_rad=LATITUDE)
    gyro_true, accel_true = plan.truth(seed=4)
    rng = np.random.default_rng(6)
    accel_matrix = np.eye(3) + rng.normal(0, 2e-3, (3, 3))
    gyro_matrix = np.eye(3) + rng.normal(0, 2e-3, (3, 3))
    accel_bias = rng.normal(0, 0.05, 3)
    fit = calibrate_multi_static(gyro_true @ gyro_matrix.T, accel_true @ accel_matrix.T + accel_bias,
                                 plan.sample_interval_s, initial=plan.initial_s, gravity=plan.gravity)
    truth = identifiable_truth(accel_matrix, accel_bias, gyro_matrix)
    assert fit.accel_bias == pytest.approx(truth["accel_bias"], abs=1e-6)
    assert fit.accel_scale == pytest.approx(truth["accel_scale"], abs=1e-6)
    assert fit.accel_non_orthogonality == pytest.approx(truth["accel_non_orthogonality"], abs=1e-6)
    # the Earth rate followed through the turns (module notes): the gyro matrix to 1e-7 (5e-9 found)
    assert fit.gyro_matrix == pytest.approx(truth["gyro_matrix"], abs=1e-7)


def _normalised_errors(records, procedure: str) -> dict[str, np.ndarray]:
    """z = (estimate - true) / predicted 1-sigma per parameter group of ``procedure``, over every record."""
    groups: dict[str, list[float]] = {}
    for result in records:
        for name, entry in getattr(result, procedure).items():
            if isinstance(entry, dict):
                groups.setdefault(name, []).extend(entry["z"])
    return {name: np.asarray(values) for name, values in groups.items()}


def _check_normalised_errors(groups: dict[str, np.ndarray]) -> None:
    """Per group: the rms of its k z within the central 99.9 % of sqrt(chi^2_k / k) (k standard normal z if the
    stated 1-sigma is right), and no |z| beyond the level k normal draws pass with 99.9 %."""
    from scipy.stats import chi2, norm

    for name, z in groups.items():
        low, high = np.sqrt(chi2.ppf([0.0005, 0.9995], z.size) / z.size)
        assert low < np.sqrt(np.mean(z**2)) < high, (name, np.sqrt(np.mean(z**2)), low, high)
        assert np.abs(z).max() < norm.isf(0.0005 / z.size), (name, np.abs(z).max())


def test_calibration_round_trip_within_the_predicted_accuracy():
    """Known errors of 12 industrial IMUs in, estimates out: the stated 1-sigma is what the errors are.

    (12 records: the rms of 36 z per 3-vector group within 0.63-1.40, of 72 within 0.74-1.28, of the gyro
    matrix's 108 within 0.78-1.23; the multi-static accelerometer biases come out at 1.35 here, 1.02 over the
    200 records of the slow test.)
    """
    records = [compare_calibration("industrial", latitude=LATITUDE, seed=seed) for seed in range(12)]
    _check_normalised_errors(_normalised_errors(records, "multi_static"))
    _check_normalised_errors(_normalised_errors(records, "six_position"))
    assert min(r.multi_static["static_intervals"] for r in records) >= 37   # every orientation and the initial one


@pytest.fixture(scope="module")
def two_hundred_calibrations():
    return [compare_calibration("industrial", latitude=LATITUDE, seed=seed) for seed in range(200)]


@pytest.mark.slow
def test_multi_static_monte_carlo_of_200_records(two_hundred_calibrations):
    """As above over 200 industrial IMUs: rms z per 3-vector group within 0.91-1.10 (600 z), the gyro matrix's
    within 0.95-1.06 (1,800 z). Found: accelerometer bias 1.02, scale 0.97, non-orthogonality 1.00, gyro bias
    0.99, gyro matrix 0.99 (before the Earth rate and the noise propagation: gyro matrix 1.46).
    """
    _check_normalised_errors(_normalised_errors(two_hundred_calibrations, "multi_static"))


@pytest.mark.slow
def test_six_position_monte_carlo_of_200_records(two_hundred_calibrations):
    """The same check of the six-position calibration on the same 200 IMUs (before each dwell and turn mean had
    its own variance in the fit's 1-sigma: rms z 1.14 for the gyro scale factors, 1.12 the misalignments)."""
    _check_normalised_errors(_normalised_errors(two_hundred_calibrations, "six_position"))


def test_slow_bias_covariance_of_interval_means_closed_form():
    """The closed form of the covariance of two interval means of sigma^2 exp(-|tau|/T) against a midpoint sum
    on a 1 ms grid (1.2e-6 relative found); overlapping, disjoint and equal spans."""
    spans = np.array([[0.0, 3.0], [3.5, 5.0], [2.0, 4.0]])
    terms = (np.array([2.0, 0.5]), np.array([0.3, 40.0]))
    step = 1e-3
    grids = [np.arange(a + step / 2, b, step) for a, b in spans]
    numeric = np.array([[sum(sigma**2 * np.exp(-np.abs(u[:, None] - v[None, :]) / T).mean()
                             for sigma, T in zip(*terms)) for v in grids] for u in grids])
    assert mean_covariance(spans, spans, terms) == pytest.approx(numeric, rel=1e-5)


def test_multi_static_slow_terms_widen_the_1_sigma():
    """An error model without slow terms changes nothing; with the grade's bias instability the 1-sigma grows."""
    plan = MultiStaticPlan(positions=12, sample_interval_s=0.02, latitude_rad=LATITUDE)
    gyro_true, accel_true = plan.truth(seed=2)
    white, full = calibration_model("industrial"), preset("industrial")
    gyro, accel = ImuSimulator(white, plan.sample_interval_s, true_gyro=gyro_true, true_accel=accel_true,
                               seed=2).window([0], 0, gyro_true.shape[0])
    fits = [calibrate_multi_static(gyro[0], accel[0], plan.sample_interval_s, initial=plan.initial_s,
                                   gravity=plan.gravity, latitude=LATITUDE, error_model=model)
            for model in (None, white, full)]
    for name in ("accel_bias_sigma", "gyro_matrix_sigma", "gyro_bias_sigma"):
        assert getattr(fits[1], name) == pytest.approx(getattr(fits[0], name), rel=1e-12)
        assert np.all(getattr(fits[2], name) > getattr(fits[0], name))


@pytest.mark.slow
def test_multi_static_monte_carlo_with_slow_terms():
    """200 industrial IMUs with the preset's bias instability (10 deg/h, 0.03 mg) left in and the error model given
    to the fit: the same bands against the turn-on errors. Found: 0.99-1.03 per group (without the model:
    accelerometer biases 1.46, gyro bias 3.0 over 40 IMUs)."""
    model = preset("industrial")
    model = replace(model, gyro=replace(model.gyro, g_sensitivity=np.zeros((3, 3))))   # what no calibration removes
    records = []
    for seed in range(200):
        plan = MultiStaticPlan(positions=36, sample_interval_s=0.01, latitude_rad=LATITUDE)
        gyro_true, accel_true = plan.truth(seed)
        simulator = ImuSimulator(model, plan.sample_interval_s, true_gyro=gyro_true,
                                 true_accel=accel_true, seed=seed)
        gyro, accel = simulator.window([0], 0, gyro_true.shape[0])
        constants = simulator.constants([0])
        fit = calibrate_multi_static(gyro[0], accel[0], plan.sample_interval_s, initial=plan.initial_s,
                                     gravity=plan.gravity, latitude=LATITUDE, error_model=model)
        truth = identifiable_truth(constants["accel_matrix"][0], constants["accel_bias"][0],
                                   constants["gyro_matrix"][0])
        start = plan.attitudes(seed)[0]
        truth["gyro_bias"] = constants["gyro_bias"][0] + constants["gyro_matrix"][0] @ (start.T @ earth_rate_ned(
            LATITUDE))
        records.append({name: (getattr(fit, name) - truth[name]).ravel() / getattr(fit, f"{name}_sigma").ravel()
                        for name in ("accel_bias", "accel_scale", "accel_non_orthogonality", "gyro_bias",
                                     "gyro_matrix")})
    _check_normalised_errors({name: np.concatenate([r[name] for r in records]) for name in records[0]})


def test_imu_simulator_and_six_position_agree_on_the_truth():
    """The calibration's truth is the simulator's: its drawn K and b (measured - true) are what six positions find.

    Navigation grade over 60 s dwells: 1-sigma from white noise only, checked per entry at 4.5 sigma.
    """
    model = preset("navigation")
    plan = SixPositionPlan(latitude_rad=LATITUDE, dwell_s=60.0, turn_s=36.0, sample_interval_s=0.05)
    gyro_true, accel_true = plan.truth()
    simulator = ImuSimulator(model, plan.sample_interval_s, true_gyro=gyro_true, true_accel=accel_true,
                             seed=8)
    gyro, accel = simulator.window([0], 0, gyro_true.shape[0])
    constants = simulator.constants([0])
    fit = calibrate_six_position(gyro[0], accel[0], plan, model.gyro.random_walk, model.accel.random_walk)
    slow = np.hypot(model.accel.bias_instability, 1e-30)   # the slow terms the fit does not model, m/s^2
    assert np.all(np.abs(fit.accel_bias - constants["accel_bias"][0]) < 4.5 * np.hypot(fit.accel_bias_sigma, slow))


def test_align_compare_refuses_no_data():
    with pytest.raises(InvalidParameter, match="record"):
        align_compare(imu=None)


def test_align_compare_json_and_figure(run_cli, tmp_path):
    """``schuler align compare --imu GRADE --json --out DIR``: the documented keys, one figure <= 7 in wide."""
    out = run_cli("align", "compare", "--imu", "navigation", "--duration", "120", "--imu-rate", "20", "--json",
                  "--out", tmp_path)
    assert out.code == 0, out.stderr
    methods = out.json()["methods"]
    assert set(methods) == set(METHOD_NAMES)
    for name, row in methods.items():
        for key in ("roll_rad", "pitch_rad", "heading_rad", "limit_heading_rad", "convergence_time_s"):
            assert math.isfinite(row[key]), (name, key)
        assert (row["heading_sigma_rad"] is None) == (name != "kalman")
        # a simulated record's truth is known: every heading within 4 of its 1-sigma limits
        assert abs(row["heading_error_rad"]) < 4 * row["limit_heading_rad"], name
    assert (tmp_path / "align_compare_heading.png").exists() and (tmp_path / "align_compare_heading.svg").exists()
    from matplotlib.image import imread

    height, width = imread(tmp_path / "align_compare_heading.png").shape[:2]
    assert width <= 700 and height <= 700


def test_north_and_calibrate_compare_commands(run_cli, tmp_path):
    """``north compare`` has schuler north on its curve; ``calibrate compare`` has the pulse method beside."""
    out = run_cli("north", "compare", "--duration", "60", "--imu-rate", "2", "--monte-carlo", "3", "--json",
                  "--out", tmp_path)
    assert out.code == 0, out.stderr
    north = out.json()
    assert set(north["methods"]) == set(NORTH_METHODS)
    assert north["ground_gyrocompass"]["sigma_rad"] > 0
    assert len(north["versus_time"]["ground_gyrocompass"]) == len(north["versus_time"]["duration_s"])
    assert (tmp_path / "north_compare_accuracy.png").exists()
    out = run_cli("calibrate", "compare", "--positions", "12", "--dwell", "10", "--imu-rate", "20",
                  "--monte-carlo", "4", "--json", "--out", tmp_path)
    assert out.code == 0, out.stderr
    calibration = out.json()
    assert calibration["pulse"]["drift_sigma_rad_s"] > 0
    assert {"gyro_bias", "accel_bias", "gyro_scale", "accel_scale"} <= set(calibration["six_position"])
    assert {"accel_non_orthogonality", "gyro_matrix"} <= set(calibration["multi_static"])
    written = json.dumps(calibration)
    assert "NaN" not in written


def test_comparisons_plot_and_write_their_table(tmp_path):
    import matplotlib.pyplot as plt
    import pandas as pd

    from schuler.registry import get_system

    align = get_system("align")
    result = align.action("compare")(imu="navigation", duration=60.0, imu_rate=10.0)
    plt.close(result.plot())
    frame = result.to_dataframe()
    assert set(frame.columns) == {f"{m}_{c}" for m in result.estimates for c in ("t_s", "heading_rad")}
    names = {p.name for p in align.write(result, tmp_path, action="compare")}
    assert names == {"align_compare_heading.png", "align_compare_heading.svg", "align_compare_heading.csv"}
    written = pd.read_csv(tmp_path / "align_compare_heading.csv")
    np.testing.assert_allclose(written["kalman_heading_rad"].dropna(), frame["kalman_heading_rad"].dropna())
    estimate = result.estimates["kalman"]
    assert "kalman" in str(estimate) and estimate.to_dict()["method"] == "kalman"
    history = estimate.to_dataframe()
    assert len(history) == estimate.time_s.size and "heading_sigma_rad" in history
    north = compare_north("tactical", latitude=math.radians(45.0), heading=0.5, duration=60.0,
                          sample_interval=0.5, members=3)
    assert list(north.to_dataframe().columns) == list(north.versus_time)
    figures = comparison_figures(north)
    assert set(figures) == {"north_compare_accuracy"} and comparison_figures(estimate) == {}
    names = {p.name for p in comparison_data_files(north, tmp_path / "north")}
    assert names == {"north_compare_accuracy.csv"}
    plt.close("all")
