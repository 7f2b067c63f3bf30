"""GNSS outages listed one by one (``outages``): the same as the scheduled ones they equal, from Python, the
command line and a scenario; bad lists refused in one line."""

from __future__ import annotations

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.exceptions import InvalidParameter
from schuler.params import IntervalsParameter
from schuler.registry import get_system
from schuler.study.scenario import parse_scenario

AIDED = get_system("aided")
SHORT = {"duration": 500.0, "nominal": False, "seed": 3}


def test_a_list_equal_to_a_schedule_gives_the_same_run():
    listed = AIDED.run(outages=[[100, 30], [300, "0.5 min"]], **SHORT)
    scheduled = AIDED.run(outage_start=100.0, outage_duration=30.0, outage_every=200.0, **SHORT)
    assert listed.outages == scheduled.outages
    assert [o["start_s"] for o in listed.outages] == [100.0, 300.0]
    assert listed.position_error_horizontal_rms_m == scheduled.position_error_horizontal_rms_m


def test_an_empty_list_means_no_outage_and_outages_past_the_end_are_dropped():
    assert AIDED.run(outages=[], duration=300.0, nominal=True).outages == []
    kept = AIDED.run(outages=[[50, 10], [900, 10]], duration=300.0, nominal=True).outages
    assert [(o["start_s"], o["duration_s"]) for o in kept] == [(50.0, 10.0)]


def test_command_line_and_scenario_write_the_same_list(run_cli):
    out = run_cli("aided", "run", "--duration", "500", "--seed", "3", "--outages", "300:30, 100 s:0.5 min", "--json")
    assert out.code == 0, out.stderr
    command = json.loads(out.stdout)
    assert command["inputs"]["outages"] == [[100.0, 30.0], [300.0, 30.0]]
    scenario = parse_scenario('system = "aided"\n[parameters]\noutages = [[100, 30], [300, "30 s"]]\n'
                              '[simulation]\nduration = "500 s"\n')
    assert scenario.values["outages"] == ((100.0, 30.0), (300.0, 30.0))
    python = AIDED.run(outages=[[100, 30], [300, 30]], **SHORT)
    for shown, exact in zip(command["outages"], python.outages, strict=True):
        assert shown == pytest.approx(exact, rel=1e-12)


@pytest.mark.parametrize("written, words", [
    ("100:30,110:5", "starts before the one at 100 s ends"),
    ("100", "is not a (start, duration) pair"),
    ("100:0", "duration > 0"),
    ("100:ten", "cannot read 'ten'"),
])
def test_bad_lists_are_one_line_and_exit_2(run_cli, written, words):
    out = run_cli("aided", "run", "--outages", written)
    assert out.code == 2 and out.stderr.count("\n") == 1 and words in out.stderr, out.stderr


def test_a_list_replaces_the_schedule_options_and_is_not_combined_with_them(run_cli):
    out = run_cli("aided", "run", "--outages", "100:30", "--outage-every", "400")
    assert out.code == 2 and "cannot be combined" in out.stderr
    with pytest.raises(InvalidParameter, match="cannot be combined"):
        AIDED.parameters.case(outages=[[1.0, 2.0]], outage_duration=30.0)
    with pytest.raises(InvalidParameter, match="not a list"):
        AIDED.parameters.case(outages=5.0)


@settings(max_examples=50, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 1e6), st.floats(1e-3, 1e3)), max_size=6))
def test_the_text_form_reads_back_what_the_list_says(pairs):
    parameter = IntervalsParameter("outages", "min", None, "Outages.")
    text = ", ".join(f"{start!r}:{duration!r}" for start, duration in pairs)
    try:
        from_list = parameter.parse([list(p) for p in pairs])
    except InvalidParameter as error:
        assert "starts before" in str(error)
        with pytest.raises(InvalidParameter, match="starts before"):
            parameter.parse(text)
        return
    assert parameter.parse(text) == from_list
    assert [start for start, _ in from_list] == sorted(60.0 * start for start, _ in pairs)
    assert parameter.check(from_list) == from_list


def test_a_list_is_one_value_beside_arrays_of_cases():
    """``evaluate_values``: the list of outages is shared by every case of a batch, not a batch of its own."""
    outages = [[100, 30], [300, 30]]
    batch = AIDED.evaluate_values({"outages": outages, "gnss_rate": [1.0, 2.0], "duration": 500.0,
                                   "nominal": True})
    for k, rate in enumerate((1.0, 2.0)):
        single = AIDED.run(outages=outages, gnss_rate=rate, duration=500.0, nominal=True)
        assert batch["position_error_horizontal_rms_m"][k] == pytest.approx(single.position_error_horizontal_rms_m,
                                                                            rel=1e-12)
    with pytest.raises(InvalidParameter, match="different lengths"):
        AIDED.evaluate_values({"gnss_rate": [1.0, 2.0], "gnss_latency": [0.0, 0.1, 0.2], "duration": 500.0})
