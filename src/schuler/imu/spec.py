"""Error models from spec-sheet figures: the TOML spec-file format and the grade presets.

A spec file writes the figures as data sheets do, units included; every value
is converted to SI through :mod:`schuler.units` (so "0.125 deg/sqrt(h)",
"7.5 deg/h/sqrt(Hz)" and "3.6361e-5 rad/s^0.5" are the same number). A bare
number is taken in the key's display unit (the table below). Unknown keys are
refused with a suggestion; a per-axis value is one string for all three axes
or a list of three.

.. code-block:: toml

    name = "my tactical IMU"
    source = "Vendor X data sheet rev. C"

    [gyro]
    bias = "1 deg/h"                      # 1-sigma turn-on bias
    bias_instability = "0.3 deg/h"       # B (IEEE 952), flicker
    flicker_tau_range = ["1 s", "1000 s"]
    gm_sigma = "0 deg/h"                 # optional first-order Gauss-Markov bias
    gm_correlation_time = "300 s"
    random_walk = "0.125 deg/sqrt(h)"    # N (ARW); "7.5 deg/h/sqrt(Hz)" is the same
    rate_random_walk = "0 deg/h/sqrt(h)" # K
    quantization_step = "0.1 arcsec"     # or quantization = Q = step / sqrt(12)
    scale_factor = "150 ppm"
    misalignment = "0.5 mrad"            # each off-diagonal entry, or a 3 x 3 list
    g_sensitivity = "1 deg/h/g"          # each entry, or a 3 x 3 list

    [accel]
    bias = ["1 mg", "1 mg", "2 mg"]
    bias_instability = "50 ug"
    random_walk = "0.065 ft/s/sqrt(h)"   # N (VRW); "120 ug/sqrt(Hz)" works too
    scale_factor = "300 ppm"

Display units (bare numbers): see :data:`GYRO_UNITS` and :data:`ACCEL_UNITS`.
"""

from __future__ import annotations

import difflib
import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from schuler.exceptions import InvalidParameter, ScenarioError
from schuler.imu.error_model import ErrorModel, SensorErrors
from schuler.units import parse_quantity

GYRO_UNITS: dict[str, str] = {
    "bias": "deg/h", "bias_instability": "deg/h", "flicker_tau_range": "s", "gm_sigma": "deg/h",
    "gm_correlation_time": "s", "random_walk": "deg/h^0.5", "rate_random_walk": "deg/h^1.5",
    "quantization": "arcsec", "quantization_step": "arcsec", "scale_factor": "ppm", "misalignment": "mrad",
    "g_sensitivity": "deg/h/g",
}
"""Spec-file keys of the [gyro] table and the unit of a bare number."""

ACCEL_UNITS: dict[str, str] = {
    "bias": "ug", "bias_instability": "ug", "flicker_tau_range": "s", "gm_sigma": "ug",
    "gm_correlation_time": "s", "random_walk": "m/s/h^0.5", "rate_random_walk": "m/s/h^1.5",
    "quantization": "m/s", "quantization_step": "m/s", "scale_factor": "ppm", "misalignment": "mrad",
}
"""Spec-file keys of the [accel] table and the unit of a bare number."""

_FIELD = {"flicker_tau_range": "flicker_tau_range_s", "gm_correlation_time": "gm_correlation_time_s"}
_TOP_LEVEL = ("name", "source", "notes", "gyro", "accel")


def _unknown(key: str, allowed, where: str) -> InvalidParameter:
    close = difflib.get_close_matches(key, list(allowed), n=1)
    hint = f"; did you mean {close[0]!r}?" if close else f"; allowed: {', '.join(allowed)}"
    return InvalidParameter(f"{where}{key}", f"unknown key{hint}")


def _parse_values(value, unit: str, name: str, shape: tuple[int, ...]) -> np.ndarray:
    if isinstance(value, list):
        rows = [_parse_values(v, unit, f"{name}[{i}]", shape[1:]) for i, v in enumerate(value)]
        if len(rows) != shape[0]:
            raise InvalidParameter(name, f"give one value or {shape[0]} (one per axis), got {len(rows)}")
        return np.array(rows)
    number = parse_quantity(value, unit, name=name)
    if number < 0:
        raise InvalidParameter(name, f"{value!r} must be >= 0 (a 1-sigma magnitude or a density)")
    return np.full(shape, number) if shape else np.array(number)


def sensor_errors_from_spec(table: dict, sensor: str) -> SensorErrors:
    """A :class:`SensorErrors` from a spec-file table (``sensor`` is "gyro" or "accel", used in messages).

    Parameters
    ----------
    table : dict
        The ``[gyro]`` or ``[accel]`` table: figures as strings with their units ("0.125 deg/sqrt(h)").
    sensor : {"gyro", "accel"}
    """
    units = GYRO_UNITS if sensor == "gyro" else ACCEL_UNITS
    if not isinstance(table, dict):
        raise InvalidParameter(sensor, "must be a table of figures")
    values: dict[str, Any] = {}  # SensorErrors fields: arrays, or the flicker range as a pair
    for key, value in table.items():
        if key not in units:
            raise _unknown(key, units, f"{sensor}.")
        name = f"{sensor}.{key}"
        if key == "flicker_tau_range":
            if not (isinstance(value, list) and len(value) == 2):
                raise InvalidParameter(name, "must be [low, high], e.g. [\"1 s\", \"1000 s\"]")
            values[_FIELD[key]] = tuple(parse_quantity(v, "s", name=name) for v in value)
            continue
        if key in ("misalignment", "g_sensitivity"):
            parsed = _parse_values(value, units[key], name, (3, 3) if isinstance(value, list) else ())
            if parsed.ndim == 0 and key == "misalignment":
                parsed = float(parsed) * (1.0 - np.eye(3))
            elif parsed.ndim == 0:
                parsed = np.full((3, 3), float(parsed))
            values[key] = parsed
            continue
        values[_FIELD.get(key, key)] = _parse_values(value, units[key], name, (3,))
    if "quantization" in values and "quantization_step" in values:
        raise InvalidParameter(f"{sensor}.quantization_step", "give quantization (Q) or quantization_step, not both")
    if "quantization_step" in values:
        values["quantization"] = values.pop("quantization_step") / math.sqrt(12.0)
    return SensorErrors(**values)


def error_model_from_spec(spec: dict, name: str = "custom") -> ErrorModel:
    """An :class:`ErrorModel` from a parsed spec (a dict as TOML gives it).

    Parameters
    ----------
    spec : dict
        The parsed spec file (figures as strings with their units).
    name : str
        Name of the model.
    """
    for key in spec:
        if key not in _TOP_LEVEL:
            raise _unknown(key, _TOP_LEVEL, "")
    notes = spec.get("notes", ())
    notes = (notes,) if isinstance(notes, str) else tuple(str(n) for n in notes)
    return ErrorModel(gyro=sensor_errors_from_spec(spec.get("gyro", {}), "gyro"),
                      accel=sensor_errors_from_spec(spec.get("accel", {}), "accel"),
                      name=str(spec.get("name", name)), source=str(spec.get("source", "")), notes=notes)


def load_spec_file(path) -> ErrorModel:
    """Read a TOML spec file (format in the module notes).

    Parameters
    ----------
    path : str or Path
        The TOML spec file.

    Raises
    ------
    ScenarioError
        The file is missing or not TOML.
    InvalidParameter
        An unknown key (with a suggestion), a unit of the wrong kind, a negative figure.
    """
    path = Path(path)
    try:
        text = path.read_bytes().decode("utf-8-sig")
    except OSError as error:
        raise ScenarioError(f"{path.name}: cannot read ({error.strerror or error})") from None
    except UnicodeDecodeError:
        raise ScenarioError(f"{path.name}: a spec file must be UTF-8 text") from None
    try:
        spec = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ScenarioError(f"{path.name}: not valid TOML ({error})") from None
    try:
        return error_model_from_spec(spec, name=path.stem)
    except InvalidParameter as error:
        raise InvalidParameter(error.name, f"{error.reason} (in {path.name})") from None


PRESET_SPECS: dict[str, dict] = {
    "navigation": {
        "name": "navigation grade (ring-laser gyro IMU)",
        "source": "Honeywell HG9900 Inertial Measurement Unit, product brochure N61-1638-000-000: gyro bias "
                  "0.0035 deg/h, ARW 0.002 deg/sqrt(h), gyro scale factor 5 ppm; accelerometer bias 25 ug, "
                  "scale factor 100 ppm (typical figures, 1 sigma)",
        "notes": ["assumed, not in the brochure: gyro bias instability 0.001 deg/h, misalignment 0.01 mrad; "
                  "accelerometer noise 10 ug/sqrt(Hz), bias instability 5 ug, misalignment 0.01 mrad"],
        "gyro": {"bias": "0.0035 deg/h", "random_walk": "0.002 deg/sqrt(h)", "scale_factor": "5 ppm",
                 "bias_instability": "0.001 deg/h", "misalignment": "0.01 mrad"},
        "accel": {"bias": "25 ug", "scale_factor": "100 ppm", "random_walk": "10 ug/sqrt(Hz)",
                  "bias_instability": "5 ug", "misalignment": "0.01 mrad"},
    },
    "tactical": {
        "name": "tactical grade (ring-laser gyro IMU)",
        "source": "Honeywell HG1700 Inertial Measurement Unit, product brochure N61-1619-000-001: gyro bias 1 deg/h, "
                  "ARW 0.125 deg/sqrt(h); accelerometer bias 1 mg, VRW 0.065 ft/s/sqrt(h) (typical figures, 1 sigma)",
        "notes": ["assumed, not in the brochure: gyro bias instability 0.3 deg/h, scale factor 150 ppm, misalignment "
                  "0.5 mrad; accelerometer bias instability 50 ug, scale factor 300 ppm, misalignment 0.5 mrad"],
        "gyro": {"bias": "1 deg/h", "random_walk": "0.125 deg/sqrt(h)", "bias_instability": "0.3 deg/h",
                 "scale_factor": "150 ppm", "misalignment": "0.5 mrad"},
        "accel": {"bias": "1 mg", "random_walk": "0.065 ft/s/sqrt(h)", "bias_instability": "50 ug",
                  "scale_factor": "300 ppm", "misalignment": "0.5 mrad"},
    },
    "industrial": {
        "name": "industrial grade (MEMS module)",
        "source": "Xsens MTi 1-series data sheet: gyro in-run bias stability 10 deg/h, noise density "
                  "0.007 deg/s/sqrt(Hz); accelerometer in-run bias stability 0.03 mg, noise density 120 ug/sqrt(Hz) "
                  "(typical figures)",
        "notes": ["in-run bias stability is read as B (IEEE 952)",
                  "assumed, not in the data sheet: gyro turn-on bias 0.1 deg/s, scale factor 1000 ppm, "
                  "misalignment 1 mrad, g-sensitivity 0.01 deg/s/g; accelerometer turn-on bias 5 mg, "
                  "scale factor 1000 ppm, misalignment 1 mrad"],
        "gyro": {"bias_instability": "10 deg/h", "random_walk": "0.007 deg/s/sqrt(Hz)", "bias": "0.1 deg/s",
                 "scale_factor": "1000 ppm", "misalignment": "1 mrad", "g_sensitivity": "0.01 deg/s/g"},
        "accel": {"bias_instability": "0.03 mg", "random_walk": "120 ug/sqrt(Hz)", "bias": "5 mg",
                  "scale_factor": "1000 ppm", "misalignment": "1 mrad"},
    },
    "consumer": {
        "name": "consumer MEMS (smartphone-class)",
        "source": "InvenSense MPU-6000/MPU-6050 Product Specification PS-MPU-6000A-00 rev. 3.4: gyro rate noise "
                  "0.005 deg/s/sqrt(Hz), initial zero-rate output +/-20 deg/s, linear acceleration sensitivity "
                  "0.1 deg/s/g, scale factor +/-3 %, cross-axis +/-2 %; accelerometer noise 400 ug/sqrt(Hz), "
                  "zero-g offset +/-50 mg (x, y), +/-80 mg (z), scale factor +/-3 %, cross-axis +/-2 % (typical)",
        "notes": ["the +/- tolerances are taken as 1 sigma (conservative)",
                  "assumed, not in the data sheet: bias instability 10 deg/h (gyro) and 0.1 mg (accelerometer)"],
        "gyro": {"random_walk": "0.005 deg/s/sqrt(Hz)", "bias": "20 deg/s", "g_sensitivity": "0.1 deg/s/g",
                 "scale_factor": "3 percent", "misalignment": "20 mrad", "bias_instability": "10 deg/h"},
        "accel": {"random_walk": "400 ug/sqrt(Hz)", "bias": ["50 mg", "50 mg", "80 mg"], "scale_factor": "3 percent",
                  "misalignment": "20 mrad", "bias_instability": "0.1 mg"},
    },
}
"""The grade presets as spec files would write them, with their sources (figures are "typical")."""

GRADES = tuple(PRESET_SPECS)
"""Grade names, best first."""


def preset(grade: str) -> ErrorModel:
    """The :class:`ErrorModel` of a grade: navigation, tactical, industrial or consumer.

    Parameters
    ----------
    grade : {"navigation", "tactical", "industrial", "consumer"}

    Examples
    --------
    >>> float(preset("tactical").gyro.random_walk[0])   # 0.125 deg/sqrt(h) in rad/sqrt(s)
    3.6361026e-05
    """
    if grade not in PRESET_SPECS:
        close = difflib.get_close_matches(str(grade), GRADES, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise InvalidParameter("grade", f"{grade!r} is not one of {', '.join(GRADES)}{hint}")
    return error_model_from_spec(PRESET_SPECS[grade], name=grade)
