"""Waypoint profiles in TOML: the file format, its validation, and the :class:`WaypointProfile` it builds.

Format
------
A profile gives the start position and a list of waypoints; between two
waypoints the speed, heading and flight-path angle move from one value to the
next along a C^2 quintic blend (:class:`~schuler.navigate.trajectory.WaypointProfile`).
Values are numbers in the unit shown, or strings with any unit of the right
kind ("45 deg", "0.5 mi/s", "10 min"). Unknown keys are errors.

.. code-block:: toml

    name = "climb and turn"        # optional label

    [start]
    latitude = 45.0                # deg (required), within +/-89
    longitude = 7.0                # deg (default 0)
    height = 1000.0                # m above the ellipsoid (default 0)

    [[waypoint]]
    time = 0.0                     # s; the first waypoint is at 0
    speed = 200.0                  # m/s ground speed
    heading = 0.0                  # deg clockwise from north; not wrapped (350 -> 370 turns right 20 deg)
    flight_path_angle = 0.0        # deg, climb positive (default 0)

    [[waypoint]]
    time = "5 min"
    speed = 250.0
    heading = 90.0
    flight_path_angle = 5.0

Times increase strictly; the profile holds the last waypoint's values after
its time. The vehicle banks for coordinated turns and pitches with its flight
path.

Examples
--------
>>> profile = parse_profile({"start": {"latitude": 45.0},
...                          "waypoint": [{"time": 0, "speed": 100, "heading": 0},
...                                       {"time": "1 min", "speed": 100, "heading": 90}]})
>>> profile.duration, round(float(np.degrees(profile.headings[-1])))
(60.0, 90)
>>> parse_profile({"start": {"latitude": 45.0}, "waypoint": [{"time": 0, "speed": 1, "headng": 0}]})
Traceback (most recent call last):
...
schuler.exceptions.InvalidParameter: waypoint[1].headng: unknown key; allowed: time, speed, heading, flight_path_angle
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np

from schuler.exceptions import InvalidParameter
from schuler.navigate.trajectory import WaypointProfile
from schuler.units import parse_quantity

_START_KEYS = {"latitude": ("deg", None), "longitude": ("deg", 0.0), "height": ("m", 0.0)}
_WAYPOINT_KEYS = {"time": ("s", None), "speed": ("m/s", None), "heading": ("deg", None),
                  "flight_path_angle": ("deg", 0.0)}
_TOP_KEYS = ("name", "start", "waypoint")


def _table(data, name: str) -> dict:
    if not isinstance(data, dict):
        raise InvalidParameter(name, f"must be a table, got {type(data).__name__}")
    return data


def _values(table: dict, keys: dict, where: str) -> dict[str, float]:
    unknown = [key for key in table if key not in keys]
    if unknown:
        raise InvalidParameter(f"{where}.{unknown[0]}", f"unknown key; allowed: {', '.join(keys)}")
    values = {}
    for key, (unit, default) in keys.items():
        if key not in table:
            if default is None:
                raise InvalidParameter(f"{where}.{key}", "missing (required)")
            values[key] = parse_quantity(default, unit, name=f"{where}.{key}")
            continue
        value = table[key]
        if isinstance(value, bool) or not isinstance(value, (int, float, str)):
            raise InvalidParameter(f"{where}.{key}", f"must be a number or a quantity string, got {value!r}")
        values[key] = parse_quantity(value, unit, name=f"{where}.{key}")
    return values


def parse_profile(data: dict) -> WaypointProfile:
    """Build a :class:`WaypointProfile` from parsed TOML data (format in the module docstring).

    Parameters
    ----------
    data : dict
        The profile's tables as :mod:`tomllib` reads them: values are numbers in the
        display units of the format (deg, m, s, m/s) or quantity strings with their own unit.

    Returns
    -------
    WaypointProfile
        The trajectory, SI (rad, m, s, m/s).

    Raises
    ------
    InvalidParameter
        Naming the offending key (``start.latitude``, ``waypoint[3].time`` ...).
    """
    data = _table(data, "profile")
    unknown = [key for key in data if key not in _TOP_KEYS]
    if unknown:
        raise InvalidParameter(unknown[0], f"unknown key; allowed: {', '.join(_TOP_KEYS)}")
    name = data.get("name", "profile")
    if not isinstance(name, str):
        raise InvalidParameter("name", f"must be a string, got {name!r}")
    if "start" not in data:
        raise InvalidParameter("start", "missing (required): a [start] table with the latitude")
    start = _values(_table(data["start"], "start"), _START_KEYS, "start")
    waypoints = data.get("waypoint")
    if not isinstance(waypoints, list) or not waypoints:
        raise InvalidParameter("waypoint", "missing: give at least one [[waypoint]] table")
    rows = [_values(_table(w, f"waypoint[{i}]"), _WAYPOINT_KEYS, f"waypoint[{i}]")
            for i, w in enumerate(waypoints, start=1)]
    times = [row["time"] for row in rows]
    if times[0] != 0.0:
        raise InvalidParameter("waypoint[1].time", f"the first waypoint must be at 0 s, got {times[0]:g} s")
    for i in range(1, len(times)):
        if times[i] <= times[i - 1]:
            raise InvalidParameter(f"waypoint[{i + 1}].time", f"{times[i]:g} s does not follow {times[i - 1]:g} s: "
                                                              "times must increase strictly")
    for i, row in enumerate(rows, start=1):
        if not 0.0 <= row["speed"] <= 1.0e4:
            raise InvalidParameter(f"waypoint[{i}].speed", f"must lie in [0, 10] km/s, got {row['speed']:g} m/s")
        if abs(row["flight_path_angle"]) >= np.radians(60.0):
            raise InvalidParameter(f"waypoint[{i}].flight_path_angle", "must lie within +/-60 deg")
    return WaypointProfile(
        latitude=start["latitude"], longitude=start["longitude"], height=start["height"],
        times=np.array(times), speeds=np.array([row["speed"] for row in rows]),
        headings=np.array([row["heading"] for row in rows]),
        flight_path_angles=np.array([row["flight_path_angle"] for row in rows]), name=name)


def load_profile(path) -> WaypointProfile:
    """Read a waypoint profile from a TOML file.

    Parameters
    ----------
    path : str or Path
        The profile file, TOML (format in the module docstring).

    Returns
    -------
    WaypointProfile
        The trajectory, SI (rad, m, s, m/s).

    Raises
    ------
    InvalidParameter
        If the file cannot be read or parsed (``trajectory``), or a key is wrong.
    """
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as error:
        raise InvalidParameter("trajectory", f"cannot read {path}: {error.strerror or error}") from None
    except tomllib.TOMLDecodeError as error:
        raise InvalidParameter("trajectory", f"{path} is not valid TOML: {error}") from None
    return parse_profile(data)
