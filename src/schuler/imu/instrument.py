"""An IMU for the other systems: ``--imu GRADE|SPEC.toml|RECORD`` on align, calibrate, north, errors and vertical
runs.

The seed systems take their instrument errors as numbers; this module turns an
IMU (a grade preset, a TOML spec file, or a recording whose identified noise
terms become a model, :func:`~schuler.imu.characterise.model_from_analysis`)
into those numbers with the one mapping of :mod:`~schuler.imu.system_inputs`,
and merges them into a case: **values the user gave explicitly win** over the
IMU's. It lives here, at the IMU layer, so that the seed systems never import
``schuler.imu`` (they stay independent); the command line and scenario files
call :func:`apply_instrument`.

The mapping (SI; every body-axis error at +1 sigma, drift = -(gyro bias);
platform x, y, z = body y, x, -z; see :mod:`~schuler.imu.system_inputs`):

========== =====================================================================
system     parameters set from the IMU
========== =====================================================================
align      ``drift_east``, ``drift_north`` (resolved with the case's ``azimuth``
           as the heading), ``drift_z``: residual gyro drift after calibration,
           sqrt(2) x the slow terms' Allan deviation over ``imu_window``;
           ``accel_bias_x``, ``accel_bias_y``: turn-on bias plus its change;
           ``sigma_drift``, ``sigma_drift_z``, ``sigma_accel`` for Monte Carlo
calibrate  ``drift_x``, ``drift_y``: the whole turn-on drift (what calibration
           measures); ``angle_random_walk``
north      ``readout_noise`` = sqrt(Q^2 + N^2 h), z gyro, h = the case's ``output_step``
errors     ``magnitude`` of the case's ``source`` (drift and accelerometer
           residuals, tilt = bias / g, azimuth from the static gyrocompassing
           limit at ``imu_latitude``, velocity 0)
vertical   ``drift_x``, ``drift_y``: residual gyro drift after calibration over
           ``imu_window`` (housing x, y = body y, x); ``accel_bias_x``,
           ``accel_bias_y``: turn-on bias plus its change
========== =====================================================================
"""

from __future__ import annotations

import math
from pathlib import Path

from schuler.exceptions import InvalidParameter, renamed_keywords
from schuler.imu.error_model import ErrorModel
from schuler.imu.spec import GRADES, load_spec_file, preset
from schuler.imu.system_inputs import (
    DEFAULT_WINDOW_S,
    SystemInputs,
    align_inputs,
    calibrate_inputs,
    errors_inputs,
    north_inputs,
    vertical_inputs,
)
from schuler.params import Case, Parameter, ParameterSet

IMU_SYSTEMS = ("align", "calibrate", "north", "errors", "vertical")
"""The systems whose runs take ``--imu``."""

IMU_OPTION = Parameter("imu", "", None, "IMU whose errors set this run's instrument parameters: a grade ("
                       + ", ".join(GRADES) + "), a TOML spec file or a recording (.csv, .imu, .parquet; its "
                       "identified noise terms). Options given explicitly win.", kind="text")
WINDOW_OPTION = Parameter("imu_window", "s", None, "With --imu: time between the gyro calibration and use; the "
                          "residual drift is the bias change over it (not set: 600 s).", minimum=1e-3, maximum=1e7)
LATITUDE_OPTION = Parameter("imu_latitude", "deg", None, "With --imu: latitude of the azimuth source's static "
                            "gyrocompassing limit (not set: 45 deg).", minimum=-89, maximum=89)

DEFAULT_LATITUDE = math.radians(45.0)
"""Latitude of ``errors``' azimuth magnitude when ``imu_latitude`` is not set, rad."""


def instrument_options(system: str) -> ParameterSet:
    """The options ``system``'s run gets from the IMU layer (empty when it has none).

    Parameters
    ----------
    system : str
        A system's name; only those of :data:`IMU_SYSTEMS` get options.

    Returns
    -------
    ParameterSet
        ``imu``, plus ``imu_window`` (align, errors, vertical) and ``imu_latitude`` (errors).
    """
    if system not in IMU_SYSTEMS:
        return ParameterSet((), owner=system)
    options = [IMU_OPTION]
    if system in ("align", "errors", "vertical"):
        options.append(WINDOW_OPTION)
    if system == "errors":
        options.append(LATITUDE_OPTION)
    return ParameterSet(options, owner=system)


def resolve_model(text: str, base: Path | None = None) -> ErrorModel:
    """The IMU a ``--imu`` value names: a grade, a ``.toml`` spec file, or a recording's identified terms.

    Parameters
    ----------
    text : str
        Grade name or file path.
    base : Path, optional
        Folder relative paths start from (a scenario's folder); default: the current one.
    """
    text = str(text).strip()
    if text.lower() in GRADES:
        return preset(text.lower())
    path = Path(text)
    if base is not None and not path.is_absolute():
        path = base / path
    if not path.is_file():
        raise InvalidParameter("imu", f"{text!r} is neither a grade ({', '.join(GRADES)}) nor an existing file "
                               "(a .toml spec, or a recording .csv, .imu or .parquet)")
    if path.suffix.lower() == ".toml":
        return load_spec_file(path)
    # the Allan machinery (numba kernels) is imported only for a recording: every seed system's command builds --imu
    from schuler.imu.characterise import analyse_file, model_from_analysis

    return model_from_analysis(analyse_file(path), name=f"identified from {path.name}")


@renamed_keywords(latitude_rad="latitude", window_s="window")
def system_inputs(system: str, model: ErrorModel, case: Case, *, window: float | None = None,
                  latitude: float | None = None) -> SystemInputs:
    """The mapping for one system: :mod:`~schuler.imu.system_inputs` with what it needs from the case.

    Parameters
    ----------
    system : {"align", "calibrate", "north", "errors", "vertical"}
        The system whose parameters the IMU sets.
    model : ErrorModel
        The IMU, SI.
    case : Case
        The system's case, SI: align uses its ``azimuth`` (rad), north its ``output_step`` (s), errors its
        ``source``.
    window : float, optional
        Time between the gyro calibration and use, s (align, errors, vertical; not set: 600 s).
    latitude : float, optional
        Latitude of the errors system's static gyrocompassing limit, rad (not set: 45 deg).

    Returns
    -------
    SystemInputs
        The system's parameter values and Monte Carlo sigmas, SI, with their units and notes.
    """
    window = DEFAULT_WINDOW_S if window is None else window
    if system == "align":
        return align_inputs(model, heading=case["azimuth"], window=window)
    if system == "calibrate":
        return calibrate_inputs(model)
    if system == "north":
        return north_inputs(model, step=case["output_step"])
    if system == "errors":
        inputs = errors_inputs(model, latitude=DEFAULT_LATITUDE if latitude is None else latitude,
                               window=window)
        source = case["source"]
        return SystemInputs("errors", inputs.model, {"magnitude": inputs.values[source]},
                            {"magnitude": inputs.sigmas.get(source, 0.0)},
                            {"magnitude": inputs.parameter_units[source]}, [f"source {source}", *inputs.notes])
    if system == "vertical":
        return vertical_inputs(model, window=window)
    raise InvalidParameter("imu", f"applies to {', '.join(IMU_SYSTEMS)} runs, not {system}")


@renamed_keywords(window_s="window", latitude_rad="latitude")
def apply_instrument(system: str, parameters: ParameterSet, case: Case, imu: str, *, window: float | None = None,
                     latitude: float | None = None, base: Path | None = None) -> tuple[Case, SystemInputs]:
    """The case with the IMU's values for every parameter the user did not give, and the mapping used.

    Parameters
    ----------
    system : {"align", "calibrate", "north", "errors", "vertical"}
        The system being run.
    parameters : ParameterSet
        The system's parameters (the merged case is validated against them).
    case : Case
        The case as the user gave it, SI; its ``given`` names win over the IMU's values.
    imu : str
        A grade name, a ``.toml`` spec file or a recording (``.csv``, ``.imu``, ``.parquet``).
    window : float, optional
        Time between the gyro calibration and use, s (not set: 600 s).
    latitude : float, optional
        Latitude of the errors system's static gyrocompassing limit, rad (not set: 45 deg).
    base : Path, optional
        Folder relative paths in ``imu`` start from (a scenario's folder); default: the current one.

    Returns
    -------
    case, inputs : Case, SystemInputs
        The merged, validated case and the mapping used.

    Raises
    ------
    InvalidParameter
        ``imu`` names nothing usable, or a mapped value lies outside the
        system's range (named with the parameter, e.g. a consumer MEMS drift
        beyond calibrate's 3600 deg/h).
    """
    model = resolve_model(imu, base)
    inputs = system_inputs(system, model, case, window=window, latitude=latitude)
    given = {name: case[name] for name in case.given}
    merged = {**{k: v for k, v in inputs.values.items() if k not in case.given}, **given}
    try:
        return parameters.case(merged), inputs
    except InvalidParameter as error:
        if error.name in given:
            raise
        raise InvalidParameter("imu", f"{imu}: {error.name} from the IMU ({error.reason}); give --"
                               f"{error.name.replace('_', '-')} explicitly or choose another IMU") from None


def apply_options(system: str, parameters: ParameterSet, case: Case, options: Case) -> Case:
    """:func:`apply_instrument` with the options of :func:`instrument_options` as one case: a system's hook.

    ``System(instrument=partial(apply_options, "align"), ...)`` lets
    ``run(imu="tactical")`` set the case exactly as ``--imu tactical`` does.

    Parameters
    ----------
    system : {"align", "calibrate", "north", "errors", "vertical"}
        The system being run.
    parameters : ParameterSet
        The system's parameters.
    case : Case
        The case as the user gave it, SI.
    options : Case
        ``imu`` (a grade, spec file or recording) and, where the system has them, ``imu_window`` (s) and
        ``imu_latitude`` (rad).
    """
    merged, _ = apply_instrument(system, parameters, case, options["imu"], window=options.get("imu_window"),
                                 latitude=options.get("imu_latitude"))
    return merged
