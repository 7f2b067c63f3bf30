"""Atomic output: a failure while writing leaves neither a partial file nor debris."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest

from schuler.core.lti import StateSpace, simulate
from schuler.io import atomic_path, save_figure_formats, write_json


def test_failed_write_leaves_no_file(tmp_path):
    target = tmp_path / "result.json"
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text('{"half": ')
            raise RuntimeError("crash mid-write")
    assert not target.exists()
    assert list(tmp_path.iterdir()) == []


def test_failed_write_keeps_the_previous_file(tmp_path):
    target = write_json(tmp_path / "result.json", {"run": 1})
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("garbage")
            raise RuntimeError("crash")
    assert target.read_text() == '{\n  "run": 1\n}\n'


def test_figures_in_two_formats(tmp_path):
    t = np.linspace(0, 100, 11)
    response = simulate(StateSpace([[0.0, 1.0], [-0.01, 0.0]], states=("x", "v")), t, initial_state=[1.0, 0.0])
    fig = response.plot()
    assert [ax.get_ylabel() for ax in fig.axes] == ["x", "v"]
    paths = save_figure_formats(fig, tmp_path / "oscillator")
    assert [p.name for p in paths] == ["oscillator.png", "oscillator.svg"]
    assert paths[0].read_bytes()[:4] == b"\x89PNG" and b"<svg" in paths[1].read_bytes()[:500]
    assert fig.number not in plt.get_fignums()  # closed after saving
