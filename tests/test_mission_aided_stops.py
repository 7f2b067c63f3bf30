"""The aided mission on the drive: zero-velocity updates at its stops, its odometer and non-holonomic constraint."""

from __future__ import annotations

import numpy as np
import pytest

from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.mission.aided_monte_carlo import aided_members
from schuler.mission.aiding import aided_budget
from schuler.mission.aiding_measurements import zupt_epochs
from schuler.mission.api import SYSTEM
from schuler.mission.evaluation import PARAMETERS
from schuler.mission.setup import mission_setup

DRIVE = {"imu": "tactical", "trajectory": "drive", "duration": 1200.0, "outage_start": 300.0,
         "outage_duration": 60.0, "outage_every": 600.0, "odometer_rate": 1.0, "zupt_rate": 1.0}
"""A 20-min drive (stops at 0, 392, 783 and 1175 s, 25 s each) with 1-Hz GNSS and two 60-s outages while
driving (300 s and 900 s); the stops' and wheel's measurements at 1 Hz, on the 1-s covariance grid."""

EVERY_AIDING = "gnss-position,gnss-velocity,zupt,odometer,nhc"


def setup_of(**values):
    return mission_setup(dict(PARAMETERS.case(values)))


def test_a_stop_collapses_the_velocity_covariance_to_the_zero_velocity_sigma():
    # GNSS out for the whole drive, so the zero-velocity updates alone aid it; at the first update of a stop the
    # velocity's prior variance P (1.9 m/s squared after 190 s of free inertia) dwarfs R = zupt_sigma^2, and the
    # update leaves R (1 - R / P + ...) per axis: zupt_sigma^2 to 3e-5. One 0.1-s step later (the budget holds
    # the covariance before each update) the tilt and accelerometer errors have added 0.4 % (measured); 1 %
    # bounds it. Inside the stop the updates keep it below zupt_sigma^2.
    sigma = 0.01
    setup = setup_of(imu="tactical", trajectory="drive", duration=600.0, aiding="gnss-position,zupt",
                     outages=[[0.0, 600.0]], zupt_sigma=sigma, zupt_rate=10.0, covariance_interval=0.1)
    budget = aided_budget(setup).budget
    start, end = setup.trajectory().stationary_intervals()[1]
    first = float(zupt_epochs(setup)[zupt_epochs(setup) > start][0])
    assert first == pytest.approx(191.7, abs=1e-9)
    at = int(np.flatnonzero(np.isclose(budget.time, first))[0])
    total = {axis: budget.variance[f"velocity_{axis}"].sum(axis=1) for axis in ("north", "east")}
    for axis, variance in total.items():
        assert variance[at] > 1e4 * sigma**2, axis  # the prior: free inertia since the start's stop
        assert variance[at + 1] == pytest.approx(sigma**2, rel=0.01), axis
        inside = (budget.time > first + 0.15) & (budget.time <= end)
        assert np.all(variance[inside] < sigma**2), axis
    # without the updates the velocity does not collapse: the drive's stops are what the budget sees
    free = aided_budget(setup_of(imu="tactical", trajectory="drive", duration=600.0, aiding="gnss-position",
                                 outages=[[0.0, 600.0]], covariance_interval=0.1)).budget
    assert free.variance["velocity_north"][at + 1].sum() > 1e4 * sigma**2


def test_the_shares_with_the_stops_and_wheel_sum_to_one():
    budget = aided_budget(setup_of(**DRIVE, aiding=EVERY_AIDING))
    sources = budget.budget.sources
    assert sources[-5:] == ("gnss_position_noise", "gnss_velocity_noise", "zupt_noise", "odometer_noise",
                            "nhc_noise")
    for outage in budget.outages:
        assert sum(outage["shares"].values()) == pytest.approx(1.0, rel=1e-9)
    shares = budget.budget.shares()  # at the end: the last stop's updates
    assert sum(shares.values()) == pytest.approx(1.0, rel=1e-9)
    assert shares["zupt_noise"] > 0.01


@pytest.mark.parametrize("source", ["zupt_noise", "odometer_noise", "nhc_noise", "gyro_random_walk",
                                    "gyro_bias_z"])
def test_switching_a_stop_or_wheel_source_off_removes_exactly_its_share(source):
    setup = setup_of(**DRIVE, aiding=EVERY_AIDING)
    full, off = aided_budget(setup), aided_budget(setup, disabled=(source,))
    # the outages' ends and the end of the drive (inside its last stop, where the zero-velocity noise is felt)
    ends = [(o["end_index"], o["horizontal_error_sigma_m"] ** 2, o["shares"]) for o in full.outages]
    ends.append((-1, full.budget.sigma("horizontal_position")[-1] ** 2, full.budget.shares()))
    for index, variance, shares in ends:
        assert shares[source] > 1e-5  # the source is felt, so a wrong bookkeeping would show
        without = off.budget.horizontal()[index]
        assert without.sum() == pytest.approx(variance * (1.0 - shares[source]), rel=1e-9)
        assert without[off.budget.sources.index(source)] == 0.0


def test_the_odometer_and_constraint_shrink_a_driven_outage_ninefold():
    # a tactical IMU in a 60-s outage while driving: the wheel's speed and the constraint bound the velocity
    # error that GNSS alone leaves to grow; measured 8.61 -> 0.928 m (x 9.28) and 7.45 -> 1.132 m (x 6.58)
    gnss = aided_budget(setup_of(**DRIVE, aiding="gnss-position"))
    wheel = aided_budget(setup_of(**DRIVE, aiding="gnss-position,odometer,nhc"))
    factors = [g["horizontal_error_sigma_m"] / w["horizontal_error_sigma_m"]
               for g, w in zip(gnss.outages, wheel.outages)]
    assert factors == pytest.approx([9.28, 6.58], rel=0.02)
    # each alone helps less than the two together (measured x 1.6 odometer, x 1.5 constraint on the first)
    for name in ("odometer", "nhc"):
        alone = aided_budget(setup_of(**DRIVE, aiding=f"gnss-position,{name}")).outages[0]
        assert 1.3 < gnss.outages[0]["horizontal_error_sigma_m"] / alone["horizontal_error_sigma_m"] < 2.0


def test_the_members_draw_the_same_data_whatever_their_chunk():
    setup = setup_of(**{**DRIVE, "duration": 600.0, "outage_start": 170.0, "outage_every": None,
                        "imu": "consumer"}, aiding=EVERY_AIDING)
    streams = RandomStreams(11)
    budget = aided_budget(setup)
    _, together = aided_members(setup, [0, 1, 2, 3], streams, 2.0, budget.start_sigma)
    _, apart = aided_members(setup, [2, 3], streams, 2.0, budget.start_sigma)
    np.testing.assert_allclose(apart.horizontal, together.horizontal[2:], rtol=1e-9, atol=1e-12)
    assert not np.allclose(together.horizontal[0], together.horizontal[1])


@pytest.mark.parametrize(("values", "name", "message"), [
    ({"trajectory": "great-circle", "aiding": "gnss-position,zupt"}, "aiding", "on the drive trajectory only"),
    ({"trajectory": "stationary", "aiding": "gnss-position,nhc"}, "aiding", "not on a stationary trajectory"),
    ({"aiding": "gnss-position,zpt"}, "aiding", "did you mean 'zupt'"),
    ({"aiding": "gnss-position,zaru"}, "aiding", "not a measurement of a mission"),
    ({"aiding": "zupt"}, "aiding", "gnss-position is needed"),
    ({"aiding": "gnss-position,zupt", "zupt_rate": 10.0}, "zupt_rate", "whole number of covariance steps"),
    ({"aiding": "gnss-position,odometer", "odometer_rate": 0.3}, "odometer_rate", "whole number of covariance"),
])
def test_stops_and_wheels_off_the_drive_or_off_the_grid_are_refused_in_one_line(values, name, message, run_cli):
    case = {**DRIVE, "duration": 600.0, "outage_every": None, **values}
    with pytest.raises(InvalidParameter, match=message) as error:
        SYSTEM.run(**case)
    assert error.value.name == name
    options = [part for key, value in case.items() if value is not None
               for part in (PARAMETERS[key].option, str(value))]
    out = run_cli("mission", "run", *options)
    assert out.code == 2 and len(out.stderr.strip().splitlines()) == 1, out.stderr


@pytest.mark.slow
def test_the_consumer_examples_covariance_is_its_filters_monte_carlo_at_every_outage_end():
    from schuler.study.scenario import load_scenario

    scenario = load_scenario("examples/mission_consumer_gnss.toml")
    assert "zupt" in scenario.given()["aiding"]
    result = scenario.definition().run(**scenario.given(), monte_carlo=1000, seed=scenario.monte_carlo.seed)
    compared = result.to_dict()["monte_carlo"]["outages"]
    assert len(compared) == 2
    # the RMS of 1000 horizontal errors (two degrees of freedom) scatters by about 1 / (2 sqrt(1000)) = 1.6 %
    for outage in compared:
        ratio = outage["horizontal_error_end_rms_m"] / outage["horizontal_error_sigma_m"]
        assert abs(ratio - 1.0) < 0.10, outage
    # the stops inside the outages: each ends well below the 3.1 m of GNSS alone
    assert max(o["horizontal_error_sigma_m"] for o in compared) < 1.5
