"""The alternating-pulse drift calibration's model: pulses, one cycle, the procedure, the 3-D plant.

Source: the alternating-pulse calibration article (schuler.references.PULSE_CALIBRATION);
equation numbers are its own. The system on the contract (evaluate, run, Monte Carlo,
reproduction, CLI) is tested in test_drift_calibration_system.py.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.core.earth import EARTH_RATE
from schuler.drift_calibration.error_budget import TYPICAL
from schuler.drift_calibration.plant import plant_reading
from schuler.drift_calibration.procedure import (
    apparent_drift,
    azimuth_from_channels,
    azimuth_from_single_channel,
    azimuth_sensitivity,
    rate_from_reading,
    run_procedure,
    separate_drift,
)
from schuler.drift_calibration.pulses import (
    from_function,
    from_samples,
    rectangular,
    triangular,
)
from schuler.drift_calibration.stabilizer import (
    Stabilizer,
    cycle_grid,
    leak_error_initial_angle,
    loop_lag_error_rectangular,
    reading_closed_form,
    simulate_cycle,
)
from schuler.exceptions import InvalidParameter, NotObservable

DEG_H = math.radians(1.0) / 3600.0
SHAPES = [rectangular(), triangular(), from_function(lambda u: np.sin(np.pi * u) ** 2, 51),
          from_samples([0, 0.3, 0.7, 1], [0.2, 1.0, 1.0, 0.2])]


def stab(shape=None, **kw):
    base = {"k1": 57.3, "torquer_gain": 1.745e-3, "angular_momentum": 0.1, "pulse_current": 0.01, "tau": 5.0,
            "shape": shape or rectangular()}
    base.update(kw)
    return Stabilizer(**base)


@pytest.mark.parametrize("delta", [-1.0, -1.5, float("nan"), [0.0, -2.0]])
def test_closed_form_and_simulation_refuse_a_second_pulse_of_no_length(delta):
    for reading in (reading_closed_form, simulate_cycle):
        with pytest.raises(InvalidParameter, match=r"duration_mismatch: must be > -1"):
            reading(stab(), 1e-5, duration_mismatch=delta)
    # just above -1 the closed form still gives a finite reading
    assert np.isfinite(reading_closed_form(stab(), 1e-5, duration_mismatch=-0.999))


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: s.name)
@pytest.mark.parametrize("quadrant_azimuth", [30.0, 120.0, 210.0, 300.0])
def test_noise_free_recovery_any_shape_all_quadrants(shape, quadrant_azimuth):
    """Ideal loop, no errors: omega_d and A0 recovered to 1e-9 relative (issue 5)."""
    for k_m, h in ((1e-4, 0.05), (5e-3, 0.3)):
        s = stab(shape, torquer_gain=k_m, angular_momentum=h)
        out = run_procedure(s, math.radians(55.0), math.radians(quadrant_azimuth), 0.1 * DEG_H, -0.3 * DEG_H)
        assert out.drift_x[0] == pytest.approx(0.1 * DEG_H, rel=1e-9)
        assert out.drift_y[0] == pytest.approx(-0.3 * DEG_H, rel=1e-9)
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
    kw = {"initial_angle": [1e-4, 0, 0, 0, 0, 0, 0], "amplitude_mismatch": [0, 1e-3, 0, 0, 0, 0, 0],
          "duration_mismatch": [0, 0, 1e-6, 0, 0, 0, -2e-6], "tilt": [0, 0, 0, 1e-2, 0, 0, 0],
          "integrator_offset": [0, 0, 0, 0, 1e-7, 0, 0], "sway_angle": [0, 0, 0, 0, 0, 1e-5, 0],
          "sensor_scale_error": [0, 0, 0, 0, 0, 0, 1e-3]}
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
    d, w0 = 0.2 * DEG_H, 4.0 * DEG_H
    r1 = simulate_cycle(s, d + w0).reading[0]
    r2 = simulate_cycle(s, d - w0).reading[0]
    drift, earth = separate_drift(r1, r2, s.k1, s.tau)
    assert drift == pytest.approx(d, rel=1e-9) and earth == pytest.approx(w0, rel=1e-10)


@pytest.mark.parametrize("azimuth", [30.0, 120.0, 210.0, 300.0])
def test_round_trip_against_3d_plant(azimuth):
    """The sign chain: first-principles plant readings -> (15)/(16) -> atan2 give back drift and A0."""
    latitude, dx, dy = math.radians(62.0), 0.3 * DEG_H, -0.2 * DEG_H
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
    latitude, tilt = math.radians(70.0), math.radians(10.0 / 3600.0)
    level = plant_reading(latitude, 0.3, own_drift=0.0, channel="x", k1=1.0, tau=5.0, pulse_rate=1e-4,
                          shape=rectangular())
    tilted = plant_reading(latitude, 0.3, own_drift=0.0, channel="x", k1=1.0, tau=5.0, pulse_rate=1e-4,
                           shape=rectangular(), pitch=-tilt)
    coupling = rate_from_reading(tilted - level, 1.0, 5.0)
    assert abs(coupling) / DEG_H == pytest.approx(EARTH_RATE * math.sin(latitude) * tilt / DEG_H, rel=1e-4)
    assert abs(coupling) / DEG_H == pytest.approx(6.9e-4, rel=0.02)


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
        a1, _, _ = azimuth_from_single_channel(wx + 1e-3 * DEG_H, latitude)
        a3 = azimuth_from_channels(wx + 1e-3 * DEG_H, wy)
        errors[azimuth] = (abs(a1 - math.radians(azimuth)), abs(a3 - math.radians(azimuth)))
        if azimuth < 85.0:  # beyond, the asin is nonlinear (even saturates): no first-order estimate
            assert errors[azimuth][0] == pytest.approx(
                1e-3 * DEG_H * azimuth_sensitivity(math.radians(azimuth), latitude, "single-axis"), rel=0.05)
    assert errors[89.0][0] > 20 * errors[10.0][0]
    assert errors[89.0][1] < 1.01 * errors[10.0][1] / abs(math.cos(math.radians(10.0))) + 1e-12


def test_multi_position_single_axis_resolves_ambiguity():
    out = run_procedure(stab(), math.radians(50), math.radians(130), DEG_H, mode="single-axis", positions=4)
    assert math.degrees(out.azimuth[0]) == pytest.approx(130.0, rel=1e-9)


def test_pole_and_bad_parameters_raise():
    with pytest.raises(NotObservable):
        run_procedure(stab(), math.pi / 2, 0.0, DEG_H)
    with pytest.raises(InvalidParameter):
        stab(k1=0.0)
    with pytest.raises(InvalidParameter):
        stab(tau=-1.0)
    with pytest.raises(InvalidParameter):
        dataclasses.replace(TYPICAL, sensor_scale_error=float("nan"))
    with pytest.raises(InvalidParameter, match="noise"):
        simulate_cycle(stab(), 1e-5, sensor_noise_density=1e-6)  # noise density without samples


@pytest.mark.parametrize("delta", [0.05, -0.2])
def test_long_duration_mismatch_tail_closed_form_vs_simulation(delta):
    """A tail far beyond the Taylor step (scaled and squared): generalised (11) still holds to 1e-10."""
    s = stab(triangular())
    rate = np.array([3e-5, -2e-5])
    kw = {"duration_mismatch": delta, "sway_angle": [1e-5, 0.0], "sway_rate": [0.0, 2e-5], "integrator_offset": 1e-7}
    np.testing.assert_allclose(simulate_cycle(s, rate, **kw).reading, reading_closed_form(s, rate, **kw), rtol=1e-10)


def test_noise_samples_held_per_step_give_the_integrals_variance():
    """Sensor noise only: the reading's spread is N K1 sqrt(2 tau) (white noise of density N integrated over 2 tau)."""
    s = stab()
    members, density = 4000, 1e-6
    samples = cycle_grid(s.shape).size - 1
    noise = np.random.default_rng(11).standard_normal((members, 2, 2, samples))
    readings = simulate_cycle(s, np.zeros(members), sensor_noise_density=density, noise=noise).reading
    # 4000 readings: the sample std is within 4 standard errors (1.1 % each) of the exact value
    assert readings.std() == pytest.approx(density * s.k1 * math.sqrt(2 * s.tau), rel=0.045)
