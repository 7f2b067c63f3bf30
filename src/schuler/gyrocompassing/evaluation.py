"""What the gyrocompassing system evaluates: its parameters, outputs and ``evaluate``.

Parameters are declared once in :data:`PARAMETERS`; :func:`evaluate` is the
vectorised evaluation of many cases (sweeps, Monte Carlo) and, with
``histories=True``, of one case in full (the chosen model's time histories).

Fidelities: ``simulated`` (default) takes the azimuth and level errors, the
settling time in the 1 % band and the constraint check from the exact
simulation of the chosen model over ``duration``; ``closed`` takes the errors
from the model's closed-form steady state and leaves the simulated-only outputs
NaN. Monte Carlo members draw the residual drifts about the platform x, y axes
(``sigma_drift``), about z (``sigma_drift_z``) and the accelerometer biases
(``sigma_accel``) independently around the case's values.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from schuler.contract import Cases, Evaluation, Output
from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY
from schuler.core.geometry import grid_points
from schuler.core.gyrocompass_design import DESIGN_DAMPING, DESIGN_TIME_CONSTANT
from schuler.core.response import Histories
from schuler.gyrocompassing import analytic, models
from schuler.gyrocompassing.case import (
    DEFAULT_INITIAL_AZIMUTH_ERROR,
    DEFAULT_MAX_LATITUDE,
    MAX_DURATION,
    AlignmentCase,
    analytic_results,
    automatic_duration,
)
from schuler.gyrocompassing.simulation import MAX_TIME_POINTS, evaluate_cases
from schuler.gyrocompassing.simulation import run_case as simulate_case
from schuler.memory import require
from schuler.params import Case, Parameter, ParameterSet

_ERROR_LIMIT = 600.0
"""Largest latitude error and initial level error accepted, arcmin (either sign)."""

_DRIFT_LIMIT = 15.0
"""Largest residual drift accepted, deg/h (either sign): about the Earth's rate, 15.04 deg/h, which the loop
compares it with; an east drift that large leaves no north to find (the azimuth error is 90 deg or more)."""

_DRIFT_RANGE = f" Within about the Earth's rate ({_DRIFT_LIMIT:g} deg/h): a larger drift leaves no north to find."

PARAMETERS = ParameterSet((
    Parameter("latitude", "deg", 50.0, "Latitude of the site.", minimum=-90, maximum=90,
              exclusive_minimum=True, exclusive_maximum=True),
    Parameter("azimuth", "deg", 0.0, "Azimuth A of the platform's x_g axis.", minimum=-360, maximum=360),
    Parameter("drift_east", "deg/h", 0.0, "Residual drift about east, Delta omega_dxi (estimate - true)."
              + _DRIFT_RANGE, minimum=-_DRIFT_LIMIT, maximum=_DRIFT_LIMIT),
    Parameter("drift_north", "deg/h", 0.0, "Residual drift about north, Delta omega_deta." + _DRIFT_RANGE,
              minimum=-_DRIFT_LIMIT, maximum=_DRIFT_LIMIT),
    Parameter("drift_x", "deg/h", 0.0, "Residual drift about the platform x axis (adds to east/north)."
              + _DRIFT_RANGE, minimum=-_DRIFT_LIMIT, maximum=_DRIFT_LIMIT),
    Parameter("drift_y", "deg/h", 0.0, "Residual drift about the platform y axis (adds to east/north)."
              + _DRIFT_RANGE, minimum=-_DRIFT_LIMIT, maximum=_DRIFT_LIMIT),
    Parameter("drift_z", "deg/h", 0.0, "Residual drift about the platform z axis (up)." + _DRIFT_RANGE,
              minimum=-_DRIFT_LIMIT, maximum=_DRIFT_LIMIT),
    Parameter("latitude_error", "arcmin", 0.0, "Error Delta phi of the latitude entered.",
              minimum=-_ERROR_LIMIT, maximum=_ERROR_LIMIT),
    Parameter("accel_bias_x", "g", 0.0, "Bias Delta a_x of the x accelerometer (measured - true).",
              minimum=-0.1, maximum=0.1),
    Parameter("accel_bias_y", "g", 0.0, "Bias Delta a_y of the y accelerometer (measured - true).",
              minimum=-0.1, maximum=0.1),
    Parameter("time_constant", "s", DESIGN_TIME_CONSTANT,
              "Time constant T of the azimuth loop (gains not given follow from T and zeta).",
              minimum=0.1, maximum=1e5),
    Parameter("damping", "", DESIGN_DAMPING, "Damping ratio zeta of the azimuth loop.",
              minimum=0.01, maximum=100),
    Parameter("c_gamma", "1/s", None, "Level correction gain c_Gamma (not set: 2 zeta / T).",
              minimum=1e-6, maximum=100),
    Parameter("c_a", "1/s", None, "Azimuth correction gain c_a (not set: 1 / (T^2 U cos(latitude))).",
              minimum=1e-6, maximum=1e8),
    Parameter("initial_azimuth_error", "deg", math.degrees(DEFAULT_INITIAL_AZIMUTH_ERROR),
              "Initial azimuth misalignment delta0.", minimum=-90, maximum=90),
    Parameter("initial_beta", "arcmin", 0.0, "Initial level error beta0 (0: levelled).",
              minimum=-_ERROR_LIMIT, maximum=_ERROR_LIMIT),
    Parameter("initial_alpha", "arcmin", 0.0, "Initial level error alpha0 (0: levelled).",
              minimum=-_ERROR_LIMIT, maximum=_ERROR_LIMIT),
    Parameter("model", "", "full", "Model: full (mu, nu) (1.17), full-ab (beta, alpha) (1.18) or simplified (1.19).",
              choices=models.MODELS, kind="choice"),
    Parameter("duration", "s", None,
              "Simulated time (not set: 2 h, or 3 settling times if longer, at most 48 h).",
              minimum=0, exclusive_minimum=True, maximum=MAX_DURATION),
    Parameter("output_step", "s", 1.0, "Output step (the simulation is exact between outputs).",
              minimum=1e-3, maximum=3600),
    Parameter("max_latitude", "deg", math.degrees(DEFAULT_MAX_LATITUDE),
              "Latitude above which azimuth is reported not observable.", minimum=0, maximum=90,
              exclusive_minimum=True, exclusive_maximum=True),
    Parameter("sigma_drift", "deg/h", 0.01, "Monte Carlo: 1-sigma of the x and y residual drifts.", minimum=0),
    Parameter("sigma_drift_z", "deg/h", 0.01, "Monte Carlo: 1-sigma of the z residual drift.", minimum=0),
    Parameter("sigma_accel", "g", 1e-4, "Monte Carlo: 1-sigma of each accelerometer bias.", minimum=0),
), owner="align",
   renamed={"time_step": "output_step", "accel_error_x": "accel_bias_x", "accel_error_y": "accel_bias_y"})
"""Every option of ``schuler align run`` (and key of an ``align`` scenario)."""

OUTPUTS = (
    Output("azimuth_error_rad", "rad", "arcmin", "azimuth error delta of the model at the end (steady state)"),
    Output("azimuth_error_analytic_rad", "rad", "arcmin", "steady state delta_y of (1.21)"),
    Output("full_minus_simplified_rad", "rad", "arcsec",
           "closed-form steady state of the full model minus (1.21): what alpha U_z adds"),
    Output("level_error_beta_rad", "rad", "arcmin", "level error beta of the model at the end"),
    Output("level_error_beta_analytic_rad", "rad", "arcmin", "steady state beta_y of (1.25)"),
    Output("azimuth_error_sigma_rad", "rad", "arcmin",
           "1-sigma of the model's steady azimuth error for the Monte Carlo sigmas"),
    Output("azimuth_error_sigma_simplified_rad", "rad", "arcmin", "the same from (1.21), drifts only"),
    Output("settling_time_s", "s", "", "settling time 5/h (or the corrected aperiodic formula)"),
    Output("settling_time_simulated_s", "s", "", "last exit from the 1 % band (simulated; inf: not settled)"),
    Output("c_gamma", "1/s", "", "level correction gain used"),
    Output("c_a", "1/s", "", "azimuth correction gain used"),
    Output("design_time_constant_s", "s", "", "time constant T of the gains used"),
    Output("design_damping", "1", "", "damping ratio zeta of the gains used"),
    Output("max_abs_delta_rad", "rad", "", "largest |delta| over the run (simulated)"),
    Output("max_abs_beta_rad", "rad", "", "largest |beta| over the run (simulated)"),
    Output("max_abs_delta_rate_rad_s", "rad/s", "", "largest |delta'| over the run (simulated)"),
    Output("constraints_ok", "1", "", "1 when |delta| < 0.4 rad, |beta| < 0.01 rad, |delta'| < 0.2 rad/s throughout"),
    Output("simulated_duration_s", "s", "", "simulated time"),
)

FIDELITIES = ("simulated", "closed")

_CHUNK_MEMBERS = 2_000
"""Members the engine simulates at once (it streams longer batches chunk by chunk)."""

_CASE_FIELDS = ("latitude", "azimuth", "drift_east", "drift_north", "drift_x", "drift_y", "drift_z",
                "latitude_error", "time_constant", "damping", "c_gamma", "c_a", "initial_azimuth_error",
                "initial_beta", "initial_alpha")


def alignment_case(cases: Cases) -> AlignmentCase:
    """The :class:`~schuler.gyrocompassing.AlignmentCase` of a batch, random terms drawn for members.

    Parameters
    ----------
    cases : Cases
        A batch of validated cases (SI values; random terms from ``cases.random``).
    """
    arrays = {name: cases.float(name) for name in _CASE_FIELDS}
    arrays["accel_error_x"] = cases.float("accel_bias_x")
    arrays["accel_error_y"] = cases.float("accel_bias_y")
    if cases.random is not None:
        draw = cases.random.normal
        for name, sigma in (("drift_x", "sigma_drift"), ("drift_y", "sigma_drift"), ("drift_z", "sigma_drift_z"),
                            ("accel_error_x", "sigma_accel"), ("accel_error_y", "sigma_accel")):
            arrays[name] = arrays[name] + cases.float(sigma) * draw(name, cases.members)
    max_latitude = cases.float("max_latitude")
    # the system has no Earth parameters: the model's constants, named so that only
    # the per-case arrays go through **arrays
    return AlignmentCase(**arrays, max_latitude=float(max_latitude.max()) if max_latitude.size else
                         DEFAULT_MAX_LATITUDE, earth_rate=EARTH_RATE, gravity=STANDARD_GRAVITY)


def single_case(case) -> AlignmentCase:
    """The :class:`AlignmentCase` of one validated case of the system (no arrays).

    Parameters
    ----------
    case : mapping
        A validated case of the system's parameters (SI values).
    """
    return _first(alignment_case(Cases.from_case(case)))


def _first(aligned: AlignmentCase) -> AlignmentCase:
    """The first case of a batch (with the random terms it drew)."""
    return AlignmentCase(**{f: (v[0] if isinstance(v, np.ndarray) else v) for f, v in vars(aligned).items()})


def evaluate(cases: Cases, histories: bool = False) -> dict[str, np.ndarray] | Evaluation:
    """Every output of :data:`OUTPUTS` for a batch of cases (SI arrays of length ``len(cases)``).

    With ``histories`` also the first case's time histories (``align_time_history``: delta, beta, delta', and
    the level angles of the full models, rad and rad/s) and its ``model``, ``regime`` and ``constraint_violations``
    (``constraints_ok`` a flag there).

    Cases are grouped by model, duration and output step (each group is one
    batched simulation on the engine), so swept durations and steps hold per case.

    Parameters
    ----------
    cases : Cases
        A batch of validated cases (SI values; random terms from ``cases.random`` at ``cases.members``).
    histories : bool
        Whether to give the first case in full (an :class:`~schuler.contract.Evaluation`).
    """
    n = len(cases)
    out = {output.name: np.full(n, np.nan) for output in OUTPUTS}
    fidelity = cases.fidelity or FIDELITIES[0]
    # a duration not set is the case's own automatic one, so a batch gives what each case alone gives
    settling = analytic_results(alignment_case(cases), "simplified")["settling_time_s"]
    automatic = np.array([automatic_duration(t) for t in np.broadcast_to(settling, (n,))])
    resolved = Cases({**{name: cases[name] for name in cases.names}, "duration": cases.value_or("duration", automatic)},
                     members=cases.members, random=cases.random, fidelity=cases.fidelity)
    for index, group in resolved.groups("model", "duration", "output_step", "max_latitude"):
        part = _evaluate_group(group, fidelity)
        for name, values in part.items():
            out[name][index] = values
    return _histories(cases, out, fidelity) if histories else out


def _evaluate_group(cases: Cases, fidelity: str) -> dict[str, np.ndarray]:
    model = str(cases["model"][0])
    case = alignment_case(cases)
    duration, step = float(cases.float("duration")[0]), float(cases.float("output_step")[0])
    simulate = fidelity == "simulated"
    if simulate:
        # the grid checked under this system's names before the simulation builds it
        points = grid_points(duration, step, names=("duration", "output_step"), max_points=MAX_TIME_POINTS)
        require(points * 8 * 6 * min(len(cases), _CHUNK_MEMBERS), "this simulation",
                "`duration` or `output_step` (or `fidelity` closed)")
    result = evaluate_cases(case, model, simulate_runs=simulate, duration=duration, time_step=step)
    full = analytic_results(case, "full-ab")["azimuth_error_rad"]
    c_gamma, c_a = result["c_gamma"], result["c_a"]
    system = case.model(model)
    gains = analytic.steady_state_gain_matrix(system.A, system.B)[..., list(system.states).index("delta"), :]
    sigmas = np.stack([cases.float("sigma_drift"), cases.float("sigma_drift"), cases.float("sigma_drift_z"),
                       np.zeros(len(cases)), cases.float("sigma_accel"), cases.float("sigma_accel")], axis=-1)
    out = {
        "azimuth_error_rad": result["azimuth_error_simulated_rad" if simulate else "azimuth_error_rad"],
        "azimuth_error_analytic_rad": result["azimuth_error_analytic_rad"],
        "full_minus_simplified_rad": full - result["azimuth_error_analytic_rad"],
        "level_error_beta_rad": result["level_error_beta_simulated_rad" if simulate else "level_error_beta_rad"],
        "level_error_beta_analytic_rad": result["level_error_beta_analytic_rad"],
        "azimuth_error_sigma_rad": np.sqrt(np.sum((gains * sigmas) ** 2, axis=-1)),
        "azimuth_error_sigma_simplified_rad": analytic.azimuth_error_sigma(
            case.latitude, c_gamma, c_a, cases.float("sigma_drift"), cases.float("sigma_drift_z"), 0.0,
            case.earth_rate),
        "settling_time_s": result["settling_time_s"],
        "c_gamma": c_gamma,
        "c_a": c_a,
        "design_time_constant_s": result["time_constant_s"],
        "design_damping": result["damping"],
    }
    if simulate:
        out.update({key: result[key] for key in ("settling_time_simulated_s", "max_abs_delta_rad", "max_abs_beta_rad",
                                                 "max_abs_delta_rate_rad_s")})
        out.update({
            "constraints_ok": np.asarray(result["constraints_ok"], dtype=float),
            "simulated_duration_s": np.full(len(cases), duration),
        })
    return out


def _histories(cases: Cases, outputs: dict[str, np.ndarray], fidelity: str) -> Evaluation:
    """The first case in full: its outputs, the model's time histories and the structured results beside them."""
    case = cases.case(0)
    scalars = {name: float(values[0]) for name, values in outputs.items()}
    if not math.isnan(scalars["constraints_ok"]):
        # the run's flag reads as a flag (True, shown yes/no) where a batch carries it as 1.0 / 0.0
        outputs = {**outputs, "constraints_ok": outputs["constraints_ok"].astype(bool)}
    extras: dict = {"model": case["model"], "regime": _regime(scalars["c_gamma"], scalars["c_a"], case["latitude"]),
                    "constraint_violations": []}
    if fidelity != "simulated":
        return Evaluation(outputs, extras=extras)
    require(member_bytes(case) * 3, "this run's histories", "`duration` or `output_step`")
    with warnings.catch_warnings():
        # evaluate has warned about the latitude already; the histories are the same case
        warnings.filterwarnings("ignore", message=r"latitude .* accuracy degrades")
        run = simulate_case(_first(alignment_case(cases)), case["model"], duration=scalars["simulated_duration_s"],
                            time_step=case["output_step"])
    extras["constraint_violations"] = list(run.violations)
    channels = {"delta_rad": run.delta, "beta_rad": run.beta, "delta_rate_rad_s": run.delta_rate}
    # the level angles of the full models (None on the simplified one)
    level = {"alpha_rad": run.alpha, "mu_rad": run.mu, "nu_rad": run.nu}
    channels.update({name: values for name, values in level.items() if values is not None})
    units = {name: "rad/s" if name.endswith("_rad_s") else "rad" for name in channels}
    return Evaluation(outputs, histories={"align_time_history": Histories(run.time, channels, units)}, extras=extras)


def _regime(c_gamma: float, c_a: float, latitude: float) -> str:
    h_sq = (c_gamma / 2) ** 2
    omega0_sq = c_a * math.cos(latitude) * EARTH_RATE
    if math.isclose(h_sq, omega0_sq, rel_tol=1e-9):
        return "critical"
    return "oscillatory" if omega0_sq > h_sq else "aperiodic"


def member_bytes(case: Case) -> int:
    """Memory one member holds while simulated: its history of 3 states and 3 outputs, 8 bytes each.

    Parameters
    ----------
    case : Case
        A validated case (SI values).
    """
    duration = case["duration"] or MAX_DURATION
    return int(6 * 8 * (duration / case["output_step"] + 2))


__all__ = ["FIDELITIES", "OUTPUTS", "PARAMETERS", "alignment_case", "evaluate", "member_bytes", "single_case"]
