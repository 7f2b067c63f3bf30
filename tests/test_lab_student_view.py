"""What a student sees in the lab: labels, defaults, figure titles and axes, the tasks' question numbers."""

from __future__ import annotations

import json

import numpy as np
import pytest

from schuler.ground_gyrocompass import plots
from schuler.ground_gyrocompass.grid import Stage
from schuler.lab import controls, figures, manual, system_page, tasks
from schuler.registry import get_system
from test_lab import attribute, walk

ALIGN = get_system("align")


def labels(page) -> dict[str, str]:
    """data-param -> the control's label text (name and unit)."""
    found = {}
    for div in walk(page):
        name = attribute(div, "data-param")
        if name:
            label = next(c for c in walk(div) if type(c).__name__ == "Label")
            found[name] = " ".join(str(span.children) for span in label.children if span is not None)
    return found


def test_parameters_are_shown_by_their_human_label_with_the_unit_and_option():
    shown = labels(system_page.layout(ALIGN))
    assert shown["drift_east"] == "drift east deg/h"
    assert shown["initial_azimuth_error"].startswith("initial azimuth error")
    hint = next(c for c in walk(controls.control(ALIGN.parameters["drift_east"])) if attribute(c, "className") ==
                "hint")
    assert hint.children.startswith("--drift-east; default ")


def test_the_parameters_panel_has_no_inner_scroll_box():
    css = (system_page.Path(figures.__file__).parent / "assets" / "lab.css").read_text()
    rule = css.split(".controls {")[1].split("}")[0]
    assert "overflow" not in rule and "max-height" not in rule


def test_a_default_written_with_its_unit_is_shown_as_a_number_in_the_display_unit():
    alpha0 = get_system("north").parameters["alpha0"]
    assert controls.initial_text(alpha0) == "0.0214675497995"  # 3.69 pi / 540 rad
    assert controls.describe(alpha0).startswith("default 0.0214675 rad;")
    # the page's default still counts as "not typed": the run takes the parameter's own default
    assert controls.typed_values(get_system("north").parameters, [{"name": "alpha0"}], ["0.0214675497995"]) == {}


def test_the_time_history_says_it_shows_the_first_part_of_the_simulated_time():
    result = system_page.run_typed(ALIGN, {})
    history, phase = figures.interactive_figures(ALIGN, result)
    axis = history["layout"]["xaxis2"]["title"]["text"]
    assert result.simulated_duration_s == 7200
    assert axis == "time [min] (the first 12.5 of 120 min simulated; the rest is steady)"
    assert max(history["data"][0]["x"]) == pytest.approx(12.5, abs=0.1)
    assert "(the first 12.5 of 120 min simulated" in phase["layout"]["title"]["text"]
    whole = system_page.run_typed(ALIGN, {"duration": "600"})
    assert figures.interactive_figures(ALIGN, whole)[0]["layout"]["xaxis2"]["title"]["text"] == "time [min]"


def test_the_misfit_maps_title_stays_inside_the_figure():
    box = {"alpha0": (-9e-4, 9e-4, 1e-4), "alpha0_dot": (-6e-4, 6e-4, 1e-4)}
    stage = Stage(box, {"alpha0": 0.0, "alpha0_dot": 0.0}, 1e-9, 247, np.ones((19, 13)))
    fig = plots.plot_misfit_map(stage, title="Misfit around the estimate (247 cells, the source's first-stage "
                                             "steps), at the estimated lambda and B")
    fig.canvas.draw()
    extent = fig.axes[0].title.get_window_extent()
    width = fig.get_size_inches()[0] * fig.dpi
    assert extent.x0 >= 0 and extent.x1 <= width


def test_task_questions_carry_the_manuals_numbers():
    for page, number in tasks.PAGES.items():
        text = json.dumps(tasks.layout(ALIGN, page).to_plotly_json(), default=str)
        for question in manual.TASK_QUESTIONS[number]:
            assert f"question {question} of the manual" in text
