"""Which systems exist, and how to get one: :func:`get_system`.

Each system subpackage defines ``SYSTEM`` (a :class:`~schuler.contract.System`)
in its ``api`` module; :func:`get_system` imports it on demand so the command
line starts fast.
"""

from __future__ import annotations

import difflib
import importlib
from typing import TYPE_CHECKING

from schuler.exceptions import InvalidParameter

if TYPE_CHECKING:  # the systems are imported on demand, so ``import schuler`` stays light
    from schuler.contract import System

SYSTEM_MODULES: dict[str, str] = {
    "errors": "schuler.navigation_errors.api",
    "vertical": "schuler.gyro_vertical.api",
    "calibrate": "schuler.drift_calibration.api",
    "align": "schuler.gyrocompassing.api",
    "north": "schuler.ground_gyrocompass.api",
    "imu": "schuler.imu.api",
    "navigate": "schuler.navigate.api",
    "mission": "schuler.mission.api",
    "aided": "schuler.aided.api",
}
"""Command name of each system -> module holding its ``SYSTEM``: the one line that registers a system."""

SUMMARIES: dict[str, str] = {
    "errors": "Schuler-tuned INS error propagation (Bollay).",
    "vertical": "Gyro vertical with integral correction (Drozdovich).",
    "calibrate": "Gyro drift calibration by alternating torque pulses.",
    "align": "Physical gyrocompassing of a platform INS.",
    "north": "Ground gyrocompass during rotor run-down.",
    "imu": "IMU recordings, spec-sheet error models and Allan variance.",
    "navigate": "Nonlinear strapdown or platform INS on WGS-84.",
    "mission": "Calibrate, align, navigate: a mission's error budget.",
    "aided": "The INS aided by GNSS through outages (error-state Kalman filter).",
}
"""Short help of each system for ``schuler --help`` (so the help imports no system); a system without one shows
its ``title``."""


def list_systems() -> list[str]:
    """The names of the registered systems, in the order of the command line (``schuler --help``).

    Examples
    --------
    >>> list_systems()[:3]
    ['errors', 'vertical', 'calibrate']
    """
    return list(SYSTEM_MODULES)


def get_system(name: str) -> System:
    """The :class:`~schuler.contract.System` registered under ``name``.

    Parameters
    ----------
    name : str
        Command name of the system (a key of :data:`SYSTEM_MODULES`).

    Examples
    --------
    >>> get_system("align").name
    'align'
    >>> get_system("allign")
    Traceback (most recent call last):
    ...
    schuler.exceptions.InvalidParameter: system: 'allign' is not a system; did you mean 'align'?
    choose from errors, vertical, calibrate, align, north, imu, navigate, mission, aided
    """
    if name not in SYSTEM_MODULES:
        hint = difflib.get_close_matches(str(name), SYSTEM_MODULES, n=1)
        suggestion = f"did you mean {hint[0]!r}? " if hint else ""
        raise InvalidParameter("system",
                               f"{name!r} is not a system; {suggestion}choose from {', '.join(SYSTEM_MODULES)}")
    return importlib.import_module(SYSTEM_MODULES[name]).SYSTEM
