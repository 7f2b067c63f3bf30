"""One result type, drawn by one hook, written by one writer: checked over the registry and on a system added
through the steps of ``docs/architecture.md``."""

from __future__ import annotations

import json
import math

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

import test_study_fake_system as fake
from schuler import get_system
from schuler.contract import Cases
from schuler.core.random import RandomStreams
from schuler.results import MonteCarloStatistics, SystemResult
from test_contract import NAMES, light


@pytest.mark.parametrize("name", NAMES)
def test_every_system_runs_through_evaluate_into_one_result_type_that_plots(name):
    system = get_system(name)
    result = system.run(**light(name))
    assert type(result) is system.result_type and isinstance(result, SystemResult)
    # run is evaluate by construction: the same outputs, bit for bit
    random = RandomStreams(0) if system.realisation else None
    direct = system.evaluate(Cases.from_case(system.case(**light(name)), members=np.array([0]), random=random,
                                             fidelity=system.check_fidelity(None)))
    for output in system.outputs:
        value, expected = result.outputs[output.name], float(np.asarray(direct[output.name])[0])
        assert (value == expected) or (math.isnan(value) and math.isnan(expected)), output.name
    figures = result.figures()
    assert figures, f"{name} run draws no figure"
    assert all(isinstance(figure, Figure) for figure in figures.values())
    for figure in figures.values():
        plt.close(figure)
    first = result.plot()
    assert isinstance(first, Figure)
    plt.close(first)


@pytest.mark.parametrize("name", NAMES)
def test_every_reproduction_is_a_result_that_draws_its_figures(name):
    system = get_system(name)
    reproduction = system.reproduce()
    data = reproduction.to_dict()
    assert json.loads(json.dumps(data)) == data
    for figure in reproduction.figures().values():
        assert isinstance(figure, Figure)
        plt.close(figure)


@pytest.fixture
def fake_system(monkeypatch):
    fake.register(monkeypatch)
    return get_system("fake")


def test_a_system_added_through_the_documented_steps_has_the_command_line_and_the_results(fake_system, run_cli,
                                                                                            tmp_path):
    # the steps: a module with parameters, outputs, evaluate(cases, histories), figures, reproduce and report,
    # assembled as SYSTEM; one line in registry.SYSTEM_MODULES. Nothing else is written for what follows.
    listed = run_cli("--help")
    assert listed.code == 0 and "fake" in listed.stdout and "Fake gyrocompass" in listed.stdout
    out = run_cli("fake", "run", "--latitude", "45", "--drift-east", "0.02", "--json", "--out", str(tmp_path / "o"))
    assert out.code == 0, out.stderr
    data = json.loads(out.stdout)
    expected = math.radians(0.02) / 3600 / (fake.EARTH_RATE * math.cos(math.radians(45)))
    assert data["azimuth_error_rad"] == pytest.approx(expected, rel=1e-12)
    assert data["method"] == "closed" and data["units"]["azimuth_error_rad"] == "rad"
    written = sorted(p.name for p in (tmp_path / "o").iterdir() if not p.name.startswith("."))
    assert written == ["fake_time_history.csv", "fake_time_history.png", "fake_time_history.svg"]
    table = pd.read_csv(tmp_path / "o" / "fake_time_history.csv")
    assert list(table.columns) == ["t_s", "azimuth_error_rad"]
    assert table["azimuth_error_rad"].iloc[-1] == pytest.approx(expected * (1 - math.exp(-4.6)), rel=1e-9)

    # from Python, with unit strings, the same case
    result = fake_system.run(latitude="45 deg", drift_east="0.02 deg/h", monte_carlo=50, seed=1)
    assert result.azimuth_error_rad == pytest.approx(expected, rel=1e-12)
    frame = result.to_dataframe()
    assert frame.index.name == "t_s" and frame.attrs["units"]["azimuth_error_rad"] == "rad"
    assert "<pre" in result._repr_html_()
    stats = result.monte_carlo["azimuth_error_rad"]
    assert isinstance(stats, MonteCarloStatistics) and stats.count == 50
    figure = result.plot("fake_time_history")
    assert isinstance(figure, Figure)
    plt.close(figure)
    with pytest.raises(KeyError, match="figures: fake_time_history"):
        result.plot("no_such_figure")
