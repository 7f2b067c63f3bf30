"""The lab's page for ``aided`` without a browser: its controls (grades suggested, the aiding names as check boxes
read from the parameter's own list), a typed run as the API runs it, and its figures (the errors inside +-3 sigma
with the outages shaded, the track); in Chromium where it is installed."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.aided.evaluation import AIDING
from schuler.imu.spec import GRADES
from schuler.lab import controls, figures, system_page
from schuler.navigate.evaluation import TRAJECTORIES
from schuler.registry import get_system
from test_lab import attribute, walk

AIDED = get_system("aided")
TYPED = {"duration": "300", "outage_start": "120", "outage_duration": "45", "gnss_rate": "2", "imu": "industrial",
         "aiding": "gnss-position"}


@pytest.fixture(scope="module")
def result():
    return system_page.run_typed(AIDED, TYPED)


def _control(page, name):
    (div,) = [c for c in walk(page) if attribute(c, "data-param") == name]
    return div


def test_the_page_offers_the_grades_and_the_aiding_names_of_the_parameters():
    page = system_page.layout(AIDED)
    controls_found = [attribute(c, "data-param") for c in walk(page) if attribute(c, "data-param")]
    assert controls_found == [*AIDED.parameters.names, "monte_carlo", "seed"]
    (suggestions,) = [c for c in walk(_control(page, "imu")) if type(c).__name__ == "Datalist"]
    assert [option.value for option in suggestions.children] == list(GRADES)
    (paths,) = [c for c in walk(_control(page, "trajectory")) if type(c).__name__ == "Datalist"]
    assert [option.value for option in paths.children] == list(TRAJECTORIES)
    (boxes,) = [c for c in walk(_control(page, "aiding")) if type(c).__name__ == "Checklist"]
    assert boxes.options == list(AIDING) and boxes.value == []  # none ticked: not set, both GNSS measurements
    for name in ("gnss_rate", "outage_start", "outage_duration", "initialisation"):
        assert [type(c).__name__ for c in walk(_control(page, name)) if type(c).__name__ in ("Input", "Checklist")] \
            == ["Input"], name


def test_ticked_names_travel_joined_and_none_ticked_is_not_set():
    parameters = system_page.page_parameters(AIDED)
    ids = [{"type": controls.PARAM, "name": "aiding"}, {"type": controls.PARAM, "name": "imu"}]
    assert controls.typed_values(parameters, ids, [["gnss-position", "gnss-velocity"], "consumer"]) == {
        "aiding": "gnss-position,gnss-velocity", "imu": "consumer"}
    assert controls.typed_values(parameters, ids, [[], ""]) == {}
    case, errors = controls.parse_typed(parameters, {"aiding": "gnss-position"})
    assert errors == {} and case["aiding"] == "gnss-position"


def test_a_typed_run_is_the_api_s(result):
    expected = AIDED.run(duration=300.0, outage_start=120.0, outage_duration=45.0, gnss_rate=2.0, imu="industrial",
                         aiding="gnss-position")
    assert result.outputs == expected.outputs
    assert result.outages[0]["start_s"] == 120.0 and result.outages[0]["duration_s"] == 45.0


def test_a_typed_trajectory_runs_as_the_api_s():
    typed = {"duration": "300", "outage_start": "120", "trajectory": "great-circle", "speed": "120",
             "heading": "45", "imu": "tactical"}
    ran = system_page.run_typed(AIDED, typed)
    expected = AIDED.run(duration=300.0, outage_start=120.0, trajectory="great-circle", speed=120.0,
                         heading=math.radians(45.0), imu="tactical")
    assert ran.outputs == expected.outputs
    drive = AIDED.run(duration=300.0, outage_start=120.0, imu="tactical")
    assert ran.outputs != drive.outputs


def test_the_error_figure_draws_three_sigma_and_shades_the_outage(result):
    errors, track = figures.interactive_figures(AIDED, result)
    assert figures.interactive_stems(AIDED) == ("aided_errors", "aided_track")
    histories = result.histories["aided_errors"]
    minutes = (histories.time - histories.time[0]) / 60.0
    for row, (error, sigma, _, unit) in enumerate(figures.ENVELOPE_ROWS, start=1):
        suffix = "" if row == 1 else str(row)
        upper, lower, drawn = [t for t in errors["data"] if t["yaxis"] == f"y{suffix}"]
        scale = 180.0 / math.pi if unit == "deg" else 1.0
        x = np.asarray(upper["x"])
        at = np.searchsorted(minutes, x - 1e-12)
        assert np.allclose(upper["y"], 3.0 * histories[sigma][at] * scale, rtol=1e-12)
        assert np.allclose(lower["y"], -np.asarray(upper["y"]), rtol=0) and lower["fill"] == "tonexty"
        assert np.allclose(drawn["y"], histories[error][np.searchsorted(minutes, np.asarray(drawn["x"]) - 1e-12)]
                           * scale, rtol=1e-12)
        assert len(x) <= figures.MAX_POINTS
    shapes = errors["layout"]["shapes"]
    assert len(shapes) == 4  # the one outage on each of the four rows
    start = (120.0 - histories.time[0]) / 60.0
    assert all(math.isclose(s["x0"], start) and math.isclose(s["x1"], start + 0.75) for s in shapes)
    # the industrial IMU's drift in the 45-s outage leaves the band only rarely (the run's own consistency)
    north = np.abs(histories["north_error_m"]) <= 3.0 * histories["north_sigma_m"]
    assert north.mean() > 0.95


def test_the_track_is_the_solution_in_metres_with_the_outage_in_red(result):
    _, track = figures.interactive_figures(AIDED, result)
    solution, outage, start = track["data"]
    navigation = result.navigation
    assert (start["x"], start["y"]) == ([0.0], [0.0]) and track["layout"]["yaxis"]["scaleanchor"] == "x"
    # the track's length is the distance the solution's velocity covers (2059 m); the GNSS updates' small steps
    # (and the IMU's noise at the stops) add 3.7 %
    length = np.sum(np.hypot(np.diff(solution["x"]), np.diff(solution["y"])))
    step = float(np.diff(navigation.time)[0])
    covered = np.sum(np.hypot(navigation["velocity_north_m_s"], navigation["velocity_east_m_s"])) * step
    assert length == pytest.approx(covered, rel=0.05) and covered > 1500.0
    inside = (navigation.time > 120.0) & (navigation.time <= 165.0)
    assert len(outage["x"]) <= figures.MAX_POINTS and inside.sum() > figures.MAX_POINTS
    assert outage["line"]["color"] == "crimson"


def test_a_run_without_histories_draws_notes():
    class Bare:
        histories: dict = {}

    drawn = figures.interactive_figures(AIDED, Bare())
    assert len(drawn) == 2 and all(d["data"] == [] for d in drawn)
