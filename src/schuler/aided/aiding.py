"""The aiding besides GNSS of ``schuler aided run``: its parameters, its data and its sources.

``--aiding`` names, beside ``gnss-position`` and ``gnss-velocity``:

* ``zupt`` and ``zaru``: zero velocity and zero angular rate at ``zupt_rate`` during the stops, the
  trajectory's own stationary intervals (``stops_from trajectory``), those of ``stop_intervals``, or those found
  in each member's IMU data (``stops_from imu``: :func:`schuler.aided.sources.detect_stops`, window
  :data:`~schuler.aided.sources.STOP_WINDOW_S`, threshold :data:`~schuler.aided.sources.STOP_THRESHOLD`;
  on the drive's vibration-free cruises it also marks the cruises, whose false updates the gate must refuse);
* ``nhc``: the wheel point's lateral and vertical velocities zero, at the odometer's epochs;
* ``odometer``: the wheel point's forward speed (:func:`schuler.aided.epochs.simulate_odometer`: white
  noise ``odometer_sigma``, scale error ``odometer_scale_error``), with an odometer scale-factor state if
  ``odometer_scale_state``;
* ``baro``: the barometric height (:func:`schuler.aided.epochs.simulate_barometer`: white noise
  ``baro_sigma``, bias ``baro_bias``), with a bias state if ``baro_bias_state``.

The drive's IMU is aligned with the vehicle: mounting angles set here are those the filter assumes, a
mounting error on the simulated drive.

On files (:func:`file_sources`) ``zupt``, ``zaru`` and ``nhc`` need no data of their own: the stops are given
(``stop_intervals``, times as in the data) or detected in the record, the constraint holds at ``odometer_rate``
over the record's span; ``odometer`` and ``baro`` need data the files do not carry.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from schuler.aided import sources
from schuler.aided.epochs import (
    DEFAULT_BAROMETER_SIGMA_M,
    DEFAULT_ODOMETER_SIGMA_M_S,
    simulate_barometer,
    simulate_odometer,
)
from schuler.aided.error_state import ErrorProcess, FilterModel
from schuler.aided.measurements import mounting_matrix
from schuler.exceptions import InvalidParameter
from schuler.navigate.drive import GroundVehicleProfile
from schuler.navigate.trajectory import Stationary, stationary_intervals
from schuler.params import Case, IntervalsParameter, Parameter

NAMES = ("zupt", "zaru", "nhc", "odometer", "baro")
"""The measurements besides GNSS ``aiding`` may name."""

SOURCES = ("zupt", "zaru", "vehicle", "baro")
"""The sources they make (:mod:`schuler.aided.sources`): nhc and odometer are one, ``vehicle``."""

ODOMETER_SCALE_SIGMA = 0.01
"""Initial 1-sigma of the odometer scale-factor state, dimensionless (1 %, a tyre's wear and pressure)."""

BAROMETER_BIAS_SIGMA_M = 10.0
"""Initial 1-sigma of the barometer bias state, m."""

PARAMETERS = (
    Parameter("stops_from", "", "trajectory", "Where zupt and zaru take the stops from: the simulated trajectory's "
              "stationary intervals (trajectory) or the IMU data, by a moving-variance test (imu).", kind="choice",
              choices=("trajectory", "imu")),
    IntervalsParameter("stop_intervals", "s", None, "Stops for zupt and zaru given one by one, start:duration pairs "
                       "(0:25,300:20; on files, times as in the data), in place of --stops-from."),
    Parameter("zupt_rate", "Hz", 10.0, "Rate of the zero-velocity and zero-rate updates during a stop.",
              minimum=0.01, maximum=100.0),
    Parameter("zupt_sigma", "m/s", 0.01, "1-sigma of the velocity at a stop.", minimum=0.0, exclusive_minimum=True,
              maximum=10.0),
    Parameter("zaru_sigma", "deg/h", 10.0, "1-sigma of the angular rate at a stop, besides the gyro noise.",
              minimum=0.0, exclusive_minimum=True, maximum=1e5),
    Parameter("odometer_rate", "Hz", 10.0, "Rate of the odometer and of the non-holonomic constraint.",
              minimum=0.01, maximum=200.0),
    Parameter("odometer_sigma", "m/s", DEFAULT_ODOMETER_SIGMA_M_S, "Odometer speed 1-sigma (simulated and assumed).",
              minimum=0.0, exclusive_minimum=True, maximum=10.0),
    Parameter("odometer_scale_error", "ppm", 0.0, "Simulated odometer scale error.", minimum=-1e5, maximum=1e5),
    Parameter("odometer_scale_state", "", False, "Estimate the odometer's scale factor (one more state).",
              kind="flag"),
    Parameter("nhc_sigma", "m/s", 0.1, "1-sigma of the wheel's lateral and vertical velocity (skid, suspension).",
              minimum=0.0, exclusive_minimum=True, maximum=10.0),
    Parameter("wheel_lever_arm_x", "m", 0.0, "IMU to the wheel's contact point, body x (forward).", minimum=-30.0,
              maximum=30.0),
    Parameter("wheel_lever_arm_y", "m", 0.0, "IMU to the wheel's contact point, body y (right).", minimum=-30.0,
              maximum=30.0),
    Parameter("wheel_lever_arm_z", "m", 0.0, "IMU to the wheel's contact point, body z (down).", minimum=-30.0,
              maximum=30.0),
    Parameter("mounting_roll", "deg", 0.0, "The IMU's roll in the vehicle frame, as the filter assumes it.",
              minimum=-180.0, maximum=180.0),
    Parameter("mounting_pitch", "deg", 0.0, "The IMU's pitch in the vehicle frame.", minimum=-90.0, maximum=90.0),
    Parameter("mounting_heading", "deg", 0.0, "The IMU's heading in the vehicle frame.", minimum=-180.0,
              maximum=180.0),
    Parameter("baro_rate", "Hz", 1.0, "Barometer rate.", minimum=0.01, maximum=100.0),
    Parameter("baro_sigma", "m", DEFAULT_BAROMETER_SIGMA_M, "Barometric height 1-sigma (simulated and assumed).",
              minimum=0.0, exclusive_minimum=True, maximum=100.0),
    Parameter("baro_bias", "m", 0.0, "Simulated barometric height bias.", minimum=-1e4, maximum=1e4),
    Parameter("baro_bias_state", "", False, "Estimate the barometer's bias (one more state).", kind="flag"),
)
"""The options of the aiding besides GNSS (module docstring)."""


def named(text: str | None) -> tuple[str, ...]:
    """The measurements besides GNSS that ``aiding`` names (already checked against the known names).

    Parameters
    ----------
    text : str or None
        Comma-separated names; None: none besides GNSS.
    """
    return tuple(name for name in NAMES if text is not None and name in
                 [part.strip() for part in str(text).split(",")])


def with_states(model: FilterModel, case: Case) -> FilterModel:
    """The filter's model with the aiding states the case asks for (odometer scale, barometer bias).

    Parameters
    ----------
    model : FilterModel
        The filter's IMU model.
    case : Case
        A validated case (``aiding``, ``odometer_scale_state``, ``baro_bias_state``).
    """
    names = named(case["aiding"])
    odometer = ErrorProcess("constant", ODOMETER_SCALE_SIGMA, axes=1) \
        if case["odometer_scale_state"] and "odometer" in names else None
    barometer = ErrorProcess("constant", BAROMETER_BIAS_SIGMA_M, axes=1) \
        if case["baro_bias_state"] and "baro" in names else None
    return dataclasses.replace(model, odometer_scale=odometer, barometer_bias=barometer)


def simulated_sources(case: Case, path, increments: np.ndarray, interval: float, members: np.ndarray, streams,
                      model: FilterModel) -> list[sources.Source]:
    """The sources besides GNSS of a simulated case, their data drawn for each member (module docstring).

    Parameters
    ----------
    case : Case
        A validated simulated case (SI).
    path : Stationary, GreatCircle or WaypointProfile
        The trajectory (``nhc`` and ``odometer`` need a ground vehicle's: a drive or at rest).
    increments : ndarray, shape (N, n, 6)
        The members' IMU increments, rad and m/s (for ``stops_from imu``).
    interval : float
        IMU interval, s.
    members : ndarray of int
        Member numbers (the addresses of the random draws).
    streams : RandomStreams or None
        The noise's source; None: noise-free data.
    model : FilterModel
        The filter's model, with its aiding states (:func:`schuler.aided.aiding.with_states`).
    """
    names = named(case["aiding"])
    duration, imu_rate = case["duration"], case["imu_rate"]
    built = _stop_sources(case, names, increments, interval, model, 0.0, lambda: stationary_intervals(path, duration))
    arm = (case["wheel_lever_arm_x"], case["wheel_lever_arm_y"], case["wheel_lever_arm_z"])
    if "odometer" in names or "nhc" in names:
        if not isinstance(path, GroundVehicleProfile | Stationary):
            wheeled = [name for name in ("nhc", "odometer") if name in names]
            raise InvalidParameter("aiding", f"{', '.join(wheeled)}: a ground vehicle's (trajectory drive or "
                                             "stationary), not a flight's")
        records = [simulate_odometer(path, duration, imu_rate=imu_rate, rate=case["odometer_rate"], lever_arm=arm,
                                     scale_factor_error=case["odometer_scale_error"], sigma=case["odometer_sigma"],
                                     streams=streams, member=int(m)) for m in members]
        speed = np.stack([record.speed_m_s for record in records]) if "odometer" in names else None
        mounting = mounting_matrix(case["mounting_roll"], case["mounting_pitch"], case["mounting_heading"])
        built.append(sources.vehicle_source(records[0].t_s, speed, model, lever_arm=arm, mounting=mounting,
                                            speed_sigma=case["odometer_sigma"], constraint_sigma=case["nhc_sigma"],
                                            constraint="nhc" in names))
    if "baro" in names:
        heights = [simulate_barometer(path, duration, imu_rate=imu_rate, rate=case["baro_rate"], bias=case["baro_bias"],
                                      sigma=case["baro_sigma"], streams=streams, member=int(m)) for m in members]
        built.append(sources.barometer_source(heights[0].t_s, np.stack([r.height_m for r in heights]),
                                              case["baro_sigma"], model))
    return built


def file_sources(case: Case, increments: np.ndarray, interval: float, t0: float, model: FilterModel
                 ) -> list[sources.Source]:
    """The sources besides GNSS of a case on files: stops and the non-holonomic constraint, which need no data.

    ``zupt`` and ``zaru`` at the stops of ``stop_intervals`` (times as in the data) or found in the record
    (``stops_from imu``); ``nhc`` at ``odometer_rate`` over the record's span. ``odometer`` and ``baro`` need
    data the files do not carry and are refused, as is ``stops_from trajectory`` (a record has no simulated
    trajectory to take them from).

    Parameters
    ----------
    case : Case
        A validated case on files (SI).
    increments : ndarray, shape (n, 6)
        The record's IMU increments, rad and m/s.
    interval : float
        IMU interval, s.
    t0 : float
        Time of the record's first sample, s (as in the data).
    model : FilterModel
        The filter's model.
    """
    names = named(case["aiding"])
    needing_data = [name for name in ("odometer", "baro") if name in names]
    if needing_data:
        raise InvalidParameter("aiding", f"{', '.join(needing_data)}: on a simulated drive only (the files hold IMU "
                                         "and GNSS data); zupt, zaru and nhc work on files")

    def refused():
        raise InvalidParameter("stops_from", "a record has no simulated trajectory to take its stops from: give "
                                             "them (`stop_intervals`, times as in the data) or find them "
                                             "(`stops_from` imu)")

    built = _stop_sources(case, names, increments[None], interval, model, t0, refused)
    if "nhc" in names:
        end = t0 + increments.shape[0] * interval
        mounting = mounting_matrix(case["mounting_roll"], case["mounting_pitch"], case["mounting_heading"])
        arm = (case["wheel_lever_arm_x"], case["wheel_lever_arm_y"], case["wheel_lever_arm_z"])
        built.append(sources.vehicle_source(sources.stop_epochs([(t0, end)], case["odometer_rate"]), None, model,
                                            lever_arm=arm, mounting=mounting, constraint_sigma=case["nhc_sigma"]))
    return built


def _stop_sources(case: Case, names, increments: np.ndarray, interval: float, model: FilterModel, t0: float,
                  given) -> list[sources.Source]:
    """ZUPT and ZARU sources at the case's stops (``given()`` supplies ``stops_from trajectory``; found ones are shifted
    by t0, the record's start)."""
    if "zupt" not in names and "zaru" not in names:
        return []
    if case["stop_intervals"] is not None:
        stops = [(start, start + length) for start, length in case["stop_intervals"]]
    elif case["stops_from"] == "trajectory":
        stops = given()
    else:
        if increments.shape[0] > 1 and not np.array_equal(increments[0], increments[-1]):
            raise InvalidParameter("stops_from", "stops found in the IMU data are one record's: run the members "
                                                 "one by one or take the trajectory's (`stops_from` trajectory)")
        noise = math.sqrt(interval)
        stops = [(t0 + start, t0 + end) for start, end in
                 sources.detect_stops(increments[0], interval, float(np.max(model.angle_random_walk)) / noise,
                                      float(np.max(model.velocity_random_walk)) / noise)]
    times = sources.stop_epochs(stops, case["zupt_rate"])
    built = []
    if "zupt" in names:
        built.append(sources.zero_velocity_source(times, case["zupt_sigma"], model))
    if "zaru" in names:
        built.append(sources.zero_rate_source(times, case["zaru_sigma"], model))
    return built
