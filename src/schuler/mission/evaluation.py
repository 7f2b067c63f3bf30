"""What the mission system evaluates: its parameters, outputs, ``evaluate`` and ``run_case``.

:func:`evaluate` runs the covariance analysis of each case
(:mod:`schuler.mission.covariance`; cases sharing every parameter are computed
once, the distinct cases of one duration, output step and vertical channel in
one batch). With random streams (a Monte Carlo), each member also flies the
nonlinear INS with its own draws (:mod:`schuler.mission.monte_carlo`) and
reports its final horizontal position error; the nominal case (no random
streams) draws nothing, so that error is 0.
"""

from __future__ import annotations

import math

import numpy as np

from schuler.contract import Cases, Output
from schuler.imu.error_model import ErrorModel
from schuler.imu.spec import GRADES
from schuler.mission.covariance import CovarianceBudget, covariance_budget, covariance_budgets
from schuler.mission.monte_carlo import final_horizontal_errors, run_members
from schuler.mission.results import MissionResult
from schuler.mission.setup import (
    ALIGNMENTS,
    CALIBRATIONS,
    TRAJECTORIES,
    VERTICAL_CHANNELS,
    error_model,
    mission_setup,
)
from schuler.navigate.mechanization import estimate_memory
from schuler.params import Case, Parameter, ParameterSet

PARAMETERS = ParameterSet((
    Parameter("grade", "", "tactical", "IMU grade preset (schuler.imu presets with their data-sheet sources).",
              choices=GRADES, kind="choice"),
    Parameter("imu_spec", "", None, "IMU spec file (TOML, as schuler imu writes them); replaces the grade.",
              kind="text"),
    Parameter("instrument", "", None, "IMU: a grade, a TOML spec file or a recording (.csv, .imu, .parquet) whose "
              "identified noise terms (Allan analysis) become the model; replaces grade and imu_spec.",
              kind="text"),
    Parameter("latitude", "deg", 45.0, "Latitude of the start point.", minimum=-80, maximum=80),
    Parameter("longitude", "deg", 0.0, "Longitude of the start point.", minimum=-180, maximum=360),
    Parameter("height", "m", 0.0, "Height of the mission above the ellipsoid.", minimum=-500, maximum=20000),
    Parameter("calibration", "", "pulse", "Gyro calibration: pulse (system 3, gyros only) or multi-position "
              "(gyro and accelerometer biases, accelerometer scale factors).", choices=CALIBRATIONS, kind="choice"),
    Parameter("calibration_duration", "s", 600.0, "Time over which the calibration averages.",
              minimum=1, maximum=86400),
    Parameter("pulse_relative_error", "%", 0.34, "Relative error of the pulse method's drift (the source's 0.34 %).",
              minimum=0, maximum=100),
    Parameter("alignment", "", "kalman", "Alignment: kalman (strapdown fine alignment), strapdown-gyrocompass "
              "(analytic, from the averaged rates and forces), gyrocompass (system 4's physical gyrocompassing) "
              "or ground-gyrocompass (north from system 5, levelling).",
              choices=ALIGNMENTS, kind="choice"),
    Parameter("alignment_duration", "s", 300.0, "Duration of the alignment at rest.", minimum=10, maximum=86400),
    Parameter("gyrocompass_time_constant", "s", 30.0, "Time constant T of system 4's azimuth loop.",
              minimum=1, maximum=3600),
    Parameter("gyrocompass_damping", "", 0.8, "Damping ratio of system 4's azimuth loop.", minimum=0.1, maximum=10),
    Parameter("north_reference_error", "arcsec", 10.0, "1-sigma heading error of the ground gyrocompass (system 5).",
              minimum=0, maximum=36000),
    Parameter("trajectory", "", "cruise", "Mission: stationary, cruise (a geodesic at the speed) or flight "
              "(take-off run, two 90-deg turns).", choices=TRAJECTORIES, kind="choice"),
    Parameter("profile", "", None, "Waypoint profile FILE.toml (format: schuler.navigate.profile) flown instead of "
              "the trajectory; its [start] and first heading set the start point and heading.", kind="text"),
    Parameter("duration", "s", 7200.0, "Mission duration (after the alignment).", minimum=60, maximum=10 * 86400),
    Parameter("speed", "m/s", 250.0, "Ground speed of cruise and flight.", minimum=0, maximum=1000),
    Parameter("heading", "deg", 30.0, "Heading at the start.", minimum=-360, maximum=360),
    Parameter("vertical_channel", "", "off", "Vertical channel: off (height held, as by an altimeter) or free.",
              choices=VERTICAL_CHANNELS, kind="choice"),
    Parameter("output_step", "s", 60.0, "Step of the histories (the covariance is exact within it).",
              minimum=1, maximum=3600),
    Parameter("initial_position_error", "m", 0.0, "1-sigma error of the start position, north and east each.",
              minimum=0, maximum=1e5),
    Parameter("imu_rate", "Hz", 2.0, "IMU rate of the Monte Carlo's nonlinear INS (reduced: exact for the "
              "noise, ample for the smooth trajectories).", minimum=0.1, maximum=1000),
), owner="mission", exclusive=(("grade", "instrument"), ("imu_spec", "instrument"),
                                *(("profile", name) for name in ("trajectory", "latitude", "longitude", "height",
                                                                 "heading", "speed"))))
"""Every option of ``schuler mission run`` (and key of a ``mission`` scenario)."""

OUTPUTS = (
    Output("position_error_sigma_m", "m", "", "1-sigma horizontal position error at the end, sqrt(sN^2 + sE^2)"),
    Output("position_error_north_sigma_m", "m", "", "1-sigma north position error at the end"),
    Output("position_error_east_sigma_m", "m", "", "1-sigma east position error at the end"),
    Output("velocity_error_sigma_m_s", "m/s", "", "1-sigma horizontal velocity error at the end"),
    Output("heading_error_sigma_rad", "rad", "arcmin", "1-sigma heading error at the end"),
    Output("initial_heading_error_sigma_rad", "rad", "arcmin", "1-sigma heading error the alignment leaves"),
    Output("initial_tilt_sigma_rad", "rad", "arcsec", "1-sigma tilt (root sum square of both) the alignment leaves"),
    Output("dominant_share", "1", "%", "share of the dominant source in the final horizontal position variance"),
    Output("member_position_error_m", "m", "",
           "a Monte Carlo member's final horizontal position error, nonlinear INS (0 in the nominal case)"),
)

_BUDGET_KEYS = tuple(p.name for p in PARAMETERS if p.name != "imu_rate")
"""The parameters the covariance analysis depends on."""


def budget_outputs(budget: CovarianceBudget) -> dict[str, float]:
    """The covariance outputs of :data:`OUTPUTS` from a budget, SI.

    Parameters
    ----------
    budget : CovarianceBudget
        The mission's covariance analysis.

    Returns
    -------
    dict of str to float
        Every output but ``member_position_error_m``: sigmas in m, m/s and rad, ``dominant_share`` a plain
        number.
    """
    shares = budget.shares()
    initial = budget.initial_covariance
    n = budget.states
    return {
        "position_error_sigma_m": float(budget.sigma("horizontal_position")[-1]),
        "position_error_north_sigma_m": float(budget.sigma("position_north")[-1]),
        "position_error_east_sigma_m": float(budget.sigma("position_east")[-1]),
        "velocity_error_sigma_m_s": float(budget.sigma("horizontal_velocity")[-1]),
        "heading_error_sigma_rad": float(budget.sigma("heading")[-1]),
        "initial_heading_error_sigma_rad": float(budget.sigma("heading")[0]),
        "initial_tilt_sigma_rad": float(math.sqrt(initial[n - 3, n - 3] + initial[n - 2, n - 2])),
        "dominant_share": float(max(shares.values())),
    }


_SHAPE_KEYS = ("duration", "output_step", "vertical_channel")
"""The parameters that fix the covariance analysis's steps and states: cases sharing them are batched."""


def _values(cases: Cases, i: int) -> dict:
    case = cases.case(i)
    return {name: case[name] for name in PARAMETERS.names}


def evaluate(cases: Cases) -> dict[str, np.ndarray]:
    """Every output of :data:`OUTPUTS` for a batch of cases (SI arrays of length ``len(cases)``).

    The covariance analysis runs once per distinct case, and the distinct cases of one duration, output step
    and vertical channel in one batch (:func:`~schuler.mission.covariance.covariance_budgets`), so that a
    Monte Carlo whose members draw their cases costs the same per member however many there are.

    Parameters
    ----------
    cases : Cases
        A batch of validated cases (SI values); with ``cases.random`` set, member ``cases.members[i]`` also flies
        the nonlinear INS with its own draws.

    Returns
    -------
    dict of str to ndarray
        Output name -> values of shape (number of cases,), SI (``member_position_error_m`` 0 without random
        streams).
    """
    n = len(cases)
    out = {output.name: np.full(n, np.nan) for output in OUTPUTS}
    out["member_position_error_m"] = np.zeros(n)
    models: dict[tuple, ErrorModel] = {}
    for shape_index, shape_group in cases.groups(*_SHAPE_KEYS):
        distinct = list(shape_group.groups(*_BUDGET_KEYS))
        setups = []
        for _, group in distinct:
            values = _values(group, 0)
            key = (values["grade"], values["imu_spec"], values["instrument"])
            if key not in models:
                models[key] = error_model(*key)
            setups.append(mission_setup(values, model=models[key]))
        for (index, group), setup, budget in zip(distinct, setups, covariance_budgets(setups)):
            rows = shape_index[index]
            for name, value in budget_outputs(budget).items():
                out[name][rows] = value
            if cases.random is not None:
                for rate_index, members in group.groups("imu_rate"):
                    rate = float(members.float("imu_rate")[0])
                    result = run_members(setup, members.members, cases.random, rate, output_step=setup.duration)
                    out["member_position_error_m"][rows[rate_index]] = final_horizontal_errors(result)
    return out


def run_case(case: Case, fidelity: str | None = None) -> MissionResult:
    """One mission in full: the covariance outputs, the budget's shares and its histories.

    Parameters
    ----------
    case : Case
        Every parameter of :data:`PARAMETERS`, SI.
    fidelity : str or None
        The contract's evaluation fidelity; this system has a single way of evaluating, so it is not used.

    Returns
    -------
    MissionResult
        The outputs (SI), each source's share of the final horizontal position variance, the dominant source,
        the instrument's name and the budget's histories.

    Examples
    --------
    >>> r = run_case(PARAMETERS.case(grade="navigation", trajectory="stationary", duration=3600.0))
    >>> round(sum(r.budget.values()), 9), r.dominant_source in r.budget
    (1.0, True)
    """
    setup = mission_setup({name: case[name] for name in PARAMETERS.names})
    budget = covariance_budget(setup)
    outputs = budget_outputs(budget)
    shares = budget.shares()
    return MissionResult(**outputs, member_position_error_m=0.0, budget=shares,
                         dominant_source=max(shares, key=lambda name: shares[name]),
                         instrument=setup.error_model.name, history=budget, monte_carlo=None)


def member_bytes(case: Case) -> int:
    """Memory one Monte Carlo member holds: its outputs and a block of noise and truth, bytes.

    Parameters
    ----------
    case : Case
        The member's parameters, SI. Not used: the estimate assumes two output points per member (the Monte
        Carlo keeps only the start and the end) and a block of 4096 IMU intervals, whatever the duration and
        rate, so it is the same for every case.

    Returns
    -------
    int
        Memory, bytes.
    """
    return int(estimate_memory(1, 2, 4096, True)) + 64 * 1024


__all__ = ["OUTPUTS", "PARAMETERS", "budget_outputs", "evaluate", "member_bytes", "run_case"]
