"""``errors`` on the contract: parameters, evaluate vs the run in full, fidelities, Monte Carlo, actions, files."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest

from schuler import get_system
from schuler.contract import Cases, monte_carlo
from schuler.core.earth import BOLLAY, FOOT, MEAN_RADIUS, STANDARD_GRAVITY, STATUTE_MILE
from schuler.core.geometry import grid_points, time_grid
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.memory import MemoryBudgetExceeded
from schuler.navigation_errors.actions import (
    PERIOD_PARAMETERS,
    VERTICAL_PARAMETERS,
    period,
    vertical,
)
from schuler.navigation_errors.api import SYSTEM
from schuler.navigation_errors.evaluation import OUTPUTS, PARAMETERS, evaluate
from schuler.navigation_errors.inputs import FLIGHT_TIME
from schuler.navigation_errors.reproduction import plot
from schuler.navigation_errors.single_channel import SOURCES

DEG_PER_H = math.radians(1) / 3600


# --- parameters -------------------------------------------------------------------------------------

def test_misspelt_magnitude_is_refused_with_a_suggestion():
    with pytest.raises(InvalidParameter, match="did you mean 'magnitude'") as error:
        get_system("errors").run(magnitud=0.1)
    assert error.value.name == "magnitud"


def test_renamed_step_is_refused_naming_output_step(run_cli):
    # "step" is too far from "output_step" for a suggestion (difflib ratio 0.53): the rename map names it
    with pytest.raises(InvalidParameter, match="step: renamed to 'output_step'"):
        SYSTEM.run(step=10.0)
    out = run_cli("errors", "run", "--step", "10")
    assert out.code == 2
    assert out.stderr.strip() == "schuler: error: --step: renamed to '--output-step' (see CHANGELOG.md)"


def test_magnitude_takes_si_numbers_and_text_in_the_source_unit():
    assert SYSTEM.case(source="drift", magnitude=1e-7)["magnitude"] == 1e-7
    assert SYSTEM.case(source="drift", magnitude="0.01")["magnitude"] == pytest.approx(0.01 * DEG_PER_H, rel=1e-12)
    assert SYSTEM.case(source="tilt", magnitude="36 arcsec")["magnitude"] == pytest.approx(math.radians(0.01))
    assert SYSTEM.case(source="velocity", magnitude="1")["magnitude"] == pytest.approx(FOOT)  # ft/s
    # as written in a scenario or on the command line: converted with the case's source
    parsed = PARAMETERS.parse({"source": "accelerometer", "magnitude": 1e-4})
    assert parsed["magnitude"] == pytest.approx(1e-4 * STANDARD_GRAVITY, rel=1e-12)
    assert SYSTEM.case()["magnitude"] is None  # not given: each source's Problem 3 value


@pytest.mark.parametrize("kwargs, reason", [
    ({"magnitude": "1 ft/s", "source": "tilt"}, "is not an angle"),
    ({"magnitude": -1e-8}, "must be finite and >= 0"),
    ({"magnitude": "-0.01"}, "must be finite and >= 0"),
    ({"magnitude": math.nan}, "must be finite and >= 0"),
    ({"magnitude": "lots"}, "cannot read 'lots' as a magnitude"),
    ({"magnitude": True}, "is not a number"),
    ({"source": "gyro"}, "is not one of"),
    ({"duration": 0.0}, "is outside"),
    ({"speed": -1.0}, "is outside"),
    ({"magnitude": "100", "source": "tilt"}, "more than 10 deg, the largest tilt error"),
    ({"magnitude": 1.0, "source": "drift"}, "more than 3600 deg/h"),
    ({"radius": 1.0}, "is outside"),
])
def test_bad_values_are_refused_naming_the_parameter(kwargs, reason):
    with pytest.raises(InvalidParameter, match=reason) as error:
        SYSTEM.run(**kwargs)
    assert error.value.name == next(iter(kwargs))


def test_speed_default_is_half_a_statute_mile_per_second():
    assert SYSTEM.case()["speed"] == pytest.approx(0.5 * STATUTE_MILE, rel=1e-12)
    assert PARAMETERS.parse({"speed": "800"})["speed"] == 800.0  # bare numbers: m/s
    assert PARAMETERS.parse({"speed": "0.5 mi/s"})["speed"] == pytest.approx(804.672, rel=1e-12)


def test_output_step_longer_than_the_duration_is_refused():
    with pytest.raises(InvalidParameter, match="longer than the duration") as error:
        SYSTEM.run(duration=100.0, output_step=200.0)
    assert error.value.name == "output_step"


def test_time_grid_ends_on_the_duration():
    assert time_grid(100.0, 30.0).tolist() == [0.0, 30.0, 60.0, 90.0, 100.0]
    assert time_grid(0.3, 0.1)[-1] == 0.3 and time_grid(0.3, 0.1).size == 4  # 0.3 / 0.1 = 2.9999999999999996
    assert grid_points(np.array([10.0, 10.5]), 1.0).tolist() == [11, 12]


# --- evaluate, the run in full, fidelities ------------------------------------------------------------------

CASES = [
    {"source": "tilt", "duration": 5000.0, "earth": "bollay"},
    {"source": "velocity", "magnitude": 0.5, "duration": 7000.0, "output_step": 35.0},
    {"source": "accelerometer", "magnitude": 2e-3, "duration": 9000.0, "earth": "drozdovich"},
    {"source": "drift", "duration": 3600.0, "earth": "bollay", "radius": 6.4e6},
    {"source": "azimuth", "duration": FLIGHT_TIME, "speed": 2000.0, "gravity": 9.81},
    {"source": "drift", "magnitude": 2 * 0.01 * DEG_PER_H, "duration": 20_000.0, "output_step": 7.0},
]


@pytest.mark.parametrize("fidelity", ["simulated", "closed"])
def test_evaluate_equals_the_run_in_full_case_by_case(fidelity):
    cases = [SYSTEM.case(**values) for values in CASES]
    batch = Cases({name: np.array([case[name] for case in cases], dtype=object
                                  if any(isinstance(case[name], str) or case[name] is None for case in cases)
                                  else float) for name in PARAMETERS.names}, fidelity=fidelity)
    out = evaluate(batch)
    for k, case in enumerate(cases):
        single = SYSTEM.result(case, fidelity).to_dict()
        for output in OUTPUTS:
            if math.isnan(out[output.name][k]):
                assert single[output.name] is None and fidelity == "closed"
            else:
                assert single[output.name] == pytest.approx(out[output.name][k], rel=1e-12, abs=1e-300)


@pytest.mark.parametrize("source", SOURCES)
def test_simulated_and_closed_fidelities_agree_to_rounding(source):
    simulated = SYSTEM.run(source=source, earth="bollay", duration=7777.0)
    closed = SYSTEM.run(source=source, earth="bollay", duration=7777.0, fidelity="closed")
    # exact matrix exponential: rounding only, relative to the largest error of the run
    assert simulated.final_spherical_m == pytest.approx(closed.final_spherical_m, abs=1e-9 * closed.max_spherical_m)
    assert simulated.simulation_minus_closed_m <= 1e-9 * closed.max_spherical_m
    assert math.isnan(closed.simulation_minus_closed_m)
    assert "simulated_m" not in closed.histories[f"errors_run_{source}"]
    assert closed.to_dict()["simulation_minus_closed_m"] is None
    assert simulated.fidelity == "simulated" and closed.fidelity == "closed"


def test_evaluate_warns_once_for_the_worst_group_that_lost_its_accuracy():
    # the drift source on a 1-km Earth: 0.5-0.9 of the error at 1e9 s (by the libraries' rounding), 4.6e-3 at 1e8 s;
    # the default Earth agrees; the one warning names the worst group
    from schuler.navigation_errors.evaluation import SIMULATION_TOLERANCE
    from schuler.navigation_errors.results import SimulationAccuracyWarning

    cases = [PARAMETERS.case(source="drift", radius=1e3, gravity=1e3, duration=d) for d in (1e8, 1e9)]
    cases.append(PARAMETERS.case(source="drift", radius=MEAN_RADIUS, gravity=STANDARD_GRAVITY, duration=1e8))
    text = ("source", "earth", "magnitude")
    cases = Cases({name: np.array([case[name] for case in cases], dtype=object if name in text else float)
                   for name in PARAMETERS.names}, fidelity="simulated")
    with pytest.warns(SimulationAccuracyWarning) as caught:
        out = evaluate(cases)
    relative = out["simulation_minus_closed_m"] / out["max_spherical_m"]
    assert len(caught) == 1 and f"by {relative[1]:.2g} of" in str(caught[0].message) and relative[1] > 0.1
    # the default Earth over 1e8 s (1.8e4 periods): 1e-11 to 1e-9 of the error by the libraries, well inside 1e-6
    assert np.all(relative[:2] > SIMULATION_TOLERANCE) and relative[2] < SIMULATION_TOLERANCE / 100


def test_unknown_fidelity_is_refused():
    with pytest.raises(InvalidParameter, match="choose from simulated, closed"):
        SYSTEM.run(fidelity="rough")


def test_run_bollay_velocity_case_and_its_histories():
    result = SYSTEM.run(source="velocity", magnitude=FOOT, duration=FLIGHT_TIME, output_step=10.0, earth="bollay")
    assert result.schuler_period_s == pytest.approx(5060.0, rel=1e-12)
    assert result.max_spherical_m / FOOT == pytest.approx(805.32, abs=0.01)  # Bollay, Problem 3: 805 ft
    histories = result.histories["errors_run_velocity"]
    assert histories.time[-1] == FLIGHT_TIME and histories.time.size == 1013
    np.testing.assert_allclose(histories["simulated_m"], histories["spherical_m"], rtol=0,
                               atol=1e-9 * result.max_spherical_m)
    assert result.final_flat_m / FOOT == pytest.approx(10_120, rel=1e-12)  # Delta_V t
    assert result.to_dict()["units"] == {**{output.name: output.unit for output in OUTPUTS}, "magnitude": "m/s"}
    assert "t_s" not in result.to_dict()  # histories go to the CSV of --out, not to JSON


def test_largest_spherical_error_bounds_the_sampled_history():
    for source in SOURCES:
        result = SYSTEM.run(source=source, duration=30_000.0, output_step=15.0)
        spherical = result.histories[f"errors_run_{source}"]["spherical_m"]
        assert np.max(np.abs(spherical)) <= result.max_spherical_m * (1 + 1e-12)
        assert np.max(np.abs(spherical)) == pytest.approx(result.max_spherical_m, rel=1e-4)


def test_a_sweep_over_sources_takes_each_source_default():
    out = SYSTEM.evaluate_values({"source": np.array(list(SOURCES), dtype=object),
                                  "earth": np.array(["bollay"] * 5, dtype=object)})
    # Bollay, Problem 3 at 10,120 s (the loop's g for the accelerometer: 1e-4 x 9.80665 here, 4,170 ft printed)
    assert out["final_flat_m"][1] / FOOT == pytest.approx(10_120, rel=1e-12)
    assert out["max_spherical_m"][1] / FOOT == pytest.approx(805.3, abs=0.05)
    assert out["final_spherical_m"][3] / FOOT == pytest.approx(10_258.5, abs=0.1)


def test_one_si_magnitude_swept_over_sources_of_different_units_is_refused():
    # a scenario's "0.01 deg/h" (rad/s) swept over source=tilt,drift would be 4.8e-8 rad of tilt
    with pytest.raises(InvalidParameter, match="one value .* for sources of different units") as error:
        SYSTEM.evaluate_values({"source": np.array(["tilt", "drift"], dtype=object), "magnitude": 0.01 * DEG_PER_H})
    assert error.value.name == "magnitude"
    # written as text (an object or a string array, as a sweep axis gives), each case reads it in its source's unit
    same = SYSTEM.evaluate_values({"source": np.array(["tilt", "drift"], dtype=object)})  # Problem 3 values
    for text in (np.array(["0.01", "0.01"], dtype=object), np.array(["0.01", "0.01"])):
        out = SYSTEM.evaluate_values({"source": np.array(["tilt", "drift"], dtype=object), "magnitude": text})
        np.testing.assert_allclose(out["max_spherical_m"], same["max_spherical_m"], rtol=1e-12)
    # the same source: one number is fine
    assert np.isfinite(SYSTEM.evaluate_values({"source": np.array(["tilt", "azimuth"], dtype=object),
                                               "magnitude": 1e-4})["final_flat_m"]).all()


def test_evaluate_is_independent_of_how_the_batch_is_cut():
    rng = np.random.default_rng(5)
    n = 40
    values = {name: np.asarray(column) for name, column in {
        "source": rng.choice(np.array(SOURCES, dtype=object), n),
        "magnitude": rng.uniform(0.0, 1e-3, n),
        "duration": rng.choice([3000.0, 5060.0, 12_345.0], n),
        "speed": rng.choice([100.0, 800.0], n),
    }.items()}
    whole = SYSTEM.evaluate_values(values)
    parts = [SYSTEM.evaluate_values({k: v[lo:lo + 7] for k, v in values.items()}) for lo in range(0, n, 7)]
    for name in whole:
        np.testing.assert_allclose(np.concatenate([p[name] for p in parts]), whole[name], rtol=1e-12, atol=0)


def test_monte_carlo_over_a_drawn_duration_is_independent_of_chunking():
    case = SYSTEM.case(source="drift", earth="bollay")
    streams = RandomStreams(3)

    def draw(members):
        return {"duration": FLIGHT_TIME + 100.0 * streams.normal("duration", members)}

    summaries = [monte_carlo(SYSTEM.evaluate, SYSTEM.outputs, case, 23, streams, chunk=chunk, draw=draw)
                 for chunk in (4, 23)]
    for name, stats in summaries[0].statistics.items():
        for key, value in dataclasses.asdict(stats).items():
            other = getattr(summaries[1][name], key)
            # a streamed std (and rms) rounds at about 1e-16 of the mean: compare it on the mean's scale
            scale = 1e-12 * abs(stats.mean) if key in ("std", "rms") else 1e-300
            assert value == pytest.approx(other, rel=1e-12, abs=scale), (name, key)
    # 23 members: the mean drift error is near the nominal R epsilon t (sigma 100 s of 10,120 s)
    mean = summaries[0].statistics["final_spherical_m"]["mean"] / FOOT
    assert mean == pytest.approx(10_258.5, rel=0.01)


def test_a_monte_carlo_needs_random_terms_or_drawn_parameters():
    # errors has no random terms of its own: N nominal members would be N copies, so it is refused ...
    with pytest.raises(InvalidParameter, match="monte_carlo: errors has no random terms"):
        SYSTEM.run(monte_carlo=5, seed=1, source="tilt")
    # ... unless parameters are drawn per member (a scenario's [monte_carlo] tables)
    result = SYSTEM.run(monte_carlo=5, seed=1, source="tilt",
                        draw=lambda members: {"duration": 3600.0 + 60.0 * members.astype(float)})
    stats = result.monte_carlo["final_spherical_m"]
    assert stats.count == 5 and stats.std > 0


def test_memory_is_refused_before_allocating(monkeypatch):
    monkeypatch.setenv("SCHULER_MEMORY_BUDGET", "64 MiB")
    with pytest.raises(MemoryBudgetExceeded, match="`duration` or `output_step`"):
        SYSTEM.run(duration=1e9, output_step=1e-3)
    # the closed fidelity evaluates without a grid: a sweep of such cases stays small
    out = SYSTEM.evaluate_values({"duration": 1e9, "output_step": 1e-3}, fidelity="closed")
    assert np.isfinite(out["final_spherical_m"]).all()
    with pytest.raises(MemoryBudgetExceeded):
        vertical(**VERTICAL_PARAMETERS.case(duration=1e5, output_step=1e-3))


# --- actions -----------------------------------------------------------------------------------------

def test_vertical_gains_from_tau_and_explicit_ones():
    result = vertical(**VERTICAL_PARAMETERS.case(order=2, time_constant=50.0))
    assert result.k1_per_s == pytest.approx(0.04)  # 2 / tau
    assert result.final_aided_m == pytest.approx(result.aided_steady_state_m, rel=1e-6)
    explicit = vertical(**VERTICAL_PARAMETERS.case(order=2, k1=0.05))
    # k2 from the default tau = 100 s: 1 / tau^2 + 2 g / R
    assert explicit.k1_per_s == 0.05
    assert explicit.k2_per_s2 == pytest.approx(1 / 100.0**2 + 2 * STANDARD_GRAVITY / MEAN_RADIUS, rel=1e-12)


@pytest.mark.parametrize("kwargs, name", [
    ({"time_constant": 50.0, "k1": 0.1}, "time_constant"),
    ({"order": 2, "k3": 1e-6}, "k3"),
    ({"k2": 1e-7}, "k2"),
    ({"order": 4}, "order"),
    ({"accel_bias_up": 1.0}, "accel_bias_up"),
    ({"duration": 1e5, "radius": 1e3, "gravity": 1e3}, "duration"),
])
def test_vertical_refuses_conflicting_or_unstable_options(kwargs, name):
    # a divergent run is refused before its numbers overflow: exp(sqrt(2) omega_s t) <= exp(200)
    with pytest.raises(InvalidParameter) as error:
        vertical(**VERTICAL_PARAMETERS.case(**kwargs))
    assert error.value.name == name


def test_problem4_hover_error_through_the_action():
    result = vertical(**VERTICAL_PARAMETERS.case(earth="bollay", accel_bias_up=-1e-4 * BOLLAY.effective_gravity,
                                                 duration=BOLLAY.schuler_period))
    # Bollay, Problem 4: 724 mi printed; 715.4 mi with z(0) = z'(0) = 0 (erratum)
    assert -result.final_closed_form_m / STATUTE_MILE == pytest.approx(715.4085, abs=1e-3)
    assert result.final_unaided_m == pytest.approx(result.final_closed_form_m, rel=1e-9)


def test_period_warns_at_orbital_speed():
    with pytest.warns(UserWarning, match="orbital speed"):
        result = period(**PERIOD_PARAMETERS.case(speed=8000.0))
    assert math.isinf(result.flight_period_s) and result.to_dict()["flight_period_s"] is None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        nine = period(**PERIOD_PARAMETERS.case(thrust_factor=9.0))
    assert nine.thrust_period_s / 60 == pytest.approx(28.1, abs=0.05)  # Bollay's footnote: 84/3 = 28 min


def test_plot_action_summarises_problem3():
    result = plot(points=101)
    assert result.max_spherical_m["tilt"] / FOOT == pytest.approx(7298.6, abs=0.1)
    assert result.largest_simulation_minus_closed_m < 1e-6
    assert result.curves.t_s.size == 101


# --- files ---------------------------------------------------------------------------------------------

def test_run_as_a_python_result():
    import matplotlib.pyplot as plt
    import pandas as pd

    result = SYSTEM.run(source="tilt", duration=3600.0)
    frame = result.to_dataframe()
    assert isinstance(frame, pd.DataFrame) and list(frame.columns) == ["flat_m", "spherical_m", "simulated_m"]
    assert frame.index.name == "t_s" and frame["spherical_m"].iloc[-1] == pytest.approx(
        result.histories["errors_run_tilt"]["spherical_m"][-1])
    figure = result.plot()
    assert isinstance(figure, plt.Figure)
    plt.close(figure)
    assert "Schuler period" in result._repr_html_()
    data = result.to_dict()
    evaluated = SYSTEM.evaluate_values({"source": "tilt", "duration": 3600.0})
    for output in OUTPUTS:
        assert data[output.name] == pytest.approx(float(evaluated[output.name][0]), rel=1e-12)
    assert data["source"] == "tilt" and data["warnings"] == []


@pytest.mark.slow
def test_files_of_every_command(tmp_path):
    import pandas as pd

    results = {
        "run": (SYSTEM.run(source="azimuth", duration=3600.0), None),
        "vertical": (SYSTEM.action("vertical")(**VERTICAL_PARAMETERS.case(duration=1000.0)), "vertical"),
        "period": (SYSTEM.action("period")(**PERIOD_PARAMETERS.case(speed=3000.0)), "period"),
        "three-d": (SYSTEM.action("three-d")(**SYSTEM.actions[3].parameters.case(duration=3600.0)), "three-d"),
        "reproduce": (SYSTEM.reproduce(), None),
        "plot": (SYSTEM.action("plot")(points=11), "plot"),
    }
    problem3 = ({f"errors_{stem}.{ext}" for stem in (*SOURCES, "overview", "vertical") for ext in ("png", "svg")}
                | {"errors_problem3.csv", "errors_problem4.csv"})
    expected = {
        "run": {"errors_run_azimuth.png", "errors_run_azimuth.svg", "errors_run_azimuth.csv"},
        "vertical": {"errors_vertical_run.png", "errors_vertical_run.svg", "errors_vertical_run.csv"},
        "period": {"errors_period.png", "errors_period.svg", "errors_period.csv"},
        "three-d": {"errors_three_d.png", "errors_three_d.svg", "errors_three_d_track.png",
                    "errors_three_d_track.svg", "errors_three_d.csv"},
        "reproduce": problem3,
        "plot": problem3,
    }
    for name, (result, action) in results.items():
        folder = tmp_path / name
        paths = SYSTEM.write(result, folder, action)
        assert {p.name for p in paths} == expected[name] == {p.name for p in folder.iterdir()}
    run = pd.read_csv(tmp_path / "run" / "errors_run_azimuth.csv")
    assert list(run.columns) == ["t_s", "flat_m", "spherical_m", "simulated_m"]
    assert run["spherical_m"].iloc[-1] == pytest.approx(results["run"][0].final_spherical_m, rel=1e-12)
    three_d = pd.read_csv(tmp_path / "three-d" / "errors_three_d.csv")
    assert three_d.columns[0] == "t_s" and "attitude_error_north_rad" in three_d.columns
    assert pd.read_csv(tmp_path / "plot" / "errors_problem3.csv").shape[0] == 11
    assert SYSTEM.figures(object()) == {} and SYSTEM.data_files(object(), tmp_path) == []
