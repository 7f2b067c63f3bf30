"""WGS-84 Earth functions (core.earth) and their numba twins (navigate._kernels), and the attitude conventions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.core.attitude import (
    attitude_error,
    dcm_from_quaternion,
    euler_from_quaternion,
    quaternion_from_euler,
    quaternion_from_rotation_vector,
    quaternion_multiply,
    rotation_vector_from_quaternion,
    wrap_angle,
)
from schuler.core.earth import (
    EARTH_RATE,
    WGS84_ECCENTRICITY_SQUARED,
    WGS84_SEMI_MAJOR_AXIS,
    centripetal_acceleration_ned,
    earth_rate_ned,
    gravity_ned,
    meridian_radius,
    normal_gravity,
    radii_of_curvature,
    somigliana_gravity,
    transport_rate_ned,
    transverse_radius,
)
from schuler.navigate import _kernels

A, E2 = WGS84_SEMI_MAJOR_AXIS, WGS84_ECCENTRICITY_SQUARED


def test_radii_of_curvature_at_the_equator_and_pole():
    # NIMA TR8350.2 (WGS-84): R_N(0) = a (1 - e^2), R_E(0) = a, both a / sqrt(1 - e^2) at the pole
    assert meridian_radius(0.0) == pytest.approx(6_335_439.327, abs=1e-3)
    assert transverse_radius(0.0) == A
    polar = A / math.sqrt(1.0 - E2)
    assert meridian_radius(math.pi / 2) == pytest.approx(polar, rel=1e-15)
    assert transverse_radius(math.pi / 2) == pytest.approx(polar, rel=1e-15)
    # the old name returns the same pair (meridian first)
    L = np.radians([10.0, 45.0, 80.0])
    np.testing.assert_array_equal(radii_of_curvature(L)[0], meridian_radius(L))


def test_somigliana_gravity_published_values_and_free_air_gradient():
    # WGS-84 normal gravity: 9.7803253359 m/s^2 at the equator, 9.8321849378 m/s^2 at the poles (TR8350.2)
    assert somigliana_gravity(0.0) == pytest.approx(9.7803253359, abs=1e-10)
    assert somigliana_gravity(math.pi / 2) == pytest.approx(9.8321849378, abs=1e-9)
    np.testing.assert_array_equal(somigliana_gravity(np.radians([0.0, 33.0])), normal_gravity(np.radians([0.0, 33.0])))
    # free-air gradient about -0.3086 mGal/m = -3.086e-6 1/s^2 (Groves 2013, Sec. 2.4.7)
    L = math.radians(45.0)
    gradient = (somigliana_gravity(L, 1.0) - somigliana_gravity(L, -1.0)) / 2.0
    assert gradient == pytest.approx(-3.086e-6, rel=2e-3)


def test_gravity_vector_and_rates_in_ned():
    L, h = math.radians(45.0), 10_000.0
    g = gravity_ned(L, h)
    assert g[1] == 0.0 and g[2] == somigliana_gravity(L, h)
    assert g[0] == pytest.approx(-8.08e-9 * h, rel=1e-12)  # Groves (2.140): -8.08e-9 h sin 2L
    np.testing.assert_allclose(earth_rate_ned(L), EARTH_RATE * np.array([math.cos(L), 0.0, -math.sin(L)]))
    # flying east along a parallel at v_E = Omega (R_E + h) cos L cancels the Earth's rotation about the axis
    v_east = EARTH_RATE * (transverse_radius(L) + h) * math.cos(L)
    total = earth_rate_ned(L) + transport_rate_ned(L, h, 0.0, v_east)
    np.testing.assert_allclose(total, 2 * EARTH_RATE * np.array([math.cos(L), 0.0, -math.sin(L)]), rtol=1e-14)
    # centripetal acceleration: Omega^2 a at the equator, pointing down (at the axis)
    np.testing.assert_allclose(centripetal_acceleration_ned(0.0), [0.0, 0.0, EARTH_RATE**2 * A], rtol=1e-15)


@pytest.mark.parametrize("latitude_deg, height", [(0.0, 0.0), (37.0, 1500.0), (-61.0, 11_000.0), (89.0, -50.0)])
def test_kernel_earth_model_matches_the_numpy_functions(latitude_deg, height):
    L = math.radians(latitude_deg)
    s, c = math.sin(L), math.cos(L)
    r_n, r_e, _, inv_rn_h, inv_re_h, inv_c = _kernels.geometry(s, c, height)
    assert r_n == pytest.approx(meridian_radius(L), rel=1e-15)
    assert r_e == pytest.approx(transverse_radius(L), rel=1e-15)
    assert inv_rn_h * (r_n + height) == pytest.approx(1.0, rel=1e-15)
    assert inv_re_h * (r_e + height) == pytest.approx(1.0, rel=1e-15)
    assert inv_c * c == pytest.approx(1.0, rel=1e-15)
    g_north, g_down = _kernels.gravity(s, c, _kernels.geometry(s, c, height)[2], height)
    np.testing.assert_allclose([g_north, 0.0, g_down], gravity_ned(L, height), rtol=1e-15, atol=1e-20)


# deadline=None: the first example may compile the numba kernels (no cache yet)
@settings(deadline=None)
@given(st.floats(-1.5, 1.5), st.floats(-1e-3, 1e-3))
def test_latitude_rotation_keeps_sine_and_cosine(latitude, delta):
    s, c = _kernels.rotate_latitude(math.sin(latitude), math.cos(latitude), delta)
    assert s == pytest.approx(math.sin(latitude + delta), abs=3e-16)
    assert c == pytest.approx(math.cos(latitude + delta), abs=3e-16)


angles = st.floats(-math.pi + 1e-6, math.pi)
pitches = st.floats(-1.5, 1.5)


@settings(max_examples=200, deadline=None)
@given(angles, pitches, angles)
def test_euler_quaternion_round_trip(roll, pitch, heading):
    q = quaternion_from_euler(roll, pitch, heading)
    assert np.linalg.norm(q) == pytest.approx(1.0, abs=1e-15)
    np.testing.assert_allclose(wrap_angle(euler_from_quaternion(q) - [roll, pitch, heading]), 0.0, atol=1e-9)
    C = dcm_from_quaternion(q)
    np.testing.assert_allclose(C @ C.T, np.eye(3), atol=1e-15)
    # C_b^n = R_z(heading) R_y(pitch) R_x(roll)
    cz, sz, cy, sy, cx, sx = (f(a) for a in (heading, pitch, roll) for f in (math.cos, math.sin))
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    np.testing.assert_allclose(C, Rz @ Ry @ Rx, atol=1e-15)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-1.8, 1.8), min_size=3, max_size=3))  # |phi| < pi: the shorter rotation
def test_rotation_vector_round_trip_numpy_and_kernel(phi):
    phi = np.array(phi)
    q = quaternion_from_rotation_vector(phi)
    np.testing.assert_allclose(rotation_vector_from_quaternion(q), phi, atol=1e-12)
    np.testing.assert_allclose(_kernels.quat_from_rotation_vector(*phi), q, atol=2e-16)
    np.testing.assert_allclose(_kernels.rotation_vector_from_quat(*q), phi, atol=1e-12)
    v = np.array([0.3, -1.2, 2.0])
    np.testing.assert_allclose(_kernels.rotate(*q, *v), dcm_from_quaternion(q) @ v, atol=1e-14)


def test_attitude_error_sign_convention():
    # spec 06: C_computed = (I - [phi x]) C_true; a pitch error -d at heading 0 is psi_E = +d,
    # which drives a positive north velocity error (delta_v' = -psi x f, f = -g down)
    q_true = quaternion_from_euler(0.0, 0.0, 0.0)
    phi = attitude_error(quaternion_from_euler(0.0, -1e-5, 0.0), q_true)
    np.testing.assert_allclose(phi, [0.0, 1e-5, 0.0], atol=1e-17)
    assert np.cross(-phi, [0.0, 0.0, -9.8])[0] > 0
    composed = quaternion_multiply(quaternion_from_rotation_vector([0.0, 0.0, -2e-6]), q_true)
    np.testing.assert_allclose(attitude_error(composed, q_true), [0.0, 0.0, 2e-6], atol=1e-18)
