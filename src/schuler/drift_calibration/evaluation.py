"""What the drift calibration evaluates: its parameters, outputs and ``evaluate`` (with one cycle's histories).

Source: the alternating-pulse calibration article
(:data:`schuler.references.PULSE_CALIBRATION`); equation numbers are its own.
Frames and signs are those of :mod:`~schuler.drift_calibration.procedure`: site
ENU, platform X, Y, Z with Z up, A0 the azimuth of the platform's Y axis
clockwise from north, ``drift_x`` and ``drift_y`` the own drifts omega_dX,
omega_dY of the gyros (the rate at which the platform turns about +X, +Y away
from its commanded orientation); estimation errors are estimated - true.

:func:`evaluate` runs whole procedures (two or more platform positions, each
one or more alternating-pulse cycles per channel, exact simulation of every
cycle) for a batch of cases at once and recovers the drifts by (13), (15), (16)
or least squares and the azimuth by atan2 or asin. The nominal case
(``cases.random is None``) is the error-free procedure. Monte Carlo members and
sweep cases with random terms draw every term of the error budget
(:mod:`~schuler.drift_calibration.error_budget`) from ``cases.random``, addressed
by member (:mod:`~schuler.drift_calibration.draws`): results do not depend on
chunking. Cases are grouped by what changes the instrument or the shape of the
procedure (mode, positions, cycles, pulse, loop) and each group is simulated
in memory-bounded batches.

Observability: the azimuth comes from the horizontal Earth rate Omega cos(phi),
so an error in the measured rates maps into the azimuth as 1 / (Omega cos(phi))
(:func:`~schuler.drift_calibration.procedure.azimuth_sensitivity`). Above
70 deg a :class:`AzimuthAccuracyWarning` says so; beyond ``max_latitude``
(85 deg unless set) :class:`~schuler.exceptions.NotObservable` is raised: the
error-free procedure still returns the azimuth to rounding there, but any
instrument error is amplified beyond use (at 89.99 deg the typical budget gives
thousands of arcmin).
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from schuler.contract import Cases, Evaluation, Output
from schuler.core.earth import EARTH_RATE
from schuler.core.response import Histories
from schuler.drift_calibration.draws import draw_errors
from schuler.drift_calibration.procedure import (
    MODES,
    apparent_drift,
    procedure_time,
    run_procedure,
)
from schuler.drift_calibration.pulses import SHAPES
from schuler.drift_calibration.stabilizer import (
    NOISE_STEPS,
    Stabilizer,
    cycle_grid,
    simulate_cycle,
)
from schuler.exceptions import NotObservable
from schuler.memory import chunk_members, require
from schuler.params import Case, Parameter, ParameterSet

DEFAULT_MAX_LATITUDE = math.radians(85.0)
"""Above this latitude the azimuth is refused as not observable (user-overridable), rad."""
DEGRADED_LATITUDE = math.radians(70.0)
"""Above this latitude a warning says that the azimuth accuracy degrades as 1 / cos(latitude), rad."""
ANGULAR_MOMENTUM = 0.1
"""Rotor angular momentum H of the modelled instrument, N m s (K_M and H drop out of (13))."""
PULSE_CURRENT = 0.01
"""Peak pulse current i of the modelled instrument, A; K_M follows from the pulse rate (K_M / H) i."""


class AzimuthAccuracyWarning(UserWarning):
    """The calibration works, but its azimuth accuracy is poor (high latitude)."""


PARAMETERS = ParameterSet((
    Parameter("latitude", "deg", 70.0, "Site latitude phi.", minimum=-90, maximum=90,
              exclusive_minimum=True, exclusive_maximum=True),
    Parameter("azimuth", "deg", 80.0, "True initial azimuth A0 of the platform Y axis, clockwise from north.",
              minimum=-360, maximum=360),
    Parameter("drift_x", "deg/h", 0.1, "True own drift omega_dX of the X gyro (platform turning about +X).",
              minimum=-3600, maximum=3600),
    Parameter("drift_y", "deg/h", None, "True own drift omega_dY of the Y gyro (not set: equal to --drift-x).",
              minimum=-3600, maximum=3600),
    Parameter("max_latitude", "deg", math.degrees(DEFAULT_MAX_LATITUDE),
              "Latitude above which the azimuth is reported not observable.", minimum=0, maximum=90,
              exclusive_minimum=True, exclusive_maximum=True),
    Parameter("mode", "", "three-axis", "Both horizontal channels (azimuth by atan2) or the X channel only (asin).",
              choices=MODES, kind="choice"),
    Parameter("pulse_duration", "s", 5.0, "Duration tau of each torque pulse (a cycle is 2 tau).",
              minimum=0, exclusive_minimum=True, maximum=3600),
    Parameter("pulse_shape", "", "rectangular", "Torque pulse shape.", choices=tuple(SHAPES), kind="choice"),
    Parameter("pulse_rate", "deg/s", 0.01, "Torquer precession rate (K_M/H) i at the pulse peak.",
              minimum=0, exclusive_minimum=True, maximum=10),
    Parameter("sensor_gain", "V/deg", 1.0, "Gain K1 of the command angle sensor.",
              minimum=0, exclusive_minimum=True, maximum=1e6),
    Parameter("loop_time_constant", "s", 0.0, "Stabilization-loop time constant T_s (0: ideal; typical 2 ms).",
              minimum=0, maximum=10),
    Parameter("sway_frequency", "Hz", 0.7, "Base sway frequency.", minimum=0, exclusive_minimum=True, maximum=1000),
    Parameter("positions", "", 2, "Equally spaced platform positions N (2: the source's 0 and 180 deg).",
              minimum=2, maximum=360, kind="integer"),
    Parameter("cycles", "", 1, "Measurement cycles averaged at each position and channel.",
              minimum=1, maximum=1000, kind="integer"),
    Parameter("sensor_noise_density", "arcsec/Hz^0.5", 0.01, "Random: command-sensor white noise density.",
              minimum=0, maximum=3600),
    Parameter("angle_random_walk", "deg/h^0.5", 0.001, "Random: gyro angle random walk.", minimum=0, maximum=100),
    Parameter("sigma_sensor_scale", "", 1e-4, "Random: 1-sigma relative error of K1 (each channel).",
              minimum=0, maximum=0.1),
    Parameter("sigma_amplitude_mismatch", "", 1e-5, "Random: 1-sigma relative +/- pulse amplitude mismatch.",
              minimum=0, maximum=0.1),
    Parameter("sigma_duration_mismatch", "", 1e-6, "Random: 1-sigma relative +/- pulse duration mismatch.",
              minimum=0, maximum=0.01),
    Parameter("sigma_pulse_asymmetry", "", 1e-5, "Random: 1-sigma tilt of the pulse top.", minimum=0, maximum=0.1),
    Parameter("sigma_integrator_offset", "arcsec", 0.002,
              "Random: 1-sigma integrator input offset as a sensor angle (each channel).", minimum=0, maximum=3600),
    Parameter("sigma_lag_compensation", "", 0.02,
              "Random: 1-sigma relative error of the T_s used to compensate the loop lag.", minimum=0, maximum=1),
    Parameter("sigma_sway", "arcsec", 0.2, "Random: 1-sigma base sway angle (each cycle).", minimum=0,
              maximum=3600),
    Parameter("sigma_turn_angle", "arcsec", 5.0, "Random: 1-sigma error of each platform turn.",
              minimum=0, maximum=3600),
    Parameter("sigma_levelling", "arcsec", 10.0, "Random: 1-sigma residual tilt of each horizontal axis.",
              minimum=0, maximum=3600),
    Parameter("sigma_initial_angle", "arcsec", 10.0, "Random: 1-sigma command-sensor angle at a cycle's start.",
              minimum=0, maximum=3600),
    Parameter("sigma_latitude", "arcmin", 1.0, "Random: 1-sigma error of the latitude entered.",
              minimum=0, maximum=600),
), owner="calibrate", renamed={
    "drift": "drift_x", "tau": "pulse_duration", "k1": "sensor_gain", "sensor_noise": "sensor_noise_density",
    "sensor_scale_error": "sigma_sensor_scale", "amplitude_mismatch": "sigma_amplitude_mismatch",
    "duration_mismatch": "sigma_duration_mismatch", "pulse_asymmetry": "sigma_pulse_asymmetry",
    "integrator_offset": "sigma_integrator_offset", "lag_compensation_error": "sigma_lag_compensation",
    "sway_amplitude": "sigma_sway", "turn_angle_error": "sigma_turn_angle", "levelling_residual": "sigma_levelling",
    "initial_angle": "sigma_initial_angle", "latitude_error": "sigma_latitude"})
"""Every option of ``schuler calibrate run`` (and key of a ``calibrate`` scenario)."""

BUDGET_TERMS = {
    "sensor_noise_density": "sensor_noise_density",
    "angle_random_walk": "angle_random_walk",
    "sigma_sensor_scale": "sensor_scale_error",
    "sigma_amplitude_mismatch": "amplitude_mismatch",
    "sigma_duration_mismatch": "duration_mismatch",
    "sigma_pulse_asymmetry": "pulse_asymmetry",
    "sigma_integrator_offset": "integrator_offset",
    "sigma_lag_compensation": "lag_compensation_error",
    "sigma_sway": "sway_amplitude",
    "sigma_turn_angle": "turn_angle_error",
    "sigma_levelling": "levelling_residual",
    "sigma_initial_angle": "initial_angle",
    "sigma_latitude": "latitude_error",
}
"""Random-term parameter -> field of :class:`~schuler.drift_calibration.error_budget.ErrorBudget`."""

OUTPUTS = (
    Output("drift_x_rad_s", "rad/s", "deg/h", "estimated own drift omega_dX of the X gyro"),
    Output("drift_y_rad_s", "rad/s", "deg/h", "estimated own drift omega_dY of the Y gyro (NaN: single-axis)"),
    Output("drift_x_error_rad_s", "rad/s", "deg/h", "drift error of the X gyro, estimated - true"),
    Output("drift_y_error_rad_s", "rad/s", "deg/h", "drift error of the Y gyro, estimated - true (NaN: single-axis)"),
    Output("relative_drift_error", "1", "%",
           "|estimated - true| / |true drift|, averaged over the measured gyros (NaN where a true drift is 0)"),
    Output("earth_rate_component_rad_s", "rad/s", "deg/h", "estimated omega_X0 = Omega cos(phi) sin(A0)"),
    Output("azimuth_rad", "rad", "deg", "estimated azimuth A0, in [0, 360) deg"),
    Output("azimuth_alternative_rad", "rad", "deg",
           "the other asin branch 180 deg - A0 (single-axis, 2 positions); else the estimate again"),
    Output("azimuth_error_rad", "rad", "arcmin", "azimuth error, estimated - true, wrapped to (-180, 180] deg"),
    Output("asin_saturated", "1", "", "1 where the single-axis asin argument exceeded 1 and was clipped"),
    Output("cycle_time_s", "s", "", "one measurement cycle, 2 tau"),
    Output("procedure_time_s", "s", "", "measuring time of the whole procedure (turns not counted)"),
)

_INSTRUMENT = ("mode", "positions", "cycles", "pulse_shape", "pulse_duration", "pulse_rate", "sensor_gain",
               "loop_time_constant", "sway_frequency")
"""Parameters that change the instrument or the shape of the procedure: each distinct set is one batch."""


def stabilizer_of(case) -> Stabilizer:
    """The instrument of a case: H = 0.1 N m s, i = 10 mA and K_M from the pulse rate (K_M / H) i.

    Parameters
    ----------
    case : Case
        A validated case (SI values).
    """
    return Stabilizer(
        k1=case["sensor_gain"], torquer_gain=case["pulse_rate"] * ANGULAR_MOMENTUM / PULSE_CURRENT,
        angular_momentum=ANGULAR_MOMENTUM, pulse_current=PULSE_CURRENT, tau=case["pulse_duration"],
        shape=SHAPES[case["pulse_shape"]](), loop_time_constant=case["loop_time_constant"],
        sway_frequency=case["sway_frequency"])


def member_bytes(case) -> int:
    """Memory one procedure needs while simulated, bytes: every cycle's grid of inputs, states and noise.

    Parameters
    ----------
    case : Case
        A validated case (SI values).
    """
    channels = 1 if case["mode"] == "single-axis" else 2
    cycles = channels * int(case["positions"]) * int(case["cycles"])
    grid = cycle_grid(SHAPES[case["pulse_shape"]](), NOISE_STEPS).size
    # per grid point of a phase: 5 inputs, 6 states and the engine's copies, signal, noise; two phases
    return int(cycles * grid * 8 * 24 * 2 + 4096)


def check_observable(latitude: np.ndarray, max_latitude: np.ndarray) -> None:
    """Raise :class:`NotObservable` beyond the latitude limit; warn when the accuracy degrades.

    Parameters
    ----------
    latitude : ndarray
        Latitude of each case, rad.
    max_latitude : ndarray
        The azimuth limit of each case (``--max-latitude``), rad.
    """
    phi = np.abs(np.asarray(latitude, dtype=float))
    if phi.size == 0:
        return
    beyond = phi > max_latitude
    if np.any(beyond):
        worst = int(np.argmax(np.where(beyond, phi, -1.0)))
        raise NotObservable(
            f"latitude: {math.degrees(phi[worst]):g} deg is beyond the azimuth limit "
            f"{math.degrees(max_latitude[worst]):g} deg (`max_latitude`): the horizontal Earth rate "
            f"Omega cos(latitude) = {EARTH_RATE * math.cos(phi[worst]):.3g} rad/s magnifies every rate error "
            f"{1 / math.cos(phi[worst]):.0f} times in the azimuth")
    highest = float(np.max(phi))
    if highest > DEGRADED_LATITUDE:
        warnings.warn(
            f"latitude {math.degrees(highest):g} deg: azimuth accuracy degrades as 1/cos(latitude), "
            f"{1 / math.cos(highest):.1f} times the equator's error for the same instrument errors",
            AzimuthAccuracyWarning, stacklevel=2)


def evaluate(cases: Cases, histories: bool = False) -> dict[str, np.ndarray] | Evaluation:
    """Every output of :data:`OUTPUTS` for a batch of cases (SI arrays of length ``len(cases)``).

    With ``histories`` it is the run in full of the batch's first case: an
    :class:`~schuler.contract.Evaluation` with the error-free cycle's histories
    (``calibrate_cycle``) and, as extras, the mode, the procedure's shape and
    the true drifts, Earth-rate component and azimuth.

    Parameters
    ----------
    cases : Cases
        A batch of validated cases (SI values; random terms from ``cases.random`` at ``cases.members``).
    histories : bool
        Whether to return the first case's cycle histories and true values too.

    Examples
    --------
    >>> out = evaluate(Cases.from_case(PARAMETERS.case(), 2))
    >>> [round(float(np.degrees(a)), 9) for a in out["azimuth_rad"]]
    [80.0, 80.0]
    """
    n = len(cases)
    out = {output.name: np.full(n, np.nan) for output in OUTPUTS}
    check_observable(cases.float("latitude"), cases.float("max_latitude"))
    for index, group in _instrument_groups(cases):
        first = group.case(0)
        need = member_bytes(first)
        require(need, "one calibration procedure", "`positions` or `cycles`")
        stabilizer = stabilizer_of(first)
        step = chunk_members(need)
        for start in range(0, len(group), step):
            part = np.arange(start, min(start + step, len(group)))
            for name, values in _evaluate_batch(group.take(part), first, stabilizer).items():
                out[name][index[part]] = values
    return _in_full(cases.case(0), out) if histories else out


def _in_full(case: Case, outputs: dict[str, np.ndarray]) -> Evaluation:
    """The outputs with one error-free cycle's histories and the case's true values."""
    stabilizer = stabilizer_of(case)
    drift_y = case["drift_x"] if case["drift_y"] is None else case["drift_y"]
    omega_x0 = float(apparent_drift(case["latitude"], case["azimuth"])[0])
    cycle = simulate_cycle(stabilizer, np.array([case["drift_x"] + omega_x0]), keep_history=True)
    cycle_history = Histories(cycle.time, {
        "platform_angle_rad": cycle.platform_angle[0], "sensor_signal_V": cycle.sensor_signal[0],
        "integrator_output_V_s": cycle.integrator_output[0]},
        {"platform_angle_rad": "rad", "sensor_signal_V": "V", "integrator_output_V_s": "V s"})
    extras: dict[str, Any] = {
        "mode": case["mode"], "positions": int(case["positions"]), "cycles": int(case["cycles"]),
        "true_drift_x_rad_s": case["drift_x"], "true_drift_y_rad_s": drift_y,
        "true_earth_rate_component_rad_s": omega_x0, "true_azimuth_rad": case["azimuth"] % (2 * math.pi)}
    return Evaluation(outputs, histories={"calibrate_cycle": cycle_history}, extras=extras)


def _instrument_groups(cases: Cases):
    """(indices, cases) of each instrument; a batch of one instrument (a Monte Carlo) without a loop over cases."""
    if len(cases) and all(np.all(cases[name] == cases[name][0]) for name in _INSTRUMENT):
        yield np.arange(len(cases)), cases
    else:
        yield from cases.groups(*_INSTRUMENT)


def _evaluate_batch(cases: Cases, instrument: Case, stabilizer: Stabilizer) -> dict[str, np.ndarray]:
    mode, positions, cycles = instrument["mode"], int(instrument["positions"]), int(instrument["cycles"])
    channels = 1 if mode == "single-axis" else 2
    drift_x = cases.float("drift_x")
    drift_y = cases.value_or("drift_y", drift_x)
    errors = None
    if cases.random is not None:
        budget = {term: cases.float(name) for name, term in BUDGET_TERMS.items()}
        budget["sway_frequency"] = cases.float("sway_frequency")
        errors = draw_errors(budget, cases.random, cases.members, channels=channels, positions=positions,
                             cycles=cycles, samples=cycle_grid(stabilizer.shape, NOISE_STEPS).size - 1)
    outcome = run_procedure(stabilizer, cases.float("latitude"), cases.float("azimuth"), drift_x, drift_y,
                            mode=mode, positions=positions, cycles=cycles, errors=errors)
    error_x = outcome.drift_x - drift_x
    error_y = outcome.drift_y - drift_y  # NaN in single-axis mode
    with np.errstate(divide="ignore", invalid="ignore"):
        relative = [np.abs(error_x) / np.abs(drift_x)] + ([] if channels == 1 else [np.abs(error_y) / np.abs(drift_y)])
    relative_mean = np.mean(relative, axis=0)
    n = len(cases)
    return {
        "drift_x_rad_s": outcome.drift_x,
        "drift_y_rad_s": outcome.drift_y,
        "drift_x_error_rad_s": error_x,
        "drift_y_error_rad_s": error_y,
        "relative_drift_error": np.where(np.isfinite(relative_mean), relative_mean, np.nan),
        "earth_rate_component_rad_s": outcome.earth_rate_component,
        "azimuth_rad": outcome.azimuth,
        "azimuth_alternative_rad": outcome.azimuth_alternative,
        "azimuth_error_rad": outcome.azimuth_error,
        "asin_saturated": outcome.saturated.astype(float),
        "cycle_time_s": np.full(n, stabilizer.cycle_time),
        "procedure_time_s": np.full(n, procedure_time(stabilizer.tau, mode, positions, cycles)),
    }
