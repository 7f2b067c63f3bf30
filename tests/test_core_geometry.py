"""Shared geometry: angle constants, the Earth rate in a level frame, the time-grid rule."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from schuler.core.earth import EARTH_RATE
from schuler.core.geometry import (
    ARCMIN,
    ARCSEC,
    DEG_PER_HOUR,
    DEGREE,
    MAX_GRID_POINTS,
    earth_rate_north_up,
    horizontal_earth_rate,
    level_frame_earth_rate,
    time_grid,
    time_grids,
    uniform_step,
)
from schuler.exceptions import InvalidParameter, NotObservable

latitudes = st.floats(-90.0, 90.0)
azimuths = st.floats(-720.0, 720.0)


def test_angle_constants_against_their_definitions():
    # 1 arcsec = pi / 648000 rad = 4.84813681109536e-6 rad (the SI brochure's definition of the second of arc)
    assert ARCSEC == pytest.approx(4.84813681109536e-6, rel=1e-14)
    assert ARCMIN == pytest.approx(math.pi / 10800.0, rel=1e-15)
    assert DEGREE == pytest.approx(math.radians(1.0), rel=1e-15)
    # 1 deg/h = 4.84813681109536e-6 rad/s (numerically one arcsec per second)
    assert DEG_PER_HOUR == pytest.approx(ARCSEC, rel=1e-15)
    assert 60 * ARCSEC == pytest.approx(ARCMIN, rel=1e-15) and 60 * ARCMIN == pytest.approx(DEGREE, rel=1e-15)


@settings(max_examples=200, deadline=None)
@given(latitude=latitudes, azimuth=azimuths)
def test_level_components_split_into_horizontal_and_vertical(latitude, azimuth):
    # for every azimuth the horizontal part has norm Omega cos L and the vertical one is Omega sin L (down: minus)
    phi, psi = math.radians(latitude), math.radians(azimuth)
    x, y, z = level_frame_earth_rate(phi, psi)
    assert math.hypot(x, y) == pytest.approx(EARTH_RATE * math.cos(phi), rel=1e-12, abs=1e-20)
    assert -z == pytest.approx(EARTH_RATE * math.sin(phi), rel=1e-12, abs=1e-20)
    assert math.sqrt(x * x + y * y + z * z) == pytest.approx(EARTH_RATE, rel=1e-12)


@settings(max_examples=100, deadline=None)
@given(latitude=latitudes, azimuth=azimuths)
def test_level_components_equal_a_rotated_navigation_frame_vector(latitude, azimuth):
    # independent construction: the NED Earth rate (Omega cos L, 0, -Omega sin L) resolved in a frame
    # turned by psi about the down axis (scipy's rotation, not the formula under test)
    phi, psi = math.radians(latitude), math.radians(azimuth)
    ned = EARTH_RATE * np.array([math.cos(phi), 0.0, -math.sin(phi)])
    resolved = Rotation.from_euler("z", psi).inv().apply(ned)
    np.testing.assert_allclose(level_frame_earth_rate(phi, psi), resolved, rtol=0, atol=1e-12 * EARTH_RATE)


def test_level_components_broadcast_and_source_frames():
    phi = np.radians([0.0, 45.0, 80.0])
    x, y, z = level_frame_earth_rate(phi[:, None], np.radians([0.0, 90.0]))
    assert x.shape == y.shape == z.shape == (3, 2)
    # x east (azimuth 90 deg): no east component of the Earth rate, and y then points south
    np.testing.assert_allclose(x[:, 1], 0.0, atol=1e-20)
    np.testing.assert_allclose(y[:, 1], -EARTH_RATE * np.cos(phi), rtol=1e-15)
    north, up = earth_rate_north_up(phi)
    np.testing.assert_allclose(x[:, 0], north, rtol=1e-15)
    np.testing.assert_allclose(-z[:, 0], up, rtol=1e-15)


@settings(max_examples=100, deadline=None)
@given(latitude=st.floats(-89.99, 89.99))
def test_horizontal_rate_is_the_north_component(latitude):
    phi = math.radians(latitude)
    assert horizontal_earth_rate(phi) == pytest.approx(EARTH_RATE * math.cos(phi), rel=1e-15)
    assert horizontal_earth_rate(phi) == earth_rate_north_up(phi)[0]


@pytest.mark.parametrize("latitude", [math.pi / 2, -math.pi / 2, np.radians(90.0), [0.1, math.pi / 2]])
def test_horizontal_rate_refuses_the_poles(latitude):
    with pytest.raises(NotObservable, match=r"^latitude: -?90 deg: .*not observable"):
        horizontal_earth_rate(latitude)


@pytest.mark.parametrize("latitude", [math.nan, math.inf, math.radians(90.1), [0.0, -2.0]])
def test_bad_latitudes_are_invalid(latitude):
    with pytest.raises(InvalidParameter, match="latitude"):
        horizontal_earth_rate(latitude)
    with pytest.raises(InvalidParameter, match="latitude"):
        level_frame_earth_rate(latitude, 0.0)


def test_bad_azimuth_and_earth_rate():
    with pytest.raises(InvalidParameter, match="azimuth"):
        level_frame_earth_rate(0.5, math.nan)
    with pytest.raises(InvalidParameter, match="earth_rate"):
        horizontal_earth_rate(0.5, earth_rate=0.0)


# ------------------------------------------------------------ the time-grid rule


@settings(max_examples=300, deadline=None)
@given(duration=st.floats(1e-3, 1e6), steps=st.floats(1.0, 5000.0))
def test_time_grid_rule(duration, steps):
    step = duration / steps
    t = time_grid(duration, step)
    assert t[0] == 0.0 and t[-1] == duration
    dt = np.diff(t)
    assert np.all(dt > 0)
    # every step but the last is the step itself (k step, rounded once)
    np.testing.assert_allclose(t[:-1], step * np.arange(t.size - 1), rtol=1e-15)
    whole = duration / step
    if abs(whole - round(whole)) <= 1e-9:  # ends on a step: n + 1 points, the last one moved by <= 1e-9 step
        assert t.size == round(whole) + 1
        assert abs(t[-1] - step * round(whole)) <= 1e-9 * step + 4 * np.spacing(duration)
    else:  # a shorter last step
        assert t.size == math.floor(whole) + 2
        assert 0.0 < dt[-1] < step


@pytest.mark.parametrize(
    ("duration", "step", "expected"),
    [
        (200.0, 1.0, 201),
        (48 * 3600.0, 10.0, 17281),
        (0.3, 0.1, 4),  # 0.3 / 0.1 = 2.9999999999999996: within rounding of 3 steps
        (100.0, 30.0, 5),
        (1.0, 1.0, 2),
        (1.0, 1.0 + 1e-12, 2),  # a step longer than the duration by rounding only
    ],
)
def test_time_grid_sizes(duration, step, expected):
    t = time_grid(duration, step)
    assert t.size == expected and t[-1] == duration


def test_time_grid_refuses_before_allocating():
    with pytest.raises(InvalidParameter, match="output_step.*at most 1,000"):
        time_grid(1e6, 1.0, names=("duration", "output_step"), max_points=1000)
    with pytest.raises(InvalidParameter, match="step"):
        time_grid(1e300, 1e-300)
    with pytest.raises(InvalidParameter, match=f"at most {MAX_GRID_POINTS:,}"):
        time_grid(172_800.0, 0.01)


@pytest.mark.parametrize(
    ("duration", "step", "name"),
    [(0.0, 1.0, "duration"), (-1.0, 1.0, "duration"), (math.nan, 1.0, "duration"), (10.0, 0.0, "time_step"),
     (10.0, math.inf, "time_step"), (10.0, 11.0, "time_step")],
)
def test_time_grid_bad_input_names_the_parameter(duration, step, name):
    with pytest.raises(InvalidParameter, match=f"^{name}: "):
        time_grid(duration, step, names=("duration", "time_step"))


def test_time_grids_equal_single_grids():
    durations, steps = np.array([200.0, 60.0, 1.0, 7.5]), np.array([1.0, 7.0, 0.3, 2.5])
    time, valid = time_grids(durations, steps)
    assert time.shape == valid.shape == (4, 201)
    for k in range(4):
        np.testing.assert_array_equal(time[k][valid[k]], time_grid(durations[k], steps[k]))
        assert np.all(time[k][~valid[k]] == 0.0)
    with pytest.raises(InvalidParameter, match="exceed"):
        time_grids(np.full(20, 100.0), 1.0, max_points=1000)


def test_uniform_step():
    assert uniform_step(np.linspace(0.0, 48 * 3600.0, 17281)) == 10.0
    assert uniform_step(time_grid(48 * 3600.0, 10.0)) == 10.0
    assert uniform_step(1e9 + np.arange(0.0, 100.0)) == pytest.approx(1.0, rel=1e-12)
    assert uniform_step(time_grid(100.0, 30.0)) is None  # shorter last step
    t = np.linspace(0.0, 100.0, 101)
    t[50] += 1e-9  # a sample off its slot by 1e-9 of a step is not uniform
    assert uniform_step(t) is None
    assert uniform_step(np.array([0.0])) is None
