"""Single-channel, vertical-channel and effective-period models of Bollay (1966), and its reproduction."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.core.earth import BOLLAY, FOOT, MEAN_RADIUS, STANDARD_GRAVITY, STATUTE_MILE
from schuler.core.lti import simulate
from schuler.exceptions import InvalidParameter
from schuler.navigation_errors.actions import VERTICAL_PARAMETERS, vertical
from schuler.navigation_errors.effective_period import (
    effective_schuler_period,
    flight_gravity,
    orbital_speed,
    thrust_gravity,
)
from schuler.navigation_errors.inputs import FLIGHT_TIME
from schuler.navigation_errors.reproduction import (
    MAGNITUDES,
    SPEED,
    problem3_rows,
    report,
    reproduce,
)
from schuler.navigation_errors.single_channel import (
    SOURCES,
    channel_model,
    flat_error,
    maximum_error,
    simulate_error,
    spherical_error,
    x_minus_sin,
)
from schuler.navigation_errors.vertical_channel import (
    BaroLoopGains,
    aided_steady_state_error,
    baro_aided_model,
    check_stable,
    critically_damped_gains,
    hover_altitude_error,
    printed_hover_expression,
    unaided_model,
)
from schuler.reproduction import printed_value

R_BOLLAY, G_BOLLAY = BOLLAY.radius, BOLLAY.effective_gravity
EARTHS = {"bollay": (R_BOLLAY, G_BOLLAY), "default": (MEAN_RADIUS, STANDARD_GRAVITY)}


# --- closed form vs simulation -------------------------------------------------------------------

@pytest.mark.parametrize("earth", sorted(EARTHS))
@pytest.mark.parametrize("source", SOURCES)
def test_spherical_closed_form_matches_simulation(source, earth):
    radius, gravity = EARTHS[earth]
    t = np.linspace(0.0, 3 * FLIGHT_TIME, 121)
    closed = spherical_error(source, MAGNITUDES[source], t, radius, gravity, SPEED)
    simulated = simulate_error(source, MAGNITUDES[source], t, radius, gravity, SPEED)
    # exact matrix exponential: agreement to rounding, relative to the error's size
    np.testing.assert_allclose(simulated, closed, rtol=0, atol=1e-9 * np.max(np.abs(closed)))


@pytest.mark.parametrize("source", SOURCES)
def test_flat_closed_form_matches_simulation_with_infinite_radius(source):
    t = np.linspace(0.0, FLIGHT_TIME, 101)
    closed = flat_error(source, MAGNITUDES[source], t, G_BOLLAY, SPEED)
    simulated = simulate_error(source, MAGNITUDES[source], t, np.inf, G_BOLLAY, SPEED)
    np.testing.assert_allclose(simulated, closed, rtol=0, atol=1e-9 * np.max(np.abs(closed)))


@pytest.mark.parametrize("source", SOURCES)
def test_spherical_tends_to_flat_for_short_times(source):
    # omega t << 1: the Schuler loop has not acted yet; the relative difference is O((omega t)^2)
    t = np.array([1.0, 10.0])
    flat = flat_error(source, MAGNITUDES[source], t, G_BOLLAY, SPEED)
    spherical = spherical_error(source, MAGNITUDES[source], t, R_BOLLAY, G_BOLLAY, SPEED)
    np.testing.assert_allclose(spherical, flat, rtol=2e-4)


def test_platform_tilt_of_the_drift_case_is_bounded_by_epsilon_over_omega():
    # spec: tilt from the local vertical is (eps/omega) sin(omega t), at most ~8 arcsec, zero at 10,120 s
    t = np.linspace(0.0, FLIGHT_TIME, 1013)
    tilt = simulate(channel_model(R_BOLLAY, G_BOLLAY), t, inputs=[0.0, MAGNITUDES["drift"]])["tilt"]
    omega = BOLLAY.schuler_frequency
    np.testing.assert_allclose(tilt, MAGNITUDES["drift"] / omega * np.sin(omega * t), atol=1e-15)
    assert math.degrees(np.max(np.abs(tilt))) * 3600 == pytest.approx(8.05, abs=0.01)


def test_x_minus_sin_series_matches_direct_formula_where_both_are_accurate():
    x = np.array([0.05, 0.1, 0.2, 0.2499, 0.2501, 1.0])
    np.testing.assert_allclose(x_minus_sin(x), x - np.sin(x), rtol=1e-10)


@settings(max_examples=25, deadline=None)
@given(
    source=st.sampled_from(SOURCES),
    duration=st.floats(1.0, 40_000.0),
    magnitude=st.floats(1e-6, 1.0),
    speed=st.floats(0.0, 3000.0),
)
def test_maximum_error_is_the_largest_value_on_a_dense_grid(source, duration, magnitude, speed):
    t = np.linspace(0.0, duration, 20_001)
    dense = np.max(np.abs(spherical_error(source, magnitude, t, MEAN_RADIUS, STANDARD_GRAVITY, speed)))
    peak = maximum_error(source, magnitude, duration, MEAN_RADIUS, STANDARD_GRAVITY, speed)
    # the grid can only miss the peak by its curvature over half a step
    assert dense <= peak * (1 + 1e-12) + 1e-12
    assert dense == pytest.approx(float(peak), rel=1e-6, abs=1e-9)


@settings(max_examples=20, deadline=None)
@given(source=st.sampled_from(SOURCES[:4]), scale=st.floats(0.1, 10.0))
def test_errors_are_linear_in_the_magnitude(source, scale):
    t = np.linspace(0.0, FLIGHT_TIME, 7)
    base = spherical_error(source, MAGNITUDES[source], t, R_BOLLAY, G_BOLLAY)
    scaled = spherical_error(source, scale * MAGNITUDES[source], t, R_BOLLAY, G_BOLLAY)
    np.testing.assert_allclose(scaled, scale * base, rtol=1e-12, atol=1e-18)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: spherical_error("gyro", 1.0, 1.0, 1.0, 1.0), "source"),
        (lambda: spherical_error("tilt", np.nan, 1.0, 1.0, 1.0), "magnitude"),
        (lambda: spherical_error("tilt", 1e-4, 1.0, 0.0, 9.8), "radius"),
        (lambda: flat_error("drift", 1e-8, -1.0, 9.8), "time"),
        (lambda: channel_model(-1.0, 9.8), "radius"),
        (lambda: maximum_error("tilt", 1.0, 1.0, 1.0, 1.0, earth="round"), "earth"),
    ],
)
def test_bad_input_raises_invalid_parameter_naming_it(call, name):
    with pytest.raises(InvalidParameter) as error:
        call()
    assert error.value.name == name


# --- Bollay (1966), Problem 3 table and Problem 4 --------------------------------------------------

PUBLISHED = [
    # (quantity, printed exactly as in Bollay 1966, where, unit, erratum?): Problem 3 summary table and
    # solution text, Problem 4 solution
    ("level misalignment 0.01 deg, flat Earth at 10,120 s", "288,000", "Problem 3, summary table", "ft", False),
    ("level misalignment 0.01 deg, flat Earth at 10,120 s", "287,500", "Problem 3, solution (a)", "ft", False),
    ("level misalignment, spherical Earth at 10,120 s", "0", "Problem 3, summary table", "ft", False),
    ("level misalignment, spherical Earth, largest error", "3650", "Problem 3, summary table", "ft", True),
    ("level misalignment, spherical Earth, largest error", "7300", "Problem 3, solution (a)", "ft", False),
    ("level misalignment, amplitude R Delta_theta", "3650", "Problem 3, solution (a)", "ft", False),
    ("launch velocity 1 ft/s, flat Earth at 10,120 s", "10,120", "Problem 3, summary table", "ft", False),
    ("launch velocity, spherical Earth at 10,120 s", "0", "Problem 3, summary table", "ft", False),
    ("launch velocity 1 ft/s, spherical Earth, largest error", "805", "Problem 3, summary table", "ft", False),
    ("accelerometer 1e-4 g, flat Earth at 10,120 s", "341,000", "Problem 3, summary table", "ft", True),
    ("accelerometer, spherical Earth at 10,120 s", "0", "Problem 3, summary table", "ft", False),
    ("accelerometer 1e-4 g, spherical Earth, largest error", "4,170", "Problem 3, summary table", "ft", False),
    ("accelerometer 1e-4 g, spherical Earth, largest error", "0.792", "Problem 3, solution (c)", "mi", False),
    ("gyro drift 0.01 deg/h, flat Earth at 10,120 s", "1.62 \u00d7 10^6", "Problem 3, summary table", "ft", True),
    ("gyro drift 0.01 deg/h, spherical Earth at 10,120 s", "10,250", "Problem 3, summary table", "ft", False),
    ("gyro drift 0.01 deg/h, spherical Earth at 10,120 s", "1.94", "Problem 3, solution (d)", "mi", False),
    ("gyro drift angle epsilon t after 2.8 h", "1.68", "Problem 3, solution (d)", "arcmin", False),
    ("azimuth 0.01 deg, flat Earth at 10,120 s", "4660", "Problem 3, summary table", "ft", False),
    ("azimuth 0.01 deg, spherical Earth at 10,120 s", "3500", "Problem 3, summary table", "ft", False),
    ("azimuth: range angle phi = r / R", "73.3", "Problem 3, solution (a)", "deg", False),
    ("azimuth: sin phi", ".957", "Problem 3, solution (a)", "1", False),
    ("hover, k = 1e-4, altitude error after t = T", "724", "Problem 4, solution", "mi", True),
]


def test_problem3_rows_have_the_published_values_and_verdicts():
    rows = problem3_rows()
    assert [(r.quantity, r.printed, r.where, r.unit, r.verdict == "erratum") for r in rows] == PUBLISHED
    assert all(r.note for r in rows if r.verdict == "erratum")
    assert not [r for r in rows if r.failed]  # no "differs": every disagreement is an explained erratum


@pytest.mark.parametrize("row", [r for r in problem3_rows() if r.verdict.startswith("agrees")],
                         ids=lambda r: f"{r.quantity}-{r.printed}")
def test_agreeing_rows_are_within_the_source_rounding(row):
    # Bollay prints three significant figures: 0.5 % (or 0.5 ft of a printed zero)
    if row.printed == "0":
        assert row.verdict == "agrees within 0.5 ft" and row.computed < 0.5
    else:
        assert row.verdict == "agrees within 0.5 %"
        assert row.computed == pytest.approx(printed_value(row.printed), rel=0.005)


def test_errata_values_recomputed_from_the_formulas():
    rows = problem3_rows()
    by_key = {(r.quantity, r.printed): r.computed for r in rows}
    tilt_max = by_key["level misalignment, spherical Earth, largest error", "3650"]
    # spec errata, recomputed with R = 3960 mi, omega = 2 pi / 5060 s, g_eff = omega^2 R
    assert tilt_max == pytest.approx(2 * 3960 * 5280 * math.radians(0.01), rel=1e-12)
    assert tilt_max == pytest.approx(7_300, rel=0.001)  # Bollay, solution text
    drift_flat = by_key["gyro drift 0.01 deg/h, flat Earth at 10,120 s", "1.62 \u00d7 10^6"]
    assert drift_flat == pytest.approx(2.70e5, rel=0.001)
    assert 6 * drift_flat == pytest.approx(1.62e6, rel=0.002)  # the printed one: no 1/6
    assert by_key["accelerometer 1e-4 g, flat Earth at 10,120 s", "341,000"] == pytest.approx(1.65e5, rel=0.001)
    assert by_key["accelerometer 1e-4 g, spherical Earth, largest error", "4,170"] == pytest.approx(4_181.76, abs=0.01)
    assert by_key["azimuth 0.01 deg, spherical Earth at 10,120 s", "3500"] == pytest.approx(3_494, abs=0.5)
    assert by_key["gyro drift 0.01 deg/h, spherical Earth at 10,120 s", "10,250"] == pytest.approx(
        3960 * 5280 * math.radians(0.01) / 3600 * 10_120, rel=1e-12)
    assert by_key["hover, k = 1e-4, altitude error after t = T", "724"] == pytest.approx(715.4085, abs=1e-3)
    # zeros at omega t = 4 pi: rounding noise is shown as 0
    assert [r.computed for r in rows if r.printed == "0"] == [0.0, 0.0, 0.0]


def test_reproduction_carries_the_source_constants_and_curves():
    reproduction = reproduce()
    assert reproduction.system == "errors" and "Bollay" in reproduction.source and "1966" in reproduction.source
    assert reproduction.details["schuler_period_s"] == pytest.approx(5060.0, rel=1e-12)
    assert reproduction.details["effective_gravity_m_s2"] / FOOT == pytest.approx(32.24, abs=0.005)
    assert reproduction.data.t_s.size == 1013 and reproduction.data.t_s[-1] == FLIGHT_TIME
    data = reproduction.to_dict()
    assert "data" not in data and data["units"] == {"computed": "the row's unit"}  # the curves stay internal


def test_hover_error_after_one_schuler_period():
    # Bollay (1966), Problem 4: k = 1e-4, t = T, R = 3960 mi: 715.4 mi with z(0) = z'(0) = 0 (printed: 724)
    z = hover_altitude_error(BOLLAY.schuler_period, -1e-4 * G_BOLLAY, R_BOLLAY, G_BOLLAY)
    assert -z / STATUTE_MILE == pytest.approx(715.4085, abs=1e-3)
    sinh = printed_hover_expression(BOLLAY.schuler_period, 1e-4, R_BOLLAY, G_BOLLAY) / STATUTE_MILE
    assert sinh == pytest.approx(715.6, abs=0.05)  # the source's expression (spec errata)
    assert sinh * 4000 / 3960 == pytest.approx(722.8, abs=0.05)  # ... with R = 4000 mi
    # the printed sinh solution is zero at t = 0 but starts at the rate k R omega_s / sqrt(2), not 0:
    # forward differences over 1 ms (truncation (sqrt(2) omega dt)^2 / 6 ~ 5e-13 relative; the cosh
    # solution's rate after 1 ms is b dt / 2 ~ 5e-7 m/s)
    assert float(printed_hover_expression(0.0, 1e-4, R_BOLLAY, G_BOLLAY)) == 0.0
    dt, omega = 1e-3, math.sqrt(G_BOLLAY / R_BOLLAY)
    printed_rate = float(printed_hover_expression(dt, 1e-4, R_BOLLAY, G_BOLLAY)) / dt
    correct_rate = float(-hover_altitude_error(dt, -1e-4 * G_BOLLAY, R_BOLLAY, G_BOLLAY)) / dt
    assert abs(correct_rate) < 1e-6
    assert printed_rate == pytest.approx(1e-4 * R_BOLLAY * omega / math.sqrt(2.0), rel=1e-9)
    assert printed_rate - correct_rate == pytest.approx(0.5596, abs=1e-4)  # m/s, about 1.8 ft/s
    # ... and it is the cosh solution's large-t limit only
    assert float(-hover_altitude_error(1.0, -1e-4 * G_BOLLAY, R_BOLLAY, G_BOLLAY)) != pytest.approx(
        float(printed_hover_expression(1.0, 1e-4, R_BOLLAY, G_BOLLAY)), rel=0.1)


def test_hover_closed_form_matches_simulation_of_the_unaided_channel():
    t = np.linspace(0.0, BOLLAY.schuler_period, 101)
    b = -1e-4 * G_BOLLAY
    simulated = simulate(unaided_model(R_BOLLAY, G_BOLLAY), t, inputs=[b])["altitude_error"]
    np.testing.assert_allclose(simulated, hover_altitude_error(t, b, R_BOLLAY, G_BOLLAY), rtol=1e-9, atol=1e-9)


# --- baro-aided vertical loop ----------------------------------------------------------------------

@pytest.mark.parametrize("order", [2, 3])
def test_critically_damped_gains_put_every_pole_at_minus_one_over_tau(order):
    gains = critically_damped_gains(order, 80.0, MEAN_RADIUS, STANDARD_GRAVITY)
    poles = baro_aided_model(gains, MEAN_RADIUS, STANDARD_GRAVITY).eigenvalues()
    # a repeated root of multiplicity m is found to about eps^(1/m): 1e-5 relative for m = 3
    np.testing.assert_allclose(poles, -1 / 80.0, atol=1e-5 / 80.0)


@pytest.mark.parametrize("order", [2, 3])
def test_aided_loop_settles_to_its_closed_form_steady_state(order):
    gains = critically_damped_gains(order, 60.0, MEAN_RADIUS, STANDARD_GRAVITY)
    b, baro = 1e-3, 4.0
    t = np.linspace(0.0, 4000.0, 81)
    h = simulate(baro_aided_model(gains, MEAN_RADIUS, STANDARD_GRAVITY), t, inputs=[b, baro])["altitude_error"]
    expected = aided_steady_state_error(gains, b, baro, MEAN_RADIUS, STANDARD_GRAVITY)
    assert h[-1] == pytest.approx(float(expected), rel=1e-9)
    closed_form = baro if order == 3 else (b + gains.k2 * baro) / (gains.k2 - 2 * STANDARD_GRAVITY / MEAN_RADIUS)
    assert expected == pytest.approx(closed_form)


def test_damping_stabilises_the_divergent_vertical_channel():
    result = vertical(**VERTICAL_PARAMETERS.case(accel_bias_up=-1e-4 * STANDARD_GRAVITY, output_step=50.6, order=3))
    assert np.max(result.poles_real_per_s) < 0
    assert abs(result.final_unaided_m) > 1e6  # pure inertial: ~1,100 km after one period
    assert abs(result.final_aided_m) < 1e-6  # third order estimates the bias away
    np.testing.assert_allclose(result.unaided_m, result.closed_form_m, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize(
    "gains, name",
    [(BaroLoopGains(-0.1, 1e-3, 0.0, 2), "k1"), (BaroLoopGains(0.1, 1e-6, 0.0, 2), "k2"),
     (BaroLoopGains(0.01, 1e-4, 1.0, 3), "k3")],
)
def test_unstable_gains_are_rejected(gains, name):
    with pytest.raises(InvalidParameter) as error:
        check_stable(gains, MEAN_RADIUS, STANDARD_GRAVITY)
    assert error.value.name == name


# --- effective Schuler period (Bollay (1966) footnote) -----------------------------------------------

def test_thrust_of_nine_g_divides_the_period_by_three():
    T0 = effective_schuler_period(MEAN_RADIUS, STANDARD_GRAVITY)
    T9 = effective_schuler_period(MEAN_RADIUS, thrust_gravity(9.0, STANDARD_GRAVITY))
    assert T9 == pytest.approx(T0 / 3, rel=1e-14)
    assert T9 / 60 == pytest.approx(28, abs=0.5)  # Bollay (1966) footnote: 84/3 = 28 minutes


def test_period_grows_without_bound_towards_orbital_speed():
    Vc = float(orbital_speed(STANDARD_GRAVITY, MEAN_RADIUS))
    speeds = Vc * np.array([0.0, 0.5, 0.9, 0.99, 0.9999])
    periods = effective_schuler_period(MEAN_RADIUS, flight_gravity(STANDARD_GRAVITY, speeds, MEAN_RADIUS))
    assert np.all(np.diff(periods) > 0)
    # g_eff = g (1 - (V/Vc)^2): T = T0 / sqrt(1 - (V/Vc)^2)
    np.testing.assert_allclose(periods, periods[0] / np.sqrt(1 - (speeds / Vc) ** 2), rtol=1e-9)
    assert np.isinf(effective_schuler_period(MEAN_RADIUS, flight_gravity(STANDARD_GRAVITY, Vc * 1.01, MEAN_RADIUS)))


@pytest.mark.slow
def test_report_writes_its_figures_and_table(tmp_path):
    section = report(tmp_path)
    assert section.system == "errors"
    assert len(section.rows) == 22 and sum(row.verdict == "erratum" for row in section.rows) == 4
    for figure in section.figures:
        assert (tmp_path / figure.path).stat().st_size > 10_000
        assert (tmp_path / figure.path).with_suffix(".svg").exists()
    assert all(figure.path.startswith("errors_") for figure in section.figures)
    assert all(command.startswith("schuler ") and "--step" not in command for command in section.commands)
