"""What the gyro vertical evaluates: its parameters, outputs and ``evaluate``.

Source: Drozdovich (1959) (:data:`schuler.references.DROZDOVICH_1959`); every
equation number below is that paper's.

Frames and signs are the model's (:mod:`schuler.gyro_vertical.model`): the
horizontal frame x0 y0 z0 with z0 *up* and x0 along the outer gimbal axis at the
azimuth ``azimuth`` (theta, clockwise from north), the velocity at
``velocity_angle`` (gamma) from x0 toward y0; tilts alpha about x (outer gimbal)
and beta about y (inner gimbal); velocity errors are measured (integrator output)
minus true, Delta v = V - v.

Parameters (SI inside; a bare number is read in the display unit shown by
``--help``, durations and steps in seconds) and how they map to the source and to
the names used before the contract:

==========================  ========================  ==================================================
parameter                   source symbol             formerly
==========================  ========================  ==================================================
``duration``                t (s)                     ``duration`` (a bare number was hours)
``output_step``             -                         ``output_step`` (``step`` in scenario files)
``speed_profile``           v(t)                      bare times were hours, now seconds
``accel_bias_x``, ``_y``    b_x, b_y (measured-true)  ``accelerometer_bias_x``, ``_y`` (bare m/s^2, now g)
``drift_x``, ``drift_y``    eps_x, eps_y              ``gyro_drift_x``, ``_y``
==========================  ========================  ==================================================

``drift_x`` and ``drift_y`` are platform drifts with the source's sign: the rates
at which the vertical turns away about its x and y axes (they add to alpha' and
beta' in the equations of :mod:`~schuler.gyro_vertical.model`), i.e. minus the
gyro biases resolved in the platform axes (``docs/conventions.md``).

Fidelities
----------
``simulated`` (default): the velocity-error statistics come from the simulation
of the full equations (5)-(13), (19) along the great circle (matrix exponential
on a stationary path, DOP853 otherwise), and the split Schuler periods are also
fitted to it. ``closed``: the systematic velocity error is the quasi-steady error
(29) along the same path (the forced motion (26), no oscillation about it);
the outputs only a simulation gives are NaN.

Outputs present in both fidelities are closed forms at the start of the path:
the transport and Coriolis acceleration W* (21), the forced tilts and the
slowly-varying velocity error of (29), the split Schuler periods of (27) and
their beat, the initial-tilt amplitude of (23).
"""

from __future__ import annotations

import sys
from types import SimpleNamespace
from typing import Any

import numpy as np

from schuler.contract import Cases, Evaluation, Output
from schuler.core.earth import PRESETS
from schuler.core.geometry import grid_points, time_grid
from schuler.core.response import Histories
from schuler.exceptions import InvalidParameter
from schuler.gyro_vertical.model import GyroVertical, forcing
from schuler.gyro_vertical.quasi_steady import (
    analyse,
    quasi_steady_response,
    split_schuler_frequencies,
    steady_errors,
)
from schuler.gyro_vertical.trajectory import (
    GreatCircleTrajectory,
    SpeedProfile,
    start_kinematics,
    transport_coriolis_acceleration,
)
from schuler.memory import require
from schuler.params import Case, Parameter, ParameterSet
from schuler.units import parse_quantity

MAX_DURATION = 60 * 86400.0
"""Longest simulated time, s (60 days)."""

POINT_BYTES = 800
"""Memory one output point of a simulated case holds at its peak, bytes: the response
and the quasi-steady error (about 20 arrays), the 8-fold zero-padded spectrum of the
oscillation and the temporaries of the solver's dense output. Measured with
tracemalloc: 510-700 bytes per point (12 h to 48 h, output steps 0.2 s to 30 s)."""
CLOSED_POINT_BYTES = 320
"""The same for the quasi-steady error (29) alone (``fidelity="closed"``): 230-270 bytes measured."""
CASE_BYTES = 4 * 2**20
"""Memory of a simulated case that does not grow with its output points (solver steps,
the decimated mode fit), bytes."""

GRID_NAMES = ("duration", "output_step")
"""The output grid's parameters, as the core's time grid (:func:`schuler.core.geometry.time_grid`) names them."""

PARAMETERS = ParameterSet((
    Parameter("latitude", "deg", 60.0, "Latitude phi of the start.", minimum=-90, maximum=90),
    Parameter("azimuth", "deg", 0.0, "Azimuth theta of the x0 axis (outer gimbal axis) at the start, "
              "clockwise from north.", minimum=-360, maximum=360),
    Parameter("velocity_angle", "deg", 90.0, "Angle gamma from x0 to the velocity, positive toward y0 "
              "(with azimuth 0, 90 deg is due west: the source's example).", minimum=-360, maximum=360),
    Parameter("speed", "m/s", 10.0, "Constant speed along the great circle (below the orbital speed "
              "sqrt(g R)).", minimum=0),
    Parameter("speed_profile", "", None, "Piecewise-linear speed instead of --speed: 'TIME: SPEED, ...' "
              "(bare times in s, speeds in m/s), e.g. '0: 0, 1 h: 10, 24 h: 10, 25 h: 20'.", kind="text"),
    Parameter("duration", "s", "48 h", "Simulated time.", minimum=0, maximum=MAX_DURATION,
              exclusive_minimum=True),
    Parameter("output_step", "s", 10.0, "Interval of the output samples.", minimum=0, exclusive_minimum=True),
    Parameter("earth", "", "default", "Earth constants (drozdovich: the source's R = 6.4e6 m, g = 9.81 m/s^2, "
              "Omega = 7.3e-5 1/s).", choices=tuple(PRESETS), kind="choice"),
    Parameter("initial_alpha", "arcmin", 0.0, "Initial tilt alpha about x (from the start position).",
              minimum=-600, maximum=600),
    Parameter("initial_beta", "arcmin", 0.0, "Initial tilt beta about y (from the start position).",
              minimum=-600, maximum=600),
    Parameter("start", "", "levelled", "Start position: levelled on the accelerometers, or the geocentric "
              "vertical.", choices=("levelled", "geocentric"), kind="choice"),
    Parameter("preset_integrators", "", True, "Preset the integrators to the true initial velocity.", kind="flag"),
    Parameter("accel_bias_x", "g", 0.0, "Bias b_x of the x accelerometer (measured - true).",
              minimum=-0.1, maximum=0.1),
    Parameter("accel_bias_y", "g", 0.0, "Bias b_y of the y accelerometer (measured - true).",
              minimum=-0.1, maximum=0.1),
    Parameter("drift_x", "deg/h", 0.0, "Platform drift eps_x about x (the source's sign: adds to alpha').",
              minimum=-1000, maximum=1000),
    Parameter("drift_y", "deg/h", 0.0, "Platform drift eps_y about y (the source's sign: adds to beta').",
              minimum=-1000, maximum=1000),
    Parameter("compensation", "", "none", "Subtract the transport and Coriolis accelerations W* (21) computed "
              "from the known trajectory.", choices=("none", "trajectory"), kind="choice"),
    Parameter("earth_rate_compensation", "", True, "Apply the Earth-rate torques (8).", kind="flag"),
    Parameter("schuler_tuning", "", 1.0, "kappa = k R / H (1: the Schuler condition (11)); the correction's "
              "period is 84.4 min / sqrt(kappa), from 14 h to 8.4 min over the range: a gyro vertical mistuned "
              "beyond that is not one.", minimum=0.01, maximum=100),
    Parameter("trajectory", "", "great-circle", "Move along the great circle, or freeze latitude and azimuth "
              "(the source's slowly-varying assumption; exact matrix-exponential solution).",
              choices=("great-circle", "frozen"), kind="choice"),
), owner="vertical", exclusive=(("speed", "speed_profile"),), renamed={
    "accelerometer_bias_x": "accel_bias_x", "accelerometer_bias_y": "accel_bias_y", "gyro_drift_x": "drift_x",
    "gyro_drift_y": "drift_y", "step": "output_step"})
"""Every option of ``schuler vertical run`` (and key of a ``vertical`` scenario)."""

FIDELITIES = ("simulated", "closed")

OUTPUTS = (
    Output("end_time_s", "s", "h", "time of the last output sample"),
    Output("final_latitude_rad", "rad", "deg", "latitude at the end of the run"),
    Output("transport_coriolis_x_m_s2", "m/s^2", "", "transport + Coriolis acceleration W*_x (21) at the start"),
    Output("transport_coriolis_y_m_s2", "m/s^2", "", "transport + Coriolis acceleration W*_y (21) at the start"),
    Output("steady_tilt_alpha_rad", "rad", "arcmin", "forced tilt alpha_r = -(W*_y + b_y)/g at the start"),
    Output("steady_tilt_beta_rad", "rad", "arcmin", "forced tilt beta_r = (W*_x + b_x)/g at the start"),
    Output("steady_velocity_error_x_m_s", "m/s", "", "slowly-varying (29) at the start: R (omega_2 alpha_r - eps_y)"),
    Output("steady_velocity_error_y_m_s", "m/s", "", "slowly-varying (29) at the start: R (omega_2 beta_r + eps_x)"),
    Output("quasi_steady_velocity_error_x_mean_m_s", "m/s", "", "mean over the run of the quasi-steady error (29)"),
    Output("quasi_steady_velocity_error_y_mean_m_s", "m/s", "", "mean over the run of the quasi-steady error (29)"),
    Output("velocity_error_x_mean_m_s", "m/s", "", "systematic error: mean of Delta v_x (simulated, or (29))"),
    Output("velocity_error_y_mean_m_s", "m/s", "", "systematic error: mean of Delta v_y (simulated, or (29))"),
    Output("velocity_error_x_rms_m_s", "m/s", "", "rms of Delta v_x over the run (simulated)"),
    Output("velocity_error_y_rms_m_s", "m/s", "", "rms of Delta v_y over the run (simulated)"),
    Output("velocity_error_x_max_abs_m_s", "m/s", "", "largest |Delta v_x| over the run (simulated)"),
    Output("velocity_error_y_max_abs_m_s", "m/s", "", "largest |Delta v_y| over the run (simulated)"),
    Output("velocity_error_x_final_m_s", "m/s", "", "Delta v_x at the end (simulated)"),
    Output("velocity_error_y_final_m_s", "m/s", "", "Delta v_y at the end (simulated)"),
    Output("tilt_alpha_max_abs_rad", "rad", "arcmin", "largest |alpha| over the run (simulated)"),
    Output("tilt_beta_max_abs_rad", "rad", "arcmin", "largest |beta| over the run (simulated)"),
    Output("schuler_period_s", "s", "min", "Schuler period 2 pi sqrt(R / (kappa g)) (11)"),
    Output("split_period_fast_s", "s", "min", "faster split Schuler mode of (27) at the start latitude"),
    Output("split_period_slow_s", "s", "min", "slower split Schuler mode of (27) at the start latitude"),
    Output("beat_period_s", "s", "h", "beat of the split modes 2 pi / |Omega sin phi| (inf at the equator)"),
    Output("fitted_period_fast_s", "s", "min", "faster mode fitted to the simulated oscillation (NaN: no fit)"),
    Output("fitted_period_slow_s", "s", "min", "slower mode fitted to the simulated oscillation (NaN: no fit)"),
    Output("tilt_oscillation_amplitude_m_s", "m/s", "", "initial tilt times sqrt(g R): the amplitude of (23)"),
)
"""What :func:`evaluate` returns for every case (SI)."""


def parse_speed_profile(text: str, label: str = "speed_profile") -> SpeedProfile:
    """Read 'TIME: SPEED, TIME: SPEED, ...' (bare times in s, speeds in m/s; units allowed).

    Parameters
    ----------
    text : str
        The profile, e.g. ``"0: 0, 1 h: 36 km/h"``.
    label : str
        Parameter name used in error messages.

    Examples
    --------
    >>> p = parse_speed_profile("0: 0, 1 h: 36 km/h")
    >>> p.times.tolist(), p.speeds.tolist()
    ([0.0, 3600.0], [0.0, 10.0])
    """
    times, speeds = [], []
    for item in str(text).split(","):
        if ":" not in item:
            raise InvalidParameter(label, f"{item.strip()!r} is not 'TIME: SPEED'")
        time_text, speed_text = item.split(":", 1)
        times.append(parse_quantity(time_text.strip(), "s", name=label))
        speeds.append(parse_quantity(speed_text.strip(), "m/s", name=label))
    try:
        return SpeedProfile(np.array(times), np.array(speeds))
    except InvalidParameter as error:
        raise InvalidParameter(label, error.reason) from None


def _speed(case) -> SpeedProfile:
    profile = case["speed_profile"]
    return parse_speed_profile(profile) if profile else SpeedProfile.constant(case["speed"])


def build_model(case) -> GyroVertical:
    """The :class:`~schuler.gyro_vertical.model.GyroVertical` of a validated case (SI values).

    Parameters
    ----------
    case : Case
        A validated case (SI values).
    """
    earth = PRESETS[case["earth"]]
    profile = case["speed_profile"]
    try:
        path = GreatCircleTrajectory(case["latitude"], case["azimuth"], case["velocity_angle"], _speed(case),
                                     earth.radius, earth.rate, frozen=case["trajectory"] == "frozen")
    except InvalidParameter as error:
        if profile and error.name == "speed":
            raise InvalidParameter("speed_profile", error.reason) from None
        raise
    return GyroVertical(
        path, earth.gravity, case["schuler_tuning"], bool(case["earth_rate_compensation"]),
        case["compensation"] == "trajectory", (case["accel_bias_x"], case["accel_bias_y"]),
        (case["drift_x"], case["drift_y"]), (case["initial_alpha"], case["initial_beta"]),
        case["start"] == "levelled", bool(case["preset_integrators"]),
    )


def member_bytes(case: Case) -> int:
    """Memory one case holds while simulated, bytes (see :data:`POINT_BYTES`).

    Parameters
    ----------
    case : Case
        A validated case (SI values).
    """
    return int(POINT_BYTES * grid_points(case["duration"], case["output_step"], names=GRID_NAMES) + CASE_BYTES)


def evaluate(cases: Cases, histories: bool = False) -> dict[str, np.ndarray] | Evaluation:
    """Every output of :data:`OUTPUTS` for a batch of cases (SI arrays of length ``len(cases)``).

    The closed forms at the start of each path are evaluated for the whole batch
    at once; the simulation (or, with ``fidelity="closed"``, the quasi-steady
    error (29) along the path) runs case by case on each case's own duration and
    output step. The model has no random terms: ``cases.random`` is not used.

    Parameters
    ----------
    cases : Cases
        A batch of validated cases (SI values; random terms from ``cases.random`` at ``cases.members``).
    histories : bool
        Also the first case in full (an :class:`~schuler.contract.Evaluation`): simulated, the histories
        ``vertical_timeseries`` (tilts, latitude, measured and true velocities, velocity errors and the
        quasi-steady error (29)); closed, ``vertical_quasi_steady`` (the forced motion (26), (29), its
        slowly-varying form and W* (21)); extras ``method``, ``nfev``, ``n_steps``, ``fitted_amplitudes_m_s``.

    Examples
    --------
    >>> case = PARAMETERS.case(latitude=np.radians(60), earth="drozdovich", duration=3600.0)
    >>> out = evaluate(Cases.from_case(case, fidelity="closed"))
    >>> round(float(out["steady_velocity_error_y_m_s"][0]), 3), bool(np.isnan(out["velocity_error_y_rms_m_s"][0]))
    (0.557, True)
    >>> list(evaluate(Cases.from_case(case, fidelity="closed"), histories=True).histories)
    ['vertical_quasi_steady']
    """
    outputs, details = _evaluate(cases, keep_histories=histories)
    if not histories:
        return outputs
    stems, extras = run_histories(cases.fidelity or FIDELITIES[0], details[0])
    return Evaluation(outputs, histories=stems, extras=extras)


def _evaluate(cases: Cases, keep_histories: bool) -> tuple[dict[str, np.ndarray], list[Any]]:
    """The outputs of :func:`evaluate`, and with ``keep_histories`` per case its analysis (simulated) or
    quasi-steady error (closed); without, each case's histories are dropped once its outputs are taken, so a
    batch holds one case's histories at a time."""
    n = len(cases)
    fidelity = cases.fidelity or FIDELITIES[0]
    out = {output.name: np.full(n, np.nan) for output in OUTPUTS}
    if n == 0:
        return out, []
    each = [cases.case(i) for i in range(n)]
    out.update(_start_closed_forms(cases, each))
    points = float(np.max(grid_points(cases.float("duration"), cases.float("output_step"), names=GRID_NAMES)))
    per_point = POINT_BYTES if fidelity == "simulated" else CLOSED_POINT_BYTES
    require(per_point * points + CASE_BYTES, "this run", "`duration` or `output_step`")
    details: list[Any] = []
    for i, case in enumerate(each):
        model = build_model(case)
        time = time_grid(case["duration"], case["output_step"], names=GRID_NAMES, max_points=sys.maxsize)  # sized above
        out["end_time_s"][i] = time[-1]
        out["final_latitude_rad"][i] = float(model.trajectory.kinematics(time[-1]).latitude)
        if fidelity == "simulated":
            analysis = analyse(model, time)
            _simulated_outputs(out, i, analysis)
            detail: Any = analysis
        else:
            quasi = quasi_steady_response(model, time)
            for axis, values in (("x", quasi.dv_x), ("y", quasi.dv_y)):
                out[f"quasi_steady_velocity_error_{axis}_mean_m_s"][i] = np.mean(values)
                out[f"velocity_error_{axis}_mean_m_s"][i] = np.mean(values)
            detail = quasi
        if keep_histories:
            details.append(detail)
    # -(0)/g is -0.0: no negative zeros in tables and files
    return {name: values + 0.0 for name, values in out.items()}, details


def _simulated_outputs(out: dict[str, np.ndarray], i: int, analysis) -> None:
    r, quasi = analysis.response, analysis.quasi_steady
    for axis, error, forced in (("x", r.velocity_error_x, quasi.dv_x), ("y", r.velocity_error_y, quasi.dv_y)):
        out[f"velocity_error_{axis}_mean_m_s"][i] = np.mean(error)
        out[f"velocity_error_{axis}_rms_m_s"][i] = np.sqrt(np.mean(error**2))
        out[f"velocity_error_{axis}_max_abs_m_s"][i] = np.max(np.abs(error))
        out[f"velocity_error_{axis}_final_m_s"][i] = error[-1]
        out[f"quasi_steady_velocity_error_{axis}_mean_m_s"][i] = np.mean(forced)
    out["tilt_alpha_max_abs_rad"][i] = np.max(np.abs(r.alpha))
    out["tilt_beta_max_abs_rad"][i] = np.max(np.abs(r.beta))
    if analysis.fit is not None:
        fast, slow = np.sort(analysis.fit.periods)
        out["fitted_period_fast_s"][i], out["fitted_period_slow_s"][i] = fast, slow


def _start_closed_forms(cases: Cases, each: list[Case]) -> dict[str, np.ndarray]:
    """W* (21), the forced tilts and velocity errors of (29), the periods of (27) and (23) at the start."""
    earth = [PRESETS[str(name)] for name in cases["earth"]]
    radius = np.array([e.radius for e in earth])
    gravity = np.array([e.gravity for e in earth])
    rate = np.array([e.rate for e in earth])
    speed = np.array([_speed(case).speeds[0] for case in each], dtype=float)
    kinematics = start_kinematics(cases.float("latitude"), cases.float("azimuth"), cases.float("velocity_angle"),
                                  speed, rate)
    kappa = cases.float("schuler_tuning")
    f_x, f_y, e_x, e_y = forcing(kinematics, radius, kappa, cases["earth_rate_compensation"].astype(bool),
                                 cases["compensation"] == "trajectory",
                                 (cases.float("accel_bias_x"), cases.float("accel_bias_y")),
                                 (cases.float("drift_x"), cases.float("drift_y")))
    steady = steady_errors(f_x, f_y, kinematics.omega_2, gravity, radius, gyro_drift=(e_x, e_y),
                           schuler_tuning=kappa)
    W_x, W_y = transport_coriolis_acceleration(kinematics, radius)
    fast, slow = split_schuler_frequencies(gravity, radius, kinematics.omega_2, kappa)
    with np.errstate(divide="ignore"):
        beat = np.where(fast > slow, 2 * np.pi / (fast - slow), np.inf)
    tilt = np.hypot(cases.float("initial_alpha"), cases.float("initial_beta"))
    return {
        "transport_coriolis_x_m_s2": np.asarray(W_x, dtype=float),
        "transport_coriolis_y_m_s2": np.asarray(W_y, dtype=float),
        "steady_tilt_alpha_rad": steady["alpha_r"], "steady_tilt_beta_rad": steady["beta_r"],
        "steady_velocity_error_x_m_s": steady["dv_x"], "steady_velocity_error_y_m_s": steady["dv_y"],
        "schuler_period_s": 2 * np.pi * np.sqrt(radius / (kappa * gravity)),
        "split_period_fast_s": 2 * np.pi / fast, "split_period_slow_s": 2 * np.pi / slow,
        "beat_period_s": beat,
        "tilt_oscillation_amplitude_m_s": tilt * np.sqrt(gravity * radius),
    }


def run_histories(fidelity: str, detail: Any) -> tuple[dict[str, Histories], dict[str, Any]]:
    """A case's histories (the CSV of ``--out``: ``vertical_timeseries`` or ``vertical_quasi_steady``) and extras.

    Parameters
    ----------
    fidelity : str
        ``"simulated"`` (``detail`` an :class:`~schuler.gyro_vertical.quasi_steady.Analysis`) or ``"closed"``
        (``detail`` a :class:`~schuler.gyro_vertical.quasi_steady.QuasiSteady`); times s, SI values.
    detail : Analysis or QuasiSteady
        What the evaluation kept of the case.
    """
    if fidelity == "simulated":
        r, q, fit = detail.response, detail.quasi_steady, detail.fit
        channels = {
            "alpha_rad": r.alpha, "beta_rad": r.beta, "latitude_rad": r.latitude,
            "measured_velocity_x_m_s": r.measured_velocity_x, "measured_velocity_y_m_s": r.measured_velocity_y,
            "true_velocity_x_m_s": r.true_velocity_x, "true_velocity_y_m_s": r.true_velocity_y,
            "velocity_error_x_m_s": r.velocity_error_x, "velocity_error_y_m_s": r.velocity_error_y,
            "quasi_steady_velocity_error_x_m_s": q.dv_x, "quasi_steady_velocity_error_y_m_s": q.dv_y,
        }
        stem, time = "vertical_timeseries", r.time
        extras = {"method": r.method, "nfev": r.nfev, "n_steps": r.n_steps,
                  "fitted_amplitudes_m_s": None if fit is None else [float(a) for a in fit.amplitudes]}
    else:
        q = detail
        channels = {
            "alpha_r_rad": q.alpha_r, "beta_r_rad": q.beta_r,
            "quasi_steady_velocity_error_x_m_s": q.dv_x, "quasi_steady_velocity_error_y_m_s": q.dv_y,
            "slowly_varying_velocity_error_x_m_s": q.slow_dv_x, "slowly_varying_velocity_error_y_m_s": q.slow_dv_y,
            "transport_coriolis_x_m_s2": q.W_star_x, "transport_coriolis_y_m_s2": q.W_star_y,
        }
        stem, time = "vertical_quasi_steady", q.time
        extras = {"method": "quasi-steady (29)", "nfev": 0, "n_steps": 0, "fitted_amplitudes_m_s": None}
    units = {name: _unit_of(name) for name in channels}
    return {stem: Histories(time, channels, units, time_name="time_s")}, extras


def _unit_of(name: str) -> str:
    """The SI unit a channel's name ends in (``_rad``, ``_m_s``, ``_m_s2``)."""
    for suffix, unit in (("_m_s2", "m/s^2"), ("_m_s", "m/s"), ("_rad", "rad")):
        if name.endswith(suffix):
            return unit
    raise ValueError(f"no unit in {name!r}")


def simulated_run(case: Case) -> SimpleNamespace:
    """One case simulated: its outputs (attributes, SI) and ``analysis``, the simulation with its modes.

    Parameters
    ----------
    case : Case
        A validated case (SI values).

    Examples
    --------
    >>> run = simulated_run(PARAMETERS.case(latitude=np.radians(60), earth="drozdovich", duration=6 * 3600.0))
    >>> round(run.steady_velocity_error_y_m_s, 3), run.analysis.response.method
    (0.557, 'DOP853')
    """
    outputs, details = _evaluate(Cases.from_case(case, fidelity="simulated"), keep_histories=True)
    return SimpleNamespace(**{name: float(values[0]) for name, values in outputs.items()}, analysis=details[0])


__all__ = ["FIDELITIES", "OUTPUTS", "PARAMETERS", "build_model", "evaluate", "member_bytes",
           "parse_speed_profile", "simulated_run"]
