"""The one attitude module: every conversion round-trips, and the representations agree (hypothesis).

Tolerances: 1e-12 on matrix entries and quaternion components (a few ulps of the trigonometry); Euler angles
are compared away from pitch = +-90 deg, where roll and heading are one degree of freedom.
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.core.attitude import (
    attitude_error,
    conjugate,
    dcm_from_euler,
    dcm_from_quaternion,
    dcm_from_rotation_vector,
    euler_from_dcm,
    euler_from_quaternion,
    quaternion_from_dcm,
    quaternion_from_euler,
    quaternion_from_rotation_vector,
    quaternion_multiply,
    rotation_vector_from_quaternion,
    skew,
    triad,
    wrap_angle,
)

angles = st.tuples(st.floats(-3.1, 3.1), st.floats(-1.5, 1.5), st.floats(-3.1, 3.1))
vectors = st.lists(st.floats(-10.0, 10.0), min_size=3, max_size=3)
rotation_vectors = st.lists(st.floats(-1.8, 1.8), min_size=3, max_size=3)  # |phi| < pi: the shorter rotation


def _is_rotation(C):
    np.testing.assert_allclose(C @ C.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(C) == pytest.approx(1.0, abs=1e-12)


@settings(max_examples=60, deadline=None)
@given(angles)
def test_euler_to_dcm_and_quaternion_agree_and_come_back(rpy):
    C = dcm_from_euler(*rpy)
    q = quaternion_from_euler(*rpy)
    _is_rotation(C)
    np.testing.assert_allclose(dcm_from_quaternion(q), C, atol=1e-12)
    np.testing.assert_allclose(euler_from_dcm(C), rpy, atol=1e-9)
    np.testing.assert_allclose(euler_from_quaternion(q), rpy, atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(angles)
def test_quaternion_from_dcm_round_trip(rpy):
    q = quaternion_from_euler(*rpy)
    q = q if q[0] >= 0 else -q
    back = quaternion_from_dcm(dcm_from_quaternion(q))
    np.testing.assert_allclose(back, q, atol=1e-12)
    assert np.linalg.norm(back) == pytest.approx(1.0, abs=1e-14)


def test_quaternion_from_dcm_near_half_turns_takes_the_large_component():
    # trace near -1: q0 ~ 0; the plain trace formula divides by ~0 there
    for axis in np.eye(3):
        C = dcm_from_rotation_vector(axis * (math.pi - 1e-9))
        q = quaternion_from_dcm(C)
        np.testing.assert_allclose(dcm_from_quaternion(q), C, atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(rotation_vectors)
def test_rotation_vector_round_trips_and_matches_rodrigues(phi):
    phi = np.array(phi)
    q = quaternion_from_rotation_vector(phi)
    np.testing.assert_allclose(rotation_vector_from_quaternion(q), phi, atol=1e-12)
    C = dcm_from_rotation_vector(phi)
    _is_rotation(C)
    np.testing.assert_allclose(dcm_from_quaternion(q), C, atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(vectors, vectors)
def test_skew_is_the_cross_product_and_antisymmetric(a, b):
    a, b = np.array(a), np.array(b)
    np.testing.assert_allclose(skew(a) @ b, np.cross(a, b), atol=1e-12)
    np.testing.assert_array_equal(skew(a).T, -skew(a))
    np.testing.assert_array_equal(skew(np.stack([a, b]))[1], skew(b))


@settings(max_examples=40, deadline=None)
@given(angles, angles)
def test_quaternion_product_composes_rotations(first, second):
    p, q = quaternion_from_euler(*first), quaternion_from_euler(*second)
    np.testing.assert_allclose(dcm_from_quaternion(quaternion_multiply(p, q)),
                               dcm_from_quaternion(p) @ dcm_from_quaternion(q), atol=1e-12)
    np.testing.assert_allclose(quaternion_multiply(q, conjugate(q)), [1.0, 0.0, 0.0, 0.0], atol=1e-14)


@settings(max_examples=60, deadline=None)
@given(st.floats(-1e3, 1e3))
def test_wrap_angle_range_and_equivalence(angle):
    wrapped = float(wrap_angle(angle))
    assert -math.pi < wrapped <= math.pi
    assert math.cos(wrapped) == pytest.approx(math.cos(angle), abs=1e-9)
    assert math.sin(wrapped) == pytest.approx(math.sin(angle), abs=1e-9)


def test_wrap_angle_keeps_pi_and_maps_minus_pi_to_pi():
    assert float(wrap_angle(math.pi)) == math.pi
    assert float(wrap_angle(-math.pi)) == math.pi


@settings(max_examples=40, deadline=None)
@given(angles, st.lists(st.floats(-1e-4, 1e-4), min_size=3, max_size=3))
def test_attitude_error_is_the_small_rotation_of_the_computed_attitude(rpy, small):
    phi = np.array(small)
    q_true = quaternion_from_euler(*rpy)
    # computed = exp(-[phi x]) true, in NED (the psi-angle sign)
    q_computed = quaternion_multiply(quaternion_from_rotation_vector(-phi), q_true)
    np.testing.assert_allclose(attitude_error(q_computed, q_true), phi, atol=1e-15)


@settings(max_examples=40, deadline=None)
@given(angles)
def test_triad_recovers_the_attitude_from_gravity_and_earth_rate(rpy):
    C = dcm_from_euler(*rpy)
    latitude = math.radians(50.0)
    gravity_nav = np.array([0.0, 0.0, 9.8])
    earth_nav = 7.292115e-5 * np.array([math.cos(latitude), 0.0, -math.sin(latitude)])
    estimate = triad(C.T @ gravity_nav, C.T @ earth_nav, gravity_nav, earth_nav)
    np.testing.assert_allclose(estimate, C, atol=1e-12)
