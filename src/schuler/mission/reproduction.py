"""The stage equations the mission chains, checked against its budget; the report section.

There is no published mission to reproduce: the rows hold the closed forms
each stage follows (Groves 2013 for strapdown levelling and gyrocompassing,
the KPI manual's (1.21) for schuler align) beside what the mission's linear map and
covariance analysis compute from the same inputs, and the budget's invariants.

Constants: WGS-84 (schuler.core.earth), Earth rate 7.292115e-5 rad/s,
g = 9.80665 m/s^2 for levelling.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from schuler.contract import FigureRef, ReportSection
from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY
from schuler.core.gyrocompass_design import DESIGN_DAMPING, DESIGN_TIME_CONSTANT, loop_gains
from schuler.io import save_figure_formats
from schuler.mission import plots
from schuler.mission.covariance import covariance_budget
from schuler.mission.evaluation import PARAMETERS, budget_histories
from schuler.mission.setup import CONSTANT_SOURCES, mission_setup
from schuler.mission.stages import initial_state_map
from schuler.references import GROVES_2013, KPI_LAB_MANUAL
from schuler.reproduction import Reproduction, Tolerance, compare
from schuler.units import from_unit, to_unit

EXAMPLE_DRIFT = from_unit(0.01, "deg/h")
"""Gyro bias of the worked rows, rad/s."""
EXAMPLE_ACCEL = from_unit(100.0, "ug")
"""Accelerometer bias of the worked rows, m/s^2."""

SOURCE = f"{GROVES_2013.citation}; {KPI_LAB_MANUAL.citation}"


def _setup(**values):
    case = PARAMETERS.case(values)
    return mission_setup({name: case[name] for name in PARAMETERS.names})


def reproduce() -> Reproduction:
    """The stage closed forms and the budget's invariants, computed by the mission's own code.

    Examples
    --------
    >>> r = reproduce()
    >>> r.failures
    []
    """
    rows = []
    latitude = math.radians(50.0)
    east = _setup(latitude=latitude, heading=0.0, trajectory="stationary", alignment="kalman")
    # heading 0: body y points east, so a y-gyro bias b gives epsilon_E = -b
    index = CONSTANT_SOURCES.index("gyro_bias_y")
    x0 = initial_state_map(east, np.eye(3), 7)
    heading = -x0[index, -1] * EXAMPLE_DRIFT
    rows.append(compare(
        "Kalman alignment heading error from a 0.01 deg/h east gyro bias, 50 deg", to_unit(heading, "arcmin"),
        "arcmin", printed="-b_E / (Omega cos L)",
        value=float(to_unit(-EXAMPLE_DRIFT / (EARTH_RATE * math.cos(latitude)), "arcmin")),
        where="Groves (2013), Sec. 5.6.2", tolerance=Tolerance(relative=1e-9),
        note="heading error = -psi_D, drift = -bias; the tan(L) psi_N term is zero without accelerometer errors"))
    physical = _setup(latitude=latitude, heading=0.0, trajectory="stationary", alignment="gyrocompass")
    x0 = initial_state_map(physical, np.eye(3), 7)
    c_gamma, c_a = loop_gains(latitude, DESIGN_TIME_CONSTANT, DESIGN_DAMPING)
    rows.append(compare(
        "physical gyrocompass azimuth error from a 0.01 deg/h east drift, 50 deg, T = 30 s",
        to_unit(x0[index, -1] * -EXAMPLE_DRIFT, "arcmin"), "arcmin", printed="(1.21)",
        value=float(to_unit(-EXAMPLE_DRIFT / (EARTH_RATE * math.cos(latitude)), "arcmin")), where="(1.21)",
        tolerance=Tolerance(relative=1e-9),
        note=f"drift about east = -b (drift = -bias); c_Gamma = {float(c_gamma):.4g} 1/s, c_a = {float(c_a):.4g} 1/s"))
    tilt = x0[CONSTANT_SOURCES.index("accel_bias_x"), -2] * EXAMPLE_ACCEL
    rows.append(compare(
        "levelling tilt psi_E from a 100 ug north accelerometer bias", to_unit(tilt, "arcsec"), "arcsec",
        printed="-b_N / g", value=float(to_unit(-EXAMPLE_ACCEL / STANDARD_GRAVITY, "arcsec")),
        where="Groves (2013), Sec. 5.6.1", tolerance=Tolerance(relative=1e-9)))
    mission = _setup(imu="tactical", trajectory="great-circle", duration=7200.0)
    budget = covariance_budget(mission)
    shares = budget.shares()
    rows.append(compare("sum of the shares of the final horizontal position variance", sum(shares.values()), "1",
                        printed="1", where="the budget's definition: shares add up to the total",
                        tolerance=Tolerance(0.0, 1e-9)))
    dominant = max(shares, key=lambda name: shares[name])
    without = covariance_budget(mission, disabled=(dominant,))
    removed = 1.0 - without.horizontal()[-1].sum() / budget.horizontal()[-1].sum()
    rows.append(compare(f"variance removed by switching off the dominant source ({dominant})", removed, "1",
                        printed=f"its share {shares[dominant]:.6f}", value=shares[dominant],
                        where="the budget's definition: switching off a source removes its share",
                        tolerance=Tolerance(1e-9)))
    return Reproduction(
        system="mission", source=SOURCE,
        constants="WGS-84; Earth rate 7.292115e-5 rad/s; g = 9.80665 m/s^2 in the levelling",
        rows=rows, notes=["no mission is published: the rows check the stage equations and the budget's invariants"],
        data=budget)


def report(figures_dir: Path) -> ReportSection:
    """The mission's section of the HTML report: the stage checks and a tactical 2-h cruise's budget.

    Parameters
    ----------
    figures_dir : Path
        Folder the budget figure (PNG) is written into.

    Returns
    -------
    ReportSection
        The report's section: the reproduction's rows, the budget figure with its caption, commands and notes.
    """
    reproduction = reproduce()
    files = save_figure_formats(plots.stacked_budget(budget_histories(reproduction.data)),
                                Path(figures_dir) / plots.BUDGET_HISTORIES, ("png",))
    shares = reproduction.data.shares()
    dominant = max(shares, key=lambda name: shares[name])
    return ReportSection(
        system="mission",
        title="A mission: calibrate, align, navigate, with an error budget",
        source=reproduction.source,
        summary=("The residuals of calibration and alignment are written as linear maps of the independent error "
                 "sources and propagated with the sources' own inputs through the WGS-84 psi-angle model: every "
                 "source's share of the final position variance, adding up to the total. A Monte Carlo of the "
                 f"nonlinear INS checks it (--monte-carlo). Tactical IMU, 2-h cruise: dominant source {dominant} "
                 f"({100 * shares[dominant]:.0f} %)."),
        rows=reproduction.rows,
        figures=[FigureRef(path.name, "Tactical IMU, pulse calibration, 5-min Kalman alignment, 2-h cruise at 250 m/s: "
                                      "horizontal position-error variance stacked by source, and the shares.")
                 for path in files],
        commands=["schuler mission reproduce",
                  "schuler run examples/mission_tactical.toml --json",
                  "schuler mission run --imu navigation --trajectory flight --monte-carlo 1000 --out mission",
                  "schuler sweep examples/mission_tactical.toml --param alignment_duration=300,900,1800"],
        notes=[*reproduction.notes, "budget of the tactical 2-h cruise (share of the final horizontal position "
               "variance): " + ", ".join(f"{name} {100 * shares[name]:.1f} %" for name in
                                         sorted(shares, key=lambda name: -shares[name])[:5])],
    )
