"""A small stand-in system for testing scenarios, sweeps and the report generically.

Its model is the steady-state gyrocompassing error psi = drift_east / (Omega cos(latitude))
with a settling time duration / gain, so every number is known in closed form.
Registered as system "fake" by the ``fake_system`` fixture of the study tests.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from schuler.contract import Cases, Evaluation, FigureRef, Output, ReportSection, System
from schuler.core.response import Histories
from schuler.params import Parameter, ParameterSet
from schuler.registry import SYSTEM_MODULES
from schuler.reproduction import Reproduction, compare

EARTH_RATE = 7.292115e-5

PARAMETERS = ParameterSet((
    Parameter("latitude", "deg", 50.0, "Latitude of the site.", minimum=-89.0, maximum=89.0),
    Parameter("drift_east", "deg/h", 0.01, "East gyro drift rate.", minimum=0.0),
    Parameter("gain", "", 1.0, "Loop gain.", minimum=0.0, exclusive_minimum=True),
    Parameter("method", "", "closed", "How to evaluate.", choices=("closed", "table"), kind="choice"),
    Parameter("members", "", 1, "Members.", minimum=1, kind="integer"),
    Parameter("duration", "s", 3600.0, "Simulated time.", minimum=0.0, exclusive_minimum=True),
    Parameter("output_step", "s", 1.0, "Time step.", minimum=0.0, exclusive_minimum=True),
    Parameter("sigma_drift", "deg/h", 0.0, "Monte Carlo 1-sigma of the drift.", minimum=0.0),
), owner="fake")

OUTPUTS = (
    Output("azimuth_error_rad", "rad", "arcmin", "steady azimuth error"),
    Output("settling_time_s", "s", "", "settling time"),
)

CALLS = {"sweep": 0}
"""Evaluations of fake_evaluate in this process (resume tests count them)."""

KILL_ABOVE = "SCHULER_FAKE_KILL_ABOVE"
"""Environment: a worker process evaluating a chunk with latitude above this (rad) dies, once."""
KILL_MARKER = "SCHULER_FAKE_KILL_MARKER"
"""Environment: file created by the worker that killed itself (so it happens once)."""


def fake_evaluate(cases: Cases, histories: bool = False) -> Evaluation:
    CALLS["sweep"] += 1
    latitude = cases.float("latitude")
    threshold = os.environ.get(KILL_ABOVE)
    marker = os.environ.get(KILL_MARKER)
    if threshold and marker and latitude.min() > float(threshold) and not Path(marker).exists():
        Path(marker).write_text(str(os.getpid()))
        os._exit(1)
    drift = cases.float("drift_east")
    if cases.random is not None:
        drift = drift + cases.float("sigma_drift") * cases.random.normal("drift_east", cases.members)
    azimuth = drift / (EARTH_RATE * np.cos(latitude))
    settling = cases.float("duration") / cases.float("gain")
    outputs = {"azimuth_error_rad": azimuth, "settling_time_s": settling * cases["members"]}
    if not histories:
        return Evaluation(outputs)
    # the first case's settling towards its steady state, e^(-t / tau) with tau = settling / 4.6 (1 % band)
    time = np.arange(0.0, cases.float("duration")[0] + cases.float("output_step")[0] / 2, cases.float("output_step")[0])
    tau = settling[0] / 4.6
    settle = Histories(time, {"azimuth_error_rad": azimuth[0] * (1 - np.exp(-time / tau))},
                       {"azimuth_error_rad": "rad"})
    return Evaluation(outputs, histories={"fake_time_history": settle}, extras={"method": str(cases["method"][0])})


def fake_figures(result) -> dict:
    if isinstance(result, Reproduction):
        return {}
    return {"fake_time_history": result.histories["fake_time_history"].plot()}


def fake_reproduce() -> Reproduction:
    result = FAKE.run(latitude=np.radians(50.0), drift_east=np.radians(0.01) / 3600)
    computed = float(np.degrees(result.azimuth_error_rad) * 60)
    return Reproduction(
        system="fake", source="Test fixture <not a real source> & co", constants="Omega = 7.292115e-5 rad/s",
        rows=[compare("azimuth error", computed, "arcmin", printed="3.556", where="p. 1", note="closed form"),
              compare("printed typo", computed, "arcmin", printed="4.0", where="p. 2",
                      erratum="the source drops a factor")],
        notes=["An erratum, explained."], data=result)


def fake_report(outdir: Path) -> ReportSection:
    import matplotlib.pyplot as plt

    from schuler.io import save_figure_formats

    latitude = np.linspace(0, 80, 50)
    fig, ax = plt.subplots(figsize=(5, 3))
    ax.plot(latitude, np.degrees(np.radians(0.01) / 3600 / (EARTH_RATE * np.cos(np.radians(latitude)))) * 60)
    ax.set_xlabel("latitude [deg]")
    ax.set_ylabel("azimuth error [arcmin]")
    ax.set_title("Steady-state azimuth error")
    save_figure_formats(fig, Path(outdir) / "fake_azimuth", ("png", "svg"))
    reproduction = fake_reproduce()
    return ReportSection(
        system="fake",
        title="A fake gyrocompass",
        source="Test fixture <not a real source> & co",
        summary="Steady-state azimuth error of a gyrocompass.",
        rows=reproduction.rows,
        figures=[
            FigureRef("fake_azimuth.png", "Azimuth error against latitude."),
        ],
        commands=["schuler fake run --latitude 50"],
        notes=["An erratum, explained."],
    )


FAKE = System(
    name="fake",
    title="Fake gyrocompass",
    reference="Test fixture",
    parameters=PARAMETERS,
    outputs=OUTPUTS,
    evaluate=fake_evaluate,
    reproduce=fake_reproduce,
    figures=fake_figures,
    report=fake_report,
    random_terms=True,
)
SYSTEM = FAKE


def register(monkeypatch) -> None:
    """Make ``get_system("fake")`` return FAKE (this module's SYSTEM)."""
    monkeypatch.setitem(SYSTEM_MODULES, "fake", __name__)


def only_systems(request, modules: dict[str, str]) -> None:
    """Make the registry hold exactly ``modules`` (name -> module) for one test, then restore it in order."""
    saved = dict(SYSTEM_MODULES)

    def restore():
        SYSTEM_MODULES.clear()
        SYSTEM_MODULES.update(saved)

    request.addfinalizer(restore)
    SYSTEM_MODULES.clear()
    SYSTEM_MODULES.update(modules)


def test_fake_run_matches_its_closed_form():
    # psi = drift / (Omega cos(lat)): 0.01 deg/h at 50 deg N: 0.01 / (15.04107 * cos 50) rad = 3.5557 arcmin
    result = fake_reproduce().data
    expected = np.radians(0.01) / 3600 / (EARTH_RATE * np.cos(np.radians(50.0)))
    assert result.azimuth_error_rad == pytest.approx(expected, rel=1e-12)
    assert np.degrees(result.azimuth_error_rad) * 60 == pytest.approx(3.5557, abs=1e-4)
