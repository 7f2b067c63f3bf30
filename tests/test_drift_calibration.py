"""System 3: alternating-pulse drift calibration (source 001)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from schuler.core.earth import EARTH_RATE
from schuler.core.geometry import ARCSEC, DEG_PER_HOUR
from schuler.drift_calibration.error_budget import NONE, TYPICAL
from schuler.drift_calibration.monte_carlo import monte_carlo
from schuler.drift_calibration.plant import plant_reading
from schuler.drift_calibration.procedure import (
    apparent_drift, azimuth_from_channels, azimuth_from_single_channel, azimuth_sensitivity, rate_from_reading,
    run_procedure, separate_drift)
from schuler.drift_calibration.pulses import from_function, from_samples, rectangular, triangular
from schuler.drift_calibration.stabilizer import (
    Stabilizer, leak_error_initial_angle, loop_lag_error_rectangular, reading_closed_form, simulate_cycle)
from schuler.exceptions import InvalidParameter, NotObservable

SHAPES = [rectangular(), triangular(), from_function(lambda u: np.sin(np.pi * u) ** 2, 51),
          from_samples([0, 0.3, 0.7, 1], [0.2, 1.0, 1.0, 0.2])]


def stab(shape=None, **kw):
    base = dict(k1=57.3, torquer_gain=1.745e-3, angular_momentum=0.1, pulse_current=0.01, tau=5.0,
                shape=shape or rectangular())
    base.update(kw)
    return Stabilizer(**base)


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: s.name)
@pytest.mark.parametrize("quadrant_azimuth", [30.0, 120.0, 210.0, 300.0])
def test_noise_free_recovery_any_shape_all_quadrants(shape, quadrant_azimuth):
    """Ideal loop, no errors: omega_d and A0 recovered to 1e-9 relative (issue 5)."""
    for k_m, h in ((1e-4, 0.05), (5e-3, 0.3)):
        s = stab(shape, torquer_gain=k_m, angular_momentum=h)
        out = run_procedure(s, math.radians(55.0), math.radians(quadrant_azimuth), 0.1 * DEG_PER_HOUR, -0.3 * DEG_PER_HOUR)
        assert out.drift_x[0] == pytest.approx(0.1 * DEG_PER_HOUR, rel=1e-9)
        assert out.drift_y[0] == pytest.approx(-0.3 * DEG_PER_HOUR, rel=1e-9)
        assert math.degrees(out.azimuth[0]) == pytest.approx(quadrant_azimuth, rel=1e-9)


@settings(max_examples=15, deadline=None)
@given(km=st.floats(1e-5, 1e-2), h=st.floats(0.01, 1.0), amp=st.floats(1e-4, 0.1),
       top=st.floats(0.0, 2.0), rate=st.floats(-1e-4, 1e-4))
def test_reading_independent_of_torquer_and_angular_momentum(km, h, amp, top, rate):
    """(13): a symmetric pulse's reading is -K1 rate tau^2 whatever K_M, H, amplitude, shape."""
    shape = from_samples([0, 0.25, 0.5, 0.75, 1], [0, 1, top, 1, 0])
    s = stab(shape, torquer_gain=km, angular_momentum=h, pulse_current=amp)
    reading = simulate_cycle(s, rate).reading[0]
    assert rate_from_reading(reading, s.k1, s.tau) == pytest.approx(rate, rel=1e-7, abs=1e-16)


def test_asymmetric_pulse_bracket_closed_form_vs_simulation():
    """(11): the bracket K1 (K_M/H) int (tau - 2t) i dt of an asymmetric pulse, simulated vs closed form."""
    shape = from_samples([0, 0.2, 1], [1, 1, 0])
    s = stab(shape)
    reading = simulate_cycle(s, 0.0).reading[0]
    bracket = s.k1 * s.pulse_rate * s.tau**2 * shape.symmetry_bracket()
    assert reading == pytest.approx(bracket, rel=1e-10)
    assert abs(bracket) > 1e-3


@pytest.mark.parametrize("shape", SHAPES[:2], ids=lambda s: s.name)
def test_error_terms_closed_form_vs_simulation(shape):
    """Mismatch, duration, tilt, offset, sway, scale error: generalised (11) vs the simulation."""
    s = stab(shape)
    kw = dict(initial_angle=[1e-4, 0, 0, 0, 0, 0, 0], amplitude_mismatch=[0, 1e-3, 0, 0, 0, 0, 0],
              duration_mismatch=[0, 0, 1e-6, 0, 0, 0, -2e-6], tilt=[0, 0, 0, 1e-2, 0, 0, 0],
              integrator_offset=[0, 0, 0, 0, 1e-7, 0, 0], sway_angle=[0, 0, 0, 0, 0, 1e-5, 0],
              sensor_scale_error=[0, 0, 0, 0, 0, 0, 1e-3])
    rate = np.full(7, 3e-5)
    simulated = simulate_cycle(s, rate, **kw).reading
    closed = reading_closed_form(s, rate, **kw)
    np.testing.assert_allclose(simulated, closed, rtol=1e-10)
    # amplitude mismatch costs epsilon (K_M/H) int_0^tau I dt / tau^2 in rate
    error = rate_from_reading(simulated[1] - reading_closed_form(s, rate[1]), s.k1, s.tau)
    assert error == pytest.approx(-1e-3 * s.pulse_rate * shape.double_integral(), rel=1e-8)


def test_loop_lag_biases_drift_but_cancels_in_earth_rate():
    """First-order loop: closed-form error vs simulation; the pulse part cancels in (16)."""
    lagged = stab(loop_time_constant=0.005)
    ideal = stab()
    for rate in (2e-5, -1e-5):
        extra = simulate_cycle(lagged, rate).reading[0] - simulate_cycle(ideal, rate).reading[0]
        assert extra == pytest.approx(loop_lag_error_rectangular(lagged, rate), rel=1e-8)
    r1 = simulate_cycle(lagged, 1e-6 + 2e-5).reading[0]
    r2 = simulate_cycle(lagged, 1e-6 - 2e-5).reading[0]
    drift, earth = separate_drift(r1, r2, lagged.k1, lagged.tau)
    scale = 1 - (0.005 / 5.0) ** 2 * (1 - math.exp(-1000.0)) ** 2
    assert earth == pytest.approx(2e-5 * scale, rel=1e-9)  # only the tiny scale term remains
    assert abs(drift - 1e-6) > 1e-8  # the pulse lag biases omega_d strongly


def test_leaky_integrator_initial_angle():
    s = stab(pulse_current=0.0, integrator_leak_time=50.0)
    assert simulate_cycle(s, 0.0, initial_angle=2e-4).reading[0] == pytest.approx(
        leak_error_initial_angle(s, 2e-4), rel=1e-9)


def test_180_degree_separation_formulas():
    """(15)/(16) separate own drift and apparent drift from the two readings."""
    s = stab(triangular())
    d, w0 = 0.2 * DEG_PER_HOUR, 4.0 * DEG_PER_HOUR
    r1 = simulate_cycle(s, d + w0).reading[0]
    r2 = simulate_cycle(s, d - w0).reading[0]
    drift, earth = separate_drift(r1, r2, s.k1, s.tau)
    assert drift == pytest.approx(d, rel=1e-9) and earth == pytest.approx(w0, rel=1e-10)


@pytest.mark.parametrize("azimuth", [30.0, 120.0, 210.0, 300.0])
def test_round_trip_against_3d_plant(azimuth):
    """The sign chain: first-principles plant readings -> (15)/(16) -> atan2 give back drift and A0."""
    latitude, dx, dy = math.radians(62.0), 0.3 * DEG_PER_HOUR, -0.2 * DEG_PER_HOUR
    readings = {}
    for channel, own in (("x", dx), ("y", dy)):
        readings[channel] = [plant_reading(latitude, math.radians(azimuth) + turn, own_drift=own, channel=channel,
                                           k1=57.3, tau=5.0, pulse_rate=2e-4, shape=triangular())
                             for turn in (0.0, math.pi)]
    drift_x, omega_x0 = separate_drift(*readings["x"], 57.3, 5.0)
    drift_y, omega_y0 = separate_drift(*readings["y"], 57.3, 5.0)
    assert drift_x == pytest.approx(dx, rel=1e-8) and drift_y == pytest.approx(dy, rel=1e-8)
    assert omega_x0 == pytest.approx(EARTH_RATE * math.cos(latitude) * math.sin(math.radians(azimuth)), rel=1e-9)
    assert math.degrees(azimuth_from_channels(omega_x0, omega_y0)) == pytest.approx(azimuth, rel=1e-9)


def test_plant_levelling_residual_matches_first_order_coupling():
    """Spec: a 10 arcsec tilt at 70 deg couples ~7e-4 deg/h; the plant agrees with -Omega sin(phi) e."""
    latitude, tilt = math.radians(70.0), 10.0 * ARCSEC
    level = plant_reading(latitude, 0.3, own_drift=0.0, channel="x", k1=1.0, tau=5.0, pulse_rate=1e-4,
                          shape=rectangular())
    tilted = plant_reading(latitude, 0.3, own_drift=0.0, channel="x", k1=1.0, tau=5.0, pulse_rate=1e-4,
                           shape=rectangular(), pitch=-tilt)
    coupling = rate_from_reading(tilted - level, 1.0, 5.0)
    assert abs(coupling) / DEG_PER_HOUR == pytest.approx(EARTH_RATE * math.sin(latitude) * tilt / DEG_PER_HOUR, rel=1e-4)
    assert abs(coupling) / DEG_PER_HOUR == pytest.approx(6.9e-4, rel=0.02)


def test_asin_ambiguity_and_conditioning():
    latitude = math.radians(70.0)
    for azimuth in (100.0, 170.0):
        wx, _, _ = apparent_drift(latitude, math.radians(azimuth))
        principal, alternative, _ = azimuth_from_single_channel(wx, latitude)
        assert math.degrees(alternative) == pytest.approx(azimuth, rel=1e-9)
        assert math.degrees(principal) == pytest.approx(180.0 - azimuth, rel=1e-9)
    # an error of 1e-3 deg/h in omega_X0: asin error grows as 1/cos A0, atan2 stays flat
    errors = {}
    for azimuth in (10.0, 80.0, 89.0):
        wx, wy, _ = apparent_drift(latitude, math.radians(azimuth))
        a1, _, _ = azimuth_from_single_channel(wx + 1e-3 * DEG_PER_HOUR, latitude)
        a3 = azimuth_from_channels(wx + 1e-3 * DEG_PER_HOUR, wy)
        errors[azimuth] = (abs(a1 - math.radians(azimuth)), abs(a3 - math.radians(azimuth)))
        if azimuth < 85.0:  # beyond, the asin is nonlinear (even saturates): no first-order estimate
            assert errors[azimuth][0] == pytest.approx(
                1e-3 * DEG_PER_HOUR * azimuth_sensitivity(math.radians(azimuth), latitude, "single-axis"), rel=0.05)
    assert errors[89.0][0] > 20 * errors[10.0][0]
    assert errors[89.0][1] < 1.01 * errors[10.0][1] / abs(math.cos(math.radians(10.0))) + 1e-12


def test_latitude_error_affects_only_single_axis():
    s = stab()
    budget = TYPICAL.only("latitude_error")
    three = monte_carlo(s, math.radians(70), math.radians(80), DEG_PER_HOUR, budget=budget, trials=200)
    single = monte_carlo(s, math.radians(70), math.radians(80), DEG_PER_HOUR, budget=budget, trials=200,
                         mode="single-axis")
    assert three.rms_azimuth_error == 0.0
    # dA = tan(phi) tan(A0) dphi
    expected = math.tan(math.radians(70)) * math.tan(math.radians(80)) * TYPICAL.latitude_error
    assert single.rms_azimuth_error == pytest.approx(expected, rel=0.15)


def test_monte_carlo_sensor_noise_matches_closed_form_and_converges():
    """Sensor noise only: RMS drift error = N sqrt(2 tau) / (sqrt(2) tau^2) (two runs averaged by (15))."""
    s = stab()
    budget = NONE.only().__class__(sensor_noise_density=1e-6)
    expected = 1e-6 * math.sqrt(2 * s.tau) / s.tau**2 / math.sqrt(2)
    deviations = []
    for trials in (250, 4000):
        mc = monte_carlo(s, math.radians(70), math.radians(80), DEG_PER_HOUR, budget=budget, trials=trials, seed=3)
        deviations.append(abs(mc.rms_drift_error / expected - 1))
        assert abs(mc.rms_drift_error / expected - 1) < 4.0 / math.sqrt(2 * trials * 2)
    assert deviations[1] < 0.05


def test_multi_position_reduces_error():
    s = stab()
    budget = TYPICAL.only("angle_random_walk")
    rms = [monte_carlo(s, math.radians(70), math.radians(80), DEG_PER_HOUR, budget=budget, trials=600, positions=n,
                       seed=1).rms_azimuth_error for n in (2, 8)]
    assert rms[1] == pytest.approx(rms[0] / 2.0, rel=0.2)  # 1/sqrt(N) for independent cycle noise


def test_multi_position_single_axis_resolves_ambiguity():
    out = run_procedure(stab(), math.radians(50), math.radians(130), DEG_PER_HOUR, mode="single-axis", positions=4)
    assert math.degrees(out.azimuth[0]) == pytest.approx(130.0, rel=1e-9)


def test_cycles_averaging_reduces_noise():
    s = stab()
    budget = TYPICAL.only("angle_random_walk")
    one = monte_carlo(s, math.radians(70), math.radians(80), DEG_PER_HOUR, budget=budget, trials=600, seed=2)
    four = monte_carlo(s, math.radians(70), math.radians(80), DEG_PER_HOUR, budget=budget, trials=600, cycles=4, seed=2)
    assert four.rms_azimuth_error == pytest.approx(one.rms_azimuth_error / 2.0, rel=0.2)


def test_pole_and_bad_parameters_raise():
    with pytest.raises(NotObservable):
        run_procedure(stab(), math.pi / 2, 0.0, DEG_PER_HOUR)
    with pytest.raises(InvalidParameter):
        stab(k1=0.0)
    with pytest.raises(InvalidParameter):
        stab(tau=-1.0)
    with pytest.raises(InvalidParameter):
        dataclasses.replace(TYPICAL, sensor_scale_error=float("nan"))


def test_cli_run_json_keys(run_cli):
    out = run_cli("calibrate", "run", "--latitude", "70", "--azimuth", "80", "--drift", "0.1 deg/h", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["drift_deg_h"] == pytest.approx(0.1, rel=1e-9)
    assert data["earth_rate_component_deg_h"] == pytest.approx(
        math.degrees(EARTH_RATE) * 3600 * math.cos(math.radians(70)) * math.sin(math.radians(80)), rel=1e-9)
    assert 0 <= data["azimuth_deg"] < 360 and data["azimuth_deg"] == pytest.approx(80.0, rel=1e-9)
    assert abs(data["azimuth_error_arcmin"]) < 1e-6 and data["cycle_time_s"] == 10.0


def test_cli_monte_carlo_positions_and_plots(run_cli, tmp_path):
    out = run_cli("calibrate", "run", "--azimuth", "350", "--mode", "single-axis", "--monte-carlo", "200",
                  "--positions", "3", "--drift-y", "0.2", "--out", tmp_path, "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["monte_carlo"]["trials"] == 200 and data["azimuth_deg"] == pytest.approx(350.0, rel=1e-9)
    assert (tmp_path / "calibrate_cycle.png").exists() and (tmp_path / "calibrate_histograms.svg").exists()


@pytest.mark.parametrize("args, option", [
    (("--latitude", "90"), "--latitude"), (("--latitude", "-90"), "--latitude"), (("--tau", "0"), "--tau"),
    (("--tau", "-1 s"), "--tau"), (("--k1", "0"), "--k1"), (("--drift", "nan"), "--drift"),
    (("--azimuth", "nan"), "--azimuth")])
def test_cli_bad_input_one_line_exit_2(run_cli, args, option):
    out = run_cli("calibrate", "run", *args)
    assert out.code == 2 and out.stderr.count("\n") == 1 and option in out.stderr


def test_other_asin_branch_only_where_it_exists(run_cli):
    # one channel over two positions measures sin(A0) only: 80 deg and 180 - 80 = 100 deg both fit
    single = run_cli("calibrate", "run", "--azimuth", "80", "--mode", "single-axis", "--positions", "2")
    assert single.code == 0, single.stderr
    branch = next(line for line in single.stdout.splitlines() if "other asin branch" in line)
    assert "100.000000 deg" in branch
    # two channels (or more positions) give A0 by atan2: no second branch to show, though the JSON keeps the key
    three = run_cli("calibrate", "run", "--azimuth", "80", "--mode", "three-axis")
    assert three.code == 0 and "other asin branch" not in three.stdout
    assert run_cli("calibrate", "run", "--azimuth", "80", "--json").json()["azimuth_alternative_deg"] == \
        pytest.approx(80.0)


def test_reproduce_human_says_which_budget_gives_the_source_numbers(run_cli):
    out = run_cli("calibrate", "reproduce")
    assert out.code == 0, out.stderr
    text = " ".join(out.stdout.split())
    assert "The typical budget x 0.181 gives the source's 2 arcmin" in text
    # relative drift error ~ 1/drift: 0.34 % with the 2-arcmin budget means about 0.237 / 0.34 = 0.7 deg/h
    assert "both of the source's numbers hold together for a drift of 0.7 deg/h" in text


def test_reproduce_scenario_and_budget_scale(run_cli):
    """Source 001: 70 deg, 80 deg, 0.34 % and 2 arcmin; the budget scaled to 2 arcmin gives a few 0.1 %."""
    out = run_cli("calibrate", "reproduce", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    scaled = data["scaled_budget"]["three-axis"]
    assert scaled["rms_azimuth_error_arcmin"] == pytest.approx(2.0, rel=1e-3)  # linear but for the fixed loop lag
    assert 0.1 < scaled["mean_relative_drift_error_percent"] < 0.6
    assert data["scaled_budget"]["single-axis"]["rms_azimuth_error_arcmin"] > 3 * 2.0


def test_sweep_vectorised_matches_run():
    from schuler.drift_calibration.api import PARAMETERS, SYSTEM

    values = {p.name: np.full(4, p.parse(p.default)) for p in PARAMETERS if p.default is not None}
    values.update(latitude=np.radians([10.0, 40.0, 70.0, -60.0]), azimuth=np.radians([5.0, 95.0, 185.0, 275.0]),
                  drift=np.array([1, 2, 3, 4]) * DEG_PER_HOUR)
    for name in ("sensor_noise", "sensor_scale_error", "amplitude_mismatch", "duration_mismatch",
                 "pulse_asymmetry", "integrator_offset", "lag_compensation_error", "sway_amplitude",
                 "angle_random_walk", "turn_angle_error", "levelling_residual", "initial_angle", "latitude_error"):
        values[name] = np.zeros(4)
    out = SYSTEM.sweep(values)
    np.testing.assert_allclose(out["azimuth_rad"], values["azimuth"], rtol=1e-9)
    np.testing.assert_allclose(out["relative_drift_error"], 0.0, atol=1e-8)
    values["angle_random_walk"] = np.full(4, TYPICAL.angle_random_walk)
    noisy = SYSTEM.sweep(values)
    assert np.all(np.abs(noisy["azimuth_error_rad"]) > 0)
