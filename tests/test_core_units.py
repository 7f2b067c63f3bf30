"""Earth constants, unit parsing (with the library's two traps) and parameters."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.core import earth
from schuler.exceptions import InvalidParameter
from schuler.params import Parameter, ParameterSet
from schuler.units import format_quantity, parse_quantity, to_unit


def test_default_schuler_period_is_84_4_minutes():
    assert earth.DEFAULT.schuler_period / 60 == pytest.approx(84.406, abs=1e-3)


def test_bollay_preset_uses_the_stated_period():
    # Bollay (1966): R = 3960 mi, g = 32.2 ft/s^2, T = 5060 s (2 pi sqrt(R/g) = 5063.1 s)
    assert earth.BOLLAY.radius == pytest.approx(3960 * 1609.344)
    assert earth.BOLLAY.gravity == pytest.approx(32.2 * 0.3048)
    assert earth.BOLLAY.schuler_period == 5060.0
    assert earth.schuler_period(earth.BOLLAY.gravity, earth.BOLLAY.radius) == pytest.approx(5063.1, abs=0.05)
    assert earth.BOLLAY.effective_gravity == pytest.approx((2 * math.pi / 5060) ** 2 * earth.BOLLAY.radius)


def test_drozdovich_preset():
    p = earth.DROZDOVICH
    assert (p.radius, p.gravity, p.rate) == (6.4e6, 9.81, 7.3e-5)
    assert p.schuler_period / 60 == pytest.approx(84.6, abs=0.1)


def test_wgs84_normal_gravity_and_radii():
    # WGS-84 (NIMA TR8350.2): gamma_e = 9.7803253359, gamma_p = 9.8321849378 m/s^2
    assert earth.normal_gravity(0.0) == pytest.approx(9.7803253359, abs=1e-10)
    assert earth.normal_gravity(np.pi / 2) == pytest.approx(9.8321849378, abs=1e-9)
    r_m, r_n = earth.radii_of_curvature(0.0)
    assert r_n == pytest.approx(6378137.0)
    assert r_m == pytest.approx(6378137.0 * (1 - earth.WGS84_ECCENTRICITY_SQUARED))
    r_m, r_n = earth.radii_of_curvature(np.pi / 2)
    assert r_m == pytest.approx(r_n)  # equal at the pole: a / sqrt(1 - e^2)


@pytest.mark.parametrize(
    "text, unit, expected",
    [
        ("0.01 deg/h", "deg/h", 0.01 * math.pi / 180 / 3600),
        ("6 h", "s", 21600.0),
        ("3960 mi", "m", 3960 * 1609.344),
        ("1 nmi", "m", 1852.0),
        ("1 ft", "m", 0.3048),
        ("1 arcmin", "rad", math.pi / 180 / 60),
        ("1 arcsec", "arcmin", math.pi / 180 / 3600),
        ("1e-4 g", "g", 1e-4 * 9.80665),
        ("50 mg", "g", 50e-3 * 9.80665),
        ("2 g0", "m/s^2", 2 * 9.80665),
        ("1 gee", "m/s^2", 9.80665),
        ("9.81 m/s^2", "g", 9.81),
        ("0.5 mi/s", "mi/s", 0.5 * 1609.344),
        (0.01, "deg/h", 0.01 * math.pi / 180 / 3600),
        ("50", "deg", math.radians(50)),
        ("1e-4", "", 1e-4),
    ],
)
def test_parse_quantity(text, unit, expected):
    assert parse_quantity(text, unit, name="x") == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize(
    "text, unit, message",
    [
        ("0.01 Hz", "deg/h", "not an angular rate"),  # trap: pint's radian is dimensionless
        ("1 rad", "deg/h", "not an angular rate"),
        ("95 percent", "deg", "not an angle"),  # trap: percent is dimensionless too
        ("1 kg", "g", "not an acceleration"),  # trap: g is gram in pint
        ("1 g", "m", "not a length"),
        ("3 m", "s", "not a time"),
        ("fast", "m/s", "cannot read"),
        ("nan deg", "deg", "not a finite number"),
        ("inf", "s", "not a finite number"),
        ("", "s", "empty"),
    ],
)
def test_parse_quantity_errors_name_the_option(text, unit, message):
    with pytest.raises(InvalidParameter, match=message) as error:
        parse_quantity(text, unit, name="drift")
    assert error.value.name == "drift"
    assert str(error.value).startswith("drift: ")


@settings(max_examples=50, deadline=None)
@given(st.floats(-1e6, 1e6, allow_nan=False), st.sampled_from(["deg", "deg/h", "arcmin", "ft", "mi", "g", "h"]))
def test_bare_numbers_round_trip_through_si(value, unit):
    si = parse_quantity(value, unit, name="x")
    assert to_unit(si, unit) == pytest.approx(value, rel=1e-12, abs=1e-12)


def test_format_quantity():
    assert format_quantity(math.radians(1 / 60), "arcmin") == "1 arcmin"


LATITUDE = Parameter("latitude", "deg", 50.0, "Latitude.", minimum=-90, maximum=90)
TAU = Parameter("tau", "s", 4.0, "Pulse duration.", minimum=0, exclusive_minimum=True)
MODE = Parameter("mode", "", "three-axis", "Mode.", choices=("three-axis", "single-axis"), kind="choice")
COUNT = Parameter("monte_carlo", "", 0, "Members.", minimum=0, kind="integer")


def test_parameter_range_and_messages():
    assert LATITUDE.parse("90 deg") == pytest.approx(math.pi / 2)
    with pytest.raises(InvalidParameter, match=r"latitude: '95 deg' is outside \[-90, 90\] deg"):
        LATITUDE.parse("95 deg")
    with pytest.raises(InvalidParameter, match=r"--tau: '0' is outside \(0, inf\) s"):
        TAU.parse("0", label=TAU.option)
    with pytest.raises(InvalidParameter, match="not one of"):
        MODE.parse("two-axis")
    with pytest.raises(InvalidParameter, match="whole number"):
        COUNT.parse("1.5")
    assert LATITUDE.help_text() == "Latitude. Range [-90, 90] deg. [default: 50 deg]"


def test_parameter_set_parses_defaults_and_refuses_unknown_names():
    values = ParameterSet([LATITUDE, TAU, MODE, COUNT], owner="demo").parse({"tau": "8 s", "mode": "Single-Axis"})
    assert dict(values) == {"latitude": pytest.approx(math.radians(50)), "tau": 8.0, "mode": "single-axis",
                            "monte_carlo": 0}
    with pytest.raises(InvalidParameter, match="did you mean 'latitude'"):
        ParameterSet([LATITUDE], owner="demo").parse({"latitud": 5})


@pytest.mark.parametrize("text", ["()", "f()", "1 +", "deg deg (", "[1, 2]"])
def test_malformed_text_is_one_clear_error(text):
    with pytest.raises(InvalidParameter, match="latitude: "):
        parse_quantity(text, "deg", name="latitude")
