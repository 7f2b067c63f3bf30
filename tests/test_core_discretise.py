"""The one exact discretiser of the Kalman filters: Van Loan's block exponential, by blocks, balanced, batched.

Held, on random models up to ||F dt|| of about 50 that grow less than a thousandfold, to expm(F dt) and to the
integral of expm(F s) W expm(F s)^T by adaptive quadrature: within 1e-12 of the largest entry, or no farther than
scipy's ``expm`` of the 2n x 2n block matrix (Van Loan 1978) is, where the exponential's own condition rules; to
the closed form of a scalar model within 5e-14 (the doublings' rounding); to the block matrix within 1e-13 on the
aided filter's own 21-state model (metres beside radians). The block matrix is no reference for stiff models: with
eigenvalues 1 and -10 over the step it is off by 2e-11 of Q where this one is within 3e-14 of the quadrature.
"""

import math

import numpy as np
import scipy.integrate
import scipy.linalg
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from schuler.core.propagation import TAYLOR_RADIUS, discretise_noise


def van_loan(F, W, dt):
    n = F.shape[-1]
    M = np.zeros(F.shape[:-2] + (2 * n, 2 * n))
    M[..., :n, :n], M[..., :n, n:], M[..., n:, n:] = -F, W, np.swapaxes(F, -1, -2)
    E = scipy.linalg.expm(M * dt)
    Phi = np.swapaxes(E[..., n:, n:], -1, -2)
    Q = Phi @ E[..., :n, n:]
    return Phi, 0.5 * (Q + np.swapaxes(Q, -1, -2))


def assert_close(found, expected, tolerance):
    for a, b in zip(found, expected):
        assert np.max(np.abs(a - b)) <= tolerance * np.max(np.abs(b))


@settings(max_examples=25, deadline=None)
@given(st.integers(1, 6), st.integers(1, 3), st.floats(-3.0, 0.5), st.floats(0.01, 5.0), st.integers(0, 2**31))
def test_equals_the_block_exponential(n, members, log_scale, dt, seed):
    rng = np.random.default_rng(seed)
    F = rng.normal(size=(members, n, n)) * 10.0**log_scale
    G = rng.normal(size=(members, n, n))
    W = G @ np.swapaxes(G, -1, -2)
    Phi = np.stack([scipy.linalg.expm(f * dt) for f in F])
    assume(np.max(np.abs(Phi)) < 1e3)  # a filter's step never grows its error state a thousandfold
    def integrand(s, f, w):
        E = scipy.linalg.expm(f * s)
        return E @ w @ E.T

    Q = np.stack([scipy.integrate.quad_vec(integrand, 0.0, dt, args=(f, w), epsabs=0.0, epsrel=1e-14)[0]
                  for f, w in zip(F, W)])
    # against the quadrature: within 1e-12 of the largest entry, or no farther than scipy's expm of the block matrix
    # (the exponential's own condition grows with ||F dt||: neither can do better on strongly growing models)
    found, block = discretise_noise(F, W, dt), van_loan(F, W, dt)
    for ours, theirs, exact in zip(found, block, (Phi, Q)):
        scale = np.max(np.abs(exact))
        error = np.max(np.abs(ours - exact)) / scale
        assert error <= max(1e-12, 2.0 * np.max(np.abs(theirs - exact)) / scale), error


@settings(max_examples=25, deadline=None)
@given(st.floats(-2.0, 2.0), st.floats(0.1, 5.0), st.floats(0.01, 10.0))
def test_a_scalar_model_equals_its_closed_form(f, w, dt):
    Phi, Q = discretise_noise(np.array([[f]]), np.array([[w]]), dt)
    # each squaring doubles Phi's relative rounding: 5e-14, or 4 ulp times 2^doublings where more (f dt = 17: 1.1e-13)
    doublings = max(0, math.ceil(math.log2(abs(f) * dt / TAYLOR_RADIUS))) if abs(f) * dt > TAYLOR_RADIUS else 0
    tolerance = max(5e-14, 4 * 2.0**doublings * np.finfo(float).eps)
    assert Phi[0, 0] == np.float64(np.exp(f * dt)) or abs(Phi[0, 0] / np.exp(f * dt) - 1) < tolerance
    # expm1(2 f dt) / 2f, in its series where f is too small for the quotient
    exact = w * np.expm1(2 * f * dt) / (2 * f) if abs(f) > 1e-8 else w * dt * (1 + f * dt)
    assert abs(Q[0, 0] / exact - 1) < tolerance


def test_a_shared_model_broadcasts_and_a_random_walk_integrates_exactly():
    Phi, Q = discretise_noise(np.array([[0.0, 1.0], [0.0, 0.0]]), np.diag([0.0, 2.0]), 3.0)
    np.testing.assert_allclose(Phi, [[1.0, 3.0], [0.0, 1.0]], atol=1e-15)
    np.testing.assert_allclose(Q, [[18.0, 9.0], [9.0, 6.0]], rtol=1e-14)  # q dt^3/3, q dt^2/2, q dt


def test_the_aided_filters_model_of_mixed_units():
    from schuler.aided.error_state import ErrorProcess, FilterModel, NavigationPoint, noise_input, system_matrix

    gm = dict(kind="gauss-markov", correlation_time=4 * 3600.0)
    model = FilterModel(np.radians(0.003) / 60, 0.03 / 60, ErrorProcess(sigma=np.radians(0.027) / 3600, **gm),
                        ErrorProcess(sigma=15e-5, **gm), ErrorProcess("constant", 300e-6),
                        ErrorProcess("constant", 300e-6))
    rng = np.random.default_rng(3)
    members = 4
    C = scipy.linalg.expm(np.cross(np.eye(3), rng.normal(size=(members, 1, 3)) * 0.5))
    point = NavigationPoint(np.full(members, 0.53), np.full(members, 20.0), rng.normal(size=(members, 3)) * 10,
                            C, np.array([0.0, 0.0, -9.8]) + rng.normal(size=(members, 3)),
                            rng.normal(size=(members, 3)) * 0.1)
    F, W = system_matrix(model, point, 7.292115e-5), noise_input(model, point.body_to_ned)
    for dt in (0.005, 1.0, 10.0):
        found, expected = discretise_noise(F, W, dt), van_loan(F, W, dt)
        assert_close(found, expected, 1e-13)
        # each block to its own size: the attitude variances (1e-12 rad^2) as well as the positions' (m^2)
        diagonal = np.diagonal(expected[1], axis1=-2, axis2=-1)
        np.testing.assert_allclose(np.diagonal(found[1], axis1=-2, axis2=-1), diagonal, rtol=1e-10)
