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

import dataclasses
import math

import numpy as np

from schuler.aided.evaluation import PARAMETERS as AIDED_PARAMETERS
from schuler.aided.evaluation import (
    SIMULATED_OUTAGE_START,
    SIMULATED_SIGMA,
    SIMULATED_VELOCITY_SIGMA,
)
from schuler.contract import Cases, Evaluation, Output
from schuler.core.response import Histories
from schuler.imu.error_model import ErrorModel
from schuler.imu.spec import GRADES
from schuler.mission.aided_monte_carlo import OUTAGE_SLOTS, aided_members, member_outputs
from schuler.mission.aiding import AidedBudget, aided_budget
from schuler.mission.covariance import CovarianceBudget, covariance_budgets
from schuler.mission.monte_carlo import final_horizontal_errors, run_members
from schuler.mission.plots import BUDGET_HISTORIES
from schuler.mission.setup import (
    AIDING_NAMES,
    AIDING_SOURCES,
    ALIGNMENTS,
    CALIBRATIONS,
    SOURCES,
    TRAJECTORIES,
    VERTICAL_CHANNELS,
    MissionSetup,
    error_model,
    mission_setup,
)
from schuler.navigate.mechanization import estimate_memory
from schuler.params import Case, Parameter, ParameterSet

_AIDED_HELP = {
    **{f"gnss_sigma_{axis}": f"GNSS position 1-sigma, {axis} (not set: {sigma:g} m)."
       for axis, sigma in zip(("north", "east", "down"), SIMULATED_SIGMA)},
    "gnss_velocity_sigma": f"GNSS velocity 1-sigma, each axis (not set: {SIMULATED_VELOCITY_SIGMA:g} m/s).",
    **{f"lever_arm_{axis}": f"IMU to GNSS antenna, body {axis} ({name}) (not set: 0)."
       for axis, name in zip("xyz", ("forward", "right", "down"))},
    "outage_start": f"Start of the first GNSS outage, from the start of navigation (not set: "
                    f"{SIMULATED_OUTAGE_START:g} s).",
    "covariance_interval": "Covariance step of the aided filter (the GNSS, zero-velocity and odometer intervals "
                           "whole numbers of them; the Monte Carlo's a whole number of IMU intervals).",
    "zupt_rate": "Rate of the zero-velocity updates during the drive's stops (its interval a whole number of "
                 "covariance steps).",
    "odometer_rate": "Rate of the odometer and of the non-holonomic constraint (its interval a whole number of "
                     "covariance steps).",
}
"""The help of schuler aided's options where the mission's differs (no files)."""

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
    Parameter("trajectory", "", "great-circle", "Mission: stationary, great-circle (a geodesic at the speed, as in "
              "schuler navigate), flight (take-off run, two 90-deg turns) or drive (a car's: four stops, 10 m/s in "
              "town, 20 m/s on the road, 90-deg turns; its own speeds).", choices=TRAJECTORIES, kind="choice",
              renamed_choices=(("cruise", "great-circle"),)),
    Parameter("profile", "", None, "Waypoint profile FILE.toml (format: schuler.navigate.profile) flown instead of "
              "the trajectory; its [start] and first heading set the start point and heading.", kind="text"),
    Parameter("duration", "s", 7200.0, "Mission duration (after the alignment).", minimum=60, maximum=10 * 86400),
    Parameter("speed", "m/s", 250.0, "Ground speed of the great circle and the flight.", minimum=0, maximum=1000),
    Parameter("heading", "deg", 30.0, "Heading at the start.", minimum=-360, maximum=360),
    Parameter("vertical_channel", "", "off", "Vertical channel: off (height held, as by an altimeter) or free.",
              choices=VERTICAL_CHANNELS, kind="choice"),
    Parameter("output_step", "s", 60.0, "Step of the histories (the covariance is exact within it).",
              minimum=1, maximum=3600),
    Parameter("initial_position_error", "m", 0.0, "1-sigma error of the start position, north and east each.",
              minimum=0, maximum=1e5),
    Parameter("imu_rate", "Hz", 2.0, "IMU rate of the Monte Carlo's nonlinear INS (reduced: exact for the "
              "noise, ample for the smooth trajectories).", minimum=0.1, maximum=1000),
    Parameter("aiding", "", None, "Aiding after the alignment, comma-separated: " + ", ".join(AIDING_NAMES)
              + " (not set: free-inertial; the filter, GNSS, stops and wheels of schuler aided, the vertical channel "
              "aided by the GNSS height; gnss-position needed; zupt, odometer and nhc on the drive only).",
              kind="text"),
    *(dataclasses.replace(AIDED_PARAMETERS[name], help=_AIDED_HELP.get(name, AIDED_PARAMETERS[name].help))
      for name in ("gnss_rate", "gnss_sigma_north", "gnss_sigma_east", "gnss_sigma_down", "gnss_velocity_sigma",
                   "lever_arm_x", "lever_arm_y", "lever_arm_z", "outage_start", "outage_duration", "outage_every",
                   "outages", "covariance_interval", "zupt_rate", "zupt_sigma", "odometer_rate", "odometer_sigma",
                   "nhc_sigma", "wheel_lever_arm_x", "wheel_lever_arm_y", "wheel_lever_arm_z")),
), owner="mission", exclusive=(*(("profile", name) for name in ("trajectory", "latitude", "longitude", "height",
                                                                "heading", "speed")),
                               *(("outages", name) for name in ("outage_start", "outage_duration", "outage_every"))),
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
    Output("outage_horizontal_error_sigma_m", "m", "",
           "1-sigma horizontal position error at the end of the worst GNSS outage (free-inertial: the whole "
           "navigation is one, the final 1-sigma; 0 when aided without outages)"),
    *(Output(f"member_outage_{k}_horizontal_error_{kind}_m", "m", "",
             f"aided Monte Carlo: a member's horizontal error {what} outage {k} (0 without it or in the nominal "
             "case)")
      for k in range(1, OUTAGE_SLOTS + 1) for kind, what in (("end", "at the end of"), ("max", "largest in"))),
)

_MEMBER_OUTPUTS = tuple(output.name for output in OUTPUTS if output.name.startswith("member_"))
"""The outputs of a Monte Carlo member (0 in the nominal case)."""

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


def _in_full(budget: CovarianceBudget, model: ErrorModel, aided: AidedBudget | None) -> tuple[dict, dict]:
    """The first case's budget in full: histories and JSON-safe extras (with aiding, each outage's end)."""
    shares = budget.shares()
    extras: dict = {"budget": shares, "dominant_source": max(shares, key=lambda name: shares[name]),
                    "instrument": model.name}
    if aided is not None:
        extras["outages"] = [{key: outage[key] for key in ("start_s", "duration_s", "horizontal_error_sigma_m",
                                                           "shares")} for outage in aided.outages]
    return {BUDGET_HISTORIES: budget_histories(budget)}, extras


EXTRA_UNITS = {"budget": "1", **{name: "1" for name in SOURCES + AIDING_SOURCES}, "outages": "1", "start_s": "s",
               "duration_s": "s", "horizontal_error_sigma_m": "m", "shares": "1"}
"""Units of the extras (the budget's keys are source names whose values are shares; the map is flat by key)."""


def _budgets(setups: list[MissionSetup]) -> list[tuple[CovarianceBudget, AidedBudget | None]]:
    """Each mission's budget: the free-inertial ones batched, the aided ones through their filter one by one."""
    free = [setup for setup in setups if setup.aiding is None]
    batched = iter(covariance_budgets(free))
    out: list[tuple[CovarianceBudget, AidedBudget | None]] = []
    for setup in setups:
        if setup.aiding is None:
            out.append((next(batched), None))
        else:
            aided = aided_budget(setup)
            out.append((aided.budget, aided))
    return out


def evaluate(cases: Cases, histories: bool = False) -> dict[str, np.ndarray] | Evaluation:
    """Every output of :data:`OUTPUTS` for a batch of cases (SI arrays of length ``len(cases)``).

    The covariance analysis runs once per distinct case, and the distinct free-inertial cases of one duration,
    output step and vertical channel in one batch (:func:`~schuler.mission.covariance.covariance_budgets`), so
    that a Monte Carlo whose members draw their cases costs the same per member however many there are. An aided
    case (``aiding`` set) runs :func:`~schuler.mission.aiding.aided_budget`, and its Monte Carlo members
    ``schuler aided``'s filter (:mod:`schuler.mission.aided_monte_carlo`).

    Parameters
    ----------
    cases : Cases
        A batch of validated cases (SI values); with ``cases.random`` set, member ``cases.members[i]`` also flies
        the nonlinear INS with its own draws.
    histories : bool
        Also the first case in full (an :class:`~schuler.contract.Evaluation`): the budget's histories
        ``mission_budget`` (:func:`budget_histories`: sigmas in m, m/s, rad, variances in m^2 over ``t_s``),
        ``budget`` (each source's share of the final horizontal position variance, summing to 1),
        ``dominant_source``, ``instrument`` (the IMU's name) and, aided, ``outages`` (per outage ``start_s``,
        ``duration_s`` in s, ``horizontal_error_sigma_m`` in m at its end and ``shares``, each source's fraction
        of that variance).

    Returns
    -------
    dict of str to ndarray, or Evaluation
        Output name -> values of shape (number of cases,), SI (``member_position_error_m`` 0 without random
        streams, as are the ``member_outage_*`` outputs).

    Examples
    --------
    >>> run = evaluate(Cases.from_case(PARAMETERS.case(imu="navigation", trajectory="stationary",
    ...                                                duration=3600.0)), histories=True)
    >>> round(sum(run.extras["budget"].values()), 9), run.extras["dominant_source"] in run.extras["budget"]
    (1.0, True)
    """
    n = len(cases)
    out = {output.name: np.full(n, np.nan) for output in OUTPUTS}
    for name in _MEMBER_OUTPUTS:
        out[name] = np.zeros(n)
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
        for (index, group), setup, (budget, aided) in zip(distinct, setups, _budgets(setups)):
            rows = shape_index[index]
            summary = budget_outputs(budget)
            for name, value in summary.items():
                out[name][rows] = value
            out["outage_horizontal_error_sigma_m"][rows] = summary["position_error_sigma_m"] if aided is None \
                else max((o["horizontal_error_sigma_m"] for o in aided.outages), default=0.0)
            if histories and rows[0] == 0:
                first = _in_full(budget, setup.error_model, aided)
            if cases.random is not None:
                for rate_index, members in group.groups("imu_rate"):
                    rate = float(members.float("imu_rate")[0])
                    target = rows[rate_index]
                    if aided is not None and setup.aiding is not None:
                        run, errors = aided_members(setup, members.members, cases.random, rate, aided.start_sigma)
                        for name, drifts in member_outputs(run, errors, setup.aiding.outages).items():
                            out[name][target] = drifts
                    else:
                        result = run_members(setup, members.members, cases.random, rate, output_step=setup.duration)
                        out["member_position_error_m"][target] = final_horizontal_errors(result)
    if not histories:
        return out
    return Evaluation(out, histories=first[0], extras=first[1], units=EXTRA_UNITS)


AIDED_STEP_BYTES = 2 * 8 * (21 * 21 + 12)
"""Bytes an aided member holds per covariance step: the filter's stored covariance and sensor estimates, twice
(the list of steps and its stacked copy)."""


def member_bytes(case: Case) -> int:
    """Memory one Monte Carlo member holds: its outputs and a block of noise and truth, bytes.

    Free-inertial, the estimate assumes two output points per member (the Monte Carlo keeps only the start and
    the end) and a block of 4096 IMU intervals, whatever the duration and rate. Aided, the filter stores its
    covariance at every covariance step and fix (:data:`AIDED_STEP_BYTES` each) and the member's increments
    (6 doubles per IMU interval).

    Parameters
    ----------
    case : Case
        The member's parameters, SI (``aiding``; ``duration`` and ``covariance_interval`` in s, ``imu_rate`` and
        ``gnss_rate`` in Hz).

    Returns
    -------
    int
        Memory, bytes.
    """
    fixed = int(estimate_memory(1, 2, 4096, True)) + 64 * 1024
    if case["aiding"] is None:
        return fixed
    events = case["duration"] * (1.0 / case["covariance_interval"] + case["gnss_rate"])
    return fixed + int(AIDED_STEP_BYTES * events + 6 * 8 * case["duration"] * case["imu_rate"])


__all__ = ["OUTPUTS", "PARAMETERS", "budget_histories", "budget_outputs", "evaluate",
           "member_bytes"]
