"""Figures of the nonlinear INS: each returns a Figure with the expected panels and data."""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pytest

from schuler.navigate import plots
from schuler.navigate.alignment import kpi_gyrocompassing
from schuler.navigate.errors import InitialErrors
from schuler.navigate.mechanization import navigate
from schuler.navigate.seeds import bollay_error_sources, drozdovich_worked_example
from schuler.navigate.trajectory import Stationary


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def test_error_panels_single_and_batch():
    single = navigate(Stationary(latitude=0.8), 600.0, imu_rate=10.0, output_step=60.0,
                      initial_errors=InitialErrors(velocity_error_north=0.1))
    fig = plots.plot_errors(single.histories(), single.mode)
    visible = [axis for axis in fig.axes if axis.get_visible()]
    assert len(visible) == 7  # the vertical channel is off: no height or vertical-velocity panel
    line = visible[0].lines[0]
    np.testing.assert_allclose(line.get_ydata(), single.position_error_north_m)
    batch = navigate(Stationary(latitude=0.8), 600.0, imu_rate=10.0, output_step=60.0, vertical_channel="free",
                     initial_errors=InitialErrors(velocity_error_north=[0.1, 0.2, 0.3]))
    fig = plots.plot_errors(batch.histories(), batch.mode)
    assert len([axis for axis in fig.axes if axis.get_visible()]) == 9
    np.testing.assert_allclose(fig.axes[0].lines[0].get_ydata(), batch.position_error_north_m.mean(axis=0))


def test_seed_figures():
    bollay = plots.plot_bollay(bollay_error_sources(imu_rate=2.0, output_step=20.0))
    assert len([axis for axis in bollay.axes if axis.get_visible()]) == 5
    drozdovich = plots.plot_drozdovich(drozdovich_worked_example(duration=6 * 3600.0, output_step=600.0))
    assert len(drozdovich.axes[0].lines) == 4
    comparison = kpi_gyrocompassing(np.radians([1 / 60, 1.0, 20.0]), duration=600.0, time_step=0.5)
    figure = plots.plot_gyrocompassing(comparison)
    assert len(figure.axes) == 2 and len(figure.axes[1].lines) == 7
    assert math.isclose(figure.axes[0].lines[0].get_ydata()[0], 1.0)
