"""The KPI manual's gyrocompass loop design, once: c_Gamma = 2 zeta / T, c_a = 1 / (T^2 U_eta), and back."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.core.earth import EARTH_RATE
from schuler.core.gyrocompass_design import DESIGN_DAMPING, DESIGN_TIME_CONSTANT, loop_design, loop_gains
from schuler.exceptions import InvalidParameter, NotObservable


def test_the_design_example():
    # the KPI manual, end of Sec. 2: "often T = 30 s, zeta = 0.8"; c_Gamma = 2 zeta / T = 0.05333 1/s, and
    # c_a = 1 / (T^2 U cos L) = 23.70 1/s at 50 deg (U = 7.292115e-5 rad/s: the manual states none)
    assert (DESIGN_TIME_CONSTANT, DESIGN_DAMPING) == (30.0, 0.8)
    latitude = math.radians(50.0)
    c_gamma, c_a = loop_gains(latitude, DESIGN_TIME_CONSTANT, DESIGN_DAMPING)
    assert isinstance(c_gamma, float) and isinstance(c_a, float)
    assert c_gamma == pytest.approx(1.6 / 30.0, rel=1e-15)
    assert c_a == pytest.approx(1.0 / (900.0 * EARTH_RATE * math.cos(latitude)), rel=1e-15)
    assert round(c_a, 2) == 23.70
    # the printed pair (0.08, 22): c_a = 22 holds for T = 30 s at 46.16 deg, where 0.08 means zeta = 1.2
    latitude_22 = math.acos(1.0 / (900.0 * EARTH_RATE * 22.0))
    T, zeta = loop_design(latitude_22, 0.08, 22.0)
    assert T == pytest.approx(30.0, rel=1e-12) and zeta == pytest.approx(1.2, rel=1e-12)


def test_arrays_broadcast_to_one_shape():
    latitudes = np.radians([0.0, 30.0, 60.0])
    c_gamma, c_a = loop_gains(latitudes, 30.0, 0.8)
    assert c_gamma.shape == c_a.shape == (3,)
    np.testing.assert_array_equal(c_gamma, 1.6 / 30.0)
    # c_a U_eta = 1 / T^2 at every latitude
    np.testing.assert_allclose(c_a * EARTH_RATE * np.cos(latitudes), 1.0 / 900.0, rtol=1e-15)
    T, zeta = loop_design(latitudes, c_gamma, c_a)
    np.testing.assert_allclose(T, 30.0, rtol=1e-14)
    np.testing.assert_allclose(zeta, 0.8, rtol=1e-14)


@settings(max_examples=200, deadline=None)
@given(time_constant=st.floats(0.1, 1e5), damping=st.floats(0.01, 100.0), latitude=st.floats(-1.5, 1.5),
       earth_rate=st.floats(1e-6, 1e-3))
def test_round_trip(time_constant, damping, latitude, earth_rate):
    c_gamma, c_a = loop_gains(latitude, time_constant, damping, earth_rate)
    assert c_gamma > 0.0 and c_a > 0.0
    T, zeta = loop_design(latitude, c_gamma, c_a, earth_rate)
    # a few roundings (a square root, two divisions) each way
    assert T == pytest.approx(time_constant, rel=1e-14) and zeta == pytest.approx(damping, rel=1e-14)
    back = loop_gains(latitude, T, zeta, earth_rate)
    assert back == pytest.approx((c_gamma, c_a), rel=1e-14)


@pytest.mark.parametrize(("time_constant", "damping", "name"),
                         [(0.0, 0.8, "time_constant"), (-30.0, 0.8, "time_constant"), (math.inf, 0.8, "time_constant"),
                          (30.0, 0.0, "damping"), (30.0, math.nan, "damping")])
def test_bad_design_names_the_parameter(time_constant, damping, name):
    with pytest.raises(InvalidParameter, match=f"^{name}: "):
        loop_gains(0.5, time_constant, damping)


def test_no_design_at_the_poles():
    with pytest.raises(NotObservable, match="latitude"):
        loop_gains(math.pi / 2, 30.0, 0.8)
    with pytest.raises(NotObservable, match="latitude"):
        loop_design(-math.pi / 2, 0.05, 20.0)
