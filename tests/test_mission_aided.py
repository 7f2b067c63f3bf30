"""The mission with aiding: the sources through the filter's closed loop, their shares, the filter's Monte Carlo."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.exceptions import InvalidParameter
from schuler.mission.aiding import aided_budget
from schuler.mission.api import SYSTEM
from schuler.mission.covariance import covariance_budget
from schuler.mission.evaluation import PARAMETERS
from schuler.mission.setup import mission_setup
from schuler.mission.survival import longest_outage, survival_figure, survival_table
from test_mission_instrument import WHITE_SPEC

SHORT = {"imu": "tactical", "trajectory": "drive", "duration": 1200.0, "aiding": "gnss-position,gnss-velocity",
         "outage_start": 300.0, "outage_duration": 60.0, "outage_every": 600.0}
"""A 20-min drive with 1-Hz GNSS positions and velocities and two 60-s outages (at 300 s and 900 s)."""


def setup_of(**values):
    return mission_setup(dict(PARAMETERS.case(values)))


def test_the_outages_are_schuler_aideds_and_their_shares_sum_to_one():
    budget = aided_budget(setup_of(**SHORT))
    assert [(o["start_s"], o["duration_s"]) for o in budget.outages] == [(300.0, 60.0), (900.0, 60.0)]
    for outage in budget.outages:
        assert budget.budget.time[outage["end_index"]] == outage["start_s"] + outage["duration_s"] - 1.0
        assert sum(outage["shares"].values()) == pytest.approx(1.0, abs=1e-12)
        assert set(outage["shares"]) == set(budget.budget.sources)
        assert "gnss_velocity_noise" in outage["shares"]
    # the drift inside an outage: the 1-sigma at its end is many times the aided one just before it
    sigma = budget.budget.sigma("horizontal_position")
    first = budget.outages[0]
    assert first["horizontal_error_sigma_m"] == pytest.approx(sigma[first["end_index"]], rel=1e-12)
    assert first["horizontal_error_sigma_m"] > 5.0 * sigma[299]


@pytest.mark.parametrize("source", ["gyro_random_walk", "accel_random_walk", "gnss_position_noise",
                                    "gnss_velocity_noise", "gyro_bias_z", "accel_bias_x"])
def test_switching_a_source_off_removes_exactly_its_share(source):
    setup = setup_of(**SHORT)
    full, off = aided_budget(setup), aided_budget(setup, disabled=(source,))
    for with_it, without in zip(full.outages, off.outages):
        share = with_it["shares"][source]
        assert share > 1e-5  # the source is felt, so a wrong bookkeeping would show
        assert without["horizontal_error_sigma_m"] ** 2 == pytest.approx(
            with_it["horizontal_error_sigma_m"] ** 2 * (1.0 - share), rel=1e-9)
        assert without["shares"][source] == 0.0


def test_the_sources_add_up_to_the_filters_own_covariance_when_it_is_given_the_true_start(tmp_path):
    # white noises only, north from a ground gyrocompass: the calibration leaves gyro biases (the noise floor) that
    # the alignment does not see, so the initial covariance is diagonal, which is what the filter starts from; its
    # own covariance is then the sum of the sources' through the same gains, at every step
    spec = tmp_path / "white.toml"
    spec.write_text(WHITE_SPEC)
    setup = setup_of(**{**SHORT, "imu": str(spec)}, alignment="ground-gyrocompass", initial_position_error=2.0)
    budget = aided_budget(setup)
    np.testing.assert_allclose(budget.budget.sigma("horizontal_position"), budget.filter_sigma, rtol=1e-9)
    assert budget.filter_sigma[0] == pytest.approx(2.0 * math.sqrt(2.0), rel=1e-12)
    assert budget.budget.shares(budget.outages[0]["end_index"])["gyro_bias_z"] > 1e-4
    # a tactical IMU's accelerometer biases tilt the alignment (correlated with them): the filter, given only the
    # diagonal, believes otherwise
    correlated = aided_budget(setup_of(**SHORT))
    end = correlated.outages[0]["end_index"]
    assert abs(correlated.filter_sigma[end] / correlated.budget.sigma("horizontal_position")[end] - 1.0) > 1e-4


def test_an_outage_as_long_as_the_mission_is_the_free_inertial_budget():
    # no fix at all: the aided recursion is the free-inertial propagation of the same sources (vertical channel
    # free, 1-s steps), on the filter's error model (its gravity -g/R beside WGS-84's gradient): measured 4e-5
    values = {"imu": "tactical", "trajectory": "drive", "duration": 600.0, "vertical_channel": "free"}
    aided = aided_budget(setup_of(**values, aiding="gnss-position", outage_start=0.0, outage_duration=600.0))
    free = covariance_budget(setup_of(**values, output_step=1.0))
    assert aided.budget.sigma("horizontal_position")[-1] == pytest.approx(free.sigma("horizontal_position")[-1],
                                                                        rel=1e-3)
    free_shares, aided_shares = free.shares(), aided.budget.shares()
    for name in ("gyro_bias_x", "accel_bias_y", "gyro_random_walk", "accel_random_walk"):
        assert aided_shares[name] == pytest.approx(free_shares[name], abs=1e-3)
    assert aided_shares["gnss_position_noise"] == 0.0


def test_the_json_names_each_outage_with_its_sigma_and_shares(run_cli):
    out = run_cli("mission", "run", "examples/mission_tactical_gnss.toml", "--monte-carlo", "2", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert [(o["start_s"], o["duration_s"]) for o in data["outages"]] == [(600.0, 60.0), (1800.0, 60.0),
                                                                         (3000.0, 60.0)]
    for outage in data["outages"]:
        assert set(outage) == {"start_s", "duration_s", "horizontal_error_sigma_m", "shares"}
        assert sum(outage["shares"].values()) == pytest.approx(1.0, abs=1e-12)
    assert data["outage_horizontal_error_sigma_m"] == max(o["horizontal_error_sigma_m"] for o in data["outages"])
    members = data["monte_carlo"]["outages"]
    assert [(o["start_s"], o["duration_s"]) for o in members] == [(o["start_s"], o["duration_s"])
                                                                  for o in data["outages"]]
    for outage, member in zip(data["outages"], members):
        assert member["horizontal_error_sigma_m"] == pytest.approx(outage["horizontal_error_sigma_m"], rel=1e-14)
        assert 0.0 < member["horizontal_error_end_rms_m"] <= member["horizontal_error_max_rms_m"]
        # two members: within a factor of a few of the 1-sigma
        assert 0.1 < member["horizontal_error_end_rms_m"] / outage["horizontal_error_sigma_m"] < 4.0


@pytest.mark.parametrize(("values", "name"), [
    ({"gnss_rate": 0.3}, "gnss_rate"),                      # 3.33 covariance steps between fixes
    ({"covariance_interval": 7.0}, "covariance_interval"),  # 1200 s is no whole number of 7-s steps
    ({"aiding": "gnss-velocty"}, "aiding"),
])
def test_bad_aiding_is_refused_in_one_line(values, name, run_cli):
    with pytest.raises(InvalidParameter) as error:
        SYSTEM.run(**{**SHORT, **values})
    assert error.value.name == name
    options = [part for key, value in {**SHORT, **values}.items() for part in (PARAMETERS[key].option, str(value))]
    out = run_cli("mission", "run", *options)
    assert out.code == 2 and len(out.stderr.strip().splitlines()) == 1, out.stderr


def test_the_monte_carlo_refuses_an_imu_rate_off_the_covariance_grid():
    with pytest.raises(InvalidParameter, match="whole number of IMU intervals"):
        SYSTEM.run(**SHORT, imu_rate=0.3, monte_carlo=1)


SHORTENED = {
    # the examples cut short, their outages and grades kept
    "tactical": ("examples/mission_tactical_gnss.toml", {"duration": 1500.0, "outage_start": 300.0,
                                                           "outage_every": 600.0}),
    "navigation": ("examples/mission_navigation_gnss.toml", {"duration": 2400.0, "outage_start": 1200.0}),
    "consumer": ("examples/mission_consumer_gnss.toml", {"duration": 900.0, "outage_start": 300.0,
                                                           "outage_every": 300.0}),
}


@pytest.mark.slow
@pytest.mark.parametrize("grade", SHORTENED)
def test_the_covariance_is_the_filters_monte_carlo_at_every_outage_end(grade):
    from schuler.study.scenario import load_scenario

    path, shortened = SHORTENED[grade]
    scenario = load_scenario(path)
    members = 300
    result = scenario.definition().run(**{**scenario.given(), **shortened}, monte_carlo=members, seed=5)
    compared = result.to_dict()["monte_carlo"]["outages"]
    assert len(compared) == len(result.outages) >= 1
    # the RMS of 300 horizontal errors (two degrees of freedom) scatters by about 1 / (2 sqrt(300)) = 2.9 %
    for outage in compared:
        ratio = outage["horizontal_error_end_rms_m"] / outage["horizontal_error_sigma_m"]
        assert abs(ratio - 1.0) < 0.10, (grade, outage)
        assert outage["horizontal_error_max_rms_m"] >= outage["horizontal_error_end_rms_m"]


@pytest.mark.parametrize("power", [1.0, 2.0, 3.0])
def test_the_longest_outage_is_exact_on_a_power_law(power):
    durations = np.array([300.0, 3.0, 30.0, 3000.0])  # any order
    sigmas = 0.02 * durations**power
    for bound in (1.0, 10.0, 100.0):
        expected = (bound / 0.02) ** (1.0 / power)
        got = longest_outage(durations, sigmas, bound)
        assert got == (pytest.approx(expected, rel=1e-12) if 3.0 <= expected <= 3000.0
                       else (0.0 if expected < 3.0 else math.inf))


def test_the_survival_table_of_a_sweep_is_the_outage_that_reaches_each_bound(tmp_path):
    import pandas as pd

    from schuler.study.scenario import load_scenario
    from schuler.study.sweep import run_sweep

    scenario = load_scenario("examples/mission_tactical_gnss.toml")
    run_sweep(scenario, tmp_path, ["imu=navigation,tactical", "duration=1500", "outage_start=600",
                                   "outage_duration=10,30,100,300"], progress=False, plots=False)
    frame = pd.read_parquet(tmp_path / "results.parquet")
    table = survival_table(frame)
    assert list(table.index) == ["navigation", "tactical"] and list(table.columns) == ["1 m", "10 m", "100 m"]
    assert np.all(table.loc["navigation"] > table.loc["tactical"])
    # the interpolated outage, run as a case of its own, ends near the bound (log-log between sweep points)
    longest = float(table.loc["tactical", "10 m"])
    assert 30.0 < longest < 100.0
    case = {**scenario.given(), "duration": 1500.0, "outage_start": 600.0, "outage_duration": longest}
    reached = SYSTEM.run(**case).outage_horizontal_error_sigma_m
    assert reached == pytest.approx(10.0, rel=0.1)
    figure = survival_figure(frame)
    assert len(figure.axes[0].lines) == 2 + 3  # a line per grade, one per bound
