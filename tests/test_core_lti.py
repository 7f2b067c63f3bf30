"""The exact linear-systems engine against closed forms, solve_ivp, and itself."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.integrate
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.core.earth import MEAN_RADIUS, STANDARD_GRAVITY, schuler_period
from schuler.core.lti import StateSpace, simulate, simulate_statistics, zoh_discretize
from schuler.exceptions import InvalidParameter

OMEGA_S = np.sqrt(STANDARD_GRAVITY / MEAN_RADIUS)


def schuler_oscillator(forced: bool = False) -> StateSpace:
    """x'' + (g/R) x = u."""
    return StateSpace(
        [[0.0, 1.0], [-(OMEGA_S**2), 0.0]],
        [[0.0], [1.0]] if forced else None,
        states=("x", "v"),
        state_units=("m", "m/s"),
    )


def test_schuler_oscillator_matches_cosine_over_ten_periods():
    period = schuler_period(STANDARD_GRAVITY, MEAN_RADIUS)
    t = np.linspace(0.0, 10 * period, 10 * 360 + 1)
    response = simulate(schuler_oscillator(), t, initial_state=[1.0, 0.0])
    # x = cos(w t): every grid point to 1e-12, so the period is right to 1e-12 relative
    np.testing.assert_allclose(response["x"], np.cos(OMEGA_S * t), rtol=0, atol=1e-12)
    np.testing.assert_allclose(response["v"], -OMEGA_S * np.sin(OMEGA_S * t), rtol=0, atol=1e-12 * OMEGA_S)


def test_schuler_period_from_eigenvalues_to_1e_12():
    eig = schuler_oscillator().eigenvalues()
    period = 2 * np.pi / np.abs(eig.imag).max()
    assert period == pytest.approx(2 * np.pi * np.sqrt(MEAN_RADIUS / STANDARD_GRAVITY), rel=1e-12)


def test_constant_forcing_gives_one_minus_cosine():
    # accelerometer-bias response x = (a / w^2)(1 - cos w t)
    a = 1e-4 * STANDARD_GRAVITY
    t = np.linspace(0.0, 3 * 5060.0, 1001)
    response = simulate(schuler_oscillator(forced=True), t, inputs=[a])
    np.testing.assert_allclose(response["x"], a / OMEGA_S**2 * (1 - np.cos(OMEGA_S * t)), rtol=1e-11, atol=1e-9)


@pytest.mark.parametrize("zeta", [0.2, 0.7, 1.0, 2.5])
def test_damped_second_order_step_response(zeta):
    wn = 0.3
    system = StateSpace([[0.0, 1.0], [-(wn**2), -2 * zeta * wn]], [[0.0], [wn**2]], C=[[1.0, 0.0]])
    t = np.linspace(0.0, 60.0, 601)
    y = simulate(system, t, inputs=[1.0]).outputs[:, 0]
    if zeta < 1:
        wd = wn * np.sqrt(1 - zeta**2)
        phi = np.arccos(zeta)
        expected = 1 - np.exp(-zeta * wn * t) * np.sin(wd * t + phi) / np.sqrt(1 - zeta**2)
    elif zeta == 1:
        expected = 1 - np.exp(-wn * t) * (1 + wn * t)
    else:
        s1 = -wn * (zeta - np.sqrt(zeta**2 - 1))
        s2 = -wn * (zeta + np.sqrt(zeta**2 - 1))
        expected = 1 + (s2 * np.exp(s1 * t) - s1 * np.exp(s2 * t)) / (s1 - s2)
    np.testing.assert_allclose(y, expected, rtol=0, atol=1e-12)


def test_piecewise_constant_input_on_nonuniform_grid():
    # integrator x' = u with u[k] held on [t_k, t_k+1): x is the exact left Riemann sum
    system = StateSpace([[0.0]], [[1.0]])
    t = np.array([0.0, 0.5, 2.0, 2.25, 7.0])
    u = np.array([[1.0], [-2.0], [4.0], [0.5], [99.0]])
    x = simulate(system, t, input_series=u)["x0"]
    np.testing.assert_allclose(x, np.concatenate([[0.0], np.cumsum(u[:-1, 0] * np.diff(t))]), atol=1e-15)


@st.composite
def stable_systems(draw):
    n = draw(st.integers(2, 4))
    seed = draw(st.integers(0, 2**31 - 1))
    rng = np.random.default_rng(seed)
    M = rng.normal(size=(n, n))
    # shift the spectrum left so the system is stable with modest stiffness
    A = M - (np.max(np.linalg.eigvals(M).real) + rng.uniform(0.1, 1.0)) * np.eye(n)
    B = rng.normal(size=(n, 1))
    x0 = rng.normal(size=n)
    u = rng.normal()
    return A, B, x0, u


@settings(max_examples=25, deadline=None)
@given(stable_systems())
def test_engine_matches_solve_ivp_on_random_stable_systems(case):
    A, B, x0, u = case
    t = np.linspace(0.0, 10.0, 51)
    exact = simulate(StateSpace(A, B), t, initial_state=x0, inputs=[u]).states
    numeric = scipy.integrate.solve_ivp(
        lambda _t, x: A @ x + B[:, 0] * u, (0.0, 10.0), x0, t_eval=t, method="DOP853", rtol=1e-12, atol=1e-14
    ).y.T
    scale = np.max(np.abs(exact), axis=0)
    assert np.max(np.abs(exact - numeric) / scale) < 1e-9


def test_batch_equals_member_by_member():
    rng = np.random.default_rng(7)
    members, n = 40, 3
    A = rng.normal(size=(n, n)) - 2 * np.eye(n)
    B = rng.normal(size=(n, 2))
    x0 = rng.normal(size=(members, n))
    u = rng.normal(size=(members, 2))
    t = np.linspace(0, 20, 401)
    batch = simulate(StateSpace(A, B), t, initial_state=x0, inputs=u)
    assert batch.states.shape == (members, t.size, n)
    for i in range(members):
        single = simulate(StateSpace(A, B), t, initial_state=x0[i], inputs=u[i])
        np.testing.assert_allclose(batch.states[i], single.states, rtol=1e-13, atol=1e-13 * np.abs(single.states).max())


def test_batch_of_different_state_matrices_equals_member_by_member():
    rng = np.random.default_rng(8)
    members = 25
    omegas = rng.uniform(1e-3, 2e-3, members)
    A = np.zeros((members, 2, 2))
    A[:, 0, 1] = 1.0
    A[:, 1, 0] = -(omegas**2)
    B = np.tile([[0.0], [1.0]], (members, 1, 1))
    t = np.linspace(0, 7200, 721)
    batch = simulate(StateSpace(A, B, states=("x", "v")), t, initial_state=[1.0, 0.0], inputs=[1e-6])
    for i in (0, 11, 24):
        single = simulate(StateSpace(A[i], B[i], states=("x", "v")), t, initial_state=[1.0, 0.0], inputs=[1e-6])
        # a batch of different A steps through time; a single model takes the
        # constant-input path (exponentials per time point): two exact algorithms
        # that agree to rounding, 1e-12 of the channel's magnitude
        scale = np.abs(single["x"]).max()
        np.testing.assert_allclose(batch["x"][i], single["x"], rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(batch["x"][i], np.cos(omegas[i] * t) + 1e-6 / omegas[i] ** 2 * (1 - np.cos(omegas[i] * t)), atol=1e-10)


def test_zoh_discretize_batches_over_steps():
    A = np.array([[0.0, 1.0], [-1.0, 0.0]])
    B = np.array([[0.0], [1.0]])
    Ad, Bd = zoh_discretize(A, B, np.array([0.1, 0.2]))
    assert Ad.shape == (2, 2, 2) and Bd.shape == (2, 2, 1)
    np.testing.assert_allclose(Ad[1], Ad[0] @ Ad[0], atol=1e-15)


def test_streaming_statistics_match_full_histories():
    rng = np.random.default_rng(3)
    system = schuler_oscillator(forced=True)
    x0 = np.column_stack([rng.normal(0, 10.0, 500), rng.normal(0, 0.1, 500)])
    u = rng.normal(0, 1e-3, (500, 1))
    t = np.linspace(0, 5060.0, 101)
    full = simulate(system, t, initial_state=x0, inputs=u)
    stats = simulate_statistics(system, t, x0, u, chunk_size=64, reservoir_size=500)
    np.testing.assert_allclose(stats.mean("x"), full["x"].mean(axis=0), rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(stats.std("x"), full["x"].std(axis=0, ddof=1), rtol=1e-9)
    np.testing.assert_allclose(stats.percentile(95, "x"), np.percentile(full["x"], 95, axis=0), rtol=1e-12)
    np.testing.assert_allclose(stats.final_outputs, full.outputs[:, -1, :], rtol=1e-13)


def test_response_table_and_named_channels():
    t = np.linspace(0, 10, 11)
    response = simulate(schuler_oscillator(), t, initial_state=[1.0, 0.0])
    frame = response.to_dataframe()
    assert list(frame.columns) == ["time", "x", "v"] and len(frame) == 11
    assert response.unit("v") == "m/s"
    with pytest.raises(KeyError):
        response["nope"]


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(A=[[1.0, 2.0]]), "A"),
        (dict(A=[[np.nan]]), "A"),
        (dict(A=np.eye(2), B=np.ones((3, 1))), "B"),
        (dict(A=np.eye(2), states=("a",)), "states"),
    ],
)
def test_bad_models_are_rejected(kwargs, name):
    with pytest.raises(InvalidParameter) as error:
        StateSpace(**kwargs)
    assert error.value.name == name


def test_bad_time_grid_is_rejected():
    with pytest.raises(InvalidParameter, match="strictly increasing"):
        simulate(schuler_oscillator(), [0.0, 2.0, 1.0])
