"""The drift calibration on the contract: parameters, evaluate, run, Monte Carlo, observability, reproduction.

Source: the alternating-pulse calibration article (schuler.references.PULSE_CALIBRATION).
Monte Carlo tests name their members and seeds; each tolerance is a stated number of
standard errors of the estimate it checks.
"""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.contract import Cases
from schuler.core.earth import EARTH_RATE
from schuler.core.random import RandomStreams
from schuler.drift_calibration.api import SYSTEM
from schuler.drift_calibration.error_budget import TYPICAL
from schuler.drift_calibration.evaluation import (
    BUDGET_TERMS,
    PARAMETERS,
    AzimuthAccuracyWarning,
)
from schuler.drift_calibration.reproduction import reproduce
from schuler.exceptions import InvalidParameter, NotObservable
from schuler.memory import MemoryBudgetExceeded

DEG_H = math.radians(1.0) / 3600.0
ARCMIN = math.radians(1.0) / 60.0
ARCSEC = ARCMIN / 60.0
NO_BUDGET = {name: 0.0 for name in BUDGET_TERMS}
"""Every random term off (a Monte Carlo member then equals the nominal case)."""


def budget(**on):
    """Only the named random terms, the others zero (SI)."""
    return {**NO_BUDGET, **on}


def mc(members: int, seed: int = 0, **si_values):
    """Monte Carlo statistics of the system at one case."""
    return SYSTEM.monte_carlo(SYSTEM.case(**si_values), members, RandomStreams(seed)).statistics


# --- parameters ------------------------------------------------------------------------------------


def test_budget_defaults_are_the_documented_typical_budget():
    # the parameters' display defaults and error_budget.TYPICAL (SI) say the same, to rounding of units
    defaults = PARAMETERS.defaults()
    for name, term in BUDGET_TERMS.items():
        assert defaults[name] == pytest.approx(getattr(TYPICAL, term), rel=1e-12), name
    assert defaults["sway_frequency"] == TYPICAL.sway_frequency


@pytest.mark.parametrize(("wrong", "suggested"), [("latitud", "latitude"), ("pulse_duraton", "pulse_duration"),
                                                 ("drift_yy", "drift_y")])
def test_misspelt_or_old_names_are_refused_with_a_suggestion(wrong, suggested):
    with pytest.raises(InvalidParameter, match=f"did you mean '{suggested}'"):
        SYSTEM.run(**{wrong: 0.1})


def test_renamed_parameters_and_run_options_are_refused():
    for old, new in (("drift", "drift_x"), ("tau", "pulse_duration"), ("k1", "sensor_gain"),
                     ("sensor_noise", "sensor_noise_density"), ("turn_angle_error", "sigma_turn_angle")):
        with pytest.raises(InvalidParameter, match=f"{old}: renamed to '{new}'"):
            SYSTEM.run(**{old: 1.0})
    # Monte Carlo count and seed are options of every run, not parameters of the case
    with pytest.raises(InvalidParameter, match="monte_carlo"):
        SYSTEM.case(monte_carlo=10)
    with pytest.raises(InvalidParameter, match="fidelity"):
        SYSTEM.run(fidelity="closed")  # one way of evaluating: a simulation of every cycle


def test_out_of_range_values_are_refused_naming_the_parameter():
    with pytest.raises(InvalidParameter, match="latitude"):
        SYSTEM.run(latitude=2.0)  # radians: 114.6 deg
    with pytest.raises(InvalidParameter, match="positions"):
        SYSTEM.run(positions=1)
    with pytest.raises(InvalidParameter, match="pulse_duration"):
        SYSTEM.run(pulse_duration=0.0)
    with pytest.raises(InvalidParameter, match="sigma_sensor_scale"):
        SYSTEM.run(sigma_sensor_scale=-1e-4)


def test_memory_is_refused_before_allocating(monkeypatch):
    monkeypatch.setenv("SCHULER_MEMORY_BUDGET", "100 MB")
    # 2 channels x 360 positions x 1000 cycles of 41-point grids: about 19 GB for one procedure
    with pytest.raises(MemoryBudgetExceeded, match="`positions` or `cycles`"):
        SYSTEM.run(positions=360, cycles=1000)


# --- evaluate and run ------------------------------------------------------------------------------

CASES = [
    {},
    {"mode": "single-axis", "azimuth": math.radians(130.0), "positions": 3},
    {"pulse_shape": "triangular", "loop_time_constant": 0.002, "drift_y": -0.3 * DEG_H, "cycles": 2},
    {"latitude": math.radians(-40.0), "azimuth": math.radians(300.0), "pulse_duration": 2.0, "positions": 4},
]


@pytest.mark.parametrize("values", CASES, ids=range(len(CASES)))
def test_run_equals_evaluate_per_case(values):
    # run_case's numbers are those of evaluate on a batch of copies of the case (the nominal case)
    single = SYSTEM.run(**values).to_dict()
    batch = SYSTEM.evaluate_values({name: np.full(3, value, dtype=object if isinstance(value, str) else float)
                                    for name, value in values.items()})
    for output in SYSTEM.outputs:
        for computed in batch[output.name]:
            expected = single[output.name]
            if expected is None:
                assert math.isnan(computed), output.name
            else:
                # bitwise in practice (no product depends on the batch size); 1e-9 is the contract's tolerance
                assert float(computed) == pytest.approx(float(expected), rel=1e-9, abs=0.0), output.name


def test_error_free_procedure_recovers_what_went_in():
    out = SYSTEM.evaluate_values({"latitude": np.radians([10.0, 40.0, 70.0, -60.0]),
                                  "azimuth": np.radians([5.0, 95.0, 185.0, 275.0]),
                                  "drift_x": np.array([1, 2, 3, 4]) * DEG_H})
    # rounding only: the rates are recovered to 1e-9 relative, the azimuth to 1e-12 rad
    np.testing.assert_allclose(out["azimuth_rad"], np.radians([5.0, 95.0, 185.0, 275.0]), rtol=1e-9)
    np.testing.assert_allclose(out["drift_x_rad_s"], np.array([1, 2, 3, 4]) * DEG_H, rtol=1e-9)
    np.testing.assert_allclose(out["relative_drift_error"], 0.0, atol=1e-8)
    assert np.all(np.abs(out["azimuth_error_rad"]) < 1e-12)


@settings(max_examples=25, deadline=None)
@given(latitude=st.floats(-85, 85), azimuth=st.floats(-360, 360), drift_x=st.floats(-10, 10),
       drift_y=st.floats(-10, 10), mode=st.sampled_from(["three-axis", "single-axis"]), positions=st.integers(2, 5))
def test_nominal_procedure_recovers_drifts_and_azimuth(latitude, azimuth, drift_x, drift_y, mode, positions):
    # invariant: without errors (15)/(16) or the least-squares fit give back the drifts and atan2 (or the
    # asin branch nearer the truth) the azimuth, for any site and drifts below the horizontal Earth rate's size
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AzimuthAccuracyWarning)
        r = SYSTEM.run(latitude=math.radians(latitude), azimuth=math.radians(azimuth), drift_x=drift_x * DEG_H,
                       drift_y=drift_y * DEG_H, mode=mode, positions=positions)
    scale = EARTH_RATE * math.cos(math.radians(latitude))
    assert abs(r.drift_x_error_rad_s) < 1e-9 * (scale + abs(drift_x) * DEG_H)
    # an rate error e maps into at most e / (Omega cos(phi) |cos A0|) of azimuth (asin), 1e-9 relative rounding
    assert abs(r.azimuth_error_rad) < 1e-6


def test_single_axis_leaves_y_unmeasured_and_relative_error_undefined_for_zero_drift():
    r = SYSTEM.run(mode="single-axis", drift_x=0.0)
    data = r.to_dict()
    assert data["drift_y_rad_s"] is None and data["drift_y_error_rad_s"] is None
    assert data["relative_drift_error"] is None  # |error| / 0: not a number, null in JSON
    assert data["true_drift_y_rad_s"] == 0.0


def test_render_labels_estimates_and_truths():
    text = str(SYSTEM.run(drift_x=0.25 * DEG_H, monte_carlo=50))
    assert "estimated drift X" in text and "true drift X" in text
    assert "estimated azimuth A0" in text and "true azimuth A0" in text
    assert "0.250000 deg/h" in text and "-0.0000" not in text
    assert "Monte Carlo (50 members, seed 0)" in text


# --- Monte Carlo: chunking, published closed forms, error growth -----------------------------------


def test_monte_carlo_is_independent_of_chunking():
    case = SYSTEM.case(mode="single-axis", positions=3, loop_time_constant=0.002)
    members = np.arange(37)
    whole = SYSTEM.evaluate(Cases.from_case(case, members.size, members=members, random=RandomStreams(9)))
    for cut in (1, 5, 36):
        first = SYSTEM.evaluate(Cases.from_case(case, cut, members=members[:cut], random=RandomStreams(9)))
        rest = SYSTEM.evaluate(Cases.from_case(case, members.size - cut, members=members[cut:],
                                               random=RandomStreams(9)))
        for name, values in whole.items():
            np.testing.assert_allclose(np.concatenate([first[name], rest[name]]), values, rtol=1e-12, atol=0)
    statistics = [SYSTEM.monte_carlo(case, 50, RandomStreams(2)).statistics for _ in range(2)]
    assert statistics[0] == statistics[1]


def test_nominal_case_has_no_random_terms_and_members_do():
    nominal = SYSTEM.evaluate(Cases.from_case(SYSTEM.case(), 2))
    drawn = SYSTEM.evaluate(Cases.from_case(SYSTEM.case(), 2, random=RandomStreams(0)))
    assert np.all(np.abs(nominal["azimuth_error_rad"]) < 1e-12)
    assert np.all(np.abs(drawn["azimuth_error_rad"]) > 1e-7)
    assert drawn["azimuth_error_rad"][0] != drawn["azimuth_error_rad"][1]
    switched_off = SYSTEM.evaluate_values({name: np.zeros(2) for name in NO_BUDGET}, members=np.arange(2),
                                          random=RandomStreams(0))
    assert np.all(np.abs(switched_off["azimuth_error_rad"]) < 1e-12)


def test_latitude_error_affects_only_single_axis():
    sigma = TYPICAL.latitude_error
    three = mc(200, **budget(sigma_latitude=sigma), drift_x=DEG_H)
    single = mc(200, **budget(sigma_latitude=sigma), drift_x=DEG_H, mode="single-axis")
    assert three["azimuth_error_rad"]["rms"] < 1e-12  # atan2 ignores the latitude: rounding only
    # asin: dA = tan(phi) tan(A0) dphi; 200 members: the RMS within 15 % (3 standard errors of 5 %)
    expected = math.tan(math.radians(70)) * math.tan(math.radians(80)) * sigma
    assert single["azimuth_error_rad"]["rms"] == pytest.approx(expected, rel=0.15)


def test_monte_carlo_sensor_noise_matches_closed_form_and_converges():
    """Sensor noise only: RMS drift error = N sqrt(2 tau) / (sqrt(2) tau^2) (two runs averaged by (15))."""
    density, tau = 1e-6, 5.0
    expected = density * math.sqrt(2 * tau) / tau**2 / math.sqrt(2)
    deviations = []
    for members in (250, 4000):
        stats = mc(members, seed=3, **budget(sensor_noise_density=density), drift_x=DEG_H)
        rms = math.sqrt((stats["drift_x_error_rad_s"]["rms"] ** 2 + stats["drift_y_error_rad_s"]["rms"] ** 2) / 2)
        deviations.append(abs(rms / expected - 1))
        # 2 channels x members samples: 4 standard errors of an RMS
        assert deviations[-1] < 4.0 / math.sqrt(2 * members * 2)
    assert deviations[1] < 0.05


@pytest.mark.parametrize(("option", "value"), [("positions", 8), ("cycles", 4)])
def test_more_positions_or_cycles_reduce_the_error(option, value):
    # angle random walk only: independent cycle noise averages as 1/sqrt(N); 600 members, 20 % (4 standard errors)
    walk = budget(angle_random_walk=TYPICAL.angle_random_walk)
    one = mc(600, seed=1, **walk, drift_x=DEG_H)["azimuth_error_rad"]["rms"]
    more = mc(600, seed=1, **walk, drift_x=DEG_H, **{option: value})["azimuth_error_rad"]["rms"]
    assert more == pytest.approx(one / 2.0, rel=0.2)


# --- near the pole (issue 13, item 10) -------------------------------------------------------------


def test_beyond_the_latitude_limit_the_azimuth_is_not_observable():
    with pytest.raises(NotObservable, match=r"latitude: 89.99 deg is beyond the azimuth limit 85 deg"):
        SYSTEM.run(latitude=math.radians(89.99))
    with pytest.raises(NotObservable, match="max_latitude"):
        SYSTEM.evaluate_values({"latitude": np.radians([10.0, 86.0])})
    with pytest.warns(AzimuthAccuracyWarning, match="latitude 87 deg: azimuth accuracy degrades"):
        allowed = SYSTEM.run(latitude=math.radians(87.0), max_latitude=math.radians(88.0))
    assert abs(allowed.azimuth_error_rad) < 1e-9  # the error-free procedure still works there
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        SYSTEM.run(latitude=math.radians(70.0))  # the source's case: no warning


def test_azimuth_error_grows_as_one_over_cos_latitude():
    # the same draws at 40 and 80 deg (sensor noise only, which does not couple to the latitude):
    # the azimuth errors scale by cos 40 / cos 80 = 4.41, to the small-angle linearisation (1e-3)
    noise = budget(sensor_noise_density=TYPICAL.sensor_noise_density)
    low = mc(300, seed=4, **noise, latitude=math.radians(40.0))["azimuth_error_rad"]["rms"]
    with pytest.warns(AzimuthAccuracyWarning):
        high = mc(300, seed=4, **noise, latitude=math.radians(80.0))["azimuth_error_rad"]["rms"]
    assert high / low == pytest.approx(math.cos(math.radians(40.0)) / math.cos(math.radians(80.0)), rel=1e-3)


# --- reproduction ----------------------------------------------------------------------------------


def test_reproduction_rows_and_verdicts():
    r = reproduce(monte_carlo=500)
    rows = {row.quantity: row for row in r.rows}
    assert not r.failures and not [row for row in r.rows if row.verdict.startswith("differs")]
    azimuth = rows["RMS azimuth error, modelled three-axis case, scaled budget"]
    # the budget scale makes it 2 arcmin; only the atan2's nonlinearity and the kept loop lag remain (0.1 %)
    assert azimuth.printed == "2 угловые минуты" and azimuth.computed == pytest.approx(2.0, rel=1e-3)
    assert azimuth.verdict == "tuned to match within 1 %" and "scaled by 0.1" in azimuth.note
    drift = rows["mean relative drift error, modelled three-axis case, scaled budget"]
    assert drift.printed == "0,34%" and drift.verdict == "tuned to match within 2 %"
    assert "deg/h chosen" in drift.note
    cycle = rows["measurement cycle 2 tau (single-axis experiments)"]
    assert (cycle.printed, cycle.computed, cycle.verdict) == ("от 8 с до 15 с", 10.0, "tuned to match within 3.5 s")
    assert rows["budget scale giving 2 arcmin"].verdict == "not printed in the source"
    # one channel (asin) at A0 = 80 deg: errors magnified 1/cos(80 deg) = 5.8 times, plus the latitude error
    assert rows["RMS azimuth error, single-axis (asin), scaled budget"].computed > 3 * 2.0
    # the budget scale is about 0.18-0.19 of the typical budget, the chosen drift about 0.7 deg/h
    assert 0.15 < r.details["budget_scale"] < 0.25
    assert 0.5 < r.details["drift_rad_s"] / DEG_H < 1.0


def test_budget_scale_is_linear():
    # the reproduction's premise: every term is linear in the budget (the 2 ms loop lag is compensated)
    typical = {name: getattr(TYPICAL, term) for name, term in BUDGET_TERMS.items()}
    half = {name: value / 2 for name, value in typical.items()}
    full = mc(200, seed=6, **typical, loop_time_constant=0.002)["azimuth_error_rad"]["rms"]
    halved = mc(200, seed=6, **half, loop_time_constant=0.002)["azimuth_error_rad"]["rms"]
    assert halved == pytest.approx(full / 2, rel=1e-3)


def test_run_with_monte_carlo_attaches_statistics():
    r = SYSTEM.run(monte_carlo=100, seed=1)
    assert r.monte_carlo.members == 100 and r.monte_carlo.seed == 1
    again = dataclasses.replace(r, monte_carlo=None)
    assert again.azimuth_rad == r.azimuth_rad
    assert r.monte_carlo.statistics["cycle_time_s"]["std"] == 0.0


@pytest.mark.slow
def test_report_writes_its_figures(tmp_path):
    section = SYSTEM.report(tmp_path)
    assert section.system == "calibrate" and len(section.rows) == 8 and len(section.figures) == 3
    assert not [row for row in section.rows if row.verdict.startswith("differs")]
    for figure in section.figures:
        assert (tmp_path / figure.path).stat().st_size > 10_000
        assert (tmp_path / figure.path).with_suffix(".svg").exists()
    assert any("--drift-x" in command for command in section.commands)


def test_run_result_reads_as_a_table_a_figure_html_and_json():
    import matplotlib.pyplot as plt
    import pandas as pd

    r = SYSTEM.run(drift_x=0.25 * DEG_H, monte_carlo=30)
    frame = r.to_dataframe()
    assert isinstance(frame, pd.DataFrame) and frame.index.name == "t_s"
    assert list(frame.columns) == ["platform_angle_rad", "sensor_signal_V", "integrator_output_V_s"]
    figure = r.plot()
    assert isinstance(figure, plt.Figure) and set(r.figures()) == {"calibrate_cycle", "calibrate_monte_carlo"}
    plt.close("all")
    assert "<pre" in r._repr_html_() and "estimated drift X" in r._repr_html_()
    data = r.to_dict()
    assert data["drift_x_rad_s"] == pytest.approx(0.25 * DEG_H, rel=1e-9) and data["mode"] == "three-axis"
    assert data["true_azimuth_rad"] == pytest.approx(math.radians(80.0)) and data["units"]["positions"] == "1"
    stats = r.monte_carlo["azimuth_error_rad"]
    assert stats.count == 30 and stats.std > 0
