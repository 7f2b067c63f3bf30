"""What the mission system evaluates: its parameters, outputs and ``evaluate``.

:func:`evaluate` runs the covariance analysis of each case
(:mod:`schuler.mission.covariance`; cases sharing every parameter are computed
once, the distinct cases of one duration, output step and vertical channel in
one batch). With random streams (a Monte Carlo), each member also flies the
nonlinear INS with its own draws (:mod:`schuler.mission.monte_carlo`) and
reports its final horizontal position error; the nominal case (no random
streams) draws nothing, so that error is 0. With ``histories=True`` the first
case's budget comes in full: its 1-sigma histories and each source's variance
(:func:`budget_histories`), the shares, the dominant source and the instrument.
"""

from __future__ import annotations

import math

import numpy as np

from schuler.contract import Cases, Evaluation, Output
from schuler.core.response import Histories
from schuler.imu.error_model import ErrorModel
from schuler.imu.spec import GRADES
from schuler.mission.covariance import CovarianceBudget, covariance_budgets
from schuler.mission.monte_carlo import final_horizontal_errors, run_members
from schuler.mission.plots import BUDGET_HISTORIES
from schuler.mission.setup import (
    ALIGNMENTS,
    CALIBRATIONS,
    SOURCES,
    TRAJECTORIES,
    VERTICAL_CHANNELS,
    error_model,
    mission_setup,
)
from schuler.navigate.mechanization import estimate_memory
from schuler.params import Case, Parameter, ParameterSet

PARAMETERS = ParameterSet((
    Parameter("imu", "", "tactical", "IMU: a grade (" + ", ".join(GRADES) + "; schuler.imu presets with their "
              "data-sheet sources), a TOML spec file (as schuler imu writes them) or a recording (.csv, .imu, "
              ".parquet) whose identified noise terms (Allan analysis) become the model.", kind="text"),
    Parameter("latitude", "deg", 45.0, "Latitude of the start point.", minimum=-80, maximum=80),
    Parameter("longitude", "deg", 0.0, "Longitude of the start point.", minimum=-180, maximum=360),
    Parameter("height", "m", 0.0, "Height of the mission above the ellipsoid.", minimum=-500, maximum=20000),
    Parameter("calibration", "", "pulse", "Gyro calibration: pulse (schuler calibrate, gyros only) or multi-position "
              "(gyro and accelerometer biases, accelerometer scale factors).", choices=CALIBRATIONS, kind="choice"),
    Parameter("calibration_duration", "s", 600.0, "Time over which the calibration averages.",
              minimum=1, maximum=86400),
    Parameter("pulse_relative_error", "%", 0.34, "Relative error of the pulse method's drift (the source's 0.34 %).",
              minimum=0, maximum=100),
    Parameter("alignment", "", "kalman", "Alignment: kalman (strapdown fine alignment), strapdown-gyrocompass "
              "(analytic, from the averaged rates and forces), gyrocompass (schuler align's physical gyrocompassing) "
              "or ground-gyrocompass (north from schuler north, levelling).",
              choices=ALIGNMENTS, kind="choice"),
    Parameter("alignment_duration", "s", 300.0, "Duration of the alignment at rest.", minimum=10, maximum=86400),
    Parameter("gyrocompass_time_constant", "s", 30.0, "Time constant T of schuler align's azimuth loop.",
              minimum=1, maximum=3600),
    Parameter("gyrocompass_damping", "", 0.8, "Damping ratio of schuler align's azimuth loop.", minimum=0.1,
              maximum=10),
    Parameter("north_reference_error", "arcsec", 10.0,
              "1-sigma heading error of the ground gyrocompass (schuler north).",
              minimum=0, maximum=36000),
    Parameter("trajectory", "", "cruise", "Mission: stationary, cruise (a geodesic at the speed), flight "
              "(take-off run, two 90-deg turns) or drive (a car's: four stops, 10 m/s in town, 20 m/s on the road, "
              "90-deg turns; its own speeds).", choices=TRAJECTORIES, kind="choice"),
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
), owner="mission", exclusive=tuple(("profile", name) for name in ("trajectory", "latitude", "longitude", "height",
                                                                   "heading", "speed")),
   renamed={"grade": "imu", "imu_spec": "imu", "instrument": "imu"})
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


def budget_histories(budget: CovarianceBudget) -> Histories:
    """The budget over time: the 1-sigma errors and each source's horizontal position variance.

    Parameters
    ----------
    budget : CovarianceBudget
        The mission's covariance analysis (SI).

    Returns
    -------
    Histories
        Over ``t_s``: ``position_error_sigma_m`` (horizontal), ``velocity_error_sigma_m_s`` (horizontal),
        ``heading_error_sigma_rad`` and ``variance_<source>_m2`` for every source, in budget order.
    """
    channels = {"position_error_sigma_m": budget.sigma("horizontal_position"),
                "velocity_error_sigma_m_s": budget.sigma("horizontal_velocity"),
                "heading_error_sigma_rad": budget.sigma("heading")}
    units = {"position_error_sigma_m": "m", "velocity_error_sigma_m_s": "m/s", "heading_error_sigma_rad": "rad"}
    horizontal = budget.horizontal()
    for i, name in enumerate(budget.sources):
        channels[f"variance_{name}_m2"] = horizontal[:, i]
        units[f"variance_{name}_m2"] = "m^2"
    return Histories(np.asarray(budget.time, dtype=float), channels, units)


def _in_full(budget: CovarianceBudget, model: ErrorModel) -> tuple[dict, dict]:
    """The first case's budget in full: histories and JSON-safe extras."""
    shares = budget.shares()
    extras = {"budget": shares, "dominant_source": max(shares, key=lambda name: shares[name]),
              "instrument": model.name}
    return {BUDGET_HISTORIES: budget_histories(budget)}, extras


EXTRA_UNITS = {"budget": "1", **{name: "1" for name in SOURCES}}
"""Units of the extras (the budget's keys are source names whose values are shares; the map is flat by key)."""


def evaluate(cases: Cases, histories: bool = False) -> dict[str, np.ndarray] | Evaluation:
    """Every output of :data:`OUTPUTS` for a batch of cases (SI arrays of length ``len(cases)``).

    The covariance analysis runs once per distinct case, and the distinct cases of one duration, output step
    and vertical channel in one batch (:func:`~schuler.mission.covariance.covariance_budgets`), so that a
    Monte Carlo whose members draw their cases costs the same per member however many there are.

    Parameters
    ----------
    cases : Cases
        A batch of validated cases (SI values); with ``cases.random`` set, member ``cases.members[i]`` also flies
        the nonlinear INS with its own draws.
    histories : bool
        Also the first case in full (an :class:`~schuler.contract.Evaluation`): the budget's histories
        ``mission_budget`` (:func:`budget_histories`: sigmas in m, m/s, rad, variances in m^2 over ``t_s``),
        ``budget`` (each source's share of the final horizontal position variance, summing to 1),
        ``dominant_source`` and ``instrument`` (the IMU's name).

    Returns
    -------
    dict of str to ndarray, or Evaluation
        Output name -> values of shape (number of cases,), SI (``member_position_error_m`` 0 without random
        streams).

    Examples
    --------
    >>> run = evaluate(Cases.from_case(PARAMETERS.case(imu="navigation", trajectory="stationary",
    ...                                                duration=3600.0)), histories=True)
    >>> round(sum(run.extras["budget"].values()), 9), run.extras["dominant_source"] in run.extras["budget"]
    (1.0, True)
    """
    n = len(cases)
    out = {output.name: np.full(n, np.nan) for output in OUTPUTS}
    out["member_position_error_m"] = np.zeros(n)
    models: dict[str, ErrorModel] = {}
    first: tuple[dict, dict] = ({}, {})
    for shape_index, shape_group in cases.groups(*_SHAPE_KEYS):
        distinct = list(shape_group.groups(*_BUDGET_KEYS))
        setups = []
        for _, group in distinct:
            values = _values(group, 0)
            if values["imu"] not in models:
                models[values["imu"]] = error_model(values["imu"])
            setups.append(mission_setup(values, model=models[values["imu"]]))
        for (index, group), setup, budget in zip(distinct, setups, covariance_budgets(setups)):
            rows = shape_index[index]
            for name, value in budget_outputs(budget).items():
                out[name][rows] = value
            if histories and rows[0] == 0:
                first = _in_full(budget, setup.error_model)
            if cases.random is not None:
                for rate_index, members in group.groups("imu_rate"):
                    rate = float(members.float("imu_rate")[0])
                    result = run_members(setup, members.members, cases.random, rate, output_step=setup.duration)
                    out["member_position_error_m"][rows[rate_index]] = final_horizontal_errors(result)
    if not histories:
        return out
    return Evaluation(out, histories=first[0], extras=first[1], units=EXTRA_UNITS)


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


__all__ = ["OUTPUTS", "PARAMETERS", "budget_histories", "budget_outputs", "evaluate",
           "member_bytes"]
