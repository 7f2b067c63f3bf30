"""A mission flown along a waypoint profile file (schuler.navigate.profile)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from schuler.core.random import RandomStreams
from schuler.mission.covariance import covariance_budget
from schuler.mission.evaluation import PARAMETERS
from schuler.mission.monte_carlo import final_horizontal_errors, run_members
from schuler.mission.setup import mission_setup

MANOEUVRING = Path(__file__).resolve().parent.parent / "examples" / "profiles" / "manoeuvring_flight.toml"

# the built-in 30-min "flight" at 45 deg N, heading 30 deg, 250 m/s, written as a profile: take-off run to 300 s,
# a right turn from 0.35 d = 630 s and a left turn from 0.7 d = 1260 s, 120 s each
FLIGHT_PROFILE = """\
name = "the flight of 30 min"
[start]
latitude = 45.0
[[waypoint]]
time = 0.0
speed = 0.0
heading = 30.0
[[waypoint]]
time = 300.0
speed = 250.0
heading = 30.0
[[waypoint]]
time = 630.0
speed = 250.0
heading = 30.0
[[waypoint]]
time = 750.0
speed = 250.0
heading = 120.0
[[waypoint]]
time = 1260.0
speed = 250.0
heading = 120.0
[[waypoint]]
time = 1380.0
speed = 250.0
heading = 30.0
"""


def setup_of(**values):
    case = PARAMETERS.case(values)
    return mission_setup({name: case[name] for name in PARAMETERS.names})


@pytest.fixture
def flight_profile(tmp_path):
    path = tmp_path / "flight.toml"
    path.write_text(FLIGHT_PROFILE)
    return path


def test_a_profile_file_of_the_built_in_flight_gives_its_budget(flight_profile):
    common = {"imu": "tactical", "duration": 1800.0}
    from_file = setup_of(profile=str(flight_profile), **common)
    assert from_file.latitude == pytest.approx(math.radians(45.0), rel=1e-15)
    assert from_file.heading == pytest.approx(math.radians(30.0), rel=1e-15)  # the first waypoint's
    built_in = covariance_budget(setup_of(trajectory="flight", latitude=math.radians(45.0), speed=250.0,
                                          heading=math.radians(30.0), **common))
    flown = covariance_budget(from_file)
    # the same waypoints and blends: the same kinematics, so the same budget to rounding
    assert np.allclose(flown.sigma("horizontal_position"), built_in.sigma("horizontal_position"), rtol=1e-9, atol=0)
    assert flown.shares() == pytest.approx(built_in.shares(), rel=1e-9, abs=1e-12)


def test_covariance_agrees_with_the_monte_carlo_along_a_profile(flight_profile):
    # 300 members: the RMS of a 2-D error has a relative standard error of about 1/sqrt(4 * 300) = 2.9 %;
    # 12 % is four of them
    setup = setup_of(profile=str(flight_profile), imu="navigation", duration=1800.0)
    sigma = covariance_budget(setup).sigma("horizontal_position")[-1]
    errors = final_horizontal_errors(run_members(setup, np.arange(300), RandomStreams(21), 2.0,
                                                 output_step=setup.duration))
    assert math.sqrt(np.mean(errors**2)) == pytest.approx(sigma, rel=0.12)


@pytest.mark.parametrize("arguments, message", [
    (("--profile", "no-such-profile.toml"), "--profile: cannot read no-such-profile.toml"),
    (("--profile", MANOEUVRING, "--latitude", "10"),
     "cannot be combined with"),
])
def test_a_bad_profile_is_refused_in_one_line(run_cli, arguments, message):
    out = run_cli("mission", "run", *arguments, "--duration", "600")
    assert out.code == 2 and out.stderr.count("\n") == 1
    assert message in out.stderr


@pytest.mark.slow
def test_covariance_agrees_with_the_monte_carlo_along_the_manoeuvring_flight():
    # climbs, descents, turns of both senses: 1,000 members, relative standard error ~1.6 %, the 10 %
    setup = setup_of(profile=str(MANOEUVRING), imu="tactical", duration=3600.0)
    sigma = covariance_budget(setup).sigma("horizontal_position")[-1]
    errors = final_horizontal_errors(run_members(setup, np.arange(1000), RandomStreams(21), 2.0,
                                                 output_step=setup.duration))
    assert math.sqrt(np.mean(errors**2)) == pytest.approx(sigma, rel=0.10)
