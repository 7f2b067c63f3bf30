"""Coulomb friction in the gimbal bearings, eqs. (30)-(32) of Drozdovich (1959)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.exceptions import InvalidParameter
from schuler.gyro_vertical.friction import (
    AccelerationInput,
    friction_from_velocity_error,
    friction_growth_rate,
    simulate_friction,
)

R, G = 6.4e6, 9.81
Q = 0.01 / R  # the source's example: |Delta v| = 0.01 m/s
SCHULER_PERIOD = 2 * math.pi * math.sqrt(R / G)


def test_friction_example_value_and_erratum():
    # Drozdovich (1959) after (32): M_fr/H = 0.01 / 6.4e6 "~ 1.6e-6 1/s"; the quotient is 1.5625e-9 1/s
    q = friction_from_velocity_error(0.01, R)
    assert q == pytest.approx(1.5625e-9)
    assert 1.6e-6 / q == pytest.approx(1024, rel=0.01)
    assert math.degrees(q) * 3600 == pytest.approx(3.2e-4, rel=0.01)  # deg/h


def test_break_away_at_the_edge_of_the_dead_zone():
    """A stuck gimbal pair: the integrator runs linearly to -R q_1 and the gyro breaks away there."""
    beta_0 = 1e-6
    r = simulate_friction((Q, Q), np.linspace(0.0, 3000.0, 31), initial_tilt=(0.0, beta_0), gravity=G, radius=R)
    begin, end = r.stick_intervals[0]
    assert begin == 0.0 and end == pytest.approx(R * Q / (G * beta_0), rel=1e-9)
    assert r.stick_velocity_errors[0, 2] == pytest.approx(-R * Q, rel=1e-9)
    assert r.cells[1] == (-1, 0)


def test_slow_ramp_reaches_the_edge_of_the_dead_zone():
    """A slow ramp of the input: the static error grows inside the zone and reaches R q_1 (issue: to 1 %)."""
    ramp = AccelerationInput.ramp(2e-3, 0.0, 24 * 3600.0)
    r = simulate_friction((Q, 0.5 * Q), np.arange(0.0, 6 * 3600.0, 10.0), acceleration=ramp, gravity=G, radius=R)
    static_x = np.abs(r.stick_velocity_errors[:, [0, 2]])
    assert static_x.max() == pytest.approx(R * Q, rel=0.01)
    assert static_x.max() <= R * Q * (1 + 1e-9)


@settings(max_examples=15, deadline=None)
@given(
    alpha_0=st.floats(-3e-6, 3e-6), beta_0=st.floats(-3e-6, 3e-6),
    dv_x=st.floats(-0.02, 0.02), dv_y=st.floats(-0.02, 0.02),
    q_1=st.floats(0.2, 2.0), q_2=st.floats(0.0, 2.0),
    W_x=st.floats(-3e-5, 3e-5), W_y=st.floats(-3e-5, 3e-5),
)
def test_static_errors_stay_in_the_dead_zone(alpha_0, beta_0, dv_x, dv_y, q_1, q_2, W_x, W_y):
    """In every stick interval both gimbals rest and |Delta v_i| <= R q_i (32, with the factor R)."""
    q = (q_1 * Q, q_2 * Q)
    time = np.arange(0.0, 6 * 3600.0, 20.0)
    r = simulate_friction(q, time, initial_tilt=(alpha_0, beta_0), initial_velocity_error=(dv_x, dv_y),
                          acceleration=AccelerationInput.ramp(W_x, W_y, 3 * 3600.0), gravity=G, radius=R)
    for (begin, end), errors in zip(r.stick_intervals, r.stick_velocity_errors):
        if begin == 0.0:
            continue  # the start may be anywhere the user put it
        assert abs(errors[0]) <= R * q[0] + 1e-9 and abs(errors[2]) <= R * q[0] + 1e-9
        assert abs(errors[1]) <= R * q[1] + 1e-9 and abs(errors[3]) <= R * q[1] + 1e-9
        inside = (time > begin) & (time < end)
        if inside.any():
            assert np.ptp(r.alpha[inside]) < 1e-13 and np.ptp(r.beta[inside]) < 1e-13
    # no chattering: a handful of switches per Schuler period
    assert len(r.switch_times) <= 12 * time[-1] / SCHULER_PERIOD + 4


def test_equilibrium_inside_the_dead_zone_stays_stuck():
    W_x = 1e-4
    r = simulate_friction((Q, Q), np.arange(0.0, 24 * 3600.0, 60.0), initial_tilt=(0.0, W_x / G),
                          initial_velocity_error=(0.006, -0.004), acceleration=AccelerationInput.constant(W_x),
                          gravity=G, radius=R)
    assert r.cells == [(0, 0)] and r.stuck_at_end
    np.testing.assert_allclose(r.velocity_error_x, 0.006, atol=1e-12)
    np.testing.assert_allclose(r.velocity_error_y, -0.004, atol=1e-12)


def test_friction_about_one_axis_precesses_the_other():
    """Coupling in (30): only beta is tilted, yet the inner bearing's friction moves alpha once beta slips."""
    r = simulate_friction((Q, Q), np.arange(0.0, 3 * 3600.0, 10.0), initial_tilt=(0.0, 1e-6), gravity=G, radius=R)
    after = r.time > r.stick_intervals[0, 1]
    assert np.max(np.abs(r.alpha[after])) > 1e-7
    # alpha starts at rate -q_2 (sign of beta' = -1 after breaking away toward -R q_1)
    k = np.argmax(after)
    assert (r.alpha[k + 1] - r.alpha[k]) / (r.time[k + 1] - r.time[k]) == pytest.approx(-Q, rel=0.05)


@pytest.mark.parametrize("ratio", [1.0, 0.5, 0.2])
def test_slip_amplitude_grows_at_the_closed_form_rate(ratio):
    """Coupled friction pumps the Schuler oscillation: amplitudes grow by 2 q_i sqrt(g R)/pi per second."""
    q = (Q, ratio * Q)
    time = np.arange(0.0, 72 * 3600.0, 20.0)
    r = simulate_friction(q, time, initial_tilt=(0.0, 1e-6), gravity=G, radius=R)
    periods = int(time[-1] // SCHULER_PERIOD)
    centres = (np.arange(periods) + 0.5) * SCHULER_PERIOD
    rates = friction_growth_rate(q, G, R)
    for values, expected in ((r.velocity_error_x, rates[0]), (r.velocity_error_y, rates[1])):
        envelope = [np.max(np.abs(values[(time >= k * SCHULER_PERIOD) & (time < (k + 1) * SCHULER_PERIOD)]))
                    for k in range(periods)]
        slope = np.polyfit(centres[periods // 3:], envelope[periods // 3:], 1)[0]
        assert slope == pytest.approx(expected, rel=0.01)
    assert r.nfev < 100_000  # event-driven: no grinding at tiny steps


def test_bad_friction_input():
    with pytest.raises(InvalidParameter, match="friction"):
        simulate_friction((-1e-9, 0.0), np.linspace(0, 10, 3))
    with pytest.raises(InvalidParameter, match="duration"):
        simulate_friction((1e-9, 1e-9), np.array([0.0, -5.0]))


def test_cli_friction(run_cli, tmp_path):
    out = run_cli("vertical", "friction", "--duration", "6 h", "--json", "--out", tmp_path)
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["dead_zone_x_m_s"] == pytest.approx(0.01)
    assert data["friction_x_rad_s"] == pytest.approx(1.5625e-9)
    assert data["max_static_velocity_error_x_m_s"] <= 0.01 * (1 + 1e-9)
    assert data["inputs"]["duration"] == 6 * 3600.0 and data["inputs"]["initial_beta"] == pytest.approx(
        math.radians(0.2 / 3600))
    assert data["units"]["switches"] == "1"
    for name in ("vertical_friction.png", "vertical_friction.svg", "vertical_friction.csv"):
        assert (tmp_path / name).exists()
    human = run_cli("vertical", "friction", "--duration", "3600", "--ramp-acceleration", "1e-4",
                    "--ramp-duration", "1800")
    assert human.code == 0 and "dead zone R q (32)" in human.stdout
    bad = run_cli("vertical", "friction", "--dead-zone", "-1")
    assert bad.code == 2 and "--dead-zone" in bad.stderr
    former = run_cli("vertical", "friction", "--ramp-time", "1")
    assert former.code == 2 and "--ramp-time" in former.stderr


def test_friction_figure_leaves_the_session_backend_alone(monkeypatch):
    import matplotlib
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    from schuler.gyro_vertical.plots import plot_friction, plot_monte_carlo

    def refuse(*args, **kwargs):
        raise AssertionError("a figure function must not switch the matplotlib backend")

    monkeypatch.setattr(matplotlib, "use", refuse)
    open_figures = plt.get_fignums()
    response = simulate_friction((Q, Q), np.linspace(0.0, 2 * SCHULER_PERIOD, 400), initial_tilt=(0.0, 1e-6))
    figure = plot_friction(response, (Q, Q), R)
    histogram = plot_monte_carlo(np.linspace(0.0, 1.0, 50), np.linspace(1.0, 2.0, 50))
    assert isinstance(figure, Figure) and len(figure.axes) == 3 and len(histogram.axes) == 2
    assert plt.get_fignums() == open_figures  # not registered with pyplot: nothing left open
