"""The suite's commands as contract Actions: ``align compare``, ``north compare``, ``calibrate compare``.

Each is an :class:`~schuler.contract.Action` whose function takes validated SI
values and returns a result of this package, drawn by
:func:`~schuler.alignment.plots.comparison_figures`; its table (``to_dataframe()``)
is the CSV beside the figure (:func:`~schuler.alignment.plots.comparison_data_files`;
:func:`~schuler.alignment.plots.write_files` writes both for a system that writes
its own files). The systems that own the command names add them to their
``actions``; the north and calibrate ones hand over
their own evaluation (``parameters`` and ``evaluate`` of schuler north or 3) so that
the ground gyrocompass and the pulse method stand beside the new methods
without this package importing a seed system.

``align compare`` reads the data from ``--record FILE`` (an option, so that
"RECORD or --imu GRADE" needs no optional positional argument) or simulates a
record of ``--imu GRADE``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from schuler.alignment.calibration_comparison import CalibrationComparison, compare_calibration
from schuler.alignment.comparison import (
    GYROCOMPASS_DESIGNS,
    AlignmentComparison,
    AlignmentSettings,
    compare_alignment,
    record_model,
    simulated_batch,
    window_record,
)
from schuler.alignment.data import StaticBatch
from schuler.alignment.north import AXES, DEFAULT_CAROUSEL_PERIOD
from schuler.alignment.north_comparison import NorthComparison, compare_north
from schuler.alignment.plots import comparison_figures, write_files
from schuler.contract import Action, Cases
from schuler.core.attitude import wrap_angle
from schuler.core.gyrocompass_design import DESIGN_DAMPING, DESIGN_TIME_CONSTANT
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.imu.files import read_record
from schuler.imu.simulate import static_truth
from schuler.imu.spec import GRADES, preset
from schuler.params import Parameter, ParameterSet

SIMULATED_LATITUDE_DEG = 45.0
"""Latitude of a simulated record when none is given, deg."""

SIMULATED_DURATION_S = 300.0
"""Length of a simulated record when none is given, s."""

_SEED = Parameter("seed", "", 0, "Seed of the simulated records (addressed draws: member 0, 1, ...).", minimum=0,
                  kind="integer")
_LATITUDE = Parameter("latitude", "deg", None, "Site latitude (not set: the record's; 45 deg when simulated).",
                      minimum=-89, maximum=89)

ALIGN_COMPARE_PARAMETERS = ParameterSet((
    Parameter("record", "", None, "IMU file at rest: PSINS .imu, CSV or Parquet (not set: a record simulated from "
              "--imu).", kind="text"),
    Parameter("imu", "", None, "IMU grade: without --record, the grade of the simulated record; with it, the grade "
              "its limits assume (not set: the closest grade to its Allan deviation).", choices=GRADES, kind="choice"),
    _LATITUDE,
    Parameter("start", "s", 0.0, "Start of the window in the record.", minimum=0),
    Parameter("duration", "s", None, "Length of the window (not set: to the record's end; 300 s when simulated).",
              minimum=0, exclusive_minimum=True),
    Parameter("heading", "deg", 30.0, "True heading of a simulated record.", minimum=-180, maximum=360),
    Parameter("imu_rate", "Hz", 100.0, "Sample rate of a simulated record.", minimum=0.1, maximum=10000),
    _SEED,
    Parameter("gyrocompass_design", "", "staged", "Design of the gyrocompass loop: staged (levelling, then azimuth, "
              "driven by velocity; stages from the error model and the window) or kpi (the KPI manual's platform "
              "design, --time-constant and --damping).", choices=GYROCOMPASS_DESIGNS, kind="choice"),
    Parameter("time_constant", "s", DESIGN_TIME_CONSTANT, "Time constant T of the gyrocompass loop's KPI design.",
              minimum=1, maximum=1e5),
    Parameter("damping", "", DESIGN_DAMPING, "Damping zeta of the gyrocompass loop's KPI design.", minimum=0.05,
              maximum=10),
    Parameter("velocity_noise", "m/s", 0.01, "Kalman filter's zero-velocity measurement noise (sway at rest).",
              minimum=0, exclusive_minimum=True, maximum=10),
    Parameter("update_interval", "s", 1.0, "Time between Kalman updates.", minimum=0, exclusive_minimum=True,
              maximum=60),
    Parameter("initial_window", "s", 30.0, "Coarse alignment over the first seconds starts the Kalman filter and the "
              "gyrocompass (at most a day; a window longer than the record takes all of it).", minimum=0,
              exclusive_minimum=True, maximum=86400),
), owner="align compare")
"""Options of ``schuler align compare``."""

NORTH_COMPARE_PARAMETERS = ParameterSet((
    Parameter("imu", "", "tactical", "IMU grade of the simulated turntable records.", choices=GRADES, kind="choice"),
    Parameter("latitude", "deg", SIMULATED_LATITUDE_DEG, "Site latitude.", minimum=-89, maximum=89),
    Parameter("heading", "deg", 30.0, "True azimuth of the x axis at table angle 0.", minimum=-180, maximum=360),
    Parameter("duration", "s", 300.0, "Total observation time of each method.", minimum=1, maximum=86400),
    Parameter("imu_rate", "Hz", 10.0, "Sample rate of the records.", minimum=0.1, maximum=1000),
    Parameter("axes", "", "x", "One gyro (x) or both horizontal gyros of the IMU (xy).", choices=AXES, kind="choice"),
    Parameter("carousel_period", "s", DEFAULT_CAROUSEL_PERIOD, "One turn of the carousel.", minimum=1),
    Parameter("monte_carlo", "", 100, "Monte Carlo records per method.", minimum=2, maximum=100_000, kind="integer"),
    _SEED,
), owner="north compare")
"""Options of ``schuler north compare``."""

CALIBRATE_COMPARE_PARAMETERS = ParameterSet((
    Parameter("imu", "", "industrial", "IMU grade of the simulated IMU.", choices=GRADES, kind="choice"),
    Parameter("latitude", "deg", SIMULATED_LATITUDE_DEG, "Site latitude.", minimum=-89, maximum=89),
    Parameter("dwell", "s", 60.0, "Six-position dwell per position.", minimum=1, maximum=3600),
    Parameter("turn", "s", 36.0, "Six-position rate-test turn (one revolution).", minimum=1, maximum=600),
    Parameter("positions", "", 36, "Multi-static orientations after the initial static period.", minimum=9,
              maximum=1000, kind="integer"),
    Parameter("static", "s", 3.0, "Multi-static hold per orientation.", minimum=1.5, maximum=600),
    Parameter("imu_rate", "Hz", 100.0, "Sample rate of the records.", minimum=1, maximum=10000),
    Parameter("monte_carlo", "", 20, "Members of schuler calibrate's pulse-method Monte Carlo (0: leave it out).",
              minimum=0, maximum=100_000, kind="integer"),
    _SEED,
), owner="calibrate compare")
"""Options of ``schuler calibrate compare``."""


def _settings(case) -> AlignmentSettings:
    return AlignmentSettings(gyrocompass_design=case["gyrocompass_design"],
                             time_constant_s=case["time_constant"], damping=case["damping"],
                             velocity_noise=case["velocity_noise"], update_interval_s=case["update_interval"],
                             initial_window_s=case["initial_window"])


def align_compare(**values) -> AlignmentComparison:
    """Every self-alignment method on one record or one simulated record (``align compare``), SI keywords.

    Parameters
    ----------
    **values
        Options of :data:`ALIGN_COMPARE_PARAMETERS` by name, in SI: ``latitude`` and ``heading`` rad;
        ``start``, ``duration``, ``time_constant``, ``update_interval`` and ``initial_window`` s; ``imu_rate`` Hz;
        ``velocity_noise`` m/s; ``damping`` plain number; ``seed`` an integer; ``record`` a file path;
        ``imu`` a grade; ``gyrocompass_design`` ``staged`` or ``kpi``. Missing ones take their defaults.

    Returns
    -------
    AlignmentComparison
        Every method's attitude, 1-sigma, convergence time and accuracy limit.

    Raises
    ------
    InvalidParameter
        Neither ``record`` nor ``imu`` given, a window outside the record, a record without a latitude.
    """
    case = ALIGN_COMPARE_PARAMETERS.case(values)
    settings = _settings(case)
    if case["record"] is None:
        grade = case["imu"]
        if grade is None:
            raise InvalidParameter("record", "give `record` FILE (a recording at rest) or `imu` GRADE "
                                   "(a simulated one)")
        model = preset(grade)
        latitude = math.radians(SIMULATED_LATITUDE_DEG) if case["latitude"] is None else case["latitude"]
        heading = float(wrap_angle(case["heading"]))
        duration = SIMULATED_DURATION_S if case["duration"] is None else case["duration"]
        batch, constants = simulated_batch(model, latitude=latitude, heading=heading, duration=duration,
                                           sample_interval=1.0 / case["imu_rate"], members=[0], seed=case["seed"])
        gyro_true, accel_true = static_truth(latitude, heading, batch.gravity)
        # every constant error acts as a bias at rest: (K - I) u + b (+ G f for the gyros)
        gyro_bias = (constants["gyro_matrix"][0] - np.eye(3)) @ gyro_true + constants["gyro_bias"][0] \
            + constants["gyro_g"][0] @ accel_true
        accel_bias = (constants["accel_matrix"][0] - np.eye(3)) @ accel_true + constants["accel_bias"][0]
        return compare_alignment(batch, model, settings, source=f"simulated {grade} record (seed {case['seed']})",
                                 model_source="grade given", truth=(0.0, 0.0, heading), biases=(gyro_bias, accel_bias))
    record = read_record(case["record"])
    batch = StaticBatch.from_record(record, latitude=case["latitude"], start=case["start"],
                                    duration=case["duration"])
    model, model_source = record_model(window_record(record, case["start"], case["duration"]), case["imu"])
    return compare_alignment(batch, model, settings, source=record.source or str(case["record"]),
                             start=case["start"], model_source=model_source)


def evaluate_with(parameters: ParameterSet, evaluate: Callable, common: dict, varying: dict | None = None, *,
                  members: int = 0, seed: int = 0) -> dict[str, np.ndarray]:
    """A system's ``evaluate`` on cases sharing ``common`` SI values, ``varying`` ones per case, or ``members``
    Monte Carlo members of one case (draws addressed by ``seed`` and member number).

    Parameters
    ----------
    parameters : ParameterSet
        The system's parameters: every case is validated by their rules.
    evaluate : callable
        The system's ``evaluate(cases) -> dict of str to ndarray``.
    common : dict of str to float
        Parameter name -> value shared by every case, SI (the parameter's SI unit).
    varying : dict of str to array_like, optional
        Parameter name -> one value per case, SI; all of the same length (the number of cases).
    members : int
        Number of Monte Carlo members of the one case (without ``varying``); 0: one nominal case, no draws.
    seed : int
        Seed of the members' random streams (used only with ``members``).

    Returns
    -------
    dict of str to ndarray
        The system's outputs, one value per case or member, in their SI units.
    """
    varying = {name: np.atleast_1d(np.asarray(value, dtype=float)) for name, value in (varying or {}).items()}
    count = len(next(iter(varying.values()))) if varying else max(1, members)
    checked = [parameters.case({**common, **{name: float(value[i]) for name, value in varying.items()}})
               for i in range(count if varying else 1)]   # every case validated by the system's own rules
    case = checked[0]
    cases = Cases.from_case(case, count, members=np.arange(count), random=RandomStreams(seed) if members else None)
    arrays = {name: cases[name] for name in cases.names}
    arrays.update(varying)
    return evaluate(Cases(arrays, members=cases.members, random=cases.random))


def north_compare_action(parameters: ParameterSet, evaluate: Callable) -> Action:
    """``north compare``, with schuler north (its ``parameters`` and ``evaluate``) as the ground gyrocompass.

    Parameters
    ----------
    parameters : ParameterSet
        schuler north's parameters (``readout_noise``, ``latitude``, ``duration`` among them).
    evaluate : callable
        schuler north's ``evaluate(cases)``; its ``north_std_predicted_rad`` output is used.

    Returns
    -------
    Action
        The ``compare`` action with :data:`NORTH_COMPARE_PARAMETERS`.
    """

    def ground_gyrocompass(durations, noise, latitude):
        outputs = evaluate_with(parameters, evaluate, {"readout_noise": noise, "latitude": latitude},
                                {"duration": durations})
        return outputs["north_std_predicted_rad"]

    def north_compare(**values) -> NorthComparison:
        case = NORTH_COMPARE_PARAMETERS.case(values)
        return compare_north(case["imu"], latitude=case["latitude"], heading=float(wrap_angle(case["heading"])),
                             duration=case["duration"], sample_interval=1.0 / case["imu_rate"], axes=case["axes"],
                             carousel_period=case["carousel_period"], members=case["monte_carlo"],
                             seed=case["seed"], ground_gyrocompass=ground_gyrocompass)

    return Action("compare",
                  "North from an IMU on a turntable: two positions, four positions, carouseling, and this system.\n\n"
                  "Simulated records of --imu GRADE; each method's azimuth with its fit 1-sigma, its analytic "
                  "accuracy and its Monte Carlo spread; accuracy against time and grade, the ground gyrocompass "
                  "(this system, read with the grade's angle noise) on the same figure with --out.",
                  north_compare, NORTH_COMPARE_PARAMETERS, write_files=write_files,
                  figures=comparison_figures)


def calibrate_compare_action(parameters: ParameterSet, evaluate: Callable) -> Action:
    """``calibrate compare``, with schuler calibrate (its ``parameters`` and ``evaluate``) as the pulse method.

    Parameters
    ----------
    parameters : ParameterSet
        schuler calibrate's parameters (``angle_random_walk``, ``drift_x``, ``latitude`` among them).
    evaluate : callable
        schuler calibrate's ``evaluate(cases)``; its ``drift_x_error_rad_s``, ``azimuth_error_rad`` and
        ``procedure_time_s`` outputs are used.

    Returns
    -------
    Action
        The ``compare`` action with :data:`CALIBRATE_COMPARE_PARAMETERS`.
    """

    def pulse_method(random_walk, drift, latitude, members, seed):
        outputs = evaluate_with(parameters, evaluate, {"angle_random_walk": random_walk, "drift_x": drift,
                                                       "latitude": latitude}, members=members, seed=seed)
        return {"drift_sigma_rad_s": float(np.std(outputs["drift_x_error_rad_s"], ddof=1)),
                "azimuth_sigma_rad": float(np.std(outputs["azimuth_error_rad"], ddof=1)),
                "procedure_time_s": float(outputs["procedure_time_s"][0])}

    def calibrate_compare(**values) -> CalibrationComparison:
        case = CALIBRATE_COMPARE_PARAMETERS.case(values)
        members = case["monte_carlo"]
        return compare_calibration(case["imu"], latitude=case["latitude"], seed=case["seed"],
                                   dwell=case["dwell"], turn=case["turn"], positions=case["positions"],
                                   static=case["static"], sample_interval=1.0 / case["imu_rate"],
                                   pulse_method=pulse_method if members >= 2 else None, pulse_members=members)

    return Action("compare",
                  "Multi-position IMU calibration beside this system's pulse method.\n\n"
                  "One simulated IMU of --imu GRADE: six positions with a rate test and the automatic multi-static "
                  "method (Tedaldi et al. 2014), every estimate beside the truth and its predicted 1-sigma; "
                  "the pulse method's drift spread from this system's Monte Carlo.",
                  calibrate_compare, CALIBRATE_COMPARE_PARAMETERS, write_files=write_files,
                  figures=comparison_figures)


ALIGN_COMPARE = Action(
    "compare",
    "Every strapdown self-alignment method on the same data: coarse (TRIAD), inertial frame, Kalman, gyrocompass.\n\n"
    "Data from --record FILE (PSINS .imu, CSV, Parquet) or a record simulated from --imu GRADE. A table of roll, "
    "pitch, heading, 1-sigma, convergence time and accuracy limit per method; heading against time on one figure "
    "with --out.",
    align_compare, ALIGN_COMPARE_PARAMETERS, figures=comparison_figures)
"""The ``align compare`` command."""
