"""Results a notebook user expects, on every registered system: dict, DataFrame, HTML, typed Monte Carlo."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from schuler import get_system
from schuler.results import MonteCarloStatistics, MonteCarloSummary
from test_contract import NAMES, light


@pytest.mark.parametrize("name", NAMES)
def test_a_run_is_a_dict_a_dataframe_and_html(name):
    system = get_system(name)
    result = system.run(**light(name))
    data = result.to_dict()
    assert json.loads(json.dumps(data)) == data
    frame = result.to_dataframe()
    assert isinstance(frame, pd.DataFrame) and len(frame) >= 1
    html = result._repr_html_()
    assert html.startswith("<pre") and "</pre>" in html and "<script" not in html
    # the HTML shows the same numbers as the plain text (the table is the same renderable)
    first_line = next(line for line in str(result).splitlines() if line.strip())
    assert first_line.strip()[:20].replace("&", "&amp;") in html


@pytest.mark.parametrize("name", [n for n in NAMES if get_system(n).random_terms])
def test_monte_carlo_statistics_are_typed_and_members_a_dataframe(name):
    system = get_system(name)
    result = system.run(monte_carlo=4, seed=3, **light(name))
    summary = result.monte_carlo
    assert isinstance(summary, MonteCarloSummary)
    for output in system.outputs:
        stats = summary[output.name]
        assert isinstance(stats, MonteCarloStatistics)
        values = summary.samples[output.name]
        finite = values[np.isfinite(values)]
        assert stats.count == finite.size
        if finite.size:
            assert stats.mean == pytest.approx(float(np.mean(finite)), rel=1e-12, abs=1e-300)
            assert stats.max == float(np.max(finite)) and stats.min == float(np.min(finite))
    members = summary.to_dataframe()
    assert isinstance(members, pd.DataFrame) and len(members) == 4 and members.index.name == "member"
    assert members.shape[1] == len(system.outputs)
    assert summary.statistics_frame().shape == (len(system.outputs), 9)
    with pytest.raises(KeyError, match="is not an output"):
        summary["no_such_output"]


def test_typed_statistics_keep_their_json():
    """The JSON of a Monte Carlo keeps its shape: statistics per output as an object of named numbers."""
    result = get_system("align").run(latitude=math.radians(50), duration=600.0, monte_carlo=5, seed=2)
    stats = result.to_dict()["monte_carlo"]["statistics"]["azimuth_error_rad"]
    assert list(stats) == ["count", "mean", "std", "min", "max", "rms", "p05", "p50", "p95"]
    assert stats["std"] == pytest.approx(result.monte_carlo["azimuth_error_rad"].std, rel=1e-12)
